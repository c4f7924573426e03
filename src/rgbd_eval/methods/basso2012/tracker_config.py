"""Parameters of the basso2012 tracker (seed 000, chapter 6; defaults from Table 6.1)."""

from __future__ import annotations

import enum
import math
from typing import Literal

from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig


class ClusterSelection(enum.Enum):
    """Which detections reach the tracker (seed 000, Table 7.4)."""

    HEIGHT = "height"
    CONFIDENCE = "confidence"


#: Longest track-management duration accepted (about 11.6 days): beyond it the
#: nanosecond stamps the tracker compares overflow (a tiny reference_rate_hz did).
MAX_DURATION_S = 1e6


class Basso2012TrackerConfig(ComponentConfig):
    """The basso2012 tracker (seed 000, chapter 6; defaults from Table 6.1).

    Frame counts are given at ``reference_rate_hz`` (the Kinect's 30 Hz) and
    converted to seconds, so that they mean the same time at any frame rate:
    ``frames_before_old: 90`` is 3 s.
    """

    name: Literal["basso2012"] = "basso2012"
    gate_distance_probability: float = Field(
        0.999, gt=0.0, lt=1.0, description="Table 6.1 ~kalman/gate_distance_probability"
    )
    acceleration_variance: float = Field(
        4.0, gt=0.0, description="Table 6.1 ~kalman/acceleration_variance (m^2/s^4)"
    )
    depth_noise_coefficient: float = Field(
        0.001425,
        ge=0.0,
        le=0.1,
        description="Kinect depth error sigma = k * d^2 (m), Figure 6.1; k from Khoshelham & Elberink 2012",
    )
    # Each track's classifier holds a selectors x weak_classifiers matrix (8 bytes a cell):
    # the bounds, ten times Table 6.1's values, keep it under 10 MB a track.
    weak_classifiers: int = Field(
        250, ge=1, le=2500, description="Table 6.1 ~recovery/weak_classifiers"
    )
    selectors: int = Field(50, ge=1, le=500, description="Table 6.1 ~recovery/selectors")
    min_prediction: float = Field(9.0, description="Table 6.1 ~recovery/min_prediction")
    min_confidence: float = Field(-0.5, description="Table 6.1 ~target/min_confidence")
    frames_before_old: int = Field(90, ge=0, description="Table 6.1 ~target/frames_before_old")
    frames_before_fake: int = Field(60, ge=1, description="Table 6.1 ~target/frames_before_fake")
    frames_remain_new: int = Field(30, ge=0, description="Table 6.1 ~target/frames_remain_new")
    detections_to_validate: int = Field(
        3, ge=1, description="Table 6.1 ~target/detections_to_validate"
    )
    reference_rate_hz: float = Field(30.0, gt=0.0, description="rate the frame counts refer to")
    classifier: bool = Field(True, description="online classifier on/off (Table 7.5)")
    classifier_memory_s: float | None = Field(
        None,
        ge=0.0,
        description="how long a lost track's classifier is kept (Figure 7.7); "
        "default frames_before_old / reference_rate_hz",
    )
    selection: ClusterSelection = Field(
        ClusterSelection.HEIGHT, description="cluster selection (Table 7.4)"
    )
    selection_confidence: float = Field(
        -3.0, description="HOG threshold when selection is 'confidence' (7.3)"
    )
    seed: int = Field(0, ge=0, description="seed of the classifier's random features")
    initial_velocity_variance: float = Field(
        1.0,
        gt=0.0,
        description="variance (m^2/s^2) of a new track's unknown velocity; not given in "
        "seed 000 (6.1): 1 m/s standard deviation covers walking speeds",
    )
    classifier_learning_rate: float = Field(
        0.05,
        gt=0.0,
        le=1.0,
        description="floor of the gain of the weak classifiers' running class means "
        "(seed 000 6.5.3 follows Grabner and Bischof [13]; the value is not given)",
    )
    static_devalidation_s: float | None = Field(
        None,
        gt=0.0,
        le=600.0,
        description="beyond the thesis, off by default: discard a validated track whose "
        "detections for this many seconds all scored below static_max_confidence and stayed "
        "within static_motion_m of their mean (a track held by a coat stand or a plant)",
    )
    static_max_confidence: float = Field(
        -1.5,
        description="for static_devalidation_s, a detection scoring below this is 'not a "
        "person': the detector's threshold, Table 5.1 ~people/min_confidence",
    )
    static_motion_m: float = Field(
        0.3,
        gt=0.0,
        le=5.0,
        description="largest distance (m) from the window's mean position that counts as "
        "not moving, for static_devalidation_s",
    )

    @model_validator(mode="after")
    def _check(self) -> Basso2012TrackerConfig:
        if self.selectors > self.weak_classifiers:
            raise ValueError(
                f"selectors={self.selectors} must not exceed weak_classifiers={self.weak_classifiers}"
            )
        durations = {}
        for name in ("frames_before_old", "frames_before_fake", "frames_remain_new"):
            try:
                durations[name] = self.seconds(getattr(self, name))
            except OverflowError:  # a frame count beyond float range
                durations[name] = math.inf
        durations["classifier_memory_s"] = self.classifier_memory_s or 0.0
        for name, seconds in durations.items():
            if not seconds <= MAX_DURATION_S:  # also catches inf from a tiny reference_rate_hz
                raise ValueError(
                    f"{name} lasts {seconds:g} s at reference_rate_hz={self.reference_rate_hz:g}, "
                    f"more than {MAX_DURATION_S:g} s"
                )
        return self

    def seconds(self, frames: int) -> float:
        """A frame count of Table 6.1 as seconds."""
        return frames / self.reference_rate_hz
