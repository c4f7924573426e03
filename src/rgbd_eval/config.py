"""Typed configuration: models that reject unknown keys, YAML loading, ``--set`` overrides.

A run is configured by one :class:`RunConfig`. Its defaults are the published
parameters of the reference system (seed 000, Tables 5.1 and 6.1); the files in
``configs/methods/`` restate them per method. Overrides use dotted keys::

    tracker.min_confidence=-1.0     detector.voxel_size=0.08     io.max_sync_gap_ms=20
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from rgbd_eval.errors import ConfigError


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)


class IoConfig(_Model):
    """How a recording is read."""

    rgb_topic: str | None = Field(None, description="RGB image topic; auto-detected when unset")
    depth_topic: str | None = Field(None, description="depth image topic; auto-detected when unset")
    rgb_info_topic: str | None = Field(None, description="RGB CameraInfo topic; auto-detected")
    depth_info_topic: str | None = Field(None, description="depth CameraInfo topic; auto-detected")
    odom_topic: str | None = Field(None, description="nav_msgs/Odometry topic; auto-detected")
    gt_topic: str | None = Field(None, description="ground-truth topic; auto-detected")
    world_frame: str | None = Field(
        None, description="world frame of the tf tree (default: the odometry's frame, else 'odom')"
    )
    max_sync_gap_ms: float = Field(
        20.0, gt=0, le=1000, description="largest RGB/depth header-stamp gap that still pairs"
    )
    max_pose_extrapolation_ms: float = Field(
        200.0, ge=0, description="how far a pose may be held beyond the first/last odometry stamp"
    )


class GroundMode(enum.Enum):
    """How the detector finds the ground plane first (seed 000, 5.1, 5.4.1)."""

    AUTO = "auto"
    POINTS = "points"
    PLANE = "plane"


class HogClassifier(enum.Enum):
    """Which person classifier scores the clusters (seed 000, 5.4.2)."""

    AUTHORS = "authors"  # Dollár's HOG + the authors' SVM: the thesis' confidence units
    OPENCV = "opencv"  # OpenCV's Dalal-Triggs INRIA people detector: another scale


class HogBorder(enum.Enum):
    """Clusters whose person window is not wholly visible (seed 000, 5.4.2)."""

    SKIP = "skip"  # the thesis: not scored, hog_default_confidence (-100)
    PAD = "pad"  # the authors' later code (PCL): scored, the window's outside black


class DetectorConfig(_Model):
    """The basso2012 detector (seed 000, chapter 5; defaults from Table 5.1, voxel 0.06 m)."""

    voxel_size: float = Field(0.06, gt=0.0, le=0.5, description="voxel grid side (m), Table 5.1")
    min_height: float = Field(1.4, ge=0.0, description="Table 5.1 ~people/min_height (m)")
    max_height: float = Field(2.3, gt=0.0, description="Table 5.1 ~people/max_height (m)")
    min_confidence: float = Field(-1.5, description="Table 5.1 ~people/min_confidence")
    publish_all: bool = Field(True, description="Table 5.1 ~people/publish_all")
    head_centroid: bool = Field(True, description="Table 5.1 ~people/head_centroid")
    max_distance: float = Field(6.5, gt=0.0, description="Table 5.1 ~people/max_distance (m)")
    min_points: int = Field(30, ge=1, description="Table 5.1 ~cluster/min_points")
    max_points: int = Field(600, ge=1, description="Table 5.1 ~cluster/max_points")
    cluster_tolerance_voxels: float = Field(
        2.0, gt=0.0, description="Euclidean clustering tolerance in voxels (5.4.2: 2 x voxel)"
    )
    ground_mode: GroundMode = Field(GroundMode.AUTO, description="initial ground plane source")
    ground_points: list[tuple[float, float, float]] | None = Field(
        None, description="three floor points (x, y, z) in the depth optical frame, mode 'points'"
    )
    ground_plane: tuple[float, float, float, float] | None = Field(
        None, description="plane a, b, c, d in the depth optical frame, mode 'plane'"
    )
    histogram_bins: int = Field(
        8, ge=2, le=32, description="bins per channel of the blob's 3D colour histogram (6.2.2)"
    )
    hog_default_confidence: float = Field(
        -100.0, description="confidence of clusters not visible top to bottom (5.4.2)"
    )
    ground_pixels: list[tuple[float, float]] | None = Field(
        None,
        description="three floor pixels (u, v) on the RGB image, mode 'points' "
        "(the ground_detector's mouse clicks, 5.4.1)",
    )
    ground_max_tilt_deg: float = Field(
        30.0,
        gt=0.0,
        lt=90.0,
        description="largest angle between the floor normal and gravity (odometry up) accepted "
        "by the automatic ground search; covers the Kinect's +-27 deg tilt (seed 000, 2.1)",
    )
    ground_min_points: int = Field(
        30,
        ge=3,
        description="fewest floor voxels within one voxel of the plane needed to refine it; "
        "with fewer the previous plane is kept (5.1, 5.4.2; as ~cluster/min_points, Table 5.1)",
    )
    subclustering: bool = Field(
        True,
        description="head-based sub-clustering of Munaro, Basso and Menegatti (IROS 2012), the "
        "thesis authors' follow-up; off = the thesis' plain Euclidean clusters (5.2)",
    )
    min_head_distance: float = Field(
        0.3,
        gt=0.0,
        description="smallest ground distance (m) between two heads and the distance below "
        "which clusters are merged (Munaro et al. IROS 2012; 0.3 m in PCL's people module)",
    )
    min_head_prominence: float = Field(
        0.1,
        ge=0.0,
        description="how far (m) a second head must rise above the lowest point between it and "
        "a higher head; the head-to-shoulder drop of an adult is about 0.3 m",
    )
    surface_correction: bool = Field(
        True,
        description="move the head centroid from the visible surface to the head's axis "
        "(4/3 of the across-view spread, exact for a sphere or upright cylinder); off = the "
        "surface mean of 5.3",
    )
    hog: HogClassifier = Field(
        HogClassifier.AUTHORS,
        description="person classifier: 'authors' (Dollár's HOG and the thesis authors' SVM, "
        "the units of the thesis' confidence thresholds) or 'opencv' (INRIA people detector)",
    )
    hog_border: HogBorder = Field(
        HogBorder.PAD,
        description="'pad' (default): every cluster is scored, the window's outside the image "
        "black (the authors' later PCL code), so people cut by the image or whose feet are "
        "hidden can start tracks; 'skip': clusters not visible top to bottom get "
        "hog_default_confidence (the thesis, 5.4.2; what `reproduce basso2012` uses)",
    )
    hog_max_ground_gap: float = Field(
        0.3,
        gt=0.0,
        description="a cluster is 'visible from top to bottom' (5.4.2), so HOG-scored, when its "
        "lowest point is at most this high (m) and its full-body box is on the image",
    )

    @model_validator(mode="after")
    def _check(self) -> DetectorConfig:
        if self.min_height >= self.max_height:
            raise ValueError(
                f"min_height={self.min_height} must be below max_height={self.max_height}"
            )
        if self.min_points > self.max_points:
            raise ValueError(
                f"min_points={self.min_points} must not exceed max_points={self.max_points}"
            )
        if self.ground_mode is GroundMode.POINTS and not (
            (self.ground_points is not None and len(self.ground_points) == 3)
            or (self.ground_pixels is not None and len(self.ground_pixels) == 3)
        ):
            raise ValueError(
                "ground_mode 'points' needs exactly three ground_points (3D) or ground_pixels "
                f"(RGB image), got ground_points={self.ground_points}, "
                f"ground_pixels={self.ground_pixels}"
            )
        if self.ground_mode is GroundMode.PLANE and self.ground_plane is None:
            raise ValueError("ground_mode 'plane' needs ground_plane: [a, b, c, d]")
        return self


class ClusterSelection(enum.Enum):
    """Which detections reach the tracker (seed 000, Table 7.4)."""

    HEIGHT = "height"
    CONFIDENCE = "confidence"


class TrackerConfig(_Model):
    """The basso2012 tracker (seed 000, chapter 6; defaults from Table 6.1).

    Frame counts are given at ``reference_rate_hz`` (the Kinect's 30 Hz) and
    converted to seconds, so that they mean the same time at any frame rate:
    ``frames_before_old: 90`` is 3 s.
    """

    gate_distance_probability: float = Field(
        0.999, gt=0.0, lt=1.0, description="Table 6.1 ~kalman/gate_distance_probability"
    )
    acceleration_variance: float = Field(
        4.0, gt=0.0, description="Table 6.1 ~kalman/acceleration_variance (m^2/s^4)"
    )
    depth_noise_coefficient: float = Field(
        0.001425,
        ge=0.0,
        description="Kinect depth error sigma = k * d^2 (m), Figure 6.1; k from Khoshelham & Elberink 2012",
    )
    weak_classifiers: int = Field(250, ge=1, description="Table 6.1 ~recovery/weak_classifiers")
    selectors: int = Field(50, ge=1, description="Table 6.1 ~recovery/selectors")
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
        "detections for this many seconds all scored below detector.min_confidence (Table 5.1: "
        "not a person) and stayed "
        "within static_motion_m of their mean (a track held by a coat stand or a mannequin)",
    )
    static_motion_m: float = Field(
        0.3,
        gt=0.0,
        le=5.0,
        description="largest distance (m) from the window's mean position that counts as "
        "not moving, for static_devalidation_s",
    )

    @model_validator(mode="after")
    def _check(self) -> TrackerConfig:
        if self.selectors > self.weak_classifiers:
            raise ValueError(
                f"selectors={self.selectors} must not exceed weak_classifiers={self.weak_classifiers}"
            )
        return self

    def seconds(self, frames: int) -> float:
        """A frame count of Table 6.1 as seconds."""
        return frames / self.reference_rate_hz


class Gating(enum.Enum):
    """How ground truth and tracks are matched (design: Evaluation)."""

    IOU = "iou"
    METRIC = "metric"


class EvaluationConfig(_Model):
    """Scoring settings."""

    gating: Gating = Field(Gating.IOU, description="'iou' on RGB boxes or 'metric' on the ground")
    threshold: float | None = Field(
        None,
        gt=0.0,
        description="IoU >= threshold (default 0.5, seed 000 7.3) or distance <= threshold "
        "in metres (default 1.0, seed 001 V-B)",
    )
    min_visibility: float = Field(
        0.0, ge=0.0, le=1.0, description="ground truth less visible than this is ignored"
    )

    def effective_threshold(self) -> float:
        if self.threshold is not None:
            return self.threshold
        return 0.5 if self.gating is Gating.IOU else 1.0

    @model_validator(mode="after")
    def _check(self) -> EvaluationConfig:
        if self.gating is Gating.IOU and self.threshold is not None and self.threshold > 1.0:
            raise ValueError(f"IoU threshold={self.threshold} must be in (0, 1]")
        return self


class RunConfig(_Model):
    """Everything one run needs besides the input paths."""

    method: str = Field("basso2012", description="detector/tracker pairing by name")
    io: IoConfig = IoConfig()
    detector: DetectorConfig = DetectorConfig()
    tracker: TrackerConfig = TrackerConfig()
    evaluation: EvaluationConfig = EvaluationConfig()


# ----------------------------------------------------------------------------- loading


def format_validation_error(err: ValidationError, source: str) -> str:
    parts = []
    for e in err.errors():
        loc = ".".join(str(p) for p in e["loc"])
        msg = e["msg"]
        if e["type"] == "extra_forbidden":
            msg = "unknown key"
        value = e.get("input")
        shown = "" if isinstance(value, dict) or e["type"] == "missing" else f" (got {value!r})"
        parts.append(f"{loc or '<root>'}: {msg}{shown}")
    return f"{source}: " + "; ".join(parts)


def _parse_value(text: str) -> Any:
    """Parse an override value as a YAML scalar/flow value (so -1.5, true, [1,2] work)."""
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError:
        return text


def set_dotted(
    data: dict[str, Any], key: str, value: Any, model: type[BaseModel] | None = None
) -> None:
    """Set ``a.b.c = value`` in the raw mapping of ``model`` (default :class:`RunConfig`).

    Every segment must be a field of its section; a ConfigError names the unknown key.
    """
    parts = key.split(".")
    if not all(parts):
        raise ConfigError(f"override {key!r}: empty key segment")
    fields: Mapping[str, Any] = (model or RunConfig).model_fields
    node = data
    for i, part in enumerate(parts):
        where = ".".join(parts[:i]) or "<root>"
        if part not in fields:
            allowed = ", ".join(sorted(fields))
            raise ConfigError(
                f"override {key!r}: unknown key {part!r} in {where} (known: {allowed})"
            )
        if i == len(parts) - 1:
            node[part] = value
            return
        annotation = fields[part].annotation
        if not (isinstance(annotation, type) and issubclass(annotation, BaseModel)):
            raise ConfigError(
                f"override {key!r}: {where}.{part} is not a section".replace("<root>.", "")
            )
        sub = node.setdefault(part, {})
        if not isinstance(sub, dict):
            raise ConfigError(f"override {key!r}: {'.'.join(parts[: i + 1])} is not a section")
        node = sub
        fields = annotation.model_fields


def parse_overrides(items: Iterable[str]) -> list[tuple[str, Any]]:
    """Parse ``key=value`` strings into (dotted key, value) pairs."""
    out = []
    for item in items:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(
                f"override {item!r}: expected KEY=VALUE, e.g. tracker.min_confidence=-1"
            )
        out.append((key.strip(), _parse_value(raw.strip())))
    return out


def build_config(
    data: Mapping[str, Any] | None = None,
    overrides: Iterable[tuple[str, Any]] = (),
    source: str = "config",
) -> RunConfig:
    """Validate a config mapping with overrides applied on top."""
    merged: dict[str, Any] = _deep_copy(dict(data or {}))
    for key, value in overrides:
        set_dotted(merged, key, value)
    try:
        return RunConfig.model_validate(merged)
    except ValidationError as err:
        raise ConfigError(format_validation_error(err, source)) from err


def _deep_copy(d: Mapping[str, Any]) -> dict[str, Any]:
    return {k: _deep_copy(v) if isinstance(v, Mapping) else v for k, v in d.items()}


def load_yaml(path: Path) -> dict[str, Any]:
    """Read a YAML mapping, as a :class:`ConfigError` on any failure."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as err:
        raise ConfigError(f"{path}: cannot read config ({err.strerror})") from err
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise ConfigError(f"{path}: not valid YAML ({err})") from err
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level, got {type(data).__name__}")
    return data


def load_config(
    path: Path | None = None, overrides: Iterable[str] = (), method: str | None = None
) -> RunConfig:
    """Load a run config from a YAML file (or the method's defaults) plus ``--set`` overrides."""
    data: dict[str, Any] = {}
    source = "defaults"
    if path is None and method is not None:
        method_file = methods_dir() / f"{method}.yaml"
        if method_file.is_file():
            path = method_file
    if path is not None:
        data = load_yaml(path)
        source = str(path)
    if method is not None:
        data["method"] = method
    return build_config(data, parse_overrides(overrides), source)


def config_to_dict(config: RunConfig) -> dict[str, Any]:
    """A JSON-ready dict of the fully resolved config."""
    return config.model_dump(mode="json")


def repo_root() -> Path:
    """The source checkout's root (where ``configs/`` and ``datasets/`` live)."""
    return Path(__file__).resolve().parents[2]


def methods_dir() -> Path:
    return repo_root() / "configs" / "methods"
