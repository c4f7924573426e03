"""Per-frame errors, id-switch and fragmentation markers, the worst-frame choice."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rgbd_eval.config import Convention, EvaluationConfig
from rgbd_eval.metrics import FrameEvents, Match, evaluate_sequence
from rgbd_eval.report.html.events import (
    FrameErrors,
    Marker,
    MarkerKind,
    busiest_frames,
    frame_errors,
    markers,
    worst_frames,
)
from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, Visibility


def _events(
    frame: int, matches: list[tuple[int, int, bool]], misses: list[int], fps: list[int]
) -> FrameEvents:
    return FrameEvents(
        frame=frame,
        matches=tuple(Match(g, t, 0.9, switch, False) for g, t, switch in matches),
        misses=tuple(misses),
        false_positives=tuple(fps),
        ignored_gt=(),
        ignored_tracks=(),
    )


# gt 1: matched (track 10), missed, matched again by track 12 (an id switch), missed at the end
# in a frame without tracks. gt 2: missed, then matched by track 11 twice, then gone. Track 20
# is a false positive in frame 0.
FRAMES = [
    _events(0, [(1, 10, False)], [2], [20]),
    _events(1, [(2, 11, False)], [1], []),
    _events(2, [(1, 12, True), (2, 11, False)], [], []),
    _events(3, [], [1], []),
]


def test_frame_errors_count_fp_fn_and_switches() -> None:
    assert frame_errors(FRAMES) == [
        FrameErrors(0, fp=1, fn=1, id_switches=0),
        FrameErrors(1, fp=0, fn=1, id_switches=0),
        FrameErrors(2, fp=0, fn=0, id_switches=1),
        FrameErrors(3, fp=0, fn=1, id_switches=0),
    ]
    assert [e.total for e in frame_errors(FRAMES)] == [2, 1, 1, 1]


@pytest.mark.parametrize("convention", list(Convention))
def test_markers_of_an_interrupted_and_switched_object(convention: Convention) -> None:
    # gt 1: matched (track 10) in frame 0, missed in 1, matched again in 2 by track 12.
    # motchallenge: its second tracked stretch starts at frame 2 (frame 1 was scored: it
    # has ground truth and track 11). motmetrics: it returns from missed at frame 2. Frame 3
    # (a miss after the last match, no tracks) adds nothing in either. gt 2's miss in frame
    # 0 is before its first match: nothing. The id switch is at frame 2, gt 1.
    assert markers(FRAMES, convention) == [
        Marker(2, 1, MarkerKind.FRAGMENTATION),
        Marker(2, 1, MarkerKind.ID_SWITCH),
    ]


def test_fragmentation_conventions_differ_where_documented() -> None:
    absent = [  # gt 1 absent from frame 1, which is scored (gt 2 and track 11 are there)
        _events(0, [(1, 10, False)], [], []),
        _events(1, [(2, 11, False)], [], []),
        _events(2, [(1, 10, False)], [], []),
    ]
    # motchallenge breaks the stretch at any scored frame without a match, absent included.
    assert markers(absent, Convention.MOTCHALLENGE) == [Marker(2, 1, MarkerKind.FRAGMENTATION)]
    # motmetrics looks only at the frames the object is present in: it was never missed.
    assert markers(absent, Convention.MOTMETRICS) == []
    no_tracks = [  # gt 1 missed in frame 1, which has no track at all
        _events(0, [(1, 10, False)], [], []),
        _events(1, [], [1], []),
        _events(2, [(1, 10, False)], [], []),
    ]
    # motchallenge's matcher skips a frame without tracks: the stretch goes on.
    assert markers(no_tracks, Convention.MOTCHALLENGE) == []
    assert markers(no_tracks, Convention.MOTMETRICS) == [Marker(2, 1, MarkerKind.FRAGMENTATION)]


def _totals(*totals: int) -> list[FrameErrors]:
    return [FrameErrors(i, fp=t, fn=0, id_switches=0) for i, t in enumerate(totals)]


def test_worst_frames_are_spread_and_skip_clean_frames() -> None:
    # 16 frames, 2 wanted: frames closer than 16 // (4 * 2) = 2 to a chosen one are skipped.
    # Frame 5 (3 errors) wins the tie with frame 6 by being earlier; 6 is within 2 of 5;
    # frame 12 (2 errors) is next. Frame 7 (1 error) would be third.
    totals = [0] * 16
    totals[5], totals[6], totals[7], totals[12] = 3, 3, 1, 2
    assert worst_frames(_totals(*totals), 2) == [5, 12]
    # 3 wanted: separation 16 // 12 = 1 skips 6 (next to 5) but not 7 (two away).
    assert worst_frames(_totals(*totals), 3) == [5, 7, 12]
    assert worst_frames(_totals(0, 0, 0), 2) == []
    assert worst_frames(_totals(1, 2), 0) == []


def test_busiest_frames_take_the_most_tracks_of_each_stretch() -> None:
    # 16 frames, 4 wanted: one from each stretch of 4, the most tracks, nearest its middle.
    tracks = [0, 1, 1, 0, 2, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1]
    # 1 and 2 tie, as near the middle (1.5): the earlier; 8-11 have none: the scene is shown.
    assert busiest_frames(tracks, 4) == [1, 4, 9, 13]
    assert busiest_frames(tracks, 1) == [4]
    assert busiest_frames([3, 0, 1], 4) == [0, 1, 2]
    assert busiest_frames([1, 2], 0) == []
    assert busiest_frames([], 4) == []


def _box(slot: int) -> Box2D:
    return Box2D(20.0 * slot, 0.0, 10.0, 30.0)


@st.composite
def sequences(draw: st.DrawFn) -> tuple[list[list[GroundTruthObject]], list[list[TrackOutput]]]:
    """Up to 12 frames; 3 people and 4 track ids placed on 4 box slots (same slot = match)."""
    n = draw(st.integers(1, 12))
    gts, tracks = [], []
    for i in range(n):
        people = draw(st.lists(st.integers(0, 2), unique=True, max_size=3))
        ids = draw(st.lists(st.integers(0, 3), unique=True, max_size=4))
        gts.append(
            [GroundTruthObject(i, i, p, _box(draw(st.integers(0, 3))), None) for p in people]
        )
        tracks.append(
            [
                TrackOutput(t, 0.0, 0.0, 1.7, _box(draw(st.integers(0, 3))), Visibility.VISIBLE)
                for t in ids
            ]
        )
    return gts, tracks


@pytest.mark.parametrize("convention", list(Convention))
@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=sequences())
def test_event_totals_equal_the_scored_counts(
    convention: Convention, data: tuple[list[list[GroundTruthObject]], list[list[TrackOutput]]]
) -> None:
    gts, tracks = data
    scores = evaluate_sequence(gts, tracks, EvaluationConfig(convention=convention))
    errors = frame_errors(scores.frames)
    marks = markers(scores.frames, convention)
    c = scores.counts
    assert sum(e.fp for e in errors) == c.fp
    assert sum(e.fn for e in errors) == c.fn
    assert sum(e.id_switches for e in errors) == c.id_switches
    assert sum(m.kind is MarkerKind.ID_SWITCH for m in marks) == c.id_switches
    assert sum(m.kind is MarkerKind.FRAGMENTATION for m in marks) == c.fragmentations
