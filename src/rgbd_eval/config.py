"""Typed configuration: models that reject unknown keys, YAML loading, ``--set`` overrides.

A run is configured by one :class:`RunConfig`: the method, how recordings are read,
the detector's and the tracker's config models (registered by name, see
:mod:`rgbd_eval.plugins`) and the scoring. Each method's defaults are its paper's
published parameters, restated in its package's ``methods/<method>/method.yaml``. Overrides use
dotted keys::

    tracker.min_confidence=-1.0     detector.voxel_size=0.08     io.max_sync_gap_ms=20
"""

from __future__ import annotations

import enum
import itertools
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, get_args, get_origin

import annotated_types
import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    SerializeAsAny,
    ValidationError,
    model_validator,
)
from pydantic.fields import FieldInfo
from pydantic_core import PydanticCustomError

from rgbd_eval.errors import ConfigError


class _Model(BaseModel):
    model_config = ConfigDict(
        extra="forbid", frozen=True, validate_default=True, allow_inf_nan=False
    )


class ComponentConfig(_Model):
    """Base of every detector's and tracker's config model; ``name`` selects the model.

    A subclass narrows ``name`` to its registered name (``name: Literal["x"] = "x"``),
    see :mod:`rgbd_eval.plugins`.
    """

    name: str


#: Roles of non-image topics that ``io.topics`` may also name.
_OTHER_ROLES = ("odometry", "ground_truth", "joint_states")


def _check_role(role: str) -> None:
    from rgbd_eval.plugins import ROLES, role_kind

    kind = role_kind(role.removesuffix("_info"))
    if role in _OTHER_ROLES or kind in ROLES:
        return
    known = ", ".join([*ROLES, *(f"{r}_info" for r in ROLES), *_OTHER_ROLES, "depth_2, ..."])
    raise ValueError(f"unknown topic role {role!r} (known: {known})")


class WheelsConfig(_Model):
    """Odometry from a ``sensor_msgs/JointState`` of a differential drive's wheels."""

    left_joint: str = Field(description="name of the left wheel's joint")
    right_joint: str = Field(description="name of the right wheel's joint")
    radius_m: float = Field(gt=0.0, le=5.0, description="wheel radius (joint rad/s -> m/s)")
    separation_m: float = Field(gt=0.0, le=10.0, description="distance 2d between the wheels")
    base_frame: str = Field("base_link", description="the robot frame the wheels move")
    odom_frame: str = Field("odom", description="the frame the robot starts at the origin of")


class IoConfig(_Model):
    """How a recording is read."""

    topics: dict[str, str] = Field(
        default_factory=dict,
        description="topic per role: colour, depth (depth_2, ... for more depth cameras), "
        "thermal, left, right, <role>_info (its CameraInfo), odometry, ground_truth; "
        "auto-detected by message type where unset and unambiguous",
    )
    world_frame: str | None = Field(
        None, description="world frame of the tf tree (default: the odometry's frame, else 'odom')"
    )
    max_sync_gap_ms: float = Field(
        20.0, gt=0, le=1000, description="largest header-stamp gap between streams that still pairs"
    )
    max_pose_extrapolation_ms: float = Field(
        200.0,
        ge=0,
        le=60_000,
        description="how far a pose may be held beyond the first/last odometry stamp",
    )
    wheels: WheelsConfig | None = Field(
        None, description="odometry from wheel speeds (JointState) instead of nav_msgs/Odometry"
    )

    @model_validator(mode="after")
    def _check(self) -> IoConfig:
        for role, topic in self.topics.items():
            _check_role(role)
            if not topic.strip():
                raise ValueError(f"topics.{role}: empty topic name")
        return self

    def topic(self, role: str) -> str | None:
        """The topic chosen for ``role`` in the config, if any."""
        return self.topics.get(role)


class Gating(enum.Enum):
    """How ground truth and tracks are matched (design: Evaluation)."""

    IOU = "iou"
    METRIC = "metric"


class Convention(enum.Enum):
    """Which reference the CLEAR MOT matching reproduces exactly (see ``rgbd_eval.metrics``).

    ``motchallenge``: the official devkit as TrackEval reproduces it (a previous match is
    kept only from the previous frame; MT means tracked in more than 80 % of frames).
    ``motmetrics``: py-motmetrics 1.4 (a previous match is kept while it stays in the gate,
    however long ago; MT at 80 % or more).
    """

    MOTCHALLENGE = "motchallenge"
    MOTMETRICS = "motmetrics"


class EvaluationConfig(_Model):
    """Scoring settings."""

    gating: Gating = Field(Gating.IOU, description="'iou' on RGB boxes or 'metric' on the ground")
    threshold: float | None = Field(
        None,
        ge=0.001,
        le=1000.0,
        description="IoU >= threshold (default 0.5, seed 000 7.3) or distance <= threshold "
        "in metres (default 1.0, seed 001 V-B)",
    )
    min_visibility: float = Field(
        0.0, ge=0.0, le=1.0, description="ground truth less visible than this is ignored"
    )
    # The benchmark's convention by default: published MOTChallenge numbers are computed
    # with it, and motmetrics 1.4's long-memory matching is a bug fixed upstream in 2023.
    convention: Convention = Field(
        Convention.MOTCHALLENGE,
        description="'motchallenge' (devkit/TrackEval) or 'motmetrics' (py-motmetrics 1.4)",
    )
    # Breakdowns and intervals (rgbd_eval.metrics.breakdowns, rgbd_eval.metrics.bootstrap).
    distance_bands: list[float] = Field(
        [2.0, 4.0, 6.0],
        min_length=1,
        max_length=50,
        description="edges (m) of the bands of distance from the camera: 0-2, 2-4, 4-6, 6+",
    )
    driving_speed: float = Field(
        0.1, gt=0.0, description="m/s above which the robot counts as driving"
    )
    turning_rate: float = Field(
        0.2, gt=0.0, description="rad/s (about 11.5 deg/s) above which the robot counts as turning"
    )
    bootstrap_replicates: int = Field(
        1000,
        ge=0,
        le=100_000,
        description="replicates of the block bootstrap behind each interval (0: none)",
    )
    bootstrap_seed: int = Field(33, ge=0, description="the seed of the block bootstrap")

    def effective_threshold(self) -> float:
        if self.threshold is not None:
            return self.threshold
        return 0.5 if self.gating is Gating.IOU else 1.0

    @model_validator(mode="after")
    def _check(self) -> EvaluationConfig:
        problem = None if self.threshold is None else threshold_problem(self.gating, self.threshold)
        if problem is not None:
            raise ValueError(problem)
        edges = self.distance_bands
        if any(not (0.0 < e < math.inf) for e in edges) or any(
            b <= a for a, b in itertools.pairwise(edges)
        ):
            raise ValueError(f"distance_bands={edges} must be increasing distances > 0 (m)")
        return self


def threshold_problem(gating: Gating, threshold: float) -> str | None:
    """Why ``threshold`` cannot gate ``gating`` (IoU in (0, 1], metres > 0 and finite), or None."""
    if gating is Gating.IOU:
        return None if 0.0 < threshold <= 1.0 else f"IoU threshold={threshold} must be in (0, 1]"
    if 0.0 < threshold < math.inf:
        return None
    return f"metric threshold={threshold} must be a finite distance > 0 (metres)"


def gating_threshold(method: str, gating: Gating) -> float | None:
    """The threshold ``gating`` takes when it is chosen without one.

    The method's own threshold where its defaults use that gating (dmtbs: metric 0.5 m),
    else None: the gating's default (IoU 0.5, 1.0 m).
    """
    evaluation = method_defaults(method)[0].get("evaluation")
    threshold = evaluation.get("threshold") if isinstance(evaluation, Mapping) else None
    if _gating_of(evaluation) != gating.value or not isinstance(threshold, int | float):
        return None
    return float(threshold)


def _gating_of(evaluation: Any) -> Any:
    """The raw gating of a raw ``evaluation`` section (the model's default where absent)."""
    default = EvaluationConfig.model_fields["gating"].default
    gating = evaluation.get("gating", default) if isinstance(evaluation, Mapping) else default
    return gating.value if isinstance(gating, Gating) else gating


class RunConfig(_Model):
    """Everything one run needs besides the input paths.

    ``detector`` and ``tracker`` are the config models registered under their
    ``name`` (:mod:`rgbd_eval.plugins`); when a section or its name is absent, the
    method's pairing fills it in. Build from raw data with :func:`build_config`,
    which names the offending key of a bad section.
    """

    method: str = Field("basso2012", description="the method (paper pairing) by name")
    io: IoConfig = IoConfig()
    detector: SerializeAsAny[ComponentConfig] = Field(
        default_factory=lambda: _unresolved("detector")
    )
    tracker: SerializeAsAny[ComponentConfig] = Field(default_factory=lambda: _unresolved("tracker"))
    evaluation: EvaluationConfig = EvaluationConfig()

    @model_validator(mode="before")
    @classmethod
    def _resolve_sections(cls, data: Any) -> Any:
        if not isinstance(data, Mapping):
            return data
        out = dict(data)
        method = out.get("method", cls.model_fields["method"].default)
        for section in ("detector", "tracker"):
            value = out.get(section)
            if isinstance(value, ComponentConfig):
                continue
            try:
                out[section] = _section(section, value, method)
            except ValidationError as err:
                model = section_model(section, out)
                raise PydanticCustomError(
                    "section", format_validation_error(err, section, section, model)
                ) from err
            except ConfigError as err:
                raise PydanticCustomError("section", str(err)) from err
        return out

    @model_validator(mode="after")
    def _check_pairing(self) -> RunConfig:
        from rgbd_eval.plugins import pairing_problem

        problem = pairing_problem(self.detector, self.tracker)
        if problem is not None:
            raise ValueError(
                f"detector {self.detector.name!r} cannot feed tracker {self.tracker.name!r}: "
                f"{problem}"
            )
        return self


def _unresolved(section: str) -> ComponentConfig:
    raise RuntimeError(f"{section} is filled in from the method before validation")


def _section(section: str, value: Any, method: Any) -> ComponentConfig:
    """The config model of ``section`` ('detector'/'tracker') validated from raw ``value``."""
    from rgbd_eval.plugins import detector_spec, method_spec, tracker_spec

    if value is None:
        value = {}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{section}: expected a mapping, got {type(value).__name__}")
    name = value.get("name")
    if name is None:
        if not isinstance(method, str):
            raise ConfigError(f"method: expected a name, got {method!r}")
        spec = method_spec(method)
        name = spec.detector if section == "detector" else spec.tracker
    if not isinstance(name, str):
        raise ConfigError(f"{section}.name: expected a name, got {name!r}")
    lookup = detector_spec if section == "detector" else tracker_spec
    model = lookup(name).config_model
    return model.model_validate({**value, "name": name})


def section_model(section: str, data: Mapping[str, Any]) -> type[BaseModel]:
    """The model of ``detector``/``tracker`` that raw run-config ``data`` selects."""
    from rgbd_eval.plugins import detector_spec, method_spec, tracker_spec

    raw = data.get(section)
    name = raw.get("name") if isinstance(raw, Mapping) else None
    if not isinstance(name, str):
        method = data.get("method", RunConfig.model_fields["method"].default)
        spec = method_spec(str(method))
        name = spec.detector if section == "detector" else spec.tracker
    return (detector_spec if section == "detector" else tracker_spec)(name).config_model


# ----------------------------------------------------------------------------- loading


#: Pydantic error types of a numeric bound: the message names one side, we add the range.
_BOUND_ERRORS = frozenset({"greater_than", "greater_than_equal", "less_than", "less_than_equal"})


def _field_at(model: type[BaseModel], loc: Sequence[Any]) -> FieldInfo | None:
    """The field of ``model`` at an error location (through nested models), if any."""
    field: FieldInfo | None = None
    current: Any = model
    for part in loc:
        if not (isinstance(current, type) and issubclass(current, BaseModel)):
            return None
        field = current.model_fields.get(str(part))
        if field is None:
            return None
        options = (field.annotation, *get_args(field.annotation))
        current = next(
            (a for a in options if isinstance(a, type) and issubclass(a, BaseModel)), None
        )
    return field


def _allowed_range(field: FieldInfo, name: str) -> str | None:
    """``lo <= name <= hi`` from a field's bounds (None when it has none)."""
    left = right = ""
    for m in field.metadata:
        if isinstance(m, annotated_types.Ge):
            left = f"{m.ge} <= "
        elif isinstance(m, annotated_types.Gt):
            left = f"{m.gt} < "
        elif isinstance(m, annotated_types.Le):
            right = f" <= {m.le}"
        elif isinstance(m, annotated_types.Lt):
            right = f" < {m.lt}"
    return f"{left}{name}{right}" if left or right else None


def validation_parts(
    err: ValidationError, prefix: str = "", model: type[BaseModel] | None = None
) -> list[tuple[str, str]]:
    """``(dotted location, message)`` of each error, the location under ``prefix``.

    With the validated ``model``, a value out of bounds names the field's whole range.
    """
    parts = []
    for e in err.errors():
        loc = ".".join(str(p) for p in (prefix, *e["loc"]) if p != "")
        msg = e["msg"]
        if e["type"] == "extra_forbidden":
            msg = "unknown key"
        value = e.get("input")
        shown = "" if isinstance(value, dict) or e["type"] == "missing" else f"got {value!r:.80}"
        field = _field_at(model, e["loc"]) if model is not None else None
        if e["type"] in _BOUND_ERRORS and field is not None and e["loc"]:
            allowed = _allowed_range(field, str(e["loc"][-1]))
            if allowed is not None:
                shown += f"; allowed: {allowed}"
        parts.append((loc, f"{msg} ({shown})" if shown else msg))
    return parts


def format_validation_error(
    err: ValidationError, source: str, prefix: str = "", model: type[BaseModel] | None = None
) -> str:
    """One line: ``source: loc: message; loc: message``."""
    parts = validation_parts(err, prefix, model)
    return f"{source}: " + "; ".join(f"{loc or '<root>'}: {msg}" for loc, msg in parts)


def _parse_value(text: str, item: str) -> Any:
    """Parse an override value as a YAML scalar/flow value (so -1.5, true, [1,2] work).

    Text that is not YAML stays text; an alias bomb or deep nesting is a ConfigError
    naming the override ``item``, as in a config file.
    """
    from rgbd_eval.files import YamlLimitError, load_yaml_bounded

    try:
        return load_yaml_bounded(text)
    except YamlLimitError as err:
        raise ConfigError(f"override {item[:80]!r}: {err}") from err
    except yaml.YAMLError:
        return text


_SECTIONS = ("detector", "tracker")


def set_dotted(
    data: dict[str, Any], key: str, value: Any, model: type[BaseModel] | None = None
) -> None:
    """Set ``a.b.c = value`` in the raw mapping of ``model`` (default :class:`RunConfig`).

    Every segment must be a field of its section; a ConfigError names the unknown key.
    In a run config, ``detector.*``/``tracker.*`` keys are those of the model the
    section's ``name`` selects, and setting another ``name`` starts that section afresh
    (the other component's parameters do not apply to it). A mapping field (``io.topics``)
    takes one more segment as its key.
    """
    parts = key.split(".")
    if not all(parts):
        raise ConfigError(f"override {key!r}: empty key segment")
    root = model or RunConfig
    fields: Mapping[str, Any] = root.model_fields
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
        section: type[BaseModel] | None = None
        if root is RunConfig and i == 0 and part in _SECTIONS:
            sub_raw = node.get(part)
            if parts[1:] == ["name"] and len(parts) == 2:
                old = sub_raw.get("name") if isinstance(sub_raw, Mapping) else None
                if old != value:
                    node[part] = {"name": value}
                    return
            section = section_model(part, node)
        elif isinstance(annotation, type) and issubclass(annotation, BaseModel):
            section = annotation
        elif get_origin(annotation) is dict and i == len(parts) - 2:
            sub = node.setdefault(part, {})
            if not isinstance(sub, dict):
                raise ConfigError(f"override {key!r}: {'.'.join(parts[: i + 1])} is not a mapping")
            sub[parts[-1]] = value
            return
        if section is None:
            raise ConfigError(
                f"override {key!r}: {where}.{part} is not a section".replace("<root>.", "")
            )
        sub = node.setdefault(part, {})
        if not isinstance(sub, dict):
            raise ConfigError(f"override {key!r}: {'.'.join(parts[: i + 1])} is not a section")
        node = sub
        fields = section.model_fields


def parse_overrides(items: Iterable[str]) -> list[tuple[str, Any]]:
    """Parse ``key=value`` strings into (dotted key, value) pairs."""
    out = []
    for item in items:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(
                f"override {item!r}: expected KEY=VALUE, e.g. tracker.min_confidence=-1"
            )
        out.append((key.strip(), _parse_value(raw.strip(), item)))
    return out


def build_config(
    data: Mapping[str, Any] | None = None,
    overrides: Iterable[tuple[str, Any]] = (),
    source: str = "config",
    override_source: str | None = None,
) -> RunConfig:
    """Validate a config mapping with overrides applied on top.

    The method and the detector/tracker names are checked first (an unknown name lists
    the known ones), then every section; an error in an overridden key is blamed on
    its ``--set``, any other on ``source``.
    """
    from rgbd_eval.plugins import method_spec

    merged: dict[str, Any] = _deep_copy(dict(data or {}))
    gating_before = _gating_of(merged.get("evaluation"))
    overridden = []
    for key, value in overrides:
        set_dotted(merged, key, value)
        overridden.append((key, value))
    method = merged.get("method", RunConfig.model_fields["method"].default)
    if not isinstance(method, str):
        raise ConfigError(f"{source}: method: expected a name, got {method!r}")
    method_spec(method)
    _threshold_follows_gating(merged, gating_before, [k for k, _ in overridden], method)
    parts: list[tuple[str, str]] = []
    for section in _SECTIONS:
        try:
            merged[section] = _section(section, merged.get(section), method)
        except ValidationError as err:
            parts += validation_parts(err, section, section_model(section, merged))
    if not parts:
        try:
            return RunConfig.model_validate(merged)
        except ValidationError as err:
            parts = validation_parts(err, model=RunConfig)
    blamed = []
    for loc, msg in parts:
        by = next(
            (f"--set {k}={v}" for k, v in overridden if loc == k or loc.startswith(f"{k}.")), None
        )
        if by is None and not loc and overridden:  # a cross-section check: name the overrides
            by = f"{source} with " + " ".join(f"--set {k}={v}" for k, v in overridden)
        blamed.append(f"{by or source}: {loc or '<root>'}: {msg}")
    raise ConfigError("; ".join(blamed))


def _threshold_follows_gating(
    merged: dict[str, Any], before: Any, keys: list[str], method: str
) -> None:
    """An override that changes the gating, with none of the threshold, resets the threshold.

    The threshold of the config's own gating (pinto2022's metric 1.0 m) means nothing under
    another gating (an IoU of 1.0 matches nothing): it becomes :func:`gating_threshold`.
    """
    evaluation = merged.get("evaluation")
    if "evaluation.gating" not in keys or "evaluation.threshold" in keys:
        return
    if not isinstance(evaluation, dict) or _gating_of(evaluation) == before:
        return
    try:
        gating = Gating(_gating_of(evaluation))
    except ValueError:  # validation names the bad gating
        return
    evaluation["threshold"] = gating_threshold(method, gating)


def _deep_copy(d: Mapping[str, Any]) -> dict[str, Any]:
    return {k: _deep_copy(v) if isinstance(v, Mapping) else v for k, v in d.items()}


def load_yaml(path: Path) -> dict[str, Any]:
    """Read a YAML mapping, as a :class:`ConfigError` on any failure."""
    from rgbd_eval.files import parse_yaml, read_text

    def error(message: str) -> ConfigError:
        return ConfigError(f"{path}: {message}")

    data = parse_yaml(read_text(Path(path), error, "config"), error)
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level, got {type(data).__name__}")
    return data


def paper_path(method: str) -> Path | None:
    """The file of a method's published numbers and claim thresholds (its package's
    ``paper.yaml``, :attr:`~rgbd_eval.plugins.MethodSpec.paper_file`), None when it has none."""
    from rgbd_eval.plugins import method_spec

    spec = method_spec(method)
    return None if spec.paper_file is None else config_dir() / spec.paper_file


def load_paper(
    method: str,
    *,
    mappings: Iterable[str] = (),
    present: Iterable[str] = (),
    path: Path | None = None,
) -> dict[str, Any]:
    """A paper's published numbers and claim thresholds (``methods/<method>/paper.yaml``).

    ``mappings`` name keys that must hold a mapping, ``present`` keys that must exist;
    anything else is a :class:`ConfigError` naming the file.
    """
    source = path or paper_path(method)
    if source is None:
        raise ConfigError(f"method {method!r} has no paper file (MethodSpec.paper_file)")
    data = load_yaml(source)
    for key in mappings:
        if not isinstance(data.get(key), dict):
            raise ConfigError(f"{source}: paper values need a mapping '{key}'")
    for key in present:
        if key not in data:
            raise ConfigError(f"{source}: paper values need '{key}'")
    return data


def method_defaults(method: str) -> tuple[dict[str, Any], str]:
    """The raw config of a method: its paper's defaults file, else its pairing and gating."""
    from rgbd_eval.plugins import method_spec

    spec = method_spec(method)
    if spec.config_file is not None:
        path = config_dir() / spec.config_file
        data = load_yaml(path)
        data["method"] = method
        return data, str(path)
    return {"method": method, "evaluation": {"gating": spec.gating}}, f"method {method}"


def load_config(
    path: Path | None = None, overrides: Iterable[str] = (), method: str | None = None
) -> RunConfig:
    """Load a run config from a YAML file (or the method's defaults) plus ``--set`` overrides.

    The config is complete and checked before any recording is opened: an unknown
    method, detector, tracker or key is a :class:`ConfigError` (exit 4).
    """
    data: dict[str, Any] = {}
    source = "defaults"
    if path is not None:
        data = load_yaml(path)
        source = str(path)
        if method is not None:
            data["method"] = method
    elif method is not None:
        data, source = method_defaults(method)
    return build_config(data, parse_overrides(overrides), source)


def config_to_dict(config: RunConfig) -> dict[str, Any]:
    """A JSON-ready dict of the fully resolved config."""
    return config.model_dump(mode="json")


# ----------------------------------------------------------------------------- resources


def repo_root() -> Path:
    """The source checkout's root, when running from one (else the package's parent)."""
    return Path(__file__).resolve().parents[2]


def in_checkout() -> bool:
    """Whether the package runs from a source checkout (editable install or PYTHONPATH)."""
    root = repo_root()
    return (root / "pyproject.toml").is_file() and (root / "configs").is_dir()


def config_dir() -> Path:
    """The shipped configs: methods, papers, scenarios, sweeps, baselines.

    From a checkout, its ``configs/``; from an installed wheel, the copy built into
    the package (``rgbd_eval/configs``, see ``setup.py``).
    """
    packaged = Path(__file__).resolve().parent / "configs"
    return repo_root() / "configs" if in_checkout() else packaged


def data_home() -> Path:
    """Where generated recordings go: ``datasets/`` in a checkout, else a user cache folder.

    Outside a checkout: ``$RGBD_EVAL_DATA``, else ``$XDG_CACHE_HOME/rgbd-eval/datasets``
    (default ``~/.cache/rgbd-eval/datasets``).
    """
    env = os.environ.get("RGBD_EVAL_DATA")
    if env:
        return Path(env)
    if in_checkout():
        return repo_root() / "datasets"
    cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(cache) / "rgbd-eval" / "datasets"
