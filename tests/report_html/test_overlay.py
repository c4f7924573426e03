"""Boxes drawn on the image, the video's frame rate, and the video writer's errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.errors import OutputError
from rgbd_eval.metrics import FrameEvents, Match
from rgbd_eval.report.html.overlay import GT_COLOUR, MISS_COLOUR, draw_frame, track_colour
from rgbd_eval.report.html.video import frame_rate, write_overlay_video
from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, TrackStatus, Visibility


def _gt(object_id: int, box: tuple[float, float, float, float]) -> GroundTruthObject:
    return GroundTruthObject(0, 0, object_id, Box2D(*box), None)


def _track(
    track_id: int,
    box: tuple[float, float, float, float],
    status: TrackStatus = TrackStatus.VALIDATED,
) -> TrackOutput:
    return TrackOutput(track_id, 0.0, 0.0, 1.7, Box2D(*box), Visibility.VISIBLE, status)


def test_boxes_are_drawn_in_their_colours_where_they_are() -> None:
    black = np.zeros((120, 160, 3), np.uint8)
    # gt 1 matched by track 4, gt 2 missed; track 5 is new (not validated) and must not be drawn.
    events = FrameEvents(0, (Match(1, 4, 0.9, False, False),), (2,), (), (), ())
    gts = [_gt(1, (10, 10, 30, 60)), _gt(2, (100, 20, 30, 60))]
    tracks = [
        _track(4, (60, 30, 20, 50)),
        _track(5, (120, 90, 20, 20), status=TrackStatus.NEW),
    ]
    out = draw_frame(black, tracks, gts, events)
    assert black.max() == 0  # the input is not modified
    # Left edges at mid-height (away from the labels): x = 10 (gt 1), 100 (gt 2), 60 (track 4).
    assert tuple(out[40, 10]) == GT_COLOUR
    assert tuple(out[50, 100]) == MISS_COLOUR
    assert tuple(out[55, 60]) == track_colour(4)
    # Nothing where only the new track was, nor inside the boxes.
    assert out[100:108, 125:135].max() == 0
    assert out[40, 25].max() == 0


def test_track_colours_never_use_the_miss_red() -> None:
    assert all(track_colour(i) != (214, 39, 40) for i in range(20))
    assert len({track_colour(i) for i in range(9)}) == 9


def test_frame_rate_is_the_median_stamp_step() -> None:
    ms = 1_000_000
    # steps 100, 100, 200 ms (and a repeated stamp, ignored): median 100 ms -> 10 fps
    assert frame_rate([0, 100 * ms, 200 * ms, 200 * ms, 400 * ms]) == pytest.approx(10.0)
    assert frame_rate([5]) == 1.0


def test_unwritable_video_is_an_output_error(recording: Path, tmp_path: Path) -> None:
    from rgbd_eval.config import load_config
    from rgbd_eval.pipeline import run_sequence

    config = load_config(method="basso2012")
    result = run_sequence(recording, config)
    target = tmp_path / "missing" / "folder" / "x.mp4"
    with pytest.raises(OutputError, match=r"x\.mp4: OpenCV cannot write MP4"):
        write_overlay_video(target, result, config)
