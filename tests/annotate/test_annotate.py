"""`annotate export` and `annotate import`: tasks, frame steps, MOT, labels, depth, bad files."""

from __future__ import annotations

import csv
import hashlib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rgbd_eval.annotate import OCCLUDED_VISIBILITY, image_name
from rgbd_eval.cli.main import app
from rgbd_eval.io.cvat import CvatBox, CvatTask, CvatTrack, cvat_xml, load_cvat, visible_boxes
from rgbd_eval.io.writer import RecordingWriter
from tests.annotate.conftest import FRAMES
from tests.io.conftest import PERIOD, RGB_CAM, T0, rgb_image

runner = CliRunner()


def _cli(*args: str, code: int = 0) -> str:
    result = runner.invoke(app, list(args))
    assert result.exit_code == code, result.output
    return result.output


def _rows(path: Path) -> list[dict[str, str]]:
    """The sidecar's people (rows with an empty id mark frames annotated with nobody)."""
    with path.open() as handle:
        return [row for row in csv.DictReader(handle) if row["id"]]


@pytest.fixture(scope="module")
def task(demo: Path, demo_run: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A task of every frame, pre-annotated with the run's tracks."""
    out = tmp_path_factory.mktemp("task") / "task"
    _cli(
        "annotate",
        "export",
        str(demo),
        "--tracks",
        str(demo_run / "demo.tracks.csv"),
        "-o",
        str(out),
    )
    return out


def test_export_writes_frames_and_tracks_as_cvat_takes_them(task: Path, demo_run: Path) -> None:
    with zipfile.ZipFile(task / "images.zip") as archive:
        names = archive.namelist()
        first = archive.read(names[0])
    assert names == [image_name(i) for i in range(FRAMES)] == sorted(names)
    assert first[:2] == b"\xff\xd8"  # JPEG
    annotations = load_cvat(task / "annotations.xml")
    assert annotations.task == CvatTask(FRAMES, width=640, height=480, name="demo")
    # Every scored track of the run, one box per frame it is on, closed by an outside box.
    scored = [r for r in _rows(demo_run / "demo.tracks.csv") if r["status"] == "validated"]
    boxes = [(b.frame, t.track_id) for t in annotations.tracks for b in t.boxes if not b.outside]
    assert sorted(boxes) == sorted((int(r["frame"]), int(r["id"])) for r in scored if r["bb_left"])
    assert all(t.source == "auto" and t.label == "person" for t in annotations.tracks)
    readme = (task / "README.txt").read_text()
    assert "CVAT for video 1.1" in readme and "--every 1" in readme


@pytest.mark.slow
def test_export_of_the_method_equals_export_of_its_run(
    demo: Path, demo_run: Path, task: Path, tmp_path: Path
) -> None:
    tracks = demo_run / "demo.tracks.csv"
    out = tmp_path / "by_method"
    _cli("annotate", "export", str(demo), "--method", "basso2012", "-o", str(out))
    digest = [hashlib.sha256((d / "images.zip").read_bytes()).hexdigest() for d in (out, task)]
    assert digest[0] == digest[1]  # the same frames, byte for byte
    mine, theirs = (load_cvat(d / "annotations.xml").tracks for d in (out, task))
    assert [t.track_id for t in mine] == [t.track_id for t in theirs]
    for a, b in zip(mine, theirs, strict=True):  # tracks.csv rounds to 0.0001 px, XML 0.01
        assert [x.frame for x in a.boxes] == [x.frame for x in b.boxes]
        corners = [(x.xtl, x.ytl, x.xbr, x.ybr) for x in a.boxes]
        assert np.allclose(corners, [(x.xtl, x.ytl, x.xbr, x.ybr) for x in b.boxes], atol=0.011)
    # Exporting again into a folder it wrote replaces it; into someone else's it refuses.
    _cli("annotate", "export", str(demo), "--tracks", str(tracks), "--every", "2", "-o", str(out))
    assert load_cvat(out / "annotations.xml").task == CvatTask(
        30, width=640, height=480, name="demo"
    )
    mine_folder = tmp_path / "mine"
    mine_folder.mkdir()
    (mine_folder / "notes.txt").write_text("mine")
    output = _cli("annotate", "export", str(demo), "-o", str(mine_folder), code=7)
    assert "not written by rgbd-eval" in output and (mine_folder / "notes.txt").exists()


def test_every_nth_frame_is_interpolated_back_onto_every_frame(
    demo: Path, demo_run: Path, tmp_path: Path
) -> None:
    out = tmp_path / "task3"
    tracks = demo_run / "demo.tracks.csv"
    _cli("annotate", "export", str(demo), "--tracks", str(tracks), "--every", "3", "-o", str(out))
    with zipfile.ZipFile(out / "images.zip") as archive:
        assert archive.namelist() == [image_name(i) for i in range(0, FRAMES, 3)]
    annotations = load_cvat(out / "annotations.xml")
    assert annotations.task is not None and annotations.task.size == FRAMES // 3
    assert "--every 3" in (out / "README.txt").read_text()
    gt = tmp_path / "every3.gt.csv"
    # --every is inferred: 20 task frames come from 60 recording frames only at 3.
    output = _cli(
        "annotate", "import", str(out / "annotations.xml"), "--recording", str(demo), "-o", str(gt)
    )
    assert "recording frame 3 x k" in output
    rows = _rows(gt)
    by_key = {(int(r["frame"]), int(r["id"])): r for r in rows}
    exported = {
        (b.frame * 3, t.track_id): b for t in annotations.tracks for b in t.boxes if not b.outside
    }
    # Keyframes land on their recording frames, as written.
    for (frame, track_id), b in exported.items():
        row = by_key[(frame, track_id)]
        assert float(row["bb_left"]) == b.xtl and float(row["bb_top"]) == b.ytl
    # Between two keyframes 3 frames apart, one third and two thirds of the way.
    track = annotations.tracks[0]
    pairs = [
        (a, b)
        for a, b in zip(track.boxes, track.boxes[1:], strict=False)
        if b.frame == a.frame + 1 and not (a.outside or b.outside)
    ]
    a, b = pairs[0]
    row = by_key[(a.frame * 3 + 1, track.track_id)]
    assert float(row["bb_left"]) == pytest.approx(a.xtl + (b.xtl - a.xtl) / 3, abs=1e-6)
    # The last task frame (19: recording frame 57) stands for itself and the two after it.
    last = next(
        t for t in annotations.tracks if t.boxes[-1].frame == 19 and not t.boxes[-1].outside
    )
    tail = [by_key[(f, last.track_id)]["bb_left"] for f in (57, 58, 59)]
    assert tail[0] == tail[1] == tail[2] and max(f for f, _ in by_key) == FRAMES - 1
    # Another --every than the export's is refused: another task's frame count.
    output = _cli(
        "annotate",
        "import",
        str(out / "annotations.xml"),
        "--recording",
        str(demo),
        "--every",
        "2",
        "-o",
        str(tmp_path / "x.csv"),
        code=5,
    )
    assert "the task has 20 frames, the recording at --every 2 30" in output


def _mot_zip(path: Path, xml: Path) -> Path:
    """The task as CVAT's MOT 1.1 export writes it: every visible box, frames from 1,
    track ids from 1, visibility 0 for occluded."""
    annotations = load_cvat(xml)
    task = annotations.task
    assert task is not None
    lines = []
    for number, track in enumerate(annotations.tracks, start=1):
        for frame, b in sorted(visible_boxes(track, task.frames).items()):
            w, h = b.xbr - b.xtl, b.ybr - b.ytl
            lines.append(
                f"{frame + 1},{number},{b.xtl},{b.ytl},{w},{h},1,1,{0.0 if b.occluded else 1.0}"
            )
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("gt/gt.txt", "\n".join(lines) + "\n")
        archive.writestr("gt/labels.txt", "person\n")
    return path


def test_mot_export_gives_the_same_ground_truth(task: Path, demo: Path, tmp_path: Path) -> None:
    from_xml = tmp_path / "xml.gt.csv"
    _cli(
        "annotate",
        "import",
        str(task / "annotations.xml"),
        "--recording",
        str(demo),
        "-o",
        str(from_xml),
    )
    mot = _mot_zip(tmp_path / "mot.zip", task / "annotations.xml")
    from_mot = tmp_path / "mot.gt.csv"
    output = _cli(
        "annotate", "import", str(mot), "--recording", str(demo), "-o", str(from_mot), code=4
    )
    assert "give --every N" in output  # MOT text does not say which frames the task holds
    _cli(
        "annotate",
        "import",
        str(mot),
        "--recording",
        str(demo),
        "--every",
        "1",
        "-o",
        str(from_mot),
    )
    xml_rows, mot_rows = _rows(from_xml), _rows(from_mot)
    assert len(xml_rows) == len(mot_rows) > 0
    key = lambda r: (int(r["frame"]), float(r["bb_left"]))  # noqa: E731 - ids differ (MOT from 1)
    for a, b in zip(sorted(xml_rows, key=key), sorted(mot_rows, key=key), strict=True):
        for column in ("frame", "stamp_ns", "x", "y", "z", "visibility", "ignore"):
            assert a[column] == b[column], column
        for column in ("bb_left", "bb_top", "bb_width", "bb_height"):
            assert float(a[column]) == pytest.approx(float(b[column]), abs=1e-6)
    assert {r["visibility"] for r in xml_rows} <= {"1.0", repr(OCCLUDED_VISIBILITY)}
    # World positions from the depth image and tf, on every box whose torso shows one surface.
    assert sum(r["x"] != "" for r in xml_rows) >= len(xml_rows) - 2


def _edited(task: Path, tmp_path: Path, old: str, new: str) -> Path:
    text = (task / "annotations.xml").read_text()
    assert old in text
    path = tmp_path / "edited.xml"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("<size>60</size>", "<size>50</size>", "contradicts itself"),
        ("<stop_frame>59</stop_frame>", "<stop_frame>69</stop_frame>", "contradicts itself"),
        ("<width>640</width>", "<width>1280</width>", "the task's images are 1280x480"),
        ('xtl="', 'xtl="-50', "reaches outside the 640x480 image"),
        ('<track id="2"', '<track id="1"', "track id 1 is used by two tracks"),
    ],
)
def test_another_tasks_annotations_are_refused(
    task: Path, demo: Path, tmp_path: Path, old: str, new: str, message: str
) -> None:
    edited = _edited(task, tmp_path, old, new)
    out = tmp_path / "bad.gt.csv"
    output = _cli(
        "annotate", "import", str(edited), "--recording", str(demo), "-o", str(out), code=5
    )
    line = output.strip()
    assert line.startswith(f"error: {edited}: ") and message in line and "\n" not in line
    assert not out.exists()


def test_size_and_frame_count_of_another_recording(task: Path, demo: Path, tmp_path: Path) -> None:
    edited = _edited(task, tmp_path, "<size>60</size>\n", "<size>61</size>\n")
    edited.write_text(
        edited.read_text().replace("<stop_frame>59</stop_frame>", "<stop_frame>60</stop_frame>")
    )
    output = _cli(
        "annotate",
        "import",
        str(edited),
        "--recording",
        str(demo),
        "-o",
        str(tmp_path / "a.csv"),
        code=5,
    )
    assert "the task has 61 frames, which no --every gives from the recording's 60 frames" in output


def _colour_only(path: Path, frames: int) -> Path:
    """A recording with colour images and no depth."""
    with RecordingWriter(path) as w:
        for i in range(frames):
            w.write_rgb(T0 + i * PERIOD, rgb_image(i), RGB_CAM)
    return path


def test_labels_and_a_recording_without_depth(tmp_path: Path) -> None:
    rec = _colour_only(tmp_path / "colour.mcap", 4)
    task = CvatTask(4, width=RGB_CAM.width, height=RGB_CAM.height)
    person = CvatTrack(
        0,
        "person",
        (CvatBox(0, 2.0, 3.0, 12.0, 40.0), CvatBox(2, 2.0, 3.0, 12.0, 40.0, outside=True)),
    )
    car = CvatTrack(1, "car", (CvatBox(1, 20.0, 20.0, 40.0, 30.0),))
    xml = tmp_path / "annotations.xml"
    xml.write_text(cvat_xml(task, [person, car]))
    gt = tmp_path / "colour.gt.csv"
    output = _cli("annotate", "import", str(xml), "--recording", str(rec))  # default -o: beside it
    assert "no depth in the recording" in output and "left out: 1 label car" in output
    rows = _rows(gt)
    assert [(r["frame"], r["id"], r["x"]) for r in rows] == [("0", "0", ""), ("1", "0", "")]
    output = _cli(
        "annotate",
        "import",
        str(xml),
        "--recording",
        str(rec),
        "-o",
        str(tmp_path / "r.csv"),
        "--other-labels",
        "refuse",
        code=5,
    )
    assert "tracks of other labels than 'person' (car)" in output
    output = _cli(
        "annotate",
        "import",
        str(xml),
        "--recording",
        str(rec),
        "-o",
        str(tmp_path / "l.csv"),
        "--label",
        "bicycle",
        code=5,
    )
    assert (
        "no box track labelled 'bicycle' (labels: car, person; choose one with --label)" in output
    )
    # Boxes only: IoU gating scores them, metric gating refuses them.
    tracks = tmp_path / "tracks.csv"
    tracks.write_text(
        "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z,stamp_ns,height,visibility,status\n"
        + "".join(
            f"{i},5,2,3,10,37,-1,1,0,0.8,{T0 + i * PERIOD},1.6,visible,validated\n"
            for i in range(2)
        )
    )
    _cli("score", str(tracks), "--gt", str(gt), "--out", str(tmp_path / "iou"))
    output = _cli(
        "score",
        str(tracks),
        "--gt",
        str(gt),
        "--gating",
        "metric",
        "--out",
        str(tmp_path / "m"),
        code=6,
    )
    assert "has no world position (world_xyz), needed for metric gating" in output
    # The sidecar it wrote is its own to replace; a sidecar someone else wrote is not.
    _cli("annotate", "import", str(xml), "--recording", str(rec))
    mine = tmp_path / "mine.gt.csv"
    mine.write_text("frame,stamp_ns,id\n")
    output = _cli("annotate", "import", str(xml), "--recording", str(rec), "-o", str(mine), code=7)
    assert "not written by `rgbd-eval annotate`" in output


def test_a_missing_subcommand_is_one_usage_line(capsys: pytest.CaptureFixture[str]) -> None:
    from tests.fuzz.cli import run_cli

    outcome = run_cli(["annotate"], capsys)
    assert outcome.code == 2
    line = outcome.stderr.strip()
    assert line.startswith("error: Missing command. (see ") and line.endswith("annotate --help)")
