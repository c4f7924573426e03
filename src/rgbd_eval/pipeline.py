"""Run one sequence: frames -> detections -> tracks -> scores. No printing, no files.

Each stage is its own function so that sweeps can reuse detections (a pure
function of the recording and the detector config) and re-run only tracking and
scoring.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from rgbd_eval.config import Gating, RunConfig
from rgbd_eval.detect.protocol import create_detector
from rgbd_eval.errors import GroundTruthError, ScoringError
from rgbd_eval.io.groundtruth import GroundTruth, load_ground_truth
from rgbd_eval.io.reader import Recording, RecordingInfo, open_recording
from rgbd_eval.metrics import SequenceScores, evaluate_sequence
from rgbd_eval.track.protocol import create_tracker
from rgbd_eval.types import Detection, GroundTruthObject, TrackOutput

#: Called after each frame with (frames done, frames in all).
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class SequenceDetections:
    """The detector's output for every frame of a recording."""

    stamps_ns: tuple[int, ...]
    detections: tuple[tuple[Detection, ...], ...]
    seconds: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class GroundTruthMatch:
    """Ground truth aligned with the recording's frames."""

    source: str
    frames: list[list[GroundTruthObject]]
    annotated_frames: int
    unmatched_frames: int


@dataclass(frozen=True)
class SequenceResult:
    """Everything one run of one sequence produced."""

    name: str
    path: str
    info: RecordingInfo
    detections: SequenceDetections
    tracks: tuple[tuple[TrackOutput, ...], ...]
    ground_truth: GroundTruthMatch | None
    scores: SequenceScores | None
    seconds: dict[str, float]


def sequence_name(path: Path) -> str:
    """A short name for reports: the file name without its container suffix."""
    return path.name[: -len(path.suffix)] if path.suffix in (".bag", ".mcap", ".db3") else path.name


def sidecar_path(path: Path) -> Path | None:
    """``<name>.gt.csv`` beside a recording, if present."""
    candidate = path.with_name(f"{sequence_name(path)}.gt.csv")
    return candidate if candidate.exists() else None


def _detect_frames(
    recording: Recording, config: RunConfig, seconds: dict[str, float]
) -> Iterator[tuple[int, tuple[Detection, ...]]]:
    """``(stamp, detections)`` of every frame from a fresh detector.

    Adds the seconds spent reading and detecting to ``seconds["read"]`` and
    ``seconds["detect"]``; the consumer's time between frames is counted in neither.
    """
    detector = create_detector(config.method, config)
    start = time.perf_counter()
    for frame in recording.frames():
        t0 = time.perf_counter()
        dets = tuple(detector.detect(frame))
        t1 = time.perf_counter()
        seconds["read"] += t0 - start
        seconds["detect"] += t1 - t0
        yield frame.stamp_ns, dets
        start = time.perf_counter()


def detect_sequence(
    recording: Recording, config: RunConfig, progress: Progress | None = None
) -> SequenceDetections:
    """Run the configured detector on every frame (a fresh detector per sequence)."""
    seconds = {"read": 0.0, "detect": 0.0}
    stamps: list[int] = []
    per_frame: list[tuple[Detection, ...]] = []
    for stamp, dets in _detect_frames(recording, config, seconds):
        stamps.append(stamp)
        per_frame.append(dets)
        if progress is not None:
            progress(len(per_frame), len(recording))
    return SequenceDetections(tuple(stamps), tuple(per_frame), seconds)


def track_sequence(
    detections: SequenceDetections, config: RunConfig
) -> tuple[tuple[TrackOutput, ...], ...]:
    """Run the configured tracker over per-frame detections (a fresh tracker per sequence)."""
    tracker = create_tracker(config.method, config)
    return tuple(
        tuple(tracker.update(stamp, dets))
        for stamp, dets in zip(detections.stamps_ns, detections.detections, strict=True)
    )


def detect_and_track(
    recording: Recording, config: RunConfig, progress: Progress | None = None
) -> tuple[SequenceDetections, tuple[tuple[TrackOutput, ...], ...]]:
    """Detect and track frame by frame; the detections kept lose their appearance descriptors.

    The results equal :func:`detect_sequence` then :func:`track_sequence` (detector
    and tracker are independent), but the descriptors (2 KB per detection for
    basso2012's colour histogram) are dropped once the tracker has seen them, so
    memory grows only by the small per-frame records (stamps, boxes, tracks).
    """
    seconds = {"read": 0.0, "detect": 0.0, "track": 0.0}
    tracker = create_tracker(config.method, config)
    stamps: list[int] = []
    per_frame: list[tuple[Detection, ...]] = []
    tracks: list[tuple[TrackOutput, ...]] = []
    for stamp, dets in _detect_frames(recording, config, seconds):
        start = time.perf_counter()
        tracks.append(tuple(tracker.update(stamp, dets)))
        seconds["track"] += time.perf_counter() - start
        stamps.append(stamp)
        per_frame.append(tuple(replace(d, appearance=None) for d in dets))
        if progress is not None:
            progress(len(per_frame), len(recording))
    return SequenceDetections(tuple(stamps), tuple(per_frame), seconds), tuple(tracks)


def match_ground_truth(
    gt: GroundTruth, stamps_ns: Sequence[int], config: RunConfig
) -> GroundTruthMatch:
    """Align annotations with frames by nearest stamp (within the sync gap)."""
    frames, unmatched = gt.align(stamps_ns, int(config.io.max_sync_gap_ms * 1e6))
    return GroundTruthMatch(gt.source, frames, len(gt.frames), unmatched)


def ground_truth_file(path: Path, gt_path: Path | None) -> GroundTruth | None:
    """An explicit file, else the ``<name>.gt.csv`` sidecar (no need to open the recording)."""
    if gt_path is not None:
        return load_ground_truth(gt_path)
    sidecar = sidecar_path(path)
    return load_ground_truth(sidecar) if sidecar is not None else None


def find_ground_truth(path: Path, recording: Recording, gt_path: Path | None) -> GroundTruth | None:
    """An explicit file, else the ``<name>.gt.csv`` sidecar, else the ground-truth topic."""
    gt = ground_truth_file(path, gt_path)
    return gt if gt is not None else recording.ground_truth_topic


def score_sequence(
    gt: GroundTruthMatch, tracks: Sequence[Sequence[TrackOutput]], config: RunConfig
) -> SequenceScores:
    """CLEAR MOT scores of one sequence; ScoringError when nothing can be compared."""
    if gt.annotated_frames and gt.unmatched_frames == gt.annotated_frames:
        raise ScoringError(
            f"{gt.source}: none of its {gt.annotated_frames} annotated frames matches a frame "
            f"stamp of the recording (within {config.io.max_sync_gap_ms} ms)"
        )
    if gt.annotated_frames == 0:
        raise GroundTruthError(gt.source, "holds no annotated object (only a header?)")
    needs = "box2d" if config.evaluation.gating is Gating.IOU else "world_xyz"
    if not any(getattr(o, needs) is not None for frame in gt.frames for o in frame):
        other = "metric" if config.evaluation.gating is Gating.IOU else "iou"
        raise ScoringError(
            f"{gt.source}: '{config.evaluation.gating.value}' gating needs "
            f"{'image boxes' if needs == 'box2d' else 'world positions'}, which this ground "
            f"truth does not have (try --gating {other})"
        )
    return evaluate_sequence(gt.frames, tracks, config.evaluation)


def run_sequence(
    path: Path,
    config: RunConfig,
    gt_path: Path | None = None,
    progress: Progress | None = None,
) -> SequenceResult:
    """Read, detect, track and (when ground truth exists) score one recording."""
    path = Path(path)
    start = time.perf_counter()
    recording = open_recording(path, config.io)
    index_s = time.perf_counter() - start
    gt = find_ground_truth(path, recording, gt_path)
    detections, tracks = detect_and_track(recording, config, progress)
    matched = scores = None
    score_s = 0.0
    if gt is not None:
        start = time.perf_counter()
        matched = match_ground_truth(gt, detections.stamps_ns, config)
        scores = score_sequence(matched, tracks, config)
        score_s = time.perf_counter() - start
    seconds = {"index": index_s, **detections.seconds, "score": score_s}
    return SequenceResult(
        name=sequence_name(path),
        path=str(path),
        info=replace(recording.info, warnings=recording.info.warnings + recording.frame_warnings),
        detections=detections,
        tracks=tracks,
        ground_truth=matched,
        scores=scores,
        seconds=seconds,
    )
