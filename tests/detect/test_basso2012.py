"""The basso2012 detector on ray-cast frames with known answers (seed 000, chapter 5).

Frames carry Kinect-like depth noise (sigma = 0.001425 d^2); the detector runs
with the thesis' parameters (Table 5.1, voxel 0.06 m) throughout.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rgbd_eval.components import create_detector
from rgbd_eval.config import build_config
from rgbd_eval.detect.ground import GroundMode
from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.basso2012.detector import STAGES, Basso2012Detector
from rgbd_eval.methods.basso2012.detector_config import Basso2012DetectorConfig as DetectorConfig
from rgbd_eval.methods.basso2012.detector_config import HogBorder, HogClassifier
from rgbd_eval.plugins import known
from rgbd_eval.types import OPTICAL_TO_BODY, Detection, Frame

from .scenes import Block, Person, Scene, camera_pose, render

VOXEL = 0.06
CFG = DetectorConfig()


def _detect(frame: Frame, cfg: DetectorConfig = CFG) -> list[Detection]:
    return Basso2012Detector(cfg).detect(frame)


def _assert_person(d: Detection, p: Person) -> None:
    assert abs(d.height - p.height) <= 0.05  # height within 5 cm
    assert np.hypot(d.position[0] - p.x, d.position[1] - p.y) <= VOXEL  # within a voxel
    assert d.position[2] == pytest.approx(p.height / 2, abs=0.05)  # theoretical centroid


@pytest.mark.parametrize(
    ("x", "y", "height", "size"),
    [
        (2.5, 0.0, 1.75, (160, 120)),
        (3.5, 0.6, 1.62, (160, 120)),
        (5.0, -0.8, 1.90, (160, 120)),
        (6.0, 0.3, 1.80, (160, 120)),
        (4.0, -0.4, 1.70, (320, 240)),
    ],
)
def test_single_person_height_and_ground_position(
    x: float, y: float, height: float, size: tuple[int, int]
) -> None:
    person = Person(x, y, height)
    dets = _detect(render(Scene(people=[person]), camera_pose(height=1.0), size))
    assert len(dets) == 1
    d = dets[0]
    _assert_person(d, person)
    assert not d.occluded
    assert d.distance == pytest.approx(np.hypot(x, y), abs=0.3)
    # Appearance: a normalised 8^3 colour histogram of the blob.
    assert d.appearance is not None and d.appearance.shape == (512,)
    assert float(d.appearance.sum()) == pytest.approx(1.0, abs=1e-5)
    assert d.box3d is not None
    assert d.box3d.min_corner[2] == pytest.approx(0.0, abs=0.02)  # the box reaches the floor
    # The full-body box runs from the head to the feet on the RGB image.
    assert d.box2d.top >= 0 and d.box2d.bottom <= 480
    assert d.confidence != CFG.hog_default_confidence


def test_appearance_follows_the_shirt_colour() -> None:
    red = Person(3.5, 0.0, shirt=(220, 30, 30), trousers=(220, 30, 30))
    blue = Person(3.5, 0.0, shirt=(30, 30, 220), trousers=(30, 30, 220))
    pose = camera_pose(height=1.0)
    h_red = _detect(render(Scene(people=[red]), pose))[0].appearance
    h_blue = _detect(render(Scene(people=[blue]), pose))[0].appearance
    assert h_red is not None and h_blue is not None
    # 8 bins: (220, 30, 30) -> bin (6, 0, 0) = 384; (30, 30, 220) -> (0, 0, 6) = 6.
    # Shading darkens pixels but keeps the dominant channel's bin high.
    red_mass = h_red.reshape(8, 8, 8)[4:, :2, :2].sum()
    blue_mass = h_blue.reshape(8, 8, 8)[:2, :2, 4:].sum()
    assert red_mass > 0.5 and blue_mass > 0.5
    assert h_red.reshape(8, 8, 8)[:2, :2, 4:].sum() < 0.05


@pytest.mark.parametrize("size", [(160, 120), (320, 240)])
def test_two_people_side_by_side_half_a_metre_apart(size: tuple[int, int]) -> None:
    # Arms touching: one Euclidean cluster, split by the head-based sub-clustering.
    a = Person(3.5, 0.25, 1.78)
    b = Person(3.5, -0.25, 1.66, shirt=(40, 160, 40))
    dets = _detect(render(Scene(people=[a, b]), camera_pose(height=1.0), size))
    assert len(dets) == 2
    by_y = sorted(dets, key=lambda d: d.position[1])
    _assert_person(by_y[0], b)
    _assert_person(by_y[1], a)


def test_without_subclustering_side_by_side_people_merge() -> None:
    # The thesis' plain clustering (5.2) cannot separate them: the ablation shows why
    # sub-clustering exists.
    a, b = Person(3.5, 0.25, 1.78), Person(3.5, -0.25, 1.66)
    frame = render(Scene(people=[a, b]), camera_pose(height=1.0))
    plain = DetectorConfig(subclustering=False, max_points=2000)
    assert len(_detect(frame, plain)) == 1


def test_three_people_walking_in_a_row_abreast() -> None:
    people = [Person(4.0, 0.5, 1.75), Person(4.0, 0.0, 1.70), Person(4.2, -0.5, 1.85)]
    dets = _detect(render(Scene(people=people), camera_pose(height=1.0)))
    assert len(dets) == 3
    for p in people:
        best = min(dets, key=lambda d: np.hypot(d.position[0] - p.x, d.position[1] - p.y))
        _assert_person(best, p)


@pytest.mark.parametrize(
    ("people", "size"),
    [
        # Shoulder to shoulder, heads 0.4 m apart, at 160x120.
        ([Person(3.5, 0.2, 1.75), Person(3.5, -0.2, 1.72)], (160, 120)),
        # Diagonal, 0.36 m apart on the ground, one partly behind the other.
        ([Person(3.0, 0.0, 1.75), Person(3.3, 0.2, 1.70)], (160, 120)),
        # Side by side at 6 m.
        ([Person(6.0, 0.22, 1.75), Person(6.0, -0.23, 1.72)], (160, 120)),
        # Facing each other, talking.
        ([Person(3.5, 0.2, 1.75, yaw=-1.57), Person(3.5, -0.2, 1.68, yaw=1.57)], (320, 240)),
        # Three abreast, 0.42 m apart.
        ([Person(4.0, 0.42, 1.7), Person(4.0, 0.0, 1.8), Person(4.0, -0.42, 1.65)], (320, 240)),
    ],
)
def test_close_groups_come_out_as_separate_people(
    people: list[Person], size: tuple[int, int]
) -> None:
    dets = _detect(render(Scene(people=people), camera_pose(height=1.0), size))
    assert len(dets) == len(people)
    for p in people:
        best = min(dets, key=lambda d: np.hypot(d.position[0] - p.x, d.position[1] - p.y))
        _assert_person(best, p)


def test_pair_in_a_corridor_under_a_ceiling() -> None:
    # One person's shoulder touches the side wall (one Euclidean cluster with the wall
    # and, through the corner, the ceiling seen above them): both still come out.
    people = [Person(4.0, 0.55, 1.75), Person(4.0, 0.1, 1.70)]
    scene = Scene(people=people, side_wall_y=0.9, ceiling=2.7)
    dets = _detect(render(scene, camera_pose(height=1.0)))
    assert len(dets) == 2
    for p in people:
        best = min(dets, key=lambda d: np.hypot(d.position[0] - p.x, d.position[1] - p.y))
        _assert_person(best, p)


def test_person_behind_an_obstacle_is_kept_and_flagged_occluded() -> None:
    # A 1 m tall box 0.8 m in front hides the legs: occluded, still detected, and not
    # visible top to bottom: with hog_border 'skip' the thesis' default confidence -100
    # (5.4.2); with 'pad' (the default) the window, legs hidden by the box, is scored.
    person = Person(4.0, 0.0, 1.75)
    scene = Scene(people=[person], blocks=[Block(3.2, 0.0, (0.5, 1.0, 1.0))])
    frame = render(scene, camera_pose(height=1.0))
    dets = _detect(frame, DetectorConfig(hog_border=HogBorder.SKIP))
    assert len(dets) == 1  # the 1 m box is below min_height 1.4
    d = dets[0]
    assert d.occluded
    assert d.confidence == -100.0
    _assert_person(d, person)
    padded = _detect(frame)[0]
    assert padded.occluded and -10.0 < padded.confidence < 10.0
    assert padded.position == d.position


def test_person_partly_hidden_by_another_is_flagged_occluded() -> None:
    front, back = Person(3.0, 0.0, 1.75), Person(4.2, 0.3, 1.85)
    dets = _detect(render(Scene(people=[front, back]), camera_pose(height=1.0)))
    assert len(dets) == 2
    near, far = dets  # ordered by distance (5.4.2)
    assert not near.occluded and far.occluded
    _assert_person(near, front)
    _assert_person(far, back)


def test_tall_cabinet_is_a_cluster_with_low_hog_confidence() -> None:
    person = Person(3.5, 1.0, 1.75)
    cabinet = Block(3.5, -0.3, (0.5, 0.6, 1.9))
    dets = _detect(render(Scene(people=[person], blocks=[cabinet]), camera_pose(height=1.0)))
    assert len(dets) == 2
    cab = min(dets, key=lambda d: abs(d.position[1] - (-0.3)))
    man = min(dets, key=lambda d: abs(d.position[1] - 1.0))
    assert cab.height == pytest.approx(1.9, abs=0.05)
    # HOG was computed (it stands on the floor, fully in view) and rejects it.
    assert cab.confidence != -100.0
    assert cab.confidence < CFG.min_confidence
    assert man.confidence > cab.confidence + 2.0
    # With publish_all off, only detections above min_confidence (Table 5.1) remain.
    strict = DetectorConfig(publish_all=False)
    kept = _detect(
        render(Scene(people=[person], blocks=[cabinet]), camera_pose(height=1.0)), strict
    )
    assert [d.position[1] for d in kept] == pytest.approx([man.position[1]])


def test_tilted_sensor_with_odometry() -> None:
    person = Person(3.5, 0.2, 1.75)
    dets = _detect(render(Scene(people=[person]), camera_pose(height=1.1, pitch_deg=10)))
    assert len(dets) == 1
    _assert_person(dets[0], person)


def test_tilted_sensor_without_odometry_finds_the_floor() -> None:
    # No odometry: the world frame is the camera body frame (level, at the camera), so
    # the gravity prior is 10 degrees off; the floor is still found (within 30 deg).
    person = Person(3.5, 0.2, 1.75)
    frame = render(Scene(people=[person]), camera_pose(height=1.1, pitch_deg=10, roll_deg=4))
    frame = dataclasses.replace(frame, camera_pose=OPTICAL_TO_BODY, has_odometry=False)
    det = Basso2012Detector(CFG)
    dets = det.detect(frame)
    assert len(dets) == 1
    assert dets[0].height == pytest.approx(1.75, abs=0.05)
    plane = det.ground_plane
    assert plane is not None
    assert plane[3] == pytest.approx(1.1, abs=0.02)  # the camera is 1.1 m above the floor


def test_person_cut_by_the_image_top_is_flagged_and_not_hog_scored() -> None:
    # Pitched down 15 degrees from 1.2 m: the top of the view at 3 m is at 1.54 m.
    # hog_border 'skip' (the thesis): not visible top to bottom, not scored.
    frame = render(Scene(people=[Person(3.0, 0.2)]), camera_pose(height=1.2, pitch_deg=15))
    dets = _detect(frame, DetectorConfig(hog_border=HogBorder.SKIP))
    assert len(dets) == 1
    assert dets[0].occluded
    assert dets[0].confidence == -100.0


@pytest.mark.parametrize("hog", [HogClassifier.AUTHORS, HogClassifier.OPENCV])
def test_pad_scores_the_person_cut_by_the_image_top(hog: HogClassifier) -> None:
    # As above; with hog_border 'pad' the window's part above the image is black and
    # the cluster gets a real confidence (the authors' later behaviour), still flagged.
    frame = render(Scene(people=[Person(3.0, 0.2)]), camera_pose(height=1.2, pitch_deg=15))
    skip = _detect(frame, DetectorConfig(hog=hog, hog_border=HogBorder.SKIP))
    pad = _detect(frame, DetectorConfig(hog=hog))  # the default
    assert skip[0].confidence == -100.0
    assert len(pad) == 1 and pad[0].occluded
    assert -10.0 < pad[0].confidence < 10.0


def test_classifiers_give_different_scales_on_the_same_person() -> None:
    frame = render(Scene(people=[Person(3.5, 0.0, 1.75)]), camera_pose(height=1.0))
    authors = _detect(frame, DetectorConfig(hog=HogClassifier.AUTHORS))[0]
    opencv = _detect(frame, DetectorConfig(hog=HogClassifier.OPENCV))[0]
    # Same cluster, same geometry; only the confidence differs.
    assert authors.position == opencv.position and authors.box2d == opencv.box2d
    assert authors.confidence != opencv.confidence


@pytest.mark.parametrize("odometry", [True, False])
def test_moving_robot_ground_plane_follows_and_world_positions_stay_put(odometry: bool) -> None:
    # The robot drives towards a standing person, turning, while its camera pitches
    # by up to +-3 degrees (1 degree per frame at most). With odometry the plane is
    # carried over by the camera's motion; without, the per-frame refinement alone
    # follows. Heights stay within 5 cm; with odometry the world position too.
    person = Person(5.0, 0.5, 1.8)
    det = Basso2012Detector(CFG)
    pitches = [0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0, -1.0, -2.0, -3.0]
    for k, pitch in enumerate(pitches):
        pose = camera_pose(x=0.15 * k, y=0.02 * k, height=1.0, pitch_deg=pitch, yaw_deg=2.0 * k)
        frame = render(Scene(people=[person]), pose, index=k)
        if not odometry:
            frame = dataclasses.replace(frame, camera_pose=OPTICAL_TO_BODY, has_odometry=False)
        dets = det.detect(frame)
        assert len(dets) == 1, f"frame {k}"
        assert dets[0].height == pytest.approx(person.height, abs=0.05), f"frame {k}"
        plane = det.ground_plane
        assert plane is not None
        # The plane's normal, in the world, is the world's up (within 0.5 degree).
        up = pose.rotation_matrix() @ plane[:3]
        assert np.degrees(np.arccos(min(1.0, up[2]))) < 0.5, f"frame {k}"
        if odometry:
            _assert_person(dets[0], person)


def test_odometry_carries_the_plane_over_a_large_pitch_step() -> None:
    # 4 degrees in one frame: at 5 m the floor moves 0.35 m, far outside the one-voxel
    # band; the odometry prediction keeps the plane (and the height) right.
    person = Person(5.0, 0.0, 1.8)
    det = Basso2012Detector(CFG)
    for k, pitch in enumerate([0.0, 4.0, -2.0]):
        frame = render(Scene(people=[person]), camera_pose(height=1.0, pitch_deg=pitch), index=k)
        dets = det.detect(frame)
        assert len(dets) == 1
        _assert_person(dets[0], person)


def test_plane_is_kept_when_the_floor_is_not_seen() -> None:
    det = Basso2012Detector(CFG)
    frame = render(Scene(people=[Person(3.0, 0.0)]), camera_pose(height=1.0))
    det.detect(frame)
    before = det.ground_plane
    assert before is not None
    # Next frame: every pixel below the horizon invalid (floor unseen).
    depth = frame.depth.copy()
    depth[depth.shape[0] // 2 + 2 :, :] = np.nan
    det.detect(dataclasses.replace(_with_images(frame, frame.rgb, depth), index=1))
    np.testing.assert_array_equal(det.ground_plane, before)
    assert det.ground.inliers < CFG.ground_min_points


@pytest.mark.parametrize("mode", ["points", "pixels", "plane"])
def test_ground_initialisation_modes(mode: str) -> None:
    # Camera 1 m above the floor, level: in the optical frame the floor is y = 1.
    person = Person(3.5, 0.0, 1.75)
    frame = render(Scene(people=[person]), camera_pose(height=1.0))
    if mode == "points":
        cfg = DetectorConfig(
            ground_mode=GroundMode.POINTS,
            ground_points=[(0.0, 1.0, 2.0), (1.0, 1.0, 3.0), (-1.0, 1.0, 4.0)],
        )
    elif mode == "pixels":
        # Clicks on floor pixels of the RGB image (as the ground_detector, 5.4.1).
        cfg = DetectorConfig(
            ground_mode=GroundMode.POINTS,
            ground_pixels=[(100.0, 400.0), (500.0, 420.0), (320.0, 460.0)],
        )
    else:
        cfg = DetectorConfig(ground_mode=GroundMode.PLANE, ground_plane=(0.0, -2.0, 0.0, 2.0))
    det = Basso2012Detector(cfg)
    dets = det.detect(frame)
    assert len(dets) == 1
    _assert_person(dets[0], person)
    assert det.ground_plane is not None
    np.testing.assert_allclose(det.ground_plane, [0.0, -1.0, 0.0, 1.0], atol=0.01)


def test_world_mode_takes_the_floor_from_the_camera_pose() -> None:
    # The thesis' floor is known (three clicked points, 5.4.1); 'world' knows it from the
    # pose: camera 1.1 m above the world's z = 0, pitched 10 degrees down. The first plane is
    # that floor exactly (no fit), so a floor with a raised platform in view cannot tilt it.
    person = Person(3.5, 0.2, 1.75)
    pose = camera_pose(height=1.1, pitch_deg=10)
    frame = render(Scene(people=[person]), pose)
    det = Basso2012Detector(DetectorConfig(ground_mode=GroundMode.WORLD))
    first = det.ground.initialise(np.zeros((0, 3)), pose, np.zeros((0, 2)), np.zeros((0, 3)), 1.0)
    assert first is not None
    up = pose.rotation_matrix() @ first[:3]
    np.testing.assert_allclose(up, [0.0, 0.0, 1.0], atol=1e-9)
    assert first[3] == pytest.approx(1.1)
    dets = det.detect(frame)
    assert len(dets) == 1
    _assert_person(dets[0], person)


def test_world_mode_without_odometry_is_a_config_error() -> None:
    frame = render(Scene(people=[Person(3.5, 0.0)]), camera_pose(height=1.0))
    frame = dataclasses.replace(frame, camera_pose=OPTICAL_TO_BODY, has_odometry=False)
    with pytest.raises(ConfigError, match="ground_mode 'world' needs the camera's pose"):
        Basso2012Detector(DetectorConfig(ground_mode=GroundMode.WORLD)).detect(frame)


def test_points_mode_without_points_is_a_config_error() -> None:
    with pytest.raises(ValueError, match="ground_points"):
        DetectorConfig(ground_mode=GroundMode.POINTS)


def test_deterministic_and_timed() -> None:
    frame = render(Scene(people=[Person(3.5, 0.25), Person(3.5, -0.25)]), camera_pose(height=1.0))
    a = Basso2012Detector(CFG)
    b = Basso2012Detector(CFG)
    da, db = a.detect(frame), b.detect(frame)
    assert [d.position for d in da] == [d.position for d in db]
    assert [d.confidence for d in da] == [d.confidence for d in db]
    assert set(a.last_timings) == set(STAGES)
    assert all(t >= 0.0 for t in a.last_timings.values())
    assert sum(a.last_timings.values()) > 0.0


def test_bad_frame_raises() -> None:
    frame = render(Scene(), camera_pose(height=1.0))
    with pytest.raises(ValueError, match="depth image"):
        Basso2012Detector(CFG).detect(_with_images(frame, frame.rgb, frame.depth[:, :10]))
    with pytest.raises(ValueError, match="rgb image"):
        Basso2012Detector(CFG).detect(_with_images(frame, frame.rgb[..., 0], frame.depth))


def _with_images(frame: Frame, rgb: np.ndarray, depth: np.ndarray) -> Frame:
    return Frame.rgbd(
        frame.index,
        frame.stamp_ns,
        rgb,
        depth,
        frame.rgb_camera,
        frame.depth_camera,
        camera_pose=frame.camera_pose,
    )


def test_empty_scene_gives_no_detections() -> None:
    assert _detect(render(Scene(), camera_pose(height=1.0))) == []


def test_registry() -> None:
    assert "basso2012" in known("detectors")
    det = create_detector(build_config())
    assert isinstance(det, Basso2012Detector)
    with pytest.raises(ConfigError, match=r"unknown detector 'nope' \(known: .*basso2012"):
        build_config({"detector": {"name": "nope"}})
