"""``rgbd-eval score`` on small MOTChallenge files written in the test."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.io.tracks import Benchmark, read_mot_gt

runner = CliRunner()

# MOT17 ground truth, 2 frames: frame,id,x,y,w,h,consider,class,visibility.
# id 1: pedestrian, scored. id 2: static person (class 7), a distractor.
# id 3: pedestrian with consider 0 (not scored, not a distractor). id 4: a car (class 3).
GT = """\
1,1,0,0,10,10,1,1,1.0
1,2,100,0,10,10,1,7,1.0
1,3,200,0,10,10,0,1,0.2
1,4,300,0,10,10,0,3,1.0
2,1,0,0,10,10,1,1,1.0
"""
# Tracks: 7 on person 1 in both frames, 8 on the static person (dropped), 9 on the
# consider-0 pedestrian (kept: a false positive), 10 on the car (a false positive).
TRACKS = """\
1,7,0,0,10,10,-1,-1,-1,-1
1,8,100,0,10,10,-1,-1,-1,-1
1,9,200,0,10,10,-1,-1,-1,-1
1,10,300,0,10,10,-1,-1,-1,-1
2,7,0,0,10,10,-1,-1,-1,-1
"""


def _write(tmp_path: Path) -> tuple[Path, Path]:
    gt = tmp_path / "gt.txt"
    tracks = tmp_path / "tracks.txt"
    gt.write_text(GT)
    tracks.write_text(TRACKS)
    return gt, tracks


def test_mot17_rules(tmp_path: Path) -> None:
    gt, _ = _write(tmp_path)
    objects = {o.object_id: o for _, _, objs in read_mot_gt(gt).frames for o in objs}
    assert not objects[1].ignore
    assert objects[2].ignore and objects[2].distractor
    assert objects[3].ignore and not objects[3].distractor
    assert objects[4].ignore and not objects[4].distractor
    # MOT15 rules (TrackEval): no classes, only the consider-0 rows (ids 3, 4) are dropped.
    mot15 = [o for _, _, objs in read_mot_gt(gt, Benchmark.MOT15).frames for o in objs]
    assert sorted({o.object_id for o in mot15 if o.ignore}) == [3, 4]
    assert not any(o.distractor for o in mot15 if o.ignore)


def test_score_writes_report_and_events(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    out = tmp_path / "out"
    result = runner.invoke(
        app, ["score", str(tracks), "--gt", str(gt), "--out", str(out), "--json"]
    )
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["evaluation"]["convention"] == "motchallenge"
    c = report["sequences"][0]["counts"]
    # 2 scored GT (id 1 twice), 2 matches; tracks 9 and 10 are FP; track 8 dropped.
    assert (c["num_gt"], c["num_matches"], c["fp"], c["fn"], c["ignored_tracks"]) == (2, 2, 2, 0, 1)
    assert report["sequences"][0]["metrics"]["hota"] is not None
    with (out / "tracks.events.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    kinds = sorted(
        (r["frame"], r["event"], r["track_id"]) for r in rows if r["event"] != "ignored_gt"
    )
    assert kinds == [
        ("1", "fp", "10"),
        ("1", "fp", "9"),
        ("1", "ignored_track", "8"),
        ("1", "match", "7"),
        ("2", "match", "7"),
    ]


def test_compare_refuses_different_conventions(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    for convention in ("motchallenge", "motmetrics"):
        result = runner.invoke(
            app,
            [
                "score",
                str(tracks),
                "--gt",
                str(gt),
                "--convention",
                convention,
                "--out",
                str(tmp_path / convention),
            ],
        )
        assert result.exit_code == 0, result.output
    result = runner.invoke(
        app, ["compare", str(tmp_path / "motchallenge"), str(tmp_path / "motmetrics")]
    )
    assert result.exit_code == 2
    assert "different conventions" in result.output


def test_bad_input_exit_codes(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    missing = runner.invoke(
        app, ["score", str(tmp_path / "nope.txt"), "--gt", str(gt), "--out", str(tmp_path / "a")]
    )
    assert missing.exit_code == 3
    no_gt = runner.invoke(
        app,
        ["score", str(tracks), "--gt", str(tmp_path / "nope.txt"), "--out", str(tmp_path / "b")],
    )
    assert no_gt.exit_code == 5
    bad = runner.invoke(
        app,
        [
            "score",
            str(tracks),
            "--gt",
            str(gt),
            "--convention",
            "devkit",
            "--out",
            str(tmp_path / "c"),
        ],
    )
    assert bad.exit_code == 4


def test_score_on_a_cluster_gives_the_same_report(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    reports = []
    for extra in ([], ["--cluster", "local:1"]):
        out = tmp_path / f"out{len(extra)}"
        args = ["score", str(tracks), "--gt", str(gt), "--out", str(out), "--json", *extra]
        result = runner.invoke(app, args)
        assert result.exit_code == 0, result.output
        reports.append(json.loads((out / "report.json").read_text())["sequences"])
    assert reports[0] == reports[1] and reports[0][0]["counts"]["num_matches"] == 2


def test_tables_give_fp_and_fn_counts_and_pt(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    out = tmp_path / "out"
    result = runner.invoke(app, ["score", str(tracks), "--gt", str(gt), "--out", str(out)])
    assert result.exit_code == 0, result.output
    # 2 scored instances: FP 2 (100 %), FN 0; person 1 tracked in both frames: MT 1, PT 0, ML 0.
    lines = result.output.splitlines()
    header = next(line for line in lines if line.lstrip().startswith("sequence"))
    assert re.search(r" FP +FN +ID Sw\. .* MT +PT +ML +Frag\. ", header), header
    row = next(line for line in lines if line.lstrip().startswith("tracks "))
    assert re.search(r" 100\.0% \(2\) +0\.0% \(0\) +0 .* 1 +0 +0 +0 +0 *$", row), row
    md = (out / "report.md").read_text()
    assert "| FP | FN |" in md and "| MT | PT | ML |" in md
    assert "| 100.0% (2) | 0.0% (0) |" in md
