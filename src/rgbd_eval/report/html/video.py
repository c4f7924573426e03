"""The overlay video of one sequence: tracks and ground truth on every RGB frame, as MP4."""

from __future__ import annotations

import itertools
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import RunConfig
from rgbd_eval.errors import OutputError
from rgbd_eval.pipeline import SequenceResult
from rgbd_eval.report.html.events import frame_errors
from rgbd_eval.report.html.overlay import draw_frame, rgb_frames

#: OpenCV's MPEG-4 Part 2 encoder, the one opencv-python-headless wheels ship for .mp4.
FOURCC = "mp4v"

#: Called after each frame with (frames done, frames in all).
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class VideoResult:
    """What :func:`write_overlay_video` wrote, and the frames it kept for the report."""

    path: Path
    frames: int
    fps: float
    kept: dict[int, NDArray[np.uint8]]


def frame_rate(stamps_ns: Sequence[int]) -> float:
    """Frames per second of a recording: 1 / the median stamp step (1.0 for a single frame)."""
    steps = [b - a for a, b in itertools.pairwise(stamps_ns) if b > a]
    return 1e9 / statistics.median(steps) if steps else 1.0


def overlay(result: SequenceResult, index: int, rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Frame ``index`` of ``result`` with its tracks, ground truth and error counts drawn."""
    gt = result.ground_truth.frames[index] if result.ground_truth is not None else []
    events = result.scores.frames[index] if result.scores is not None else None
    caption = f"{result.name}  frame {index}"
    if events is not None:
        e = frame_errors([events])[0]
        caption += f"  FP {e.fp}  FN {e.fn}  ID sw {e.id_switches}"
    return draw_frame(rgb, result.tracks[index], gt, events, caption)


def write_overlay_video(
    path: Path,
    result: SequenceResult,
    config: RunConfig,
    keep: Sequence[int] = (),
    progress: Progress | None = None,
) -> VideoResult:
    """Re-read ``result``'s recording and write every frame with its overlay to ``path`` (MP4).

    The video plays at the recording's rate (:func:`frame_rate`). The overlaid
    frames listed in ``keep`` are returned, so the report need not read them again.
    """
    import cv2

    fps = frame_rate(result.detections.stamps_ns)
    total = len(result.tracks)
    writer: cv2.VideoWriter | None = None
    kept: dict[int, NDArray[np.uint8]] = {}
    wanted = set(keep)
    written = 0
    try:
        for index, rgb in rgb_frames(Path(result.path), config):
            if index >= total:
                break
            if rgb is None:
                raise OutputError(
                    path, f"method {config.method!r} reads no colour stream to draw the video on"
                )
            image = overlay(result, index, rgb)
            if writer is None:
                height, width = image.shape[:2]
                writer = cv2.VideoWriter(
                    str(path), cv2.VideoWriter.fourcc(*FOURCC), fps, (width, height)
                )
                if not writer.isOpened():
                    raise OutputError(path, f"OpenCV cannot write MP4 ({FOURCC}) here")
            writer.write(np.ascontiguousarray(image[:, :, ::-1]))
            if index in wanted:
                kept[index] = image
            written += 1
            if progress is not None:
                progress(written, total)
    finally:
        if writer is not None:
            writer.release()
    if written != total:
        raise OutputError(
            path, f"the recording gave {written} frames on re-reading, the run had {total}"
        )
    return VideoResult(path, written, fps, kept)
