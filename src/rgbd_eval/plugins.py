"""Methods as plug-ins: named detectors, trackers and papers, each with its typed config model.

A *method* is a named pairing of a detector and a tracker (seed systems: ``basso2012``,
``pinto2022``, ...). Detectors and trackers register themselves with their config
model (a :class:`~rgbd_eval.config.ComponentConfig` subclass whose ``name`` field is
the registered name) beside their factory; a method registers the pairing, the streams
it reads, its paper and its default gating; a paper registers its experiments for
``rgbd-eval reproduce``.

Discovery needs no hand-edited import list. :func:`load_plugins` imports

1. every package (or module) in :mod:`rgbd_eval.methods`, one per method, found by a
   package scan (a new method registers by existing): its ``__init__`` registers the
   detector, tracker, method and paper. The package is named, not imported, here: the
   registry knows names and specs, and methods import it, never the other way;
2. every entry point of the group ``rgbd_eval.plugins`` (installed third-party methods);
3. every module named in ``$RGBD_EVAL_PLUGINS`` (comma-separated; for methods kept in a
   project's own folder, e.g. ``RGBD_EVAL_PLUGINS=my_lab.tracker``).

A detector states the :class:`DetectionContract` of its output; a tracker may refuse
a contract (:attr:`TrackerSpec.check`), so that a detector and a tracker of different
methods pair where their data allows and are refused, when the config loads, where
it does not.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rgbd_eval.errors import ConfigError
from rgbd_eval.verdicts import Verdict

if TYPE_CHECKING:
    from distributed import Client

    from rgbd_eval.config import ComponentConfig
    from rgbd_eval.detect.protocol import Detector
    from rgbd_eval.track.protocol import Tracker

ENTRY_POINT_GROUP = "rgbd_eval.plugins"
ENV_VAR = "RGBD_EVAL_PLUGINS"
_SCANNED_PACKAGES = ("rgbd_eval.methods",)

#: The stream roles a recording can hold (``io.topics.<role>``, ``--topic ROLE=/name``).
#: Extra depth cameras of a rig are ``depth_2``, ``depth_3``, ... (see :func:`role_kind`).
ROLES = ("colour", "depth", "thermal", "left", "right", "disparity")


def role_kind(role: str) -> str:
    """``depth_3`` -> ``depth``: the kind of image a role holds."""
    base, sep, number = role.rpartition("_")
    return base if sep and number.isdigit() else role


@dataclass(frozen=True)
class StreamSpec:
    """A stream a detector or tracker reads: its role, whether it must exist, and how many.

    ``multiple`` takes every camera of that kind (``depth``, ``depth_2``, ...), as a
    multi-camera rig has them.
    """

    role: str
    required: bool = True
    multiple: bool = False

    def __post_init__(self) -> None:
        if self.role not in ROLES:
            raise ValueError(f"stream role {self.role!r} is not one of {', '.join(ROLES)}")


@dataclass(frozen=True)
class DetectionContract:
    """What a detector's :class:`~rgbd_eval.types.Detection` s carry.

    ``appearance`` names the descriptor kind (e.g. ``rgb_histogram``) and
    ``appearance_size`` its length; ``position_resolution_m`` is the quantisation
    of positions (basso2012's voxel side), which a tracker may use as measurement noise.
    """

    world_position: bool = True
    box2d: bool = True
    appearance: str | None = None
    appearance_size: int = 0
    position_resolution_m: float = 0.0


@dataclass(frozen=True)
class DetectorSpec:
    """A registered detector."""

    name: str
    config_model: type[ComponentConfig]
    factory: Callable[[Any], Detector]
    streams: tuple[StreamSpec, ...]
    contract: Callable[[Any], DetectionContract]
    #: Names of the stages the detector times (``last_timings``), in pipeline order.
    stages: tuple[str, ...] = ()
    summary: str = ""
    #: The frames the detector only learns from before it can detect anything (a background
    #: model's initialisation) and what sets them, from its config; None: it needs none.
    warmup: Callable[[Any], tuple[int, str] | None] = field(default=lambda _c: None)


@dataclass(frozen=True)
class TrackerSpec:
    """A registered tracker.

    ``needs_frame``: the tracker reads the frame's images too (track-before-detect,
    template search, blob images); such trackers get no detection cache in sweeps.
    ``check`` returns why a detection contract cannot feed this tracker (None: it can).
    """

    name: str
    config_model: type[ComponentConfig]
    factory: Callable[[Any, DetectionContract], Tracker]
    needs_frame: bool = False
    streams: tuple[StreamSpec, ...] = ()
    check: Callable[[Any, DetectionContract], str | None] = field(default=lambda _c, _d: None)
    stages: tuple[str, ...] = ()
    summary: str = ""


@dataclass(frozen=True)
class MethodSpec:
    """A named method: the paper's detector and tracker and how it is scored."""

    name: str
    detector: str
    tracker: str
    title: str
    #: The seed (paper text) that specifies it, e.g. ``000`` (see DESIGN.md).
    seed: str = ""
    gating: str = "iou"
    #: The method's default config (``method.yaml``): an absolute path (a method package's own
    #: file), or one relative to the config folder.
    config_file: str | Path | None = None
    #: The paper's published numbers and claim thresholds (``paper.yaml``), likewise.
    paper_file: str | Path | None = None


@dataclass(frozen=True)
class PaperSpec:
    """A paper's experiments for ``rgbd-eval reproduce <method>``.

    ``scenarios`` are the synthetic recordings it needs (scenario names or YAML paths);
    ``run`` gets them as ``{name: recording path}`` plus the options, and returns the
    result to write. It may be named as ``"module:function"``, imported when the paper is
    reproduced (:meth:`experiments`): a method's experiments drive runs and sweeps, which
    find methods through this registry, so a method package names its experiments rather
    than importing them.
    """

    method: str
    title: str
    scenarios: tuple[str, ...]
    run: Callable[[Mapping[str, Path], ReproduceOptions], ReproduceResult] | str

    def experiments(self) -> Callable[[Mapping[str, Path], ReproduceOptions], ReproduceResult]:
        """The function that runs the experiments (``run``, imported when named)."""
        if not isinstance(self.run, str):
            return self.run
        module, sep, name = self.run.partition(":")
        try:
            run = getattr(importlib.import_module(module), name) if sep else None
        except (ImportError, AttributeError) as err:
            raise ConfigError(f"paper {self.method!r}: cannot load {self.run!r}: {err}") from err
        if not callable(run):
            raise ConfigError(f"paper {self.method!r}: {self.run!r} is not a 'module:function'")
        return run  # type: ignore[no-any-return]


@dataclass(frozen=True)
class ReproduceOptions:
    """What ``rgbd-eval reproduce`` passes to a paper's experiments."""

    #: The Dask client to run sweeps on (None: a local cluster of one in-process worker).
    client: Client | None = None
    cache: Path | None = None
    progress: Callable[[str], None] = field(default=lambda _m: None)
    #: The folder of generated recordings (``--data``; None: the datasets folder), for
    #: experiments that render their own (per scenario seed).
    data: Path | None = None


@dataclass(frozen=True)
class ReproduceResult:
    """A paper's reproduction: the Markdown shown to people and the JSON for machines."""

    markdown: str
    data: Mapping[str, Any]
    #: (claim, verdict) pairs: a :class:`~rgbd_eval.verdicts.Verdict`, or a bool (held or
    #: failed on one run); how many held, failed and were inconclusive is the summary line.
    claims: tuple[tuple[str, bool | Verdict], ...] = ()

    def verdicts(self) -> list[tuple[str, Verdict]]:
        """The claims with their verdicts (a bool read as one run's)."""
        return [(t, v if isinstance(v, Verdict) else Verdict.of(v)) for t, v in self.claims]


@dataclass
class _Registry:
    detectors: dict[str, DetectorSpec] = field(default_factory=dict)
    trackers: dict[str, TrackerSpec] = field(default_factory=dict)
    methods: dict[str, MethodSpec] = field(default_factory=dict)
    papers: dict[str, PaperSpec] = field(default_factory=dict)
    loaded: bool = False


_REGISTRY = _Registry()


def _check_name(kind: str, name: str) -> None:
    if not name or not name.strip() or name != name.strip():
        raise ValueError(f"{kind} name must be a non-empty string without spaces, got {name!r}")


def _add(table: dict[str, Any], kind: str, name: str, spec: Any) -> None:
    _check_name(kind, name)
    existing = table.get(name)
    if existing is not None and existing != spec:
        raise ValueError(f"{kind} name {name!r} is already registered")
    table[name] = spec


def _check_model(kind: str, name: str, model: type[ComponentConfig]) -> None:
    _check_name(kind, name)
    default = model.model_fields["name"].default
    if default != name:
        raise ValueError(
            f"{kind} {name!r}: its config model {model.__name__} must default name to {name!r}, "
            f"got {default!r}"
        )


def register_detector(spec: DetectorSpec) -> DetectorSpec:
    """Register a detector (its config model's ``name`` must default to the spec's name)."""
    _check_model("detector", spec.name, spec.config_model)
    _add(_REGISTRY.detectors, "detector", spec.name, spec)
    return spec


def register_tracker(spec: TrackerSpec) -> TrackerSpec:
    """Register a tracker (its config model's ``name`` must default to the spec's name)."""
    _check_model("tracker", spec.name, spec.config_model)
    _add(_REGISTRY.trackers, "tracker", spec.name, spec)
    return spec


def register_method(spec: MethodSpec) -> MethodSpec:
    """Register a method (the detector and tracker may register later)."""
    _add(_REGISTRY.methods, "method", spec.name, spec)
    return spec


def register_paper(spec: PaperSpec) -> PaperSpec:
    """Register a paper's experiments under its method's name."""
    _add(_REGISTRY.papers, "paper", spec.method, spec)
    return spec


def load_plugins() -> None:
    """Import the built-in modules, the entry points and ``$RGBD_EVAL_PLUGINS`` (once)."""
    if _REGISTRY.loaded:
        return
    _REGISTRY.loaded = True
    for package_name in _SCANNED_PACKAGES:
        package = importlib.import_module(package_name)
        for info in pkgutil.iter_modules(package.__path__, prefix=f"{package_name}."):
            importlib.import_module(info.name)
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            ep.load()
        except ImportError as err:
            raise ConfigError(f"plug-in entry point {ep.name!r} ({ep.value}): {err}") from err
    for module in filter(None, (m.strip() for m in os.environ.get(ENV_VAR, "").split(","))):
        try:
            importlib.import_module(module)
        except ImportError as err:
            raise ConfigError(f"${ENV_VAR}: cannot import {module!r}: {err}") from err


def _lookup(table: Mapping[str, Any], kind: str, name: str) -> Any:
    load_plugins()
    spec = table.get(name)
    if spec is None:
        known = ", ".join(sorted(table)) or "none"
        raise ConfigError(f"unknown {kind} {name!r} (known: {known})")
    return spec


def detector_spec(name: str) -> DetectorSpec:
    """The registered detector ``name``; ConfigError naming the known ones."""
    spec: DetectorSpec = _lookup(_REGISTRY.detectors, "detector", name)
    return spec


def tracker_spec(name: str) -> TrackerSpec:
    """The registered tracker ``name``; ConfigError naming the known ones."""
    spec: TrackerSpec = _lookup(_REGISTRY.trackers, "tracker", name)
    return spec


def method_spec(name: str) -> MethodSpec:
    """The registered method ``name``; ConfigError naming the known ones."""
    spec: MethodSpec = _lookup(_REGISTRY.methods, "method", name)
    return spec


def paper_spec(name: str) -> PaperSpec:
    """The registered paper of method ``name``; ConfigError naming the known ones."""
    spec: PaperSpec = _lookup(_REGISTRY.papers, "paper", name)
    return spec


def known(kind: str) -> list[str]:
    """Registered names of ``detectors``, ``trackers``, ``methods`` or ``papers``, sorted."""
    load_plugins()
    table: Mapping[str, Any] = getattr(_REGISTRY, kind)
    return sorted(table)


def pairing_problem(
    detector_config: ComponentConfig, tracker_config: ComponentConfig
) -> str | None:
    """Why this detector cannot feed this tracker (None when it can)."""
    det = detector_spec(detector_config.name)
    trk = tracker_spec(tracker_config.name)
    return trk.check(tracker_config, det.contract(detector_config))


def streams_of(detector: DetectorSpec, tracker: TrackerSpec) -> tuple[StreamSpec, ...]:
    """The streams a pairing reads: the detector's, then the tracker's others (first wins)."""
    out: dict[str, StreamSpec] = {}
    for s in (*detector.streams, *(tracker.streams if tracker.needs_frame else ())):
        if s.role in out:
            prev = out[s.role]
            out[s.role] = StreamSpec(
                s.role, prev.required or s.required, prev.multiple or s.multiple
            )
        else:
            out[s.role] = s
    return tuple(out.values())
