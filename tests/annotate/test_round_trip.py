"""The CVAT round trip on the demo: export, edit as an annotator would, import, score.

The run's tracks pre-annotate the task, so the unedited task scores the tracks against
themselves; each edit then changes the counts by exactly what it should.
"""

from __future__ import annotations

import csv
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app

runner = CliRunner()


def _cli(*args: str, code: int = 0) -> str:
    result = runner.invoke(app, list(args))
    assert result.exit_code == code, result.output
    return result.output


def _counts(tracks: Path, gt: Path, out: Path) -> dict[str, int]:
    report = json.loads(_cli("score", str(tracks), "--gt", str(gt), "--out", str(out), "--json"))
    return report["sequences"][0]["counts"]


def _visible(root: ET.Element) -> dict[int, dict[int, ET.Element]]:
    """Track id -> frame -> its visible <box> element."""
    return {
        int(t.get("id", "")): {
            int(b.get("frame", "")): b for b in t.findall("box") if b.get("outside") == "0"
        }
        for t in root.findall("track")
    }


def _corners(box: ET.Element) -> tuple[float, float, float, float]:
    return tuple(float(box.get(k, "")) for k in ("xtl", "ytl", "xbr", "ybr"))  # type: ignore[return-value]


def _overlaps(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


@pytest.mark.slow
def test_annotators_edits_reach_the_score_exactly(
    demo: Path, demo_run: Path, tmp_path: Path
) -> None:
    tracks = demo_run / "demo.tracks.csv"
    task = tmp_path / "task"
    _cli("annotate", "export", str(demo), "--tracks", str(tracks), "-o", str(task))
    assert {p.name for p in task.iterdir()} >= {"annotations.xml", "images.zip", "README.txt"}
    xml = task / "annotations.xml"

    # Unedited: the tracks scored against their own boxes (clipped to the image).
    gt0 = tmp_path / "unedited.gt.csv"
    _cli("annotate", "import", str(xml), "--recording", str(demo), "-o", str(gt0))
    c0 = _counts(tracks, gt0, tmp_path / "s0")
    assert c0["num_matches"] > 0 and c0["id_switches"] == 0

    tree = ET.parse(xml)
    root = tree.getroot()
    boxes = _visible(root)
    per_frame: dict[int, set[int]] = {}
    for track_id, frames in boxes.items():
        for f in frames:
            per_frame.setdefault(f, set()).add(track_id)
    # The score's timeline is the annotated frames (frames with a person): every edit below
    # stays on frames that keep another person, so the timeline, and with it every frame's
    # tracks, stays as it was.
    ids = sorted(boxes, key=lambda i: len(boxes[i]))

    # 1. Delete a track the method made (the shortest whose frames all show someone else).
    deleted = next(i for i in ids if all(len(per_frame[f]) > 1 for f in boxes[i]))
    n_deleted = len(boxes[deleted])
    root.remove(next(t for t in root.findall("track") if t.get("id") == str(deleted)))
    for f in boxes[deleted]:
        per_frame[f].discard(deleted)

    # 2. Mark 3 frames of another track outside (the person "left" the image): the first box
    #    of the span becomes an outside keyframe, the next two go, the box after stays.
    span_track, span = next(
        (i, fs[k : k + 3])
        for i in ids
        if i != deleted
        for fs in [sorted(boxes[i])]
        for k in range(1, len(fs) - 3)
        if fs[k + 3] == fs[k] + 3 and all(len(per_frame[f]) > 1 for f in fs[k : k + 3])
    )
    element = next(t for t in root.findall("track") if t.get("id") == str(span_track))
    element_boxes = {int(b.get("frame", "")): b for b in element.findall("box")}
    element_boxes[span[0]].set("outside", "1")
    for f in span[1:]:
        element.remove(element_boxes[f])
    for f in span:
        per_frame[f].discard(span_track)

    # 3. Move one box of a remaining track far from every box of its frame.
    moved_track, moved_frame = next(
        (i, f) for i in sorted(boxes) if i != deleted for f in sorted(boxes[i]) if f not in span
    )
    box = boxes[moved_track][moved_frame]
    xtl, ytl, xbr, ybr = _corners(box)
    width = xbr - xtl
    new = (2.0, ytl, 2.0 + width, ybr) if xtl > 320 else (638.0 - width, ytl, 638.0, ybr)
    others = [_corners(boxes[i][moved_frame]) for i in per_frame[moved_frame] if i != moved_track]
    assert not any(_overlaps(new, o) for o in others)
    box.set("xtl", f"{new[0]:.2f}")
    box.set("xbr", f"{new[2]:.2f}")

    # 4. Add a person the method missed: keyframes on 10 frames apart, CVAT interpolates
    #    the 8 between, outside after; in the top left corner, where no track box is.
    frames = sorted(f for f, present in per_frame.items() if present)
    start = next(
        f for f in frames if all(g in per_frame and per_frame[g] for g in range(f, f + 10))
    )
    added = ET.SubElement(root, "track", {"id": "900", "label": "person", "source": "manual"})
    for f, x, outside in ((start, 1.0, "0"), (start + 9, 10.0, "0"), (start + 10, 10.0, "1")):
        ET.SubElement(
            added,
            "box",
            {
                "frame": str(f),
                "outside": outside,
                "occluded": "0",
                "keyframe": "1",
                "xtl": f"{x:.2f}",
                "ytl": "1.00",
                "xbr": f"{x + 12:.2f}",
                "ybr": "25.00",
                "z_order": "0",
            },
        )
    for f in range(start, start + 10):
        corner = (1.0 + (f - start), 1.0, 13.0 + (f - start), 25.0)
        assert not any(_overlaps(corner, _corners(boxes[i][f])) for i in per_frame[f])
    tree.write(tmp_path / "edited.xml", encoding="utf-8", xml_declaration=True)

    gt1 = tmp_path / "edited.gt.csv"
    _cli(
        "annotate", "import", str(tmp_path / "edited.xml"), "--recording", str(demo), "-o", str(gt1)
    )
    with gt1.open() as handle:
        rows = list(csv.DictReader(handle))
    assert {int(r["frame"]) for r in rows} == {int(r["frame"]) for r in csv.DictReader(gt0.open())}
    added_rows = [r for r in rows if r["id"] == "900"]
    assert [int(r["frame"]) for r in added_rows] == list(range(start, start + 10))
    assert float(added_rows[1]["bb_left"]) == 2.0  # interpolated: 1 + (10 - 1) / 9

    c1 = _counts(tracks, gt1, tmp_path / "s1")
    # By hand, from the unedited counts:
    # - the deleted track's n_deleted boxes: its track boxes become false positives;
    # - the 3 frames outside: that track's boxes there become false positives;
    # - the moved box: a miss (nothing on it) and a false positive (its track, uncovered);
    # - the added person: 10 misses (no track there).
    assert c1["num_gt"] == c0["num_gt"] - n_deleted - 3 + 10
    assert c1["fp"] == c0["fp"] + n_deleted + 3 + 1
    assert c1["fn"] == c0["fn"] + 1 + 10
    assert c1["num_matches"] == c0["num_matches"] - n_deleted - 3 - 1
    assert c1["id_switches"] == c0["id_switches"] == 0
