"""CVAT for video 1.1 and MOT 1.1: read as CVAT writes them, interpolated as CVAT does.

``tests/data/cvat/datumaro_for_video.xml`` is a CVAT for video 1.1 export from CVAT's own
sample data (provenance in ``tests/data/cvat/README.md``): a task of 4 frames, 10 to 19
every 3rd frame, 25x20 images, box, points, polyline and skeleton tracks.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from rgbd_eval.errors import GroundTruthError
from rgbd_eval.io.cvat import (
    CvatBox,
    CvatTask,
    CvatTrack,
    cvat_xml,
    load_cvat,
    parse_cvat_xml,
    parse_mot,
    visible_boxes,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "cvat"
SAMPLE = DATA / "datumaro_for_video.xml"


def test_reads_cvats_sample_export() -> None:
    annotations = load_cvat(SAMPLE)
    task = annotations.task
    assert task is not None
    # <size>4</size>, <start_frame>10</start_frame>, <stop_frame>19</stop_frame>, step=3
    assert (task.size, task.start_frame, task.stop_frame, task.step) == (4, 10, 19, 3)
    assert list(task.frames) == [10, 13, 16, 19]
    assert (task.width, task.height) == (25, 20)
    assert task.labels == ("klhg", "z U k", "II", "skeleton", "1", "2", "3", "4")
    # Only track 0 holds boxes; the points, polyline and skeleton tracks are counted, not read.
    assert [t.track_id for t in annotations.tracks] == [0]
    assert dict(annotations.other_shapes) == {"points": 1, "polyline": 1, "skeleton": 1}
    track = annotations.tracks[0]
    assert track.label == "II" and track.source == "manual"
    assert track.boxes[0] == CvatBox(10, 3.0, 4.0, 10.0, 5.0, occluded=True, keyframe=True)
    assert [b.outside for b in track.boxes] == [False, True, True]
    # Visible on frame 10 only: outside from 13 on (the box of 16 is outside too).
    assert visible_boxes(track, task.frames) == {10: track.boxes[0]}


def _task(size: int = 10) -> CvatTask:
    return CvatTask(size, width=100, height=80, name="t")


def test_interpolates_between_keyframes_as_cvat() -> None:
    track = CvatTrack(
        5,
        "person",
        (
            CvatBox(0, 0.0, 0.0, 10.0, 10.0, attributes=(("colour", "red"),)),
            CvatBox(4, 40.0, 8.0, 50.0, 20.0, occluded=True),
            CvatBox(6, 40.0, 8.0, 50.0, 20.0, outside=True),
            CvatBox(8, 1.0, 2.0, 3.0, 4.0),
        ),
    )
    boxes = visible_boxes(track, range(10))
    # Frames 0-4: keyframes 0 and 4, linear in between: frame 1 is 1/4 of the way.
    assert (boxes[1].xtl, boxes[1].ytl, boxes[1].xbr, boxes[1].ybr) == (10.0, 2.0, 20.0, 12.5)
    assert boxes[1].keyframe is False and boxes[1].occluded is False  # the earlier box's flag
    assert boxes[1].attributes == (("colour", "red"),)
    assert boxes[4].occluded is True and boxes[4].attributes == (("colour", "red"),)  # carried
    # Frame 5 lies between a visible box and the outside one: CVAT interpolates toward it.
    assert boxes[5].xtl == 40.0 and boxes[5].occluded is True
    # Outside at 6 and until the next box (8); from 8 the last box lasts to the end.
    assert 6 not in boxes and 7 not in boxes
    assert (boxes[8].xtl, boxes[9].xtl, boxes[9].keyframe) == (1.0, 1.0, False)
    assert sorted(boxes) == [0, 1, 2, 3, 4, 5, 8, 9]
    # Only the frames asked for (a task every 2nd frame), and none before the first box.
    assert sorted(visible_boxes(track, range(-2, 10, 2))) == [0, 2, 4, 8]


def test_writes_what_it_reads_in_cvats_layout() -> None:
    tracks = [
        CvatTrack(
            3,
            "person",
            (
                CvatBox(0, 1.234, 2.0, 30.5, 40.0, occluded=True),
                CvatBox(2, 5.0, 6.0, 35.0, 46.0, attributes=(("ignored", "true"),)),
                CvatBox(3, 5.0, 6.0, 35.0, 46.0, outside=True),
            ),
            source="auto",
        )
    ]
    text = cvat_xml(_task(), tracks)
    assert text.startswith('<?xml version="1.0" encoding="utf-8"?>\n<annotations>\n  <version>1.1')
    # Attribute order and 2-decimal coordinates as CVAT's exporter writes them.
    assert (
        '<box frame="0" outside="0" occluded="1" keyframe="1" xtl="1.23" ytl="2.00" '
        'xbr="30.50" ybr="40.00" z_order="0">'
    ) in text
    assert '<attribute name="ignored">true</attribute>' in text
    back = parse_cvat_xml(text, "t.xml")
    assert back.task == _task()
    assert back.tracks[0].boxes[0].xtl == 1.23  # CVAT's precision
    assert back.tracks[0].boxes[1:] == tracks[0].boxes[1:]
    assert back.tracks[0].source == "auto"


def _with(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new, 1)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda t: _with(t, '<track id="3"', '<track id="3" label="person"/>\n  <track id="3"'),
            "track id 3 is used by two tracks",
        ),
        (lambda t: _with(t, '<box frame="2"', '<box frame="0"'), "frame 0 has two boxes"),
        (
            lambda t: _with(t, '<box frame="2"', '<box frame="12"'),
            "frame 12 is not a frame of the task",
        ),
        (lambda t: _with(t, "<size>10</size>", "<size>11</size>"), "the file contradicts itself"),
        (
            lambda t: _with(
                t, "<frame_filter></frame_filter>", "<frame_filter>every 2</frame_filter>"
            ),
            "expected empty or step=N",
        ),
        (lambda t: _with(t, 'xbr="30.50"', 'xbr="-1"'), "has no area"),
        (lambda t: _with(t, 'occluded="1"', 'occluded="yes"'), "occluded='yes': expected 0 or 1"),
        (
            lambda t: _with(t, "<version>1.1</version>", "<version>1.0</version>"),
            "expected CVAT for video 1.1",
        ),
        (
            lambda t: _with(t, "<meta>", '<image id="0" name="a.jpg"/><meta>'),
            "export the task as 'CVAT for video 1.1'",
        ),
        (
            lambda t: _with(t, "<annotations>", '<!DOCTYPE a [<!ENTITY x "y">]><annotations>'),
            "<!DOCTYPE>",
        ),
        (lambda t: t[:-30], "not well-formed XML"),
    ],
)
def test_bad_files_are_one_clear_error(edit: object, message: str) -> None:
    tracks = [
        CvatTrack(
            3,
            "person",
            (
                CvatBox(0, 1.234, 2.0, 30.5, 40.0, occluded=True),
                CvatBox(2, 5.0, 6.0, 35.0, 46.0),
            ),
        )
    ]
    text = edit(cvat_xml(_task(), tracks))  # type: ignore[operator]
    with pytest.raises(GroundTruthError) as err:
        parse_cvat_xml(text, "bad.xml")
    assert message in str(err.value) and str(err.value).startswith("bad.xml: ")
    assert "\n" not in str(err.value)


# MOT 1.1 as CVAT's documentation shows it (no sample export could be had): frame_id,
# track_id, x, y, w, h, "not ignored", class_id, visibility; labels.txt one per line.
MOT_GT = """1,1,10,20,30,60,1,1,1.0
2,1,12,20,30,60,1,1,0.0
4,1,20,20,30,60,1,1,1.0
1,2,50,5,10,20,0,2,1.0
3,3,1,1,5,5,1,1,0.25
"""
MOT_LABELS = "person\ncar\n"


def test_reads_mot_as_cvat_imports_it() -> None:
    annotations = parse_mot(MOT_GT, MOT_LABELS, "gt.txt")
    assert annotations.task is None and annotations.kind == "MOT 1.1"
    by_id = {t.track_id: t for t in annotations.tracks}
    assert {i: t.label for i, t in by_id.items()} == {1: "person", 2: "car", 3: "person"}
    one = visible_boxes(by_id[1], range(6))
    # Frames count from 1; a gap (frame 3) is outside, and the track ends after its last row.
    assert sorted(one) == [0, 1, 3]
    assert one[1].occluded is True and one[0].occluded is False  # visibility 0 = occluded
    assert (one[0].xtl, one[0].ytl, one[0].xbr, one[0].ybr) == (10.0, 20.0, 40.0, 80.0)
    assert by_id[2].boxes[0].attribute("ignored") == "true"  # not_ignored 0
    assert by_id[3].boxes[0].attribute("visibility") == "0.25"
    # Without labels.txt, MOTChallenge's classes: 1 is pedestrian.
    assert parse_mot(MOT_GT, None, "gt.txt").tracks[0].label == "pedestrian"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1,-1,10,20,30,60,1,1,1.0\n", "have no track id"),
        ("0,1,10,20,30,60,1,1,1.0\n", "MOT frames count from 1"),
        ("1,1,10,20,0,60,1,1,1.0\n", "has no area"),
        ("1,1,10,20,30,60,1,9,1.0\n", "the labels are 1 to 2"),
        ("1,1,10,20,30,60,1,1,1.0\n1,1,10,20,30,60,1,1,1.0\n", "two boxes in frame 1"),
        ("1,1,10,20,30,60,1,1,1.0\n2,1,10,20,30,60,1,2,1.0\n", "changes its label"),
        ("1,1,10\n", "3 fields"),
    ],
)
def test_bad_mot_is_one_clear_error(text: str, message: str) -> None:
    with pytest.raises(GroundTruthError, match=message):
        parse_mot(text, MOT_LABELS, "gt.txt")


def test_loads_exports_as_cvat_downloads_them(tmp_path: Path) -> None:
    # CVAT for video 1.1: a zip with annotations.xml (and images/ when asked for).
    xml_zip = tmp_path / "task_video.zip"
    with zipfile.ZipFile(xml_zip, "w") as archive:
        archive.write(SAMPLE, "annotations.xml")
        archive.writestr("images/frame_000000.png", b"")
    assert load_cvat(xml_zip).tracks == load_cvat(SAMPLE).tracks
    # MOT 1.1: gt/gt.txt and gt/labels.txt in the zip, or the folder unpacked.
    mot_zip = tmp_path / "task_mot.zip"
    with zipfile.ZipFile(mot_zip, "w") as archive:
        archive.writestr("gt/gt.txt", MOT_GT)
        archive.writestr("gt/labels.txt", MOT_LABELS)
    assert load_cvat(mot_zip).tracks == parse_mot(MOT_GT, MOT_LABELS, "x").tracks
    folder = tmp_path / "unpacked"
    (folder / "gt").mkdir(parents=True)
    (folder / "gt" / "gt.txt").write_text(MOT_GT)
    (folder / "gt" / "labels.txt").write_text(MOT_LABELS)
    assert load_cvat(folder).tracks == parse_mot(MOT_GT, MOT_LABELS, "x").tracks
    assert load_cvat(folder / "gt" / "gt.txt").tracks[1].label == "car"
    empty = tmp_path / "empty.zip"
    with zipfile.ZipFile(empty, "w") as archive:
        archive.writestr("readme.txt", "")
    with pytest.raises(GroundTruthError, match=r"neither annotations\.xml"):
        load_cvat(empty)
