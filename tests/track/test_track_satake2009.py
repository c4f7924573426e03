"""satake2009 tracker: robot motion from the frame's odometry, output in the world frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rgbd_eval.methods.satake2009.detector import (
    Satake2009Contract,
    Satake2009DetectorConfig,
    distance_grid,
)
from rgbd_eval.methods.satake2009.tracker import (
    Satake2009Tracker,
    Satake2009TrackerConfig,
    planar_pose,
)
from rgbd_eval.plugins import DetectionContract
from rgbd_eval.types import OPTICAL_TO_BODY, Box2D, CameraModel, Detection, Frame, Pose, Stream
from tests.detect.satake_scenes import CAM as SEARCH_CAM
from tests.detect.satake_scenes import scene_depth

CAM = CameraModel(64, 48, 40.0, 40.0, 31.5, 23.5)
CONTRACT = Satake2009Contract(detector=Satake2009DetectorConfig())
#: These tests feed exact detections to the filter: no template search in the (blank) images.
NO_SEARCH = {"local_search": False}


def _frame(index: int, x: float, y: float, yaw: float) -> Frame:
    """A frame whose left camera stands at (x, y, 1.2) looking along ``yaw``."""
    T = np.eye(4)
    c, s = math.cos(yaw), math.sin(yaw)
    T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    T[:3, 3] = (x, y, 1.2)
    pose = Pose.from_matrix(T).compose(OPTICAL_TO_BODY)
    img = np.zeros((48, 64, 3), np.uint8)
    stamp = index * 50_000_000  # 20 fps
    left = Stream(img, "rgb8", CAM, stamp, pose)
    return Frame(index, stamp, {"left": left, "right": left}, camera_pose=pose, has_odometry=True)


def test_planar_pose_reads_the_heading_of_the_optical_axis() -> None:
    assert planar_pose(_frame(0, 1.0, 2.0, 0.5).stream("left").pose) == pytest.approx((1, 2, 0.5))


def test_a_static_person_stays_put_while_the_robot_drives_and_turns() -> None:
    # The robot drives an arc (0.3 m/s, 0.4 rad/s); a person stands at world (4, 1).
    # Detections are exact, so every output must be (4, 1) with one id; the EKF's
    # prediction in the robot frame must agree with the next detection (no new ids).
    trk = Satake2009Tracker(Satake2009TrackerConfig(sigma_v=0.05, **NO_SEARCH), CONTRACT)
    box = Box2D(0, 0, 1, 1)
    for k in range(40):
        t = k * 0.05
        yaw = 0.4 * t
        x, y = (0.3 / 0.4) * math.sin(yaw), (0.3 / 0.4) * (1 - math.cos(yaw))
        out = trk.update(
            k * 50_000_000, [Detection((4.0, 1.0, 1.7), 1.7, 1.0, box)], _frame(k, x, y, yaw)
        )
        if k >= 1:
            assert [o.track_id for o in out] == [1]
            assert (out[0].x, out[0].y) == (
                pytest.approx(4.0, abs=1e-9),
                pytest.approx(1.0, abs=1e-9),
            )
    # the velocity estimate of a standing person stays near zero despite the robot's motion
    assert np.hypot(*trk.tracks[0].x[3:]) < 0.05


def test_an_unseen_track_is_kept_for_max_missed_s_then_dropped() -> None:
    # 20 fps, max_missed_s = 0.5: seen at frames 0-2, kept (occluded) through frame 12
    # (0.5 s after frame 2), gone at frame 13. With coast_min_hits = 4 it would not be
    # output at all once unseen (3 matches).
    cfg = Satake2009TrackerConfig(max_missed_s=0.5, coast_min_hits=3, **NO_SEARCH)
    trk = Satake2009Tracker(cfg, CONTRACT)
    det = [Detection((3.0, 0.0, 1.7), 1.7, 1.0, Box2D(0, 0, 1, 1))]
    for k in range(3):
        trk.update(k * 50_000_000, det, _frame(k, 0.0, 0.0, 0.0))
    for k in range(3, 13):
        out = trk.update(k * 50_000_000, [], _frame(k, 0.0, 0.0, 0.0))
        assert [(o.track_id, o.visibility.name) for o in out] == [(1, "OCCLUDED")]
    assert trk.update(13 * 50_000_000, [], _frame(13, 0.0, 0.0, 0.0)) == []
    strict = Satake2009Tracker(cfg.model_copy(update={"coast_min_hits": 4}), CONTRACT)
    for k in range(3):
        strict.update(k * 50_000_000, det, _frame(k, 0.0, 0.0, 0.0))
    assert strict.update(3 * 50_000_000, [], _frame(3, 0.0, 0.0, 0.0)) == []
    assert len(strict.tracks) == 1  # still kept, only not output


def test_a_second_match_on_the_same_body_starts_no_track() -> None:
    # Two detections 0.3 m apart (< min_separation_m = 0.5): the first starts track 1; the
    # second, unmatched, is within 0.5 m of it and starts nothing. At 0.8 m it would.
    box = Box2D(0, 0, 1, 1)
    for gap, n_tracks in ((0.3, 1), (0.8, 2)):
        trk = Satake2009Tracker(Satake2009TrackerConfig(**NO_SEARCH), CONTRACT)
        trk.update(0, [Detection((3.0, 0.0, 1.7), 1.7, 1.0, box)], _frame(0, 0.0, 0.0, 0.0))
        dets = [
            Detection((3.0, 0.0, 1.7), 1.7, 1.0, box),
            Detection((3.0, gap, 1.7), 1.7, 1.0, box),
        ]
        trk.update(50_000_000, dets, _frame(1, 0.0, 0.0, 0.0))
        assert len(trk.tracks) == n_tracks


def test_distance_grid() -> None:
    # 1.0 * 1.5^k up to 3.5: 1.0, 1.5, 2.25, 3.375
    cfg = Satake2009DetectorConfig(min_distance_m=1.0, max_distance_m=3.5, distance_ratio=1.5)
    assert distance_grid(cfg) == pytest.approx([1.0, 1.5, 2.25, 3.375])


def test_the_tracker_needs_the_satake2009_detectors_contract() -> None:
    # It searches templates in the detector's depth with the detector's settings.
    with pytest.raises(ValueError, match="pair it with detector satake2009"):
        Satake2009Tracker(Satake2009TrackerConfig(), DetectionContract())


def _depth_frame(index: int, person_y: float) -> Frame:
    """A level camera 1.2 m up at the origin, a 1.75 m figure 3 m ahead at ``person_y``.

    Its depth comes as the ``disparity`` stream (as a DisparityImage would give it), so
    the tracker's template search runs on exact depth, without SGBM.
    """
    T = np.eye(4)
    T[2, 3] = 1.2
    pose = Pose.from_matrix(T).compose(OPTICAL_TO_BODY)
    stamp = index * 50_000_000
    img = np.zeros((SEARCH_CAM.height, SEARCH_CAM.width, 3), np.uint8)
    left = Stream(img, "rgb8", SEARCH_CAM, stamp, pose)
    depth = Stream(scene_depth((3.0, person_y)), "depth", SEARCH_CAM, stamp, pose)
    return Frame(index, stamp, {"left": left, "disparity": depth}, camera_pose=pose)


@pytest.mark.parametrize(("local_search", "chroma"), [(True, 0.0), (False, 0.0), (True, 6.0)])
def test_the_search_around_the_prediction_observes_without_detections(
    local_search: bool, chroma: float
) -> None:
    # A person walks left at 0.6 m/s (3 cm per 50 ms frame), 3 m ahead. Whole-image
    # detections (head top, 1.75 m) start the track in frames 0-1; from frame 2 on there
    # are none. Searching around its prediction the tracker still observes the person
    # every frame (VISIBLE, following y); without the search the track only coasts. The
    # images are blank (one colour top to bottom): with the colour test on (min chroma 6)
    # the search's observations are rejected as a mannequin's would be, and it coasts too.
    cfg = Satake2009TrackerConfig(local_search=local_search, coast_min_hits=2)
    contract = Satake2009Contract(detector=Satake2009DetectorConfig(min_head_torso_chroma=chroma))
    trk = Satake2009Tracker(cfg, contract)
    box = Box2D(0, 0, 1, 1)
    for k in range(7):
        y = 0.2 + 0.03 * k
        dets = [Detection((3.0, y, 1.75), 1.75, 0.9, box)] if k < 2 else []
        out = trk.update(k * 50_000_000, dets, _depth_frame(k, y))
    assert [o.track_id for o in out] == [1]
    if local_search and not chroma:
        assert out[0].visibility.name == "VISIBLE"
        assert trk.tracks[0].hits == 7
        # head-top observations: y within a few cm, the figure's head is at 3 m +- its depth
        assert out[0].y == pytest.approx(0.2 + 0.03 * 6, abs=0.06)
        assert out[0].x == pytest.approx(3.0, abs=0.2)
    else:
        assert out[0].visibility.name == "OCCLUDED"
        assert trk.tracks[0].hits == 2
