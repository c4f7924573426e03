"""Ground-truth formats: CSV round trip, KTP 2D/3D, alignment, and contradictions."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.errors import GroundTruthError
from rgbd_eval.io import groundtruth
from rgbd_eval.types import Box2D, GroundTruthObject


def test_csv_round_trip(tmp_path: Path) -> None:
    objs = [
        GroundTruthObject(0, 100, 1, Box2D(10.5, 20, 30, 90), (1.0, 2.0, 0.9), 1.0),
        GroundTruthObject(0, 100, 2, None, (3.0, -1.0, 0.8), 0.5, ignore=True),
        GroundTruthObject(1, 200, 1, Box2D(11, 20, 30, 90), None, 0.25),
    ]
    path = tmp_path / "seq.gt.csv"
    groundtruth.write_csv(path, objs)
    gt = groundtruth.load_ground_truth(path)
    assert [o for _, _, frame in gt.frames for o in frame] == objs
    assert gt.ids == {1, 2} and gt.has_boxes and gt.has_world


def test_ktp_2d_and_3d(tmp_path: Path) -> None:
    p2 = tmp_path / "gt2d.txt"
    p2.write_text("1338995447.5: 1 233 96 110 303, 2 0 0 0 0\n1338995447.533333: 2 10 20 30 40\n")
    gt = groundtruth.load_ground_truth(p2)
    # "0 0 0 0" means not annotated: frame 0 has only id 1.
    assert [(f, s, [o.object_id for o in objs]) for f, s, objs in gt.frames] == [
        (0, 1_338_995_447_500_000_000, [1]),
        (1, 1_338_995_447_533_333_000, [2]),
    ]
    assert gt.frames[0][2][0].box2d == Box2D(233, 96, 110, 303)
    p3 = tmp_path / "gt3d.txt"
    p3.write_text("10.0: 1 1.5 0.2 3.0, 2 0 0 0\n")
    gt3 = groundtruth.load_ground_truth(p3)
    assert gt3.frames[0][2][0].world_xyz == (1.5, 0.2, 3.0) and gt3.num_objects == 1


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("1.0: 1 2 3 4 5, 2 1 2 3\n", "mixes 2D and 3D"),
        ("1.0 1 2 3 4 5\n", "expected '<stamp>: id"),
        ("abc: 1 2 3 4 5\n", "bad stamp"),
        ("1.0: 1 2 3\n", "needs 'id x y w h'"),
        ("1.0: 1 2 3 4 5, 1 6 7 8 9\n", "id 1 appears twice in frame 0"),
    ],
)
def test_ktp_errors(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "gt.txt"
    path.write_text(text)
    with pytest.raises(GroundTruthError, match=match):
        groundtruth.load_ground_truth(path)


@pytest.mark.parametrize(
    ("rows", "match"),
    [
        (["0,1,1,0,0,1,1,,,,1"], "two stamps|two frames"),  # paired with the base row below
        (["0,100,1,0,0,1,1,,,,1"], "id 1 appears twice"),
        (["2,100,5,0,0,1,1,,,,1"], "two frames share stamp 100"),
        (["1,200,1,0,0,-1,1,,,,1"], "line 3: box size -1.0x1.0 is negative"),
        (["1,200,1,0,0,-0,1,,,,1"], "line 3: box size -0.0x1.0 is negative"),
        (["1,200,1,0,0,0,1,,,,1"], "line 3: box size 0.0x1.0 is empty"),
        (["1,200,1,0,0,1,1e300,,,,1"], "line 3: box .* lies beyond"),
        (["1,200,1,0,0,1,1,1e30,0,0,1"], "line 3: position .* lies beyond"),
        (["-1,200,1,0,0,1,1,,,,1"], "line 3: frame number -1 outside"),
        (["1,99999999999999999999,1,0,0,1,1,,,,1"], "line 3: stamp .* outside"),
        (["1,200,,0,0,1,1,,,,1"], "line 3: a row without id .* has a box"),
        (["1,200,1,0,0,1,1,,,,1.5"], "visibility 1.5 outside"),
        (["1,200,x,0,0,1,1,,,,1"], "line 3"),
    ],
)
def test_csv_contradictions(tmp_path: Path, rows: list[str], match: str) -> None:
    path = tmp_path / "gt.csv"
    header = ",".join(groundtruth.CSV_COLUMNS[:11])
    path.write_text("\n".join([header, "0,100,1,0,0,1,1,,,,1", *rows]) + "\n")
    with pytest.raises(GroundTruthError, match=match):
        groundtruth.load_ground_truth(path)


@pytest.mark.parametrize(
    ("text", "ignore"),
    [("0", False), ("1", True), ("", False), ("false", False), ("FALSE", False), ("True", True)],
)
def test_csv_ignore_spellings(tmp_path: Path, text: str, ignore: bool) -> None:
    path = tmp_path / "gt.csv"
    path.write_text(",".join(groundtruth.CSV_COLUMNS) + f"\n0,100,1,0,0,1,1,,,,1,{text}\n")
    (obj,) = groundtruth.load_ground_truth(path).frames[0][2]
    assert obj.ignore is ignore


@pytest.mark.parametrize("text", ["2", "no", "yes", "-1", "1.0", "x"])
def test_csv_other_ignore_values_are_refused(tmp_path: Path, text: str) -> None:
    path = tmp_path / "gt.csv"
    path.write_text(",".join(groundtruth.CSV_COLUMNS) + f"\n0,100,1,0,0,1,1,,,,1,{text}\n")
    with pytest.raises(GroundTruthError, match=f"line 2: ignore '{text}' is not 0, 1, false or"):
        groundtruth.load_ground_truth(path)


def test_csv_empty_frames_round_trip(tmp_path: Path) -> None:
    """Frames annotated with nobody in them are rows with an empty id; they are annotated
    frames (``run`` scores from the first annotated frame to the last)."""
    path = tmp_path / "gt.csv"
    objs = [GroundTruthObject(1, 200, 7, Box2D(0, 0, 1, 1), None)]
    groundtruth.write_csv(path, objs, [(0, 100), (1, 200), (2, 300)])
    gt = groundtruth.load_ground_truth(path)
    assert [(f, s, len(o)) for f, s, o in gt.frames] == [(0, 100, 0), (1, 200, 1), (2, 300, 0)]
    header_only = tmp_path / "empty.csv"
    groundtruth.write_csv(header_only, [], [(0, 100)])
    with pytest.raises(GroundTruthError, match="holds no annotated object"):
        groundtruth.load_ground_truth(header_only)


def test_missing_columns_and_file(tmp_path: Path) -> None:
    path = tmp_path / "gt.csv"
    path.write_text("frame,id\n0,1\n")
    with pytest.raises(GroundTruthError, match="missing columns stamp_ns"):
        groundtruth.load_ground_truth(path)
    with pytest.raises(GroundTruthError, match="not found"):
        groundtruth.load_ground_truth(tmp_path / "nope.csv")


def test_align_by_stamp_and_by_index() -> None:
    objs = [GroundTruthObject(i, 1000 + 100 * i, 1, Box2D(0, 0, 1, 1), None) for i in range(3)]
    gt = groundtruth.from_objects("mem", objs)
    # Recording frames at 1005, 1195 and 5000: the third annotation (1200) matches 1195 (5 ns away),
    # the second (1100) is 95 ns from 1005 and 1195 -> over the 10 ns gap: unmatched.
    per_frame, unmatched, matched = gt.match([1005, 1195, 5000], max_gap_ns=10)
    assert [len(p) for p in per_frame] == [1, 1, 0] and unmatched == 1 and matched == [0, 1]
    assert per_frame[1][0].frame == 2
    no_stamps = groundtruth.from_objects(
        "mem", [GroundTruthObject(1, 0, 1, Box2D(0, 0, 1, 1), None)]
    )
    per_frame, unmatched = no_stamps.align([7, 8], max_gap_ns=0)
    assert no_stamps.match([7, 8], max_gap_ns=0)[2] == [1]
    assert [len(p) for p in per_frame] == [0, 1] and unmatched == 0


@pytest.mark.parametrize(
    ("rows", "expected"),
    [
        # The first row with a problem is named, whichever check finds it (arrays or objects).
        (["1,1,0,0,5,5,1,1,1", "1,1,0,0,5,5,1,1,1", "2,2,0,0,0,5,1,1,1"], "id 1 appears twice"),
        (
            ["1,1,0,0,5,5,1,1,1", "2,2,0,0,0,5,1,1,1", "3,3,0,0,5,5,1,1,1", "3,3,0,0,5,5,1,1,1"],
            "frame 1, id 2: box size 0.0x5.0 is empty",
        ),
        (["1,1,0,0,5,-0,1,1,1"], "frame 0, id 1: box size 5.0x-0.0 is negative"),
    ],
)
def test_mot_gt_names_first_problem(tmp_path: Path, rows: list[str], expected: str) -> None:
    from rgbd_eval.io.tracks import read_mot_gt

    path = tmp_path / "gt.txt"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(GroundTruthError, match=expected):
        read_mot_gt(path)


def test_mot_gt_objects_as_read_row_by_row(tmp_path: Path) -> None:
    """Classes, consider flags and visibility (clamped, NaN to 0) as the devkit reads them."""
    from rgbd_eval.io.tracks import read_mot_gt

    path = tmp_path / "gt.txt"
    path.write_text("1,4,1.5,2,3,4,1,1,1.7\n1,5,0,0,3,4,0,1,nan\n2,4,0,0,3,4,1,7,-0.2\n")
    frames = read_mot_gt(path).frames
    assert [(f, [o.object_id for o in objs]) for f, _, objs in frames] == [(0, [4, 5]), (1, [4])]
    first, second = frames[0][2]
    assert first.box2d == Box2D(1.5, 2.0, 3.0, 4.0)
    assert (first.visibility, first.ignore, first.distractor) == (1.0, False, False)
    assert (second.visibility, second.ignore, second.distractor) == (0.0, True, False)
    third = frames[1][2][0]
    assert (third.visibility, third.ignore, third.distractor) == (0.0, True, True)
    assert str(third.visibility) == "0.0"
