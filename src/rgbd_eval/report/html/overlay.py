"""Tracks and ground truth drawn on the RGB image (for the worst-frame strip and the video).

Colours: a track has the colour of its id (matplotlib's ``tab10`` without its
red, as in the bird's-eye plot); ground truth is white, a missed object red; a false-positive
track is labelled ``FP``, a match that switched ids ``SW``. Occluded tracks are
drawn thin. Only tracks that take part in scoring are drawn (validated, not
``NOT_VISIBLE``).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import RunConfig
from rgbd_eval.metrics import FrameEvents
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.pipeline import open_for
from rgbd_eval.types import Box2D, Frame, GroundTruthObject, TrackOutput, Visibility

RGB = tuple[int, int, int]
GT_COLOUR: RGB = (255, 255, 255)
MISS_COLOUR: RGB = (230, 20, 20)
#: matplotlib's tab10 without red, which marks misses and id switches.
_TRACK_COLOURS = (
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)


def track_colour(track_id: int) -> RGB:
    """The colour of a track id, in the overlays and the bird's-eye plot alike."""
    return _TRACK_COLOURS[track_id % len(_TRACK_COLOURS)]


def rgb_of(frame: Frame) -> NDArray[np.uint8] | None:
    """The frame's colour image (H x W x 3, RGB order), None without a colour stream.

    The one place that knows where a Frame keeps its colour image.
    """
    stream = frame.streams.get("colour")
    return None if stream is None else stream.image


def rgb_frames(
    path: Path, config: RunConfig, wanted: Sequence[int] | None = None
) -> Iterator[tuple[int, NDArray[np.uint8] | None]]:
    """``(index, rgb)`` of the recording's frames (only ``wanted`` ones if given), in order.

    Re-reads the recording with the streams of the configured method, so the frame
    indices are those of the run; stops after the last wanted frame. ``rgb`` is None
    where the frame has no colour stream (a depth-only method reads none).
    """
    keep = None if wanted is None else set(wanted)
    if keep is not None and not keep:
        return
    last = None if keep is None else max(keep)
    for index, frame in enumerate(open_for(path, config).frames()):
        if keep is None or index in keep:
            yield index, rgb_of(frame)
        if last is not None and index >= last:
            return


def _box(image: NDArray[np.uint8], box: Box2D, colour: RGB, thickness: int) -> tuple[int, int]:
    import cv2

    x0, y0 = round(box.left), round(box.top)
    x1, y1 = round(box.left + box.width), round(box.top + box.height)
    cv2.rectangle(image, (x0, y0), (x1, y1), colour, thickness, cv2.LINE_AA)
    return x0, y0


def _label(
    image: NDArray[np.uint8], text: str, x: int, y: int, colour: RGB, below: bool = False
) -> None:
    """``text`` on a filled tag of ``colour`` at (x, y), kept inside the image."""
    import cv2

    font, scale, weight = cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1
    (w, h), base = cv2.getTextSize(text, font, scale, weight)
    height, width = image.shape[:2]
    x = min(max(x, 0), max(width - w - 4, 0))
    top = y if below else y - h - base - 4
    top = min(max(top, 0), max(height - h - base - 4, 0))
    cv2.rectangle(image, (x, top), (x + w + 4, top + h + base + 4), colour, cv2.FILLED)
    ink = (0, 0, 0) if sum(colour) > 380 else (255, 255, 255)
    cv2.putText(image, text, (x + 2, top + h + 2), font, scale, ink, weight, cv2.LINE_AA)


def drawn_tracks(tracks: Sequence[TrackOutput]) -> list[TrackOutput]:
    """The tracks :func:`draw_frame` draws: those scored, with a box on the image."""
    return [t for t in tracks if t.box2d is not None and is_scored_track(t)]


def draw_frame(
    rgb: NDArray[np.uint8],
    tracks: Sequence[TrackOutput],
    ground_truth: Sequence[GroundTruthObject],
    events: FrameEvents | None,
    caption: str = "",
) -> NDArray[np.uint8]:
    """A copy of ``rgb`` with ground-truth and track boxes, labels and a caption."""
    image = np.ascontiguousarray(rgb.copy())
    missed = set(events.misses) if events is not None else set()
    false_pos = set(events.false_positives) if events is not None else set()
    switched = {m.track_id for m in events.matches if m.id_switch} if events is not None else set()
    for o in ground_truth:
        if o.box2d is None:
            continue
        colour = MISS_COLOUR if o.object_id in missed else GT_COLOUR
        x, y = _box(image, o.box2d, colour, 1 if o.ignore else 2)
        bottom = round(o.box2d.top + o.box2d.height)
        tag = "miss" if o.object_id in missed else ("ign" if o.ignore else "gt")
        _label(image, f"{tag} {o.object_id}", x, bottom, colour, below=True)
    for t in drawn_tracks(tracks):
        assert t.box2d is not None  # drawn_tracks keeps only tracks with a box
        colour = track_colour(t.track_id)
        occluded = t.visibility is Visibility.OCCLUDED
        x, y = _box(image, t.box2d, colour, 1 if occluded else 3)
        text = f"id {t.track_id}" + (" occl" if occluded else "")
        if t.track_id in false_pos:
            text += " FP"
        if t.track_id in switched:
            text += " SW"
        _label(image, text, x, y, colour)
    if caption:
        _label(image, caption, 0, 0, (0, 0, 0), below=True)
    return image
