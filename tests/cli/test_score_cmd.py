"""``rgbd-eval score`` on small MOTChallenge files written in the test."""

from __future__ import annotations

import csv
import io
import json
import re
from pathlib import Path
from typing import Any

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


def test_gating_option_replaces_the_config_files_threshold(tmp_path: Path) -> None:
    """Issue 28: a config's metric 1.0 m kept under ``--gating iou`` (nothing can match)."""
    gt, tracks = _write(tmp_path)
    config = tmp_path / "metric.yaml"
    config.write_text("evaluation:\n  gating: metric\n  threshold: 1.0\n")
    out = tmp_path / "out"
    args = ["score", str(tracks), "--gt", str(gt), "--config", str(config), "--gating", "iou"]
    result = runner.invoke(app, [*args, "--out", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["evaluation"]["threshold"] == 0.5
    # Boxes equal to the ground truth's (IoU 1.0) match at 0.5.
    assert report["sequences"][0]["counts"]["num_matches"] == 2


def test_threshold_outside_its_gating_range_is_a_usage_error(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    base = ["score", str(tracks), "--gt", str(gt), "--out", str(tmp_path / "o")]
    for options in (["--threshold", "2"], ["--gating", "metric", "--threshold", "nan"]):
        result = runner.invoke(app, [*base, *options])
        assert result.exit_code == 2, result.output
        assert "Invalid value for '--threshold'" in result.output
    result = runner.invoke(app, [*base, "--gating", "iou", "--threshold", "1"])
    assert result.exit_code == 0, result.output


# Issue 28: MOTChallenge text counts frames from 1, our CSV sidecar from 0 (the recording's
# frame index). Five recording frames, 0..4. Person 1 walks right 20 px a frame with a
# 10 px wide box, so a box one frame off overlaps nothing (IoU 0).
SIDECAR = "frame,stamp_ns,id,bb_left,bb_top,bb_width,bb_height,x,y,z,visibility,ignore\n" + "".join(
    f"{k},0,1,{20 * k},0,10,10,,,,1,0\n" for k in range(5)
)
# The tracker, in MOTChallenge frames 1..5 (recording frames 0..4): track 7 follows person 1
# exactly in MOT frames 1-4 and loses it in 5; track 9 is a false alarm in MOT frame 5.
MOT_FROM_1 = "".join(f"{f},7,{20 * (f - 1)},0,10,10,1,-1,-1,-1\n" for f in range(1, 5)) + (
    "5,9,500,0,10,10,1,-1,-1,-1\n"
)
# By hand, frames mapped (MOT f = recording f - 1): 5 frames, 5 ground-truth instances,
# 4 matches (frames 0-3), FN 1 (frame 4, track lost), FP 1 (track 9).
# Off by one (MOT f taken as recording f), as before the fix: frames 0..5, 6 of them;
# frame 0 has no track (FN); in 1-4 track 7 is 20 px behind the person (FN + FP each);
# track 9 is a FP in a frame 5 the recording does not have; so FN 5, FP 5, no match.


def _scored(tracks: Path, gt: Path, out: Path) -> dict[str, Any]:
    """``score TRACKS --gt GT``: the report's one sequence."""
    result = runner.invoke(app, ["score", str(tracks), "--gt", str(gt), "--out", str(out)])
    assert result.exit_code == 0, result.output
    sequence: dict[str, Any] = json.loads((out / "report.json").read_text())["sequences"][0]
    return sequence


def test_mot_tracks_against_the_sidecar_map_frame_bases(tmp_path: Path) -> None:
    gt, tracks = tmp_path / "rec.gt.csv", tmp_path / "tracks.txt"
    gt.write_text(SIDECAR)
    tracks.write_text(MOT_FROM_1)
    out = tmp_path / "out"
    seq = _scored(tracks, gt, out)
    c = seq["counts"]
    assert seq["frames"] == 5
    assert (c["num_gt"], c["num_matches"], c["fn"], c["fp"], c["id_switches"]) == (5, 4, 1, 1, 0)
    # events.csv numbers frames as the ground truth does (the sidecar: from 0).
    with (out / "tracks.events.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert sorted({int(r["frame"]) for r in rows}) == [0, 1, 2, 3, 4]
    assert [(r["frame"], r["event"]) for r in rows if r["event"] != "match"] == [
        ("4", "miss"),
        ("4", "fp"),
    ]


def test_our_tracks_csv_against_mot_ground_truth_map_frame_bases(tmp_path: Path) -> None:
    """The other way round: a run's tracks.csv (from 0) scored against MOT gt.txt (from 1)."""
    gt, tracks = tmp_path / "gt.txt", tmp_path / "seq.tracks.csv"
    # gt.txt: person 1 in MOT frames 1..3 at x = 20 (f - 1), MOT17 columns.
    gt.write_text("".join(f"{f},1,{20 * (f - 1)},0,10,10,1,1,1.0\n" for f in (1, 2, 3)))
    header = "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z\n"
    # tracks.csv: recording frames 0..2, exactly on the person: 3 matches, nothing else.
    tracks.write_text(header + "".join(f"{k},4,{20 * k},0,10,10,-1,1,1,1\n" for k in (0, 1, 2)))
    seq = _scored(tracks, gt, tmp_path / "out")
    c = seq["counts"]
    assert seq["frames"] == 3
    assert (c["num_gt"], c["num_matches"], c["fn"], c["fp"]) == (3, 3, 0, 0)


def test_mot_text_with_a_frame_0_is_refused(tmp_path: Path) -> None:
    gt, tracks = _write(tmp_path)
    zero = tmp_path / "zero.txt"
    zero.write_text("0,7,0,0,10,10,-1,-1,-1,-1\n" + TRACKS)
    result = runner.invoke(app, ["score", str(zero), "--gt", str(gt), "--out", str(tmp_path / "a")])
    assert result.exit_code == 3, result.output
    assert "frames count from 1" in result.output
    zero_gt = tmp_path / "zero_gt.txt"
    zero_gt.write_text("0,1,0,0,10,10,1,1,1.0\n" + GT)
    result = runner.invoke(
        app, ["score", str(tracks), "--gt", str(zero_gt), "--out", str(tmp_path / "b")]
    )
    assert result.exit_code == 5, result.output
    assert "frames count from 1" in result.output


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


def test_score_reports_breakdowns_intervals_and_where_it_fails(tmp_path: Path) -> None:
    # MOT17 ground truth (frame,id,box,consider,class,visibility): person 1 20 % visible,
    # person 2 90 %, 30 frames. Tracks (frame,id,box,conf,...): 2 on person 2 in every frame
    # (conf 0.9), 1 on person 1 in the even frames (conf 0.4), 3 nowhere in frames 1-10 (0.1).
    gt_rows, track_rows = [], []
    for f in range(1, 31):
        gt_rows += [f"{f},1,0,0,20,40,1,1,0.2", f"{f},2,100,0,20,40,1,1,0.9"]
        track_rows.append(f"{f},2,100,0,20,40,0.9,-1,-1,-1")
        if f % 2 == 0:
            track_rows.append(f"{f},1,0,0,20,40,0.4,-1,-1,-1")
        if f <= 10:
            track_rows.append(f"{f},3,300,0,20,40,0.1,-1,-1,-1")
    gt = tmp_path / "gt.txt"
    gt.write_text("\n".join(gt_rows) + "\n")
    tracks = tmp_path / "seq.txt"
    tracks.write_text("\n".join(track_rows) + "\n")
    out = tmp_path / "out"
    args = ["score", str(tracks), "--gt", str(gt), "--out", str(out), "--curve"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    seq = report["sequences"][0]
    lo, hi = seq["intervals"]["mota"]
    assert lo <= seq["metrics"]["mota"] <= hi and seq["block_length"] >= 1
    assert report["overall"]["intervals"]["mota"] == seq["intervals"]["mota"]
    breakdowns = seq["breakdowns"]
    # Text files carry no camera: distance and motion are not available, and say why.
    assert not breakdowns["distance"]["available"] and not breakdowns["motion"]["available"]
    assert "no camera pose" in breakdowns["distance"]["reason"]
    visibility = {b["band"]: b for b in breakdowns["visibility"]["bands"]}
    # Person 1 (20 %): 30 instances, missed in the 15 odd frames: MOTA (FP-free) 50 %.
    low = visibility["0-25 %"]
    assert (low["counts"]["num_gt"], low["counts"]["fn"], low["counts"]["fp"]) == (30, 15, None)
    assert low["metrics"]["mota"] == 0.5 and not breakdowns["visibility"]["mota_includes_fp"]
    assert visibility["75-100 %"]["metrics"]["mota"] == 1.0
    # Where it fails: the 20 % band, 15 misses in 30 frames.
    (worst,) = report["analysis"]["where_it_fails"]
    assert (worst["breakdown"], worst["band"], worst["errors_per_frame"]) == (
        "visibility",
        "0-25 %",
        0.5,
    )
    persons = {p["gt_id"]: p for p in seq["persons"]}
    assert persons[1]["coverage"] == 0.5 and persons[1]["track_ids"] == [1]
    # Person 1's 14 gaps of one frame all end on track 1 again: recovered.
    assert seq["gaps"][0] == {"frames": "1", "gaps": 14, "recovered": 14, "rate": 1.0}
    # The curve at the three confidences present: 0.1 keeps everything, 0.4 drops the FPs,
    # 0.9 also person 1's track.
    curve = report["analysis"]["curve"]
    assert [p["threshold"] for p in curve["points"]] == [0.1, 0.4, 0.9]
    assert [p["metrics"]["fp"] for p in curve["points"]] == [10, 0, 0]
    assert curve["best"]["mota"] == 0.4
    named = seq["frames_file"]["name"]
    assert named == "seq.frames.npz" and (out / named).is_file()
    md = (out / "report.md").read_text()
    for section in ("## Where it fails", "## Intervals", "### Visibility", "## Per person"):
        assert section in md
    assert "## Confidence threshold curve" in md
    html = (out / "report.html").read_text()
    assert html.index("Where it fails") < html.index("<h2>Metrics</h2>")


def test_events_csv_is_what_the_csv_module_writes() -> None:
    # events_csv joins its lines itself: they must stay the csv module's, byte for byte.
    from rgbd_eval.metrics import FrameEvents, Match
    from rgbd_eval.report.run import EVENTS_HEADER, events_csv

    frames = [
        FrameEvents(
            0,
            (Match(1, 7, 0.5, False, False), Match(-2, 8, 1 / 3, True, True)),
            (3,),
            (9,),
            (4, 5),
            (6,),
        ),
        FrameEvents(1, (), (), (), (), ()),
        FrameEvents(2, (Match(2**52, 7, 1.0, True, False),), (), (10, 11), (), ()),
    ]
    rows: list[list[object]] = []
    for e, stamp, number in zip(frames, (0, 10**18, 5), (1, 2, 3), strict=True):
        for m in e.matches:
            kind = "switch" if m.id_switch else "match"
            sim = f"{m.similarity:.6f}"
            rows.append([number, stamp, kind, m.gt_id, m.track_id, sim, int(m.recall_error)])
        rows += [[number, stamp, "miss", g, "", "", ""] for g in e.misses]
        rows += [[number, stamp, "fp", "", t, "", ""] for t in e.false_positives]
        rows += [[number, stamp, "ignored_gt", g, "", "", ""] for g in e.ignored_gt]
        rows += [[number, stamp, "ignored_track", "", t, "", ""] for t in e.ignored_tracks]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(EVENTS_HEADER)
    writer.writerows(rows)
    assert events_csv(frames, (0, 10**18, 5), (1, 2, 3)) == buf.getvalue()
    assert events_csv([], (), ()) == ",".join(EVENTS_HEADER) + "\n"
