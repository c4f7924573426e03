"""Benchmark the pipeline stage by stage on one recording, against the floor of decoding it.

One repeat streams the recording once, frame by frame, through a fresh detector and
tracker (memory stays flat), then scores it when ground truth exists. Every stage is
timed on its own: ``index`` (the index pass: topic choice, RGB/depth pairing, tf),
``decode`` (reading and decoding each frame), the detector's own stages (for
basso2012 ``pointcloud``, ``voxel``, ``ground``, ``clustering``, ``subclustering``,
``features``, ``hog``, and ``detections`` for the rest of its call), ``track``,
``score`` (loading the ground truth, matching, CLEAR MOT) and ``other`` (loop
overhead: whatever the others do not cover), so the stages of one repeat sum to its
wall time. The floor is the same recording read and decoded alone
(:func:`rgbd_eval.io.benchmark.time_read`); *tracking alone* replays the repeat's
detections, held in memory, through a fresh tracker. Figures are medians over
repeats, per frame. By default the process is pinned to one CPU and OpenCV to one
thread (:func:`one_core`), so the figures are one-core figures. No printing.
"""

from __future__ import annotations

import os
import resource
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from rgbd_eval.components import needs_frame
from rgbd_eval.config import RunConfig
from rgbd_eval.errors import ConfigError, InputError
from rgbd_eval.io.benchmark import time_read
from rgbd_eval.pipeline import (
    DETECT_REST,
    TRACK_REST,
    detect_and_track,
    find_ground_truth,
    match_ground_truth,
    open_for,
    score_sequence,
    track_sequence,
)
from rgbd_eval.plugins import detector_spec, streams_of, tracker_spec

SCHEMA_VERSION = 2

#: Stages before and after detection, in pipeline order.
READ_STAGES = ("index", "decode")
LATE_STAGES = ("score", "other")

#: Called after each frame with (frames done, frames in all repeats).
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class BenchResult:
    """Per-frame timings of one recording (medians over repeats)."""

    schema_version: int
    path: str
    method: str
    frames: int
    repeats: int
    rgb_size: tuple[int, int]
    depth_size: tuple[int, int]
    detections_per_frame: float
    tracks_per_frame: float
    scored: bool
    #: Median milliseconds per frame of each stage, in pipeline order.
    stage_ms: dict[str, float]
    #: Milliseconds per frame of the whole pipeline, each repeat (wall clock).
    total_ms_repeats: tuple[float, ...]
    #: Milliseconds per frame to index and decode the recording alone, each repeat.
    floor_ms_repeats: tuple[float, ...]
    #: Milliseconds per frame to iterate the image messages' raw bytes (median).
    raw_ms: float
    raw_reader: str
    #: Milliseconds per frame of a fresh tracker fed the cached detections (median).
    track_alone_ms: float
    #: Peak resident set size of this process so far (MiB); it includes the detections
    #: held for the tracking-alone replay (`rgbd-eval run` keeps them without descriptors).
    peak_rss_mib: float
    openblas_threads: str | None
    #: CPUs the process was allowed to run on (None: not known on this platform).
    cpus: tuple[int, ...] | None = None
    #: CPU milliseconds per frame of the whole pipeline (this process, user + system), each
    #: repeat. On a loaded machine the wall figures grow with the load; this does not.
    cpu_ms_repeats: tuple[float, ...] = ()

    @property
    def total_ms(self) -> float:
        """Median milliseconds per frame of the whole pipeline."""
        return statistics.median(self.total_ms_repeats)

    @property
    def fps(self) -> float:
        """Frames per second of the whole pipeline (median repeat)."""
        return 1e3 / self.total_ms

    @property
    def floor_ms(self) -> float:
        """Median milliseconds per frame to index and decode alone."""
        return statistics.median(self.floor_ms_repeats)

    @property
    def floor_fps(self) -> float:
        """Frames per second of decoding alone: no pipeline can be faster."""
        return 1e3 / self.floor_ms

    @property
    def ratio(self) -> float:
        """Pipeline time over decode-only time (1 would mean processing is free)."""
        return self.total_ms / self.floor_ms

    @property
    def track_alone_fps(self) -> float:
        """Frames per second of tracking alone, from cached detections."""
        return 1e3 / self.track_alone_ms if self.track_alone_ms > 0.0 else float("inf")

    @property
    def cpu_ms(self) -> float:
        """Median CPU milliseconds per frame of the whole pipeline (0 when not measured)."""
        return statistics.median(self.cpu_ms_repeats) if self.cpu_ms_repeats else 0.0

    @property
    def cpu_fps(self) -> float:
        """Frames per second the pipeline would reach with its core to itself (CPU time)."""
        return 1e3 / self.cpu_ms if self.cpu_ms > 0.0 else float("inf")

    def stage_fps(self, stage: str) -> float:
        """Frames per second of one stage alone (``inf`` when it took no time)."""
        ms = self.stage_ms[stage]
        return 1e3 / ms if ms > 0.0 else float("inf")

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict, derived figures included."""
        return {
            "schema_version": self.schema_version,
            "path": self.path,
            "method": self.method,
            "frames": self.frames,
            "repeats": self.repeats,
            "rgb_size": list(self.rgb_size),
            "depth_size": list(self.depth_size),
            "detections_per_frame": self.detections_per_frame,
            "tracks_per_frame": self.tracks_per_frame,
            "scored": self.scored,
            "stage_ms": dict(self.stage_ms),
            "total_ms": self.total_ms,
            "fps": self.fps,
            "total_ms_repeats": list(self.total_ms_repeats),
            "floor_ms": self.floor_ms,
            "floor_fps": self.floor_fps,
            "floor_ms_repeats": list(self.floor_ms_repeats),
            "ratio": self.ratio,
            "raw_ms": self.raw_ms,
            "raw_reader": self.raw_reader,
            "track_alone_ms": self.track_alone_ms,
            "track_alone_fps": self.track_alone_fps,
            "peak_rss_mib": self.peak_rss_mib,
            "openblas_threads": self.openblas_threads,
            "cpus": None if self.cpus is None else list(self.cpus),
            "cpu_ms": self.cpu_ms,
            "cpu_fps": self.cpu_fps if self.cpu_ms_repeats else None,
            "cpu_ms_repeats": list(self.cpu_ms_repeats),
        }


@dataclass(frozen=True)
class _Repeat:
    frames: int
    seconds: dict[str, float]
    wall_s: float
    cpu_s: float
    detections: int
    tracks: int
    scored: bool
    rgb_size: tuple[int, int]
    depth_size: tuple[int, int]
    track_alone_s: float


def one_core() -> tuple[int, ...] | None:
    """Pin this process to one of its CPUs and OpenCV to one thread; the CPUs now allowed.

    BLAS is single-threaded already (see :mod:`rgbd_eval.cli`). Where the platform
    cannot pin (macOS), only OpenCV is limited and None is returned.
    """
    import cv2

    cv2.setNumThreads(1)
    if not hasattr(os, "sched_setaffinity"):
        return None
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    return allowed_cpus()


def allowed_cpus() -> tuple[int, ...] | None:
    """The CPUs this process may run on (None where the platform does not say)."""
    return tuple(sorted(os.sched_getaffinity(0))) if hasattr(os, "sched_getaffinity") else None


def peak_rss_mib() -> float:
    """Peak resident set size of this process (MiB; Linux reports KiB, macOS bytes)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1024.0 if os.uname().sysname != "Darwin" else peak / 2.0**20


def _one_repeat(
    path: Path, config: RunConfig, done: int, total: int, progress: Progress | None
) -> _Repeat:
    """Stream the recording once through detector, tracker and scorer (the loop of ``run``)."""
    wall = time.perf_counter()
    cpu = time.process_time()
    recording = open_for(path, config)
    index_s = time.perf_counter() - wall
    start = time.perf_counter()
    gt = find_ground_truth(path, recording, None)
    gt_s = time.perf_counter() - start

    def advance(frames_done: int, _frames: int) -> None:
        if progress is not None:
            progress(done + frames_done, total)

    detections, tracks = detect_and_track(recording, config, advance, keep_appearance=True)
    start = time.perf_counter()
    scored = gt is not None
    if gt is not None:
        score_sequence(match_ground_truth(gt, detections.stamps_ns, config), tracks, config)
    score_s = gt_s + time.perf_counter() - start
    wall_s = time.perf_counter() - wall
    cpu_s = time.process_time() - cpu
    seconds = {"index": index_s, "decode": detections.seconds["read"]}
    seconds.update(
        {
            k.removeprefix("stage."): v
            for k, v in detections.seconds.items()
            if k.startswith("stage.")
        }
    )
    seconds["score"] = score_s
    seconds["other"] = max(0.0, wall_s - sum(seconds.values()))
    start = time.perf_counter()
    track_sequence(detections, config, open_for(path, config) if needs_frame(config) else None)
    track_alone_s = time.perf_counter() - start
    first = next(recording.frames(), None) if detections.stamps_ns else None
    sizes = (
        {}
        if first is None
        else {r: (s.image.shape[1], s.image.shape[0]) for r, s in first.streams.items()}
    )
    return _Repeat(
        frames=len(detections.stamps_ns),
        seconds=seconds,
        wall_s=wall_s,
        cpu_s=cpu_s,
        detections=sum(len(d) for d in detections.detections),
        tracks=sum(len(t) for t in tracks),
        scored=scored,
        rgb_size=sizes.get("colour", (0, 0)),
        depth_size=sizes.get("depth", (0, 0)),
        track_alone_s=track_alone_s,
    )


def _stage_order(stages: set[str], config: RunConfig) -> list[str]:
    """Reading, the detector's stages, the tracker's, then scoring, in pipeline order."""
    order = (
        *READ_STAGES,
        *detector_spec(config.detector.name).stages,
        DETECT_REST,
        *tracker_spec(config.tracker.name).stages,
        TRACK_REST,
        *LATE_STAGES,
    )
    known = [s for s in order if s in stages]
    return [*known, *sorted(stages - set(known))]


def benchmark(
    path: Path | str,
    config: RunConfig,
    repeats: int = 3,
    progress: Progress | None = None,
) -> BenchResult:
    """Time every stage of the configured pipeline on ``path``, ``repeats`` times, and the floor.

    Raises the package's errors for a bad recording or config (InputError, ConfigError, ...).
    """
    if repeats < 1:
        raise ConfigError(f"repeat={repeats} must be >= 1")
    path = Path(path)
    runs: list[_Repeat] = []
    floors: list[float] = []
    raws: list[float] = []
    raw_reader = ""
    for _ in range(repeats):
        # decode-only floor first, then the pipeline: both see the same cache state
        read = time_read(
            path,
            config.io,
            streams_of(detector_spec(config.detector.name), tracker_spec(config.tracker.name)),
        )
        if read.frames == 0:
            raise InputError(path, "no synchronised RGB/depth frames to benchmark")
        frames = read.frames
        total = frames * repeats
        floors.append((read.index_s + read.frames_s) * 1e3 / frames)
        raws.append(read.raw_floor_s * 1e3 / frames)
        raw_reader = read.raw_floor_reader
        runs.append(_one_repeat(path, config, len(runs) * frames, total, progress))
    frames = runs[0].frames
    stages = _stage_order({s for r in runs for s in r.seconds}, config)
    stage_ms = {
        s: statistics.median(r.seconds.get(s, 0.0) * 1e3 / frames for r in runs) for s in stages
    }
    first = runs[0]
    return BenchResult(
        schema_version=SCHEMA_VERSION,
        path=str(path),
        method=f"{config.method} ({config.detector.name} + {config.tracker.name})",
        frames=frames,
        repeats=repeats,
        rgb_size=first.rgb_size,
        depth_size=first.depth_size,
        detections_per_frame=first.detections / frames,
        tracks_per_frame=first.tracks / frames,
        scored=first.scored,
        stage_ms=stage_ms,
        total_ms_repeats=tuple(r.wall_s * 1e3 / frames for r in runs),
        floor_ms_repeats=tuple(floors),
        raw_ms=statistics.median(raws),
        raw_reader=raw_reader,
        track_alone_ms=statistics.median(r.track_alone_s * 1e3 / frames for r in runs),
        peak_rss_mib=peak_rss_mib(),
        openblas_threads=os.environ.get("OPENBLAS_NUM_THREADS"),
        cpus=allowed_cpus(),
        cpu_ms_repeats=tuple(r.cpu_s * 1e3 / frames for r in runs),
    )
