"""Write a scenario as a recording (ROS1 .bag or ROS2 .mcap) plus its ground-truth CSV.

Topics and tf tree (see :mod:`rgbd_eval.sim.rig`): RGB and depth images with
their CameraInfos, ``/odom`` and ``/tf`` (odom -> base_link, drifting
odometry), ``/tf_static`` (base_link -> camera_link -> optical frames) and
``/ground_truth`` (true world frame). The sidecar ``<stem>.gt.csv`` holds the
same ground truth.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from rgbd_eval import __version__
from rgbd_eval.config import data_home
from rgbd_eval.errors import OutputError
from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.writer import RecordingWriter, StreamOptions
from rgbd_eval.outdir import check_output_file
from rgbd_eval.sim import rig
from rgbd_eval.sim.rig import RigSensor
from rgbd_eval.sim.rig_sensors import make_rig_sensor
from rgbd_eval.sim.scenario import Scenario, load_scenario, scenario_paths, scenarios_dir
from rgbd_eval.sim.simulate import SimFrame, Simulator
from rgbd_eval.types import GroundTruthObject

ProgressCallback = Callable[[int, int], None]
SynthContainer = Literal["ros1", "mcap"]
#: Who wrote a synthetic recording, its sidecar, preview and following record (the manifest's
#: name for them, whichever command generated them: synth, or run/bench/reproduce on first use).
OWNER = "synth"


@dataclass(frozen=True)
class SynthResult:
    """What :func:`synthesize` wrote and how fast."""

    recording: Path
    ground_truth_csv: Path
    frames: int
    people_instances: int
    seconds: float
    recording_bytes: int

    @property
    def frames_per_second(self) -> float:
        return self.frames / self.seconds if self.seconds > 0 else float("inf")


def ground_truth_path(out_path: Path | str) -> Path:
    """The sidecar CSV next to a recording: ``<dir>/<stem>.gt.csv``."""
    p = Path(out_path)
    return p.with_name(p.stem + ".gt.csv")


def stream_options(scenario: Scenario) -> StreamOptions:
    """The writer options a scenario asks for."""
    r = scenario.recording
    return StreamOptions(
        rgb_format=r.rgb_format,
        depth_encoding=r.depth_encoding,
        depth_compressed=r.depth_compressed,
        jpeg_quality=r.jpeg_quality,
    )


def container_for(out_path: Path | str) -> SynthContainer:
    """``ros1`` for ``.bag``, ``mcap`` for ``.mcap``; anything else is a ValueError."""
    suffix = Path(out_path).suffix
    if suffix == ".bag":
        return "ros1"
    if suffix == ".mcap":
        return "mcap"
    raise ValueError(f"out_path={str(out_path)!r} must end in .bag or .mcap")


#: Bumped whenever rendering changes the bytes on purpose (tests/sim/test_determinism.py pins
#: them): two recordings of the same provenance must then be the same bytes.
RENDERER_VERSION = 3


def provenance(
    sim: Simulator, frames: int, container: SynthContainer, closed_loop: str | None = None
) -> dict[str, object]:
    """The provenance record of a recording (:mod:`rgbd_eval.io.provenance`).

    ``closed_loop`` identifies what drove the robot when the path is not the scenario's.
    """
    sc = sim.source_scenario  # as written: with the seed, it names the paths walked
    return {
        "generator": "rgbd-eval synth",
        "tool_version": __version__,
        "renderer_version": RENDERER_VERSION,
        "scenario": sc.name,
        "scenario_sha256": sc.digest(),
        "scenario_file_sha256": sc.source_sha256,
        "seed": sim.seed,
        "frames": frames,
        "container": container,
        "closed_loop": closed_loop,
    }


def write_static(w: RecordingWriter, sim: Simulator, sensors: Sequence[RigSensor]) -> None:
    """The static transforms of the robot's cameras and of the rig's sensors."""
    first = sim.scenario.stamp_ns(0)
    w.write_static_transform(first, rig.BASE_FRAME, rig.CAMERA_LINK, sim.base_to_link)
    w.write_static_transform(first, rig.CAMERA_LINK, rig.RGB_FRAME, sim.link_to_rgb)
    w.write_static_transform(first, rig.CAMERA_LINK, rig.DEPTH_FRAME, sim.link_to_depth)
    for sensor in sensors:
        for parent, child, pose in sensor.static_transforms():
            w.write_static_transform(first, parent, child, pose)


def write_frame(w: RecordingWriter, sim: Simulator, f: SimFrame) -> None:
    """One frame's odometry, tf, Kinect images (unless ``robot_camera`` is off) and ground truth."""
    stamp = f.stamp_ns
    w.write_odometry(stamp, rig.WORLD_FRAME, rig.BASE_FRAME, f.base_odom)
    w.write_transform(stamp, rig.WORLD_FRAME, rig.BASE_FRAME, f.base_odom)
    if sim.scenario.robot_camera:
        w.write_rgb(stamp, f.rgb, sim.rgb_camera)
        w.write_depth(stamp, f.depth, sim.depth_camera)
    w.write_ground_truth(stamp, rig.WORLD_FRAME, f.ground_truth)


def synthesize(
    scenario: Scenario,
    out_path: Path | str,
    container: SynthContainer | None = None,
    seed: int | None = None,
    progress: ProgressCallback | None = None,
    overwrite: bool = True,
    max_frames: int | None = None,
) -> SynthResult:
    """Render ``scenario`` and write it to ``out_path`` plus ``<stem>.gt.csv``.

    ``container`` defaults from the suffix (``.bag`` -> ros1, ``.mcap`` -> mcap);
    ``seed`` defaults to the scenario's; ``progress(done, total)`` is called after
    every frame; ``max_frames`` truncates the sequence (tests, previews).
    Both files appear atomically. Same scenario and seed give the same bytes.
    Either file replaces only one ``synth`` wrote, unchanged since (``overwrite=False``:
    none); both are checked before rendering (OutputError, as for a full disk).
    """
    out = Path(out_path)
    kind: SynthContainer = container if container is not None else container_for(out)
    if kind not in ("ros1", "mcap"):
        raise ValueError(f"container={kind!r} must be 'ros1' or 'mcap'")
    csv_path = ground_truth_path(out)
    for target in (out, csv_path):
        if not overwrite and os.path.lexists(target):
            raise OutputError(target, "exists; not replaced")
        check_output_file(target, OWNER)  # a user's annotations beside it are never replaced
    sim = Simulator(scenario, seed)
    total = sim.n_frames if max_frames is None else min(sim.n_frames, max_frames)
    if total < 1:
        raise ValueError(f"max_frames={max_frames} must be at least 1")
    start = time.perf_counter()
    truth: list[GroundTruthObject] = []
    annotated: list[tuple[int, int]] = []  # every frame, people in view or not
    try:
        with RecordingWriter(out, kind, stream_options(scenario), owner=OWNER) as w:
            extra = [make_rig_sensor(c, rig.WORLD_FRAME) for c in scenario.rig]
            w.write_provenance(scenario.stamp_ns(0), provenance(sim, total, kind))
            write_static(w, sim, extra)
            for f in sim.frames(list(range(total))):
                write_frame(w, sim, f)
                for k, sensor in enumerate(extra):
                    sensor.write(w, sim.scene_view(f.index, k))
                truth.extend(f.ground_truth)
                annotated.append((f.index, f.stamp_ns))
                if progress is not None:
                    progress(f.index + 1, total)
    except OSError as err:  # a full disk: the writer removed its temporary file
        raise OutputError(out, f"cannot write ({err.strerror or err})") from err
    write_csv(csv_path, truth, annotated, OWNER)
    elapsed = time.perf_counter() - start
    return SynthResult(out, csv_path, total, len(truth), elapsed, out.stat().st_size)


# ----------------------------------------------------------------------------- datasets/

#: The scenario of the embedded demo sequence.
DEMO = "demo"


def dataset_path(name: str, container: SynthContainer = "mcap") -> Path:
    """Where ``synth --all`` puts a scenario's recording.

    The small demo lives in the data folder (:func:`rgbd_eval.config.data_home`:
    ``datasets/`` in a checkout, a user cache folder otherwise), generated on first
    use; the other scenarios go to its ``generated/`` subfolder.
    """
    if container not in ("ros1", "mcap"):
        raise ValueError(f"container={container!r} must be 'ros1' or 'mcap'")
    suffix = ".bag" if container == "ros1" else ".mcap"
    folder = data_home()
    if name != DEMO:
        folder = folder / "generated"
    return folder / f"{name}{suffix}"


def demo_recording(progress: ProgressCallback | None = None) -> Path:
    """The demo recording ``datasets/demo.mcap``, generated (scenario seed) if missing."""
    path = dataset_path(DEMO)
    if not path.exists() or not ground_truth_path(path).exists():
        synthesize(load_scenario(scenarios_dir() / f"{DEMO}.yaml"), path, "mcap", None, progress)
    return path


def scenario_file(name_or_path: str | Path) -> Path:
    """A scenario's YAML: a path as given, or a name in ``configs/scenarios``."""
    source = Path(name_or_path)
    return source if source.suffix in (".yaml", ".yml") else scenarios_dir() / f"{source}.yaml"


def recording_path(yaml_path: Path, folder: Path | None = None, seed: int | None = None) -> Path:
    """Where :func:`ensure_scenario` keeps a scenario's recording at ``seed``:
    ``<name>.mcap`` at the scenario's own seed, ``<name>-seed<seed>.mcap`` at another, in
    ``folder`` (default: :func:`dataset_path`)."""
    own = seed is None or seed == load_scenario(yaml_path).seed
    stem = yaml_path.stem if own else f"{yaml_path.stem}-seed{seed}"
    return dataset_path(stem) if folder is None else Path(folder) / f"{stem}.mcap"


def is_current(path: Path, yaml_path: Path, seed: int | None = None) -> bool:
    """Whether the recording at ``path`` is what rendering the scenario at ``seed`` (default:
    its own) makes now: present with its ground truth, and its provenance names the same
    scenario digest, seed and renderer version (else the scene file or the renderer changed
    since it was made)."""
    from rgbd_eval.io.provenance import read

    if not path.exists() or not ground_truth_path(path).exists():
        return False
    scenario = load_scenario(yaml_path)
    prov = read(path)
    return prov is not None and (
        prov.get("scenario_sha256") == scenario.digest()
        and prov.get("seed") == (scenario.seed if seed is None else seed)
        and prov.get("renderer_version") == RENDERER_VERSION
    )


#: CPU seconds spent rendering by :func:`ensure_scenario` for this process, including
#: what other processes report back through :func:`add_rendering_cpu`.
_RENDERING_CPU_S = [0.0]


def rendering_cpu_s() -> float:
    """CPU seconds spent rendering recordings in :func:`ensure_scenario` for this process
    (``reproduce`` reports them as rendering, apart from the experiments' method time)."""
    return _RENDERING_CPU_S[0]


def add_rendering_cpu(seconds: float) -> None:
    """Count rendering done for this process elsewhere (a cluster worker's task)."""
    _RENDERING_CPU_S[0] += seconds


def ensure_scenario(
    name_or_path: str | Path,
    folder: Path | None = None,
    say: Callable[[str], None] | None = None,
    seed: int | None = None,
) -> Path:
    """The recording of a scenario (a name in ``configs/scenarios`` or a YAML path) at
    ``seed`` (default: the scenario's own), at :func:`recording_path` in ``folder``;
    rendered when absent or not :func:`is_current` (``synth`` replaces only the files it
    wrote: a user's file of that name is an OutputError, never replaced)."""
    yaml_path = scenario_file(name_or_path)
    path = recording_path(yaml_path, folder, seed)
    if is_current(path, yaml_path, seed):
        return path
    if say is not None:
        state = "out of date (the scene or the renderer changed)" if path.exists() else "absent"
        say(f"generating {path} ({state}) ...")
    start = time.process_time()
    synthesize(load_scenario(yaml_path), path, "mcap", seed=seed)
    add_rendering_cpu(time.process_time() - start)
    return path


def synthesize_all(
    container: SynthContainer = "mcap",
    seed: int | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> list[SynthResult]:
    """``synth --all``: every scenario of ``configs/scenarios`` to its :func:`dataset_path`.

    ``progress(name, done, total)`` is called after every frame.
    """
    results = []
    for path in scenario_paths():
        scenario = load_scenario(path)
        name = path.stem

        def report(done: int, total: int, name: str = name) -> None:
            if progress is not None:
                progress(name, done, total)

        results.append(synthesize(scenario, dataset_path(name, container), container, seed, report))
    return results
