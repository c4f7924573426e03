"""Detecting one recording in frame chunks on several workers, bit-identical to one pass.

basso2012 carries one thing from frame to frame: its ground plane, refined on
every frame from the previous frame's plane (seed 000, 5.1 and 5.4.2), so frame
k's detections depend on every frame before it, and a chunk cannot start from
a fresh detector. But the plane comes from the cheap first stages of the
detector alone (point cloud, voxel grid, ground: about a fifth of its time, the
clustering, features and HOG that follow carry nothing), so the state at the
start of chunk k is found by a chain of *advance* passes over chunks
``0..k-1`` (:meth:`~rgbd_eval.detect.protocol.ResumableDetector.advance`),
and each chunk is then detected in full from that state, in parallel with the
rest of the chain. The joined chunks equal the sequential run bit for bit
(tests/test_chunked.py). Detectors that are not resumable run in one piece.

Cost: the chain re-reads and re-runs the ground stages of every chunk but the
last: with K chunks, ``(K-1)/K`` of those stages again. Each task reads its own
frames only (:meth:`~rgbd_eval.io.recording.Recording.frames` starts at the first
one's log time), so no chunk or link re-reads the frames before it.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from rgbd_eval.components import create_detector
from rgbd_eval.config import RunConfig
from rgbd_eval.detect.protocol import ResumableDetector
from rgbd_eval.errors import ConfigError
from rgbd_eval.io.recording import Recording
from rgbd_eval.pipeline import SequenceDetections, detect_sequence

#: Fewest frames worth a chunk of their own when the chunk count is chosen automatically:
#: each chunk task re-creates its detector and opens the recording's reader at its first frame.
MIN_CHUNK_FRAMES = 60


@dataclass(frozen=True)
class ChunkPlan:
    """Split a recording's detection into at most ``chunks`` pieces of ``min_frames`` or more.

    ``advance_cost``: the advance pass's cost per frame as a fraction of a detection's
    (:func:`advance_cost`). Chunk ``k`` waits for the advance pass over the frames
    before it, so with a cost ``r > 0`` the chunks shrink geometrically, each by a factor
    ``1 - r``: then ``r * start_k + length_k`` is the same for every chunk, and a worker
    that advances over chunk 0 and then detects chunk 1 ends with the worker that detects
    chunk 0 (exact for two chunks; for more, an approximation: the model charges each
    chunk its whole advance chain, whose links are in fact shared). 0 gives chunks of
    equal length. Results never depend on it.
    """

    chunks: int
    min_frames: int = MIN_CHUNK_FRAMES
    advance_cost: float = 0.0

    def __post_init__(self) -> None:
        if self.chunks < 1 or self.min_frames < 1:
            raise ConfigError(
                f"chunks ({self.chunks}) and min_frames ({self.min_frames}) must be at least 1"
            )
        if not 0.0 <= self.advance_cost < 1.0:
            raise ConfigError(f"advance_cost ({self.advance_cost}) must be in [0, 1)")

    def spans(self, frames: int) -> list[tuple[int, int]]:
        """``chunks`` frame ranges covering ``0:frames`` in order; the tail ones empty when
        the recording is too short for that many chunks of ``min_frames``."""
        used = max(1, min(self.chunks, frames // self.min_frames))
        while True:
            bounds = self._bounds(frames, used)
            if used == 1 or min(b - a for a, b in itertools.pairwise(bounds)) >= self.min_frames:
                break
            used -= 1  # the geometric shrink left the last chunk too short
        spans = list(itertools.pairwise(bounds))
        return spans + [(frames, frames)] * (self.chunks - used)

    def _bounds(self, frames: int, used: int) -> list[int]:
        """Chunk boundaries: lengths in proportion to ``(1 - r)**k``, rounded down."""
        if self.advance_cost == 0.0:
            return [frames * i // used for i in range(used + 1)]
        weights = list(itertools.accumulate((1.0 - self.advance_cost) ** k for k in range(used)))
        return [0] + [int(frames * w / weights[-1]) for w in weights[:-1]] + [frames]


def resumable(config: RunConfig) -> bool:
    """Whether the configured detector can be detected in chunks."""
    return isinstance(create_detector(config), ResumableDetector)


def advance_cost(config: RunConfig) -> float:
    """The configured detector's ``advance_cost`` (an advance pass's cost per frame as a
    fraction of a detection's, which a :class:`ResumableDetector` may declare), else 0."""
    value = getattr(create_detector(config), "advance_cost", 0.0)
    return float(value) if isinstance(value, int | float) and 0.0 <= value < 1.0 else 0.0


def advance(
    recording: Recording, config: RunConfig, span: tuple[int, int], state: object | None
) -> object:
    """The detector's carried state after frames ``span``, starting from ``state``
    (None: a fresh detector)."""
    detector = create_detector(config)
    if not isinstance(detector, ResumableDetector):
        raise ConfigError(f"detector {config.detector.name!r} cannot resume from a state")
    if state is not None:
        detector.restore_state(state)
    skip = set(recording.info.selected.streams) - detector.advance_reads
    for frame in recording.frames(*span, skip=skip):
        detector.advance(frame)
    return detector.carry_state()


@dataclass(frozen=True)
class Chunk:
    """The detections of one chunk, how many of its depth frames held no valid (or no
    plausible) pixel, and why the first implausible one was dropped."""

    detections: SequenceDetections
    empty_depth_frames: int
    implausible_depth: str | None = None


def detect_chunk(
    recording: Recording, config: RunConfig, span: tuple[int, int], state: object | None
) -> Chunk:
    """Detections of frames ``span`` from a detector resumed at ``state`` (None: fresh)."""
    detections = detect_sequence(recording, config, span=span, state=state)
    unusable = len(recording.empty_depth_frames) + len(recording.implausible_depth_frames)
    problem = recording.implausible_depth_problem if recording.implausible_depth_frames else None
    return Chunk(detections, unusable, problem)


def join(recording: Recording, chunks: Sequence[Chunk]) -> SequenceDetections:
    """The chunks of one recording, in order, as one :class:`SequenceDetections`.

    Raises the recording's own error when no depth frame of any chunk held a valid
    pixel, as a pass over the whole recording does.
    """
    frames = sum(len(c.detections.stamps_ns) for c in chunks)
    if frames != len(recording):
        raise ValueError(f"chunks hold {frames} of {len(recording)} frames")
    if frames and sum(c.empty_depth_frames for c in chunks) == frames:
        problem = next((c.implausible_depth for c in chunks if c.implausible_depth), None)
        raise recording.no_depth_error(problem)
    seconds: dict[str, float] = {}
    for c in chunks:
        for name, value in c.detections.seconds.items():
            seconds[name] = seconds.get(name, 0.0) + value
    return SequenceDetections(
        stamps_ns=tuple(s for c in chunks for s in c.detections.stamps_ns),
        detections=tuple(d for c in chunks for d in c.detections.detections),
        seconds=seconds,
    )
