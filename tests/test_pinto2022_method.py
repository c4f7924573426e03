"""pinto2022 as a registered method: its config file, typed config models and pairings."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.components import create_detector, create_tracker
from rgbd_eval.config import load_config
from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.pinto2022.detector import Pinto2022Detector
from rgbd_eval.methods.pinto2022.detector_config import Pinto2022DetectorConfig, ReidBackend
from rgbd_eval.methods.pinto2022.tracker import Pinto2022Tracker
from rgbd_eval.methods.pinto2022.tracker_config import Pinto2022TrackerConfig
from rgbd_eval.types import Box2D, Detection


def test_method_defaults_come_from_its_config_file() -> None:
    config = load_config(method="pinto2022")
    assert isinstance(config.detector, Pinto2022DetectorConfig)
    assert isinstance(config.tracker, Pinto2022TrackerConfig)
    assert config.detector.reid.backend is ReidBackend.COLOUR_TEXTURE
    t = config.tracker
    # eq. 3, eq. 9, eq. 17 (S_max), III-E; thresholds in colour_texture units (the yaml's comment)
    assert (t.sigma_position, t.sigma_velocity, t.sigma_measurement, t.s_max) == (
        0.2,
        1.0,
        0.2,
        0.05,
    )
    assert (t.confirm_hits, t.max_misses) == (3, 5)
    assert (t.t_lower, t.t_upper, t.t_recover) == (0.305, 0.549, 0.328)
    # the model's defaults agree with the method file
    assert Pinto2022TrackerConfig() == t
    assert config.evaluation.effective_threshold() == 1.0


def test_factories_build_the_detector_and_tracker() -> None:
    config = load_config(method="pinto2022")
    assert isinstance(create_detector(config), Pinto2022Detector)
    assert isinstance(create_tracker(config), Pinto2022Tracker)


def test_thresholds_in_other_units_are_refused() -> None:
    with pytest.raises(ConfigError, match="recalibrate"):
        load_config(method="pinto2022", overrides=["detector.reid.backend=mobilenet"])
    config = load_config(
        method="pinto2022",
        overrides=["detector.reid.backend=mobilenet", "tracker.appearance=mobilenet"],
    )
    assert config.tracker.appearance == "mobilenet"


def test_backends_that_need_a_file_say_so() -> None:
    with pytest.raises(ConfigError, match=r"person\.model"):
        load_config(method="pinto2022", overrides=["detector.person.backend=onnx"])
    with pytest.raises(ConfigError, match=r"person\.source"):
        load_config(method="pinto2022", overrides=["detector.person.backend=recorded"])
    with pytest.raises(ConfigError, match="t_lower"):
        load_config(method="pinto2022", overrides=["tracker.t_lower=0.9"])


def test_mixed_pairing_pinto_detector_with_basso_tracker() -> None:
    # basso2012's on-line classifier learns colour histograms: refused with it, accepted without.
    with pytest.raises(ConfigError, match="classifier"):
        load_config(method="basso2012", overrides=["detector.name=pinto2022"])
    config = load_config(
        method="basso2012", overrides=["detector.name=pinto2022", "tracker.classifier=false"]
    )
    assert isinstance(config.detector, Pinto2022DetectorConfig)
    tracker = create_tracker(config)
    # a pinto2022 detection (240-d colour_texture embedding) is tracked, its embedding unused
    det = Detection(
        position=(2.0, 0.0, 0.9),
        height=1.7,
        confidence=0.9,
        box2d=Box2D(100, 100, 50, 150),
        distance=2.0,
        appearance=np.zeros(240, dtype=np.float32),
    )
    tracker.update(0, [det])
