"""EPFL-RGBD import: layout scan, annotation parser, derived positions, recording round trip."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from rgbd_eval.errors import DecodeError, GroundTruthError, InputError
from rgbd_eval.io.epfl_rgbd import (
    CAMERA_FRAME,
    EPFL_KINECT2,
    WORLD_FRAME,
    frame_stamp_ns,
    ground_position,
    import_sequence,
    read_depth,
    read_image_plane_annotations,
    scan_sequence,
    start_stamp_ns,
)
from rgbd_eval.io.groundtruth import read_csv
from rgbd_eval.io.recording import open_recording
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.types import Box2D, Pose
from tests.io.epfl_folder import (
    TAG,
    board_box,
    colour,
    optical_to_floor,
    render_depth_m,
    write_sequence,
)


def _camera_in_floor(height_m: float, pitch_deg: float) -> Pose:
    T = np.eye(4)
    T[:3, :3] = optical_to_floor(pitch_deg)
    T[:3, 3] = (0.0, 0.0, height_m)
    return Pose.from_matrix(T)


# ----------------------------------------------------------------------------- annotations


def _yaml(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "ground_truth_image_plane.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_annotations_read_per_sequence_frame_and_person(tmp_path: Path) -> None:
    path = _yaml(
        tmp_path,
        "20141008_141323_00:\n"
        "  34: {1: [100, 50, 40, 120], 3: [300, 60, 35, 110]}\n"
        "  35: {}\n"
        "  '36': {1: [101.5, 50, 40, 120]}\n"
        f"{TAG}:\n"
        "  40: {2: [10, 20, 30, 40]}\n",
    )
    boxes = read_image_plane_annotations(path, "20141008_141323_00")
    assert boxes == {
        34: {1: Box2D(100, 50, 40, 120), 3: Box2D(300, 60, 35, 110)},
        35: {},
        36: {1: Box2D(101.5, 50, 40, 120)},
    }
    assert read_image_plane_annotations(path, TAG) == {40: {2: Box2D(10, 20, 30, 40)}}
    # Unquoted, YAML 1.1 reads 20141008_141323_00 as the integer 2014100814132300 (above);
    # the published file quotes it.
    quoted = _yaml(tmp_path, "'20141008_141323_00': {7: {4: [1, 2, 3, 4]}}\n")
    assert read_image_plane_annotations(quoted, "20141008_141323_00") == {7: {4: Box2D(1, 2, 3, 4)}}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[1, 2]\n", "expected a mapping"),
        ("other: {}\n", "no sequence '20140804_160621_00' (sequences: other)"),
        (f"{TAG}: [1, 2]\n", "expected a mapping {frame"),
        (f"{TAG}:\n  x1: {{1: [1, 2, 3, 4]}}\n", "frame 'x1' is not an integer"),
        (f"{TAG}:\n  5: [1, 2, 3, 4]\n", "frame 5: expected {person id"),
        (f"{TAG}:\n  5: {{1: [1, 2, 3]}}\n", "frame 5: box [1, 2, 3] is not a list [x, y, w, h]"),
        (f"{TAG}:\n  5: {{1: [1, 2, a, 4]}}\n", "frame 5: box [1, 2, 'a', 4] holds a non-number"),
        (f"{TAG}:\n  5: {{1: [1, 2, 0, 4]}}\n", "frame 5: box [1, 2, 0, 4] has no area"),
        (f"{TAG}:\n  5: {{1: [1, 2, .nan, 4]}}\n", "is not finite"),
        (f"{TAG}:\n  5: {{bob: [1, 2, 3, 4]}}\n", "frame 5: person id 'bob' is not an integer"),
        (f"{TAG}:\n  5: {{1: [1, 2, 3, 4]}}\n  '5': {{}}\n", "frame 5 given twice"),
        (f"{TAG}:\n  5: {{1: [1, 2, 3, 4], 1: [1, 2, 3, 4]}}\n", "duplicate key 1"),
        (f"{TAG}: {{5: {{1: [1, 2, 3, 4]}}\n", "not valid YAML"),
    ],
)
def test_malformed_annotations_are_one_line_ground_truth_errors(
    tmp_path: Path, text: str, message: str
) -> None:
    path = _yaml(tmp_path, text)
    with pytest.raises(GroundTruthError) as err:
        read_image_plane_annotations(path, TAG)
    assert message in str(err.value) and str(path) in str(err.value)
    assert "\n" not in str(err.value)
    assert err.value.exit_code == 5


def test_missing_annotation_file_is_a_ground_truth_error(tmp_path: Path) -> None:
    with pytest.raises(GroundTruthError, match="ground truth"):
        read_image_plane_annotations(tmp_path / "nope.yaml", TAG)


# ----------------------------------------------------------------------------- layout


def test_scan_finds_frames_in_number_order_with_and_without_colour(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [None, None, None])
    seq = scan_sequence(folder)
    assert [f.number for f in seq.frames] == [0, 1, 2] and seq.has_rgb and seq.tag == TAG
    for path in folder.glob("rgb*.png"):
        path.unlink()
    assert not scan_sequence(folder).has_rgb


def test_scan_rejects_folders_that_are_not_the_layout(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not a folder"):
        scan_sequence(tmp_path / "absent")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match=r"no depth<N>\.png images"):
        scan_sequence(tmp_path / "empty")
    folder = write_sequence(tmp_path, [None, None, None])
    (folder / "rgb000001.png").unlink()
    with pytest.raises(InputError, match=r"rgb000001\.png is missing \(1 frames"):
        scan_sequence(folder)


def test_depth_png_is_millimetres_with_zero_invalid(tmp_path: Path) -> None:
    mm = np.array([[0, 1], [1500, 65535]], dtype=np.uint16)
    cv2.imwrite(str(tmp_path / "depth000000.png"), mm)
    depth = read_depth(tmp_path / "depth000000.png")
    assert math.isnan(depth[0, 0])
    # 1 mm, 1.5 m and 65.535 m: the PNG value / 1000.
    assert depth[0, 1] == pytest.approx(0.001) and depth[1, 0] == pytest.approx(1.5)
    assert depth[1, 1] == pytest.approx(65.535)


def test_colour_or_text_where_depth_is_expected_is_a_decode_error(tmp_path: Path) -> None:
    cv2.imwrite(str(tmp_path / "depth000000.png"), colour(0))
    with pytest.raises(DecodeError, match="expected a 16-bit one-channel depth PNG"):
        read_depth(tmp_path / "depth000000.png")
    (tmp_path / "depth000001.png").write_text("not a png")
    with pytest.raises(DecodeError, match="cannot read as a PNG image"):
        read_depth(tmp_path / "depth000001.png")


def test_stamps_start_at_the_tag_time_and_step_by_the_frame_period() -> None:
    # 2014-08-04 16:06:21 UTC is 1407168381 s after the epoch.
    start = start_stamp_ns(TAG)
    assert start == 1_407_168_381_000_000_000
    assert frame_stamp_ns(start, 3, 30.0) == start + 100_000_000  # 3 / 30 Hz = 0.1 s
    assert start_stamp_ns("my_sequence") == 0


# ----------------------------------------------------------------------------- positions


def test_position_of_a_board_facing_a_level_camera_is_exact() -> None:
    # Camera 2 m above the floor, level; the board (0.5 x 1.8 m) stands at x = 4 m, y = 0.6 m.
    # Every torso pixel sees the board at optical depth 4 m, so x = 4 exactly; y is the mean
    # over a window symmetric about the box centre (within a pixel, 4 m / 365.8 = 1.1 cm);
    # z = half the height of the box's top edge: 1.8 / 2 = 0.9 within half a pixel row.
    board = (4.0, 0.6)
    depth = render_depth_m(2.0, 0.0, board)
    x, y, w, h = board_box(2.0, 0.0, board)
    pos = ground_position(depth, Box2D(x, y, w, h), EPFL_KINECT2, _camera_in_floor(2.0, 0.0))
    assert pos is not None
    assert pos[0] == pytest.approx(4.0, abs=1e-6)
    assert pos[1] == pytest.approx(0.6, abs=0.012)
    assert pos[2] == pytest.approx(0.9, abs=0.012)


def test_position_with_a_pitched_camera_keeps_the_floor_coordinates() -> None:
    # Pitched 15 deg down (EPFL-CORRIDOR's floor normal leans 14.5 deg): the board's pixels
    # still back-project onto the plane x = 3.5 m, and y to its centre 0.6 m to the right.
    board = (3.5, -0.6)
    depth = render_depth_m(2.0, 15.0, board)
    box = Box2D(*(float(v) for v in board_box(2.0, 15.0, board)))
    pos = ground_position(depth, box, EPFL_KINECT2, _camera_in_floor(2.0, 15.0))
    assert pos is not None
    assert pos[0] == pytest.approx(3.5, abs=0.01)  # only the depth's mm rounding
    assert pos[1] == pytest.approx(-0.6, abs=0.02)


def test_background_behind_the_torso_is_left_out_and_empty_boxes_have_no_position() -> None:
    # Half the torso window sees the wall 2 m behind the board: the median still falls on
    # whichever surface holds most pixels, and the +-0.3 m band drops the other one.
    board = (4.0, 0.0)
    depth = render_depth_m(2.0, 0.0, board)
    x, y, w, h = board_box(2.0, 0.0, board)
    shifted = Box2D(x + 0.4 * w, y, w, h)  # 40% of the window now off the board's right edge
    pos = ground_position(depth, shifted, EPFL_KINECT2, _camera_in_floor(2.0, 0.0))
    assert pos is not None and pos[0] == pytest.approx(4.0, abs=1e-6)
    nothing = np.full_like(depth, np.nan)
    assert ground_position(nothing, shifted, EPFL_KINECT2, _camera_in_floor(2.0, 0.0)) is None
    outside = Box2D(600.0, 10.0, 50.0, 100.0)  # right of the 512-pixel image
    assert ground_position(depth, outside, EPFL_KINECT2, _camera_in_floor(2.0, 0.0)) is None


# ----------------------------------------------------------------------------- round trip


def test_round_trip_through_an_mcap_keeps_images_camera_tf_and_ground_truth(
    tmp_path: Path,
) -> None:
    boards = [None, (4.0, 0.5), (3.8, 0.4)]
    folder = write_sequence(tmp_path, boards)
    pose = _camera_in_floor(2.0, 0.0)
    out = tmp_path / "out" / "lab.mcap"
    annotations = folder.parent / "ground_truth_image_plane.yaml"
    summary = import_sequence(
        scan_sequence(folder), out, annotations=annotations, world_T_optical=pose
    )
    assert (summary.frames, summary.annotated_frames, summary.boxes, summary.positions) == (
        3,
        2,
        2,
        2,
    )
    rec = open_recording(out)
    assert len(rec) == 3 and rec.info.world_frame == WORLD_FRAME and rec.info.has_odometry
    start = start_stamp_ns(TAG)
    for n, frame in enumerate(rec.frames()):
        assert frame.stamp_ns == frame_stamp_ns(start, n, 30.0)
        expected_mm = cv2.imread(str(folder / f"depth{n:06d}.png"), cv2.IMREAD_UNCHANGED)
        got_mm = np.where(np.isfinite(frame.depth), np.round(frame.depth * 1000), 0)
        assert np.array_equal(got_mm.astype(np.uint16), expected_mm)
        assert np.array_equal(frame.rgb, cv2.cvtColor(colour(n), cv2.COLOR_BGR2RGB))
        cam = frame.depth_camera
        assert (cam.width, cam.height, cam.fx, cam.cy) == (
            512,
            424,
            EPFL_KINECT2.fx,
            EPFL_KINECT2.cy,
        )
        assert cam.frame_id == CAMERA_FRAME
        assert np.allclose(frame.camera_pose.matrix(), pose.matrix(), atol=1e-9)
    csv_gt = read_csv(tmp_path / "out" / "lab.gt.csv")
    topic_gt = rec.ground_truth_topic
    assert topic_gt is not None
    for gt in (csv_gt, topic_gt):
        frames = {f: objs for f, _, objs in gt.frames if objs}
        assert sorted(frames) == [1, 2]
        obj = frames[1][0]
        assert obj.object_id == 1 and obj.box2d == Box2D(*board_box(2.0, 0.0, (4.0, 0.5)))
        assert obj.world_xyz is not None and obj.world_xyz[0] == pytest.approx(4.0, abs=1e-6)
        assert obj.stamp_ns == frame_stamp_ns(start, 1, 30.0)


def test_without_a_floor_boxes_are_written_alone_and_no_tf(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [(4.0, 0.0)], rgb=False)
    out = tmp_path / "lab.bag"
    summary = import_sequence(
        scan_sequence(folder), out, annotations=folder.parent / "ground_truth_image_plane.yaml"
    )
    assert summary.positions == 0 and summary.boxes == 1
    rec = open_recording(out, streams=(StreamSpec("colour", required=False), StreamSpec("depth")))
    assert not rec.info.has_odometry and rec.info.selected.rgb is None
    obj = read_csv(tmp_path / "lab.gt.csv").frames[0][2][0]
    assert obj.world_xyz is None and obj.box2d is not None


def test_an_annotated_frame_without_its_image_is_refused_and_nothing_is_written(
    tmp_path: Path,
) -> None:
    folder = write_sequence(tmp_path, [(4.0, 0.0), (4.0, 0.0), (4.0, 0.0)])
    for kind in ("rgb", "depth"):
        (folder / f"{kind}000001.png").unlink()
    out = tmp_path / "lab.mcap"
    annotations = folder.parent / "ground_truth_image_plane.yaml"
    for max_frames in (None, 1):  # checked against the whole folder, converted or not
        with pytest.raises(GroundTruthError, match=r"frame 1 is annotated but depth000001\.png"):
            import_sequence(
                scan_sequence(folder), out, annotations=annotations, max_frames=max_frames
            )
    assert not out.exists() and not (tmp_path / "lab.gt.csv").exists()


def test_max_frames_converts_a_prefix_and_counts_its_annotations(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [(4.0, 0.0), None, (4.0, 0.2)])
    summary = import_sequence(
        scan_sequence(folder),
        tmp_path / "lab.mcap",
        annotations=folder.parent / "ground_truth_image_plane.yaml",
        max_frames=2,
    )
    # Frames 0 and 1 are written; of the annotated frames 0 and 2 only frame 0 is among them.
    assert (summary.frames, summary.annotated_frames, summary.boxes) == (2, 1, 1)


def test_a_bad_image_midway_leaves_no_half_written_recording(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [None, None, None])
    (folder / "depth000002.png").write_text("truncated")
    out = tmp_path / "lab.mcap"
    with pytest.raises(DecodeError, match=r"depth000002\.png: cannot read as a PNG image"):
        import_sequence(scan_sequence(folder), out)
    assert not out.exists() and not list(tmp_path.glob(".lab.mcap.tmp-*"))
