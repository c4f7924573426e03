"""The optional static de-validation of the basso2012 tracker (beyond the thesis, off by default).

Micro-scenarios at 30 Hz with a 1 s window (30 frame periods), the detector's person
threshold -1.5 (Table 5.1), track-initialisation threshold -0.5 and 3 detections to
validate (Table 6.1).
"""

from __future__ import annotations

from rgbd_eval.components import create_tracker
from rgbd_eval.config import build_config
from rgbd_eval.methods.basso2012.tracker import Basso2012Tracker
from rgbd_eval.track.synthetic import person_detection
from rgbd_eval.types import Detection, TrackOutput, TrackStatus

RATE = 30.0


def _tracker(**tracker: object) -> Basso2012Tracker:
    t = create_tracker(build_config({"tracker": tracker}))
    assert isinstance(t, Basso2012Tracker)
    return t


def _run(t: Basso2012Tracker, frames: list[list[Detection]]) -> list[list[TrackOutput]]:
    return [t.update(round(k * 1e9 / RATE), dets) for k, dets in enumerate(frames)]


def _object(k: int, confidence: float, x: float = 3.0) -> list[Detection]:
    """A coat stand at (x, 0): three confident frames (validated at frame 2), then ``confidence``."""
    return [person_detection(x, 0.0, confidence=1.0 if k < 3 else confidence)]


def _validated(out: list[TrackOutput]) -> list[int]:
    return [o.track_id for o in out if o.status is TrackStatus.VALIDATED]


def test_default_off_keeps_the_thesis_tracker() -> None:
    # 150 frames (5 s) of a motionless object scoring -2: the thesis keeps its track throughout.
    outs = _run(_tracker(), [_object(k, -2.0) for k in range(150)])
    assert all(_validated(o) == [1] for o in outs[2:])


def test_a_motionless_unconfident_track_is_discarded_after_the_window() -> None:
    outs = _run(_tracker(static_devalidation_s=1.0), [_object(k, -2.0) for k in range(60)])
    # Confident at frames 0..2, then -2 from frame 3 (t = 0.1 s). The window [t - 1 s, t] holds
    # only scores < -1.5 once its start is past frame 2, i.e. t - 1 s >= 3/30 s: frame 33.
    assert _validated(outs[32]) == [1]
    assert outs[33] == []
    # no new track: -2 is below min_confidence, so no detection starts one (6.4.1)
    assert all(o == [] for o in outs[33:])


def test_one_person_like_detection_in_the_window_keeps_the_track() -> None:
    # a score of -1.5 (not below the person threshold) every 20 frames (0.67 s < 1 s window)
    frames = [_object(k, -1.5 if k % 20 == 0 else -2.0) for k in range(90)]
    outs = _run(_tracker(static_devalidation_s=1.0), frames)
    assert all(_validated(o) == [1] for o in outs[2:])
    # a still person scoring -1.0 (between -1.5 and the tracker's -0.5) keeps the track
    outs = _run(_tracker(static_devalidation_s=1.0), [_object(k, -1.0) for k in range(90)])
    assert all(_validated(o) == [1] for o in outs[2:])


def test_a_moving_unconfident_person_keeps_the_track() -> None:
    # walking at 1 m/s along y, scoring -2 after validation: over a 1 s window the positions
    # span 1 m, so the farthest is 0.5 m from their mean > static_motion_m 0.3
    frames = [
        [person_detection(3.0, k / RATE, confidence=1.0 if k < 3 else -2.0)] for k in range(90)
    ]
    outs = _run(_tracker(static_devalidation_s=1.0), frames)
    assert all(_validated(o) == [1] for o in outs[2:])
    # with a 0.6 m motion bound (1 m span: 0.5 m from the mean) the same walker counts as static
    outs = _run(_tracker(static_devalidation_s=1.0, static_motion_m=0.6), frames)
    assert outs[33] == []


def test_an_unseen_window_is_no_evidence() -> None:
    # the object is hidden for frames 10..39: at frame 40 the window (frames 10..40) holds one
    # detection plus the one before it; both are at -2, but 2 < detections_to_validate (3)
    frames = [_object(k, -2.0) if not 10 <= k < 40 else [] for k in range(41)]
    outs = _run(_tracker(static_devalidation_s=1.0), frames)
    assert _validated(outs[40]) == [1]
