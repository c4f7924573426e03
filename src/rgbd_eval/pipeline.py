"""Run one sequence: frames -> detections -> tracks -> scores. No printing, no files.

Each stage is its own function so that sweeps can reuse detections (a pure
function of the recording and the detector config) and re-run only tracking and
scoring.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from rgbd_eval.components import create_detector, create_tracker, needs_frame
from rgbd_eval.config import Gating, RunConfig
from rgbd_eval.detect.protocol import ResumableDetector
from rgbd_eval.errors import ConfigError, GroundTruthError, InputError, ScoringError
from rgbd_eval.io.groundtruth import GroundTruth, load_ground_truth
from rgbd_eval.io.recording import Recording, RecordingInfo, open_recording
from rgbd_eval.metrics import SequenceScores, evaluate_sequence
from rgbd_eval.plugins import detector_spec, streams_of, tracker_spec
from rgbd_eval.types import Detection, Frame, GroundTruthObject, Pose, TrackOutput

#: Called after each frame with (frames done, frames in all).
Progress = Callable[[int, int], None]
#: Stage names for what a detector's / tracker's call spends outside its named stages.
DETECT_REST = "detections"
TRACK_REST = "track"


@dataclass(frozen=True)
class SequenceDetections:
    """The detector's output for every frame of a recording.

    ``camera_poses``: the camera's world pose of every frame (``Frame.camera_pose``), for
    the breakdowns by distance and robot motion; empty where not kept (the detection cache).
    """

    stamps_ns: tuple[int, ...]
    detections: tuple[tuple[Detection, ...], ...]
    seconds: dict[str, float] = field(default_factory=dict)
    camera_poses: tuple[Pose, ...] = ()


@dataclass(frozen=True)
class GroundTruthMatch:
    """Ground truth aligned with the recording's frames.

    Only the frames from the first recording frame an annotated frame matched to the
    last (``span``) are scored: before and after, nothing says whether nobody was there
    or nobody annotated (a file covering the first 10 of 40 frames is not 30 empty
    frames). Frames inside the span without annotations are frames with nobody in them.
    """

    source: str
    frames: list[list[GroundTruthObject]]
    annotated_frames: int
    unmatched_frames: int
    span: tuple[int, int] | None = None
    max_gap_ms: float = 0.0

    @property
    def unscored_frames(self) -> int:
        """Recording frames outside the annotated span (not scored)."""
        if self.span is None:
            return 0
        return len(self.frames) - (self.span[1] - self.span[0] + 1)

    @property
    def warnings(self) -> tuple[str, ...]:
        """Annotated frames matching no recording frame, recording frames left unscored."""
        out = []
        if self.unmatched_frames:
            out.append(
                f"{self.unmatched_frames} of {self.annotated_frames} annotated frames of "
                f"{self.source} match no frame of the recording (nearest stamp within "
                f"{self.max_gap_ms:g} ms) and are not scored"
            )
        if self.unscored_frames and self.span is not None:
            out.append(
                f"{self.unscored_frames} of {len(self.frames)} frames lie outside the "
                f"annotated span (frames {self.span[0]}..{self.span[1]}) and are not scored"
            )
        return tuple(out)


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


def open_for(path: Path, config: RunConfig) -> Recording:
    """Open ``path`` for the streams the configured detector and tracker read."""
    streams = streams_of(detector_spec(config.detector.name), tracker_spec(config.tracker.name))
    return open_recording(path, config.io, streams)


def _add_stages(
    stages: dict[str, float], timings: Mapping[str, float], rest: str, total: float
) -> None:
    """Add a component's named stage seconds, and what its call spent outside them as ``rest``."""
    named = 0.0
    for stage, sec in timings.items():
        stages[stage] = stages.get(stage, 0.0) + sec
        named += sec
    stages[rest] = stages.get(rest, 0.0) + max(0.0, total - named)


def _detect_frames(
    recording: Recording,
    config: RunConfig,
    seconds: dict[str, float],
    stages: dict[str, float],
    span: tuple[int, int] | None = None,
    state: object | None = None,
) -> Iterator[tuple[Frame, tuple[Detection, ...]]]:
    """``(frame, detections)`` of every frame (or of frames ``span``) from a fresh detector
    (restored to ``state``, see :class:`~rgbd_eval.detect.protocol.ResumableDetector`).

    Adds the seconds spent reading and detecting to ``seconds["read"]`` and
    ``seconds["detect"]``, and the detector's own stages (:attr:`Detector.last_timings`,
    the rest of its call as ``detections``) to ``stages``; the consumer's time between
    frames is counted in neither.
    """
    detector = create_detector(config)
    if state is not None:
        if not isinstance(detector, ResumableDetector):
            raise ConfigError(f"detector {config.detector.name!r} cannot resume from a state")
        detector.restore_state(state)
    start = time.perf_counter()
    for frame in recording.frames(*(span or (0, len(recording)))):
        t0 = time.perf_counter()
        dets = tuple(detector.detect(frame))
        t1 = time.perf_counter()
        seconds["read"] += t0 - start
        seconds["detect"] += t1 - t0
        _add_stages(stages, detector.last_timings, DETECT_REST, t1 - t0)
        yield frame, dets
        start = time.perf_counter()


def _stage_seconds(seconds: dict[str, float], stages: dict[str, float]) -> dict[str, float]:
    return {**seconds, **{f"stage.{k}": v for k, v in stages.items()}}


def detect_sequence(
    recording: Recording,
    config: RunConfig,
    progress: Progress | None = None,
    span: tuple[int, int] | None = None,
    state: object | None = None,
) -> SequenceDetections:
    """Run the configured detector on every frame (a fresh detector per sequence).

    ``span`` and ``state``: frames ``start:stop`` only, from a detector resumed at ``state``.
    """
    seconds = {"read": 0.0, "detect": 0.0}
    stages: dict[str, float] = {}
    stamps: list[int] = []
    per_frame: list[tuple[Detection, ...]] = []
    for frame, dets in _detect_frames(recording, config, seconds, stages, span, state):
        stamps.append(frame.stamp_ns)
        per_frame.append(dets)
        if progress is not None:
            progress(len(per_frame), len(recording))
    return SequenceDetections(tuple(stamps), tuple(per_frame), _stage_seconds(seconds, stages))


def track_sequence(
    detections: SequenceDetections, config: RunConfig, recording: Recording | None = None
) -> tuple[tuple[TrackOutput, ...], ...]:
    """Run the configured tracker over per-frame detections (a fresh tracker per sequence).

    A tracker that needs frames (:func:`rgbd_eval.track.protocol.needs_frame`) gets them
    from ``recording``, read again (ConfigError when it is not given).
    """
    tracker = create_tracker(config)
    pairs = zip(detections.stamps_ns, detections.detections, strict=True)
    if not needs_frame(config):
        return tuple(tuple(tracker.update(stamp, dets)) for stamp, dets in pairs)
    if recording is None:
        raise ConfigError(
            f"tracker {config.tracker.name!r} reads frames: replaying it needs the recording"
        )
    out = []
    for (stamp, dets), frame in zip(pairs, recording.frames(), strict=True):
        if frame.stamp_ns != stamp:
            raise InputError(recording.path, f"frame {frame.index} changed since it was detected")
        out.append(tuple(tracker.update(stamp, dets, frame)))
    return tuple(out)


def detect_and_track(
    recording: Recording,
    config: RunConfig,
    progress: Progress | None = None,
    keep_appearance: bool = False,
) -> tuple[SequenceDetections, tuple[tuple[TrackOutput, ...], ...]]:
    """Detect and track frame by frame; the detections kept lose their appearance descriptors.

    The results equal :func:`detect_sequence` then :func:`track_sequence` (detector
    and tracker are independent), but the descriptors (2 KB per detection for
    basso2012's colour histogram) are dropped once the tracker has seen them, so
    memory grows only by the small per-frame records (stamps, boxes, tracks);
    ``keep_appearance`` keeps them (for a replay of the tracker, as ``bench`` does).
    ``seconds`` of the result hold ``read``, ``detect`` and ``track`` and, as
    ``stage.<name>``, the detector's and tracker's own stages (the rest of their
    calls as ``stage.detections`` and ``stage.track``): the figures of ``bench``.
    """
    seconds = {"read": 0.0, "detect": 0.0, "track": 0.0}
    stages: dict[str, float] = {}
    tracker = create_tracker(config)
    with_frame = needs_frame(config)
    stamps: list[int] = []
    poses: list[Pose] = []
    per_frame: list[tuple[Detection, ...]] = []
    tracks: list[tuple[TrackOutput, ...]] = []
    for frame, dets in _detect_frames(recording, config, seconds, stages):
        start = time.perf_counter()
        if with_frame:
            tracks.append(tuple(tracker.update(frame.stamp_ns, dets, frame)))
        else:
            tracks.append(tuple(tracker.update(frame.stamp_ns, dets)))
        spent = time.perf_counter() - start
        seconds["track"] += spent
        _add_stages(stages, tracker.last_timings, TRACK_REST, spent)
        stamps.append(frame.stamp_ns)
        poses.append(frame.camera_pose)
        per_frame.append(
            dets if keep_appearance else tuple(replace(d, appearance=None) for d in dets)
        )
        if progress is not None:
            progress(len(per_frame), len(recording))
    sequence = SequenceDetections(
        tuple(stamps), tuple(per_frame), _stage_seconds(seconds, stages), tuple(poses)
    )
    return sequence, tuple(tracks)


def match_ground_truth(
    gt: GroundTruth, stamps_ns: Sequence[int], config: RunConfig
) -> GroundTruthMatch:
    """Align annotations with frames by nearest stamp (within the sync gap)."""
    gap_ms = config.io.max_sync_gap_ms
    frames, unmatched, matched = gt.match(stamps_ns, int(gap_ms * 1e6))
    span = (matched[0], matched[-1]) if matched else None
    return GroundTruthMatch(gt.source, frames, len(gt.frames), unmatched, span, gap_ms)


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
    """CLEAR MOT scores of the annotated span of one sequence (the frames outside get empty
    events, see :class:`GroundTruthMatch`); ScoringError when nothing can be compared."""
    if gt.annotated_frames and gt.unmatched_frames == gt.annotated_frames:
        raise ScoringError(
            f"{gt.source}: none of its {gt.annotated_frames} annotated frames matches a frame "
            f"stamp of the recording (within {config.io.max_sync_gap_ms} ms)"
        )
    if not any(gt.frames):
        raise GroundTruthError(
            gt.source,
            "holds no annotated object (only a header?)"
            if gt.annotated_frames == 0
            else "annotates nobody in the frames that match the recording",
        )
    needs = "box2d" if config.evaluation.gating is Gating.IOU else "world_xyz"
    if not any(getattr(o, needs) is not None for frame in gt.frames for o in frame):
        other = "metric" if config.evaluation.gating is Gating.IOU else "iou"
        raise ScoringError(
            f"{gt.source}: '{config.evaluation.gating.value}' gating needs "
            f"{'image boxes' if needs == 'box2d' else 'world positions'}, which this ground "
            f"truth does not have (try --gating {other})"
        )
    if len(tracks) != len(gt.frames):
        raise ScoringError(
            f"ground truth has {len(gt.frames)} frames but the tracker output has "
            f"{len(tracks)}; they must be index-aligned"
        )
    first, last = gt.span if gt.span is not None else (0, len(gt.frames) - 1)
    scores = evaluate_sequence(
        gt.frames[first : last + 1], tracks[first : last + 1], config.evaluation
    )
    return scores.placed(first, len(gt.frames))


def warmup_warnings(config: RunConfig, frames: int) -> tuple[str, ...]:
    """A warning when every frame goes to the detector's warm-up (it then detects nothing)."""
    warmup = detector_spec(config.detector.name).warmup(config.detector)
    if warmup is None or frames > warmup[0]:
        return ()
    return (
        f"the {config.detector.name} detector spends all {frames} frames of the recording on "
        f"{warmup[1]} and detects nothing",
    )


def run_sequence(
    path: Path,
    config: RunConfig,
    gt_path: Path | None = None,
    progress: Progress | None = None,
) -> SequenceResult:
    """Read, detect, track and (when ground truth exists) score one recording."""
    path = Path(path)
    start = time.perf_counter()
    recording = open_for(path, config)
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
        info=replace(
            recording.info,
            warnings=(
                *recording.info.warnings,
                *recording.frame_warnings,
                *warmup_warnings(config, len(recording)),
            ),
        ),
        detections=detections,
        tracks=tracks,
        ground_truth=matched,
        scores=scores,
        seconds=seconds,
    )
