"""`rgbd-eval import epfl-rgbd` from the command line: options, errors, and a dmtbs run on it."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.io.groundtruth import read_csv
from rgbd_eval.io.recording import open_recording
from tests.io.epfl_folder import write_sequence

runner = CliRunner()


def _import(folder: Path, out: Path, *extra: str) -> tuple[int, str]:
    result = runner.invoke(app, ["import", "epfl-rgbd", str(folder), "-o", str(out), *extra])
    return result.exit_code, " ".join(result.output.split())  # rich wraps long lines


def test_floor_from_the_first_frame_places_the_camera_and_the_people(tmp_path: Path) -> None:
    # Camera 2 m up, pitched 10 deg down; the board stands 4 m ahead, 0.5 m to the left.
    folder = write_sequence(tmp_path, [None, (4.0, 0.5)], pitch_deg=10.0)
    code, output = _import(folder, tmp_path / "lab.mcap")
    assert code == 0, output
    assert (
        "2 frames" in output and "1 boxes in 1 annotated frames, 1 with a world position" in output
    )
    # RANSAC on the mm-rounded floor: height to 5 mm, pitch to a few tenths of a degree.
    found = re.search(r"camera ([\d.]+) m above the floor, looking ([\d.]+) deg down", output)
    assert found is not None, output
    assert float(found[1]) == pytest.approx(2.0, abs=0.005)
    assert float(found[2]) == pytest.approx(10.0, abs=0.3)
    frame = next(iter(open_recording(tmp_path / "lab.mcap").frames()))
    # RANSAC on the floor recovers the camera height (to the depth's mm rounding).
    assert frame.camera_pose.translation[2] == pytest.approx(2.0, abs=0.005)
    ((_, _, objs),) = [f for f in read_csv(tmp_path / "lab.gt.csv").frames if f[2]]
    x, y, _ = objs[0].world_xyz or (0.0, 0.0, 0.0)
    assert (x, y) == (pytest.approx(4.0, abs=0.01), pytest.approx(0.5, abs=0.02))


def test_floor_given_as_a_plane_or_none(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [(4.0, 0.0)])
    # Level camera 2 m above the floor: in its optical frame (y down) the floor is y = 2,
    # i.e. 0 x + 1 y + 0 z - 2 = 0.
    code, output = _import(folder, tmp_path / "a.mcap", "--floor", "0,1,0,-2")
    assert code == 0, output
    pose = next(iter(open_recording(tmp_path / "a.mcap").frames())).camera_pose
    assert pose.translation == pytest.approx((0.0, 0.0, 2.0))
    code, output = _import(folder, tmp_path / "b.mcap", "--floor", "none", "--no-rgb")
    assert code == 0, output
    assert "0 with a world position" in output


def test_no_gt_writes_the_recording_alone(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [None], annotate=False)
    code, output = _import(folder, tmp_path / "a.mcap", "--no-gt", "--floor", "none")
    assert code == 0, output
    assert (tmp_path / "a.mcap").exists() and not (tmp_path / "a.gt.csv").exists()


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["import", "ktp", "x", "-o", "a.mcap"], 4, "format 'ktp': expected one of epfl-rgbd"),
        (["--floor", "1,2,3"], 4, "--floor '1,2,3': expected 4 comma-separated"),
        (["--floor", "0,0,0,1"], 4, "plane normal (a, b, c) must be non-zero"),
        (["--fps", "0"], 4, "--fps 0.0: must be within 0.1..1000 Hz"),
        (["--fps", "1e-300"], 4, "--fps 1e-300: must be within 0.1..1000 Hz"),
        (["--frames", "0"], 4, "--frames 0: must be at least 1"),
        (["--intrinsics", "1,2,3"], 4, "--intrinsics '1,2,3': expected 4"),
        (["--no-gt", "--annotations", "gt.yaml"], 4, "contradict"),
    ],
)
def test_bad_options_are_one_line_errors(
    tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    folder = write_sequence(tmp_path, [None])
    if args[0] == "import":
        result = runner.invoke(app, args)
    else:
        result = runner.invoke(
            app, ["import", "epfl-rgbd", str(folder), "-o", str(tmp_path / "a.mcap"), *args]
        )
    assert result.exit_code == code, result.output
    assert message in result.output and result.output.count("\n") == 1
    assert not (tmp_path / "a.mcap").exists()


def test_bad_input_gets_its_exit_code(tmp_path: Path) -> None:
    folder = write_sequence(tmp_path, [None], annotate=False)
    code, output = _import(folder, tmp_path / "a.mcap")
    assert code == 5 and "ground_truth_image_plane.yaml: not found beside" in output
    code, output = _import(tmp_path / "nowhere", tmp_path / "a.mcap")
    assert code == 3 and "not a folder" in output
    code, output = _import(folder, tmp_path / "a.txt", "--no-gt")
    assert code == 4 and "name a .mcap or .bag recording" in output
    (tmp_path / "dir.mcap").mkdir()
    code, output = _import(folder, tmp_path / "dir.mcap", "--no-gt")
    assert code == 7 and "is a folder" in output


def test_no_floor_in_view_asks_for_one(tmp_path: Path) -> None:
    # Pitched 60 deg up... expressed as -60 deg of pitch: the camera sees the wall only.
    folder = write_sequence(tmp_path, [None], pitch_deg=-40.0, annotate=False)
    code, output = _import(folder, tmp_path / "a.mcap", "--no-gt")
    assert code == 3 and "give --floor a,b,c,d or --floor none" in output, output


@pytest.mark.slow
def test_dmtbs_runs_on_an_imported_sequence_in_the_ground_truth_frame(tmp_path: Path) -> None:
    # 30 empty frames initialise the background (dmtbs init_frames: 30), then the board walks
    # 1.2 m to the left at x = 4 m for 20 frames. The track is reported from its third hit
    # (confirm_hits: 3), so 2 of the 20 ground-truth instances are missed: MOTA = 18/20 = 90%.
    # MOTP is the distance between dmtbs's blob and the position derived from the box: both
    # in the world frame the import wrote, within a few cm.
    boards = [None] * 30 + [(4.0, -0.6 + 1.2 * i / 19) for i in range(20)]
    folder = write_sequence(tmp_path, boards, pitch_deg=10.0)
    code, output = _import(folder, tmp_path / "lab.mcap", "--no-rgb")
    assert code == 0, output
    result = runner.invoke(
        app, ["run", str(tmp_path / "lab.mcap"), "--method", "dmtbs", "--out", str(tmp_path / "r")]
    )
    assert result.exit_code == 0, result.output
    overall = json.loads((tmp_path / "r" / "report.json").read_text())["overall"]
    counts = overall["counts"]
    assert (counts["num_gt"], counts["fn"], counts["fp"], counts["id_switches"]) == (20, 2, 0, 0)
    assert overall["metrics"]["mota"] == pytest.approx(0.9)
    assert overall["metrics"]["motp"] < 0.05
