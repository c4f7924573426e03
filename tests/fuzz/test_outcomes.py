"""Runs that must succeed with the right result, and interruptions that must leave nothing."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.writer import DEPTH_INFO_TOPIC
from tests.fuzz.cli import SRC, leftovers, run_cli
from tests.fuzz.corpus import (
    DAMAGED_DEPTH_TOPIC,
    FRAMES,
    damaged_ros1,
    flip_byte,
    good_recording,
    ground_truth_objects,
    half_data,
    odd_recording,
    short_step,
    without_statistics,
    zero_k,
)
from tests.io.conftest import depth_image


def test_bom_ground_truth_scores_as_without(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    plain = tmp_path / "plain.csv"
    write_csv(plain, ground_truth_objects())
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())  # as a spreadsheet program saves it
    reports = []
    for gt in (plain, bom):
        out = tmp_path / f"out_{gt.stem}"
        result = run_cli(["run", str(rec), "--gt", str(gt), "--out", str(out)], capsys)
        assert result.code == 0, result.stderr
        reports.append(json.loads((out / "report.json").read_text()))
    assert reports[0]["sequences"][0]["counts"] == reports[1]["sequences"][0]["counts"]
    assert reports[1]["sequences"][0]["counts"]["num_gt"] == FRAMES


def test_some_empty_depth_frames_are_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def depth(i: int) -> np.ndarray:
        d = depth_image(i)
        return np.full_like(d, np.nan) if i in (1, 2) else d

    rec = odd_recording(tmp_path / "gaps.bag", depth=depth)
    out = tmp_path / "out"
    result = run_cli(["run", str(rec), "--out", str(out)], capsys)
    assert result.code == 0, result.stderr
    warning = "2 of 4 depth frames hold no valid pixel"
    assert warning in result.stderr  # warnings go to stderr (issue 28)
    assert any(
        warning in w
        for w in json.loads((out / "report.json").read_text())["sequences"][0]["warnings"]
    )


def test_rerun_keeps_the_users_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = good_recording(tmp_path)
    out = tmp_path / "runs" / "ci"
    assert run_cli(["run", str(rec), "--out", str(out)], capsys).code == 0
    (out / "compare.md").write_text("written by compare --markdown")
    assert run_cli(["run", str(rec), "--out", str(out)], capsys).code == 0
    assert (out / "compare.md").read_text() == "written by compare --markdown"
    assert (out / "report.json").is_file() and leftovers(tmp_path) == []


def test_output_is_checked_before_the_recording_is_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    flip_byte(rec, 200)  # a corrupt recording would fail with 3 once read
    (tmp_path / "file.txt").write_text("x")
    result = run_cli(["run", str(rec), "--out", str(tmp_path / "file.txt")], capsys)
    assert result.code == 7, result.stderr  # the output problem comes first


def test_interrupted_sweep_leaves_no_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import rgbd_eval.sweep

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(rgbd_eval.sweep, "run_sweep", interrupted)
    rec = good_recording(tmp_path)
    out = tmp_path / "sweep"
    args = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec), "--out", str(out)]
    result = run_cli([*args, "--jobs", "1"], capsys)
    assert result.code == 130 and result.error_lines == ["error: interrupted"]
    assert not out.exists() and leftovers(tmp_path) == []


def test_sweep_writes_all_outputs_or_none(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    out = tmp_path / "sweep"
    args = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec), "--out", str(out)]
    result = run_cli([*args, "--jobs", "1"], capsys)
    assert result.code == 0, result.stderr
    assert {p.name for p in out.iterdir()} >= {"sweep.csv", "sweep.json", "sweep.png"}
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_inside_a_c_extension_is_an_interruption(
    signum: int,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A signal handled while numba's dispatcher runs Python code reaches us as a SystemError
    whose cause is our Interrupted (issue 28, sig_run_hup: a traceback and exit 1)."""
    import rgbd_eval.pipeline
    from rgbd_eval.cli.common import Interrupted

    def dispatcher(*args: object, **kwargs: object) -> None:
        try:
            raise Interrupted(signum)  # what the handler raises
        except Interrupted as err:
            raise SystemError("CPUDispatcher(<function _back_project>) returned a result") from err

    monkeypatch.setattr(rgbd_eval.pipeline, "run_sequence", dispatcher)
    out = tmp_path / "out"
    result = run_cli(["run", str(good_recording(tmp_path)), "--out", str(out)], capsys)
    assert result.code == 128 + signum, result.stderr
    assert result.error_lines == [f"error: interrupted by signal {signum}"]
    assert not out.exists() and leftovers(tmp_path) == []


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_during_run_cleans_up(signum: int, tmp_path: Path) -> None:
    rec = good_recording(tmp_path)
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(SRC))
    proc = subprocess.Popen(
        [sys.executable, "-m", "rgbd_eval", "run", str(rec), "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    # The staging folder appears before any recording is read; terminate then.
    for _ in range(600):
        if leftovers(tmp_path) or proc.poll() is not None:
            break
        time.sleep(0.05)
    proc.send_signal(signum)
    _, stderr = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the run finished before the signal arrived")
    assert proc.returncode == 128 + signum, stderr
    assert stderr.strip().splitlines() == [f"error: interrupted by signal {int(signum)}"]
    assert leftovers(tmp_path) == [] and not out.exists()


def test_mcap_without_statistics_is_read_not_called_empty(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = without_statistics(good_recording(tmp_path), tmp_path / "nostats.mcap")
    out = tmp_path / "out"
    result = run_cli(["run", str(rec), "--out", str(out)], capsys)
    assert result.code == 0, result.stderr  # was exit 3, "recording is empty (no messages)"
    report = json.loads((out / "report.json").read_text())
    assert report["sequences"][0]["frames"] == FRAMES and report["sequences"][0]["scored"]


DAMAGE: dict[str, tuple[dict[str, Any], str, str]] = {
    "truncated_payload": ({"image": half_data}, DAMAGED_DEPTH_TOPIC, "data holds 768 bytes"),
    "wrong_step": ({"image": short_step}, DAMAGED_DEPTH_TOPIC, "step 63 is less than"),
    "cut_message": ({"cut": 100}, DAMAGED_DEPTH_TOPIC, "sequence length"),
    "camera_info_k_zero": ({"info": zero_k}, DEPTH_INFO_TOPIC, "K is all zero"),
}


@pytest.mark.parametrize("damage", list(DAMAGE), ids=list(DAMAGE))
def test_a_damaged_ros1_message_is_skipped_counted_and_reported(
    damage: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    kwargs, topic, problem = DAMAGE[damage]
    # Frame 0's depth Image (or its CameraInfo, the first one, which the camera model
    # used to come from) is damaged; frames 1..3 are intact.
    rec = damaged_ros1(tmp_path / "damaged.bag", lambda i: i == 0, **kwargs)
    out = tmp_path / "out"
    result = run_cli(["run", str(rec), "--out", str(out)], capsys)
    assert result.code == 0, result.stderr
    warning = f"damaged messages skipped: {topic} 1 of {FRAMES} ("
    assert warning in result.stderr and problem in result.stderr
    seq = json.loads((out / "report.json").read_text())["sequences"][0]
    assert [(s["topic"], s["count"], s["total"]) for s in seq["skipped_messages"]] == [
        (topic, 1, FRAMES)
    ]
    assert any(warning in w for w in seq["warnings"])
    # A lost depth image loses its frame (its RGB partner is dropped, unpaired); a lost
    # CameraInfo loses nothing (the camera model comes from the next one).
    assert seq["frames"] == (FRAMES if topic == DEPTH_INFO_TOPIC else FRAMES - 1)
    assert seq["scored"]
    inspected = run_cli(["inspect", str(rec), "--json"], capsys)
    assert inspected.code == 0, inspected.stderr
    skipped = json.loads(inspected.stdout)["recording"]["skipped"]
    assert [(s["topic"], s["count"]) for s in skipped] == [(topic, 1)]


def test_score_force_writes_into_a_foreign_folder_and_keeps_its_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.fuzz.corpus import MOT_GT, MOT_TRACKS

    (tmp_path / "tracks.txt").write_text(MOT_TRACKS)
    (tmp_path / "gt.txt").write_text(MOT_GT)
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    args = ["score", str(tmp_path / "tracks.txt"), "--gt", str(tmp_path / "gt.txt")]
    assert run_cli([*args, "--out", str(out)], capsys).code == 7
    result = run_cli([*args, "--out", str(out), "--force"], capsys)
    assert result.code == 0, result.stderr
    assert (out / "notes.txt").read_text() == "mine\n"
    # 2 frames, one person, one track on it in both: MOTA 1.
    assert json.loads((out / "report.json").read_text())["sequences"][0]["metrics"]["mota"] == 1.0
    # A re-run replaces what score wrote and still keeps the user's file, without --force.
    assert run_cli([*args, "--out", str(out)], capsys).code == 0
    assert (out / "notes.txt").is_file() and leftovers(tmp_path) == []


def test_a_corrupt_npz_cache_entry_is_recomputed_with_one_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    cache = tmp_path / "cache"
    args = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec)]
    args += ["--cache", str(cache), "--cluster", "local:1"]
    first = run_cli([*args, "--out", str(tmp_path / "s1")], capsys)
    assert first.code == 0, first.stderr
    (entry,) = list(cache.rglob("*.det"))  # a header and sha256, then the .npz payload
    # The .npz lost its last third (its zip central directory), as a full disk leaves it.
    entry.write_bytes(entry.read_bytes()[: entry.stat().st_size * 2 // 3])
    second = run_cli([*args, "--out", str(tmp_path / "s2")], capsys)
    assert second.code == 0, second.stderr
    assert "Traceback" not in second.stderr
    warnings = [line for line in second.stderr.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and "recomputing" in warnings[0], second.stderr

    # The same numbers as from intact detections; the entry is intact again.
    def counts(folder: str) -> list[dict[str, object]]:  # the records without their timings
        data = json.loads((tmp_path / folder / "sweep.json").read_text())
        return [{k: v for k, v in r.items() if "second" not in k} for r in data["records"]]

    assert counts("s1") == counts("s2") and len(counts("s1")) == 2
    third = run_cli([*args, "--out", str(tmp_path / "s3")], capsys)
    assert third.code == 0 and "warning:" not in third.stderr


def _run_report(
    args: list[str], out: Path, capsys: pytest.CaptureFixture[str]
) -> tuple[str, dict[str, Any]]:
    """``rgbd-eval run ARGS --out OUT``: stdout and the one sequence of report.json."""
    result = run_cli([*args, "--out", str(out)], capsys)
    assert result.code == 0, result.stderr
    # warnings go to stderr (issue 28), one line each: "warning: <sequence>: ..."
    return result.stderr, json.loads((out / "report.json").read_text())["sequences"][0]


def test_frames_outside_the_annotated_span_are_not_scored(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ground truth of frames 0-1 of 4 is not ground truth saying frames 2-3 are empty."""
    rec = good_recording(tmp_path)
    first_two = tmp_path / "first2.csv"
    write_csv(first_two, ground_truth_objects()[:2])
    stderr, seq = _run_report(["run", str(rec), "--gt", str(first_two)], tmp_path / "a", capsys)
    warning = "2 of 4 frames lie outside the annotated span (frames 0..1) and are not scored"
    assert warning in " ".join(stderr.split())
    assert any(warning in w for w in seq["warnings"])
    assert seq["ground_truth"]["unscored_frames"] == 2
    assert seq["ground_truth"]["scored_span"] == [0, 1]
    assert seq["counts"]["num_gt"] == 2 and seq["counts"]["num_frames"] == 2
    # Frames 2-3 annotated as empty (rows without id) are scored: no warning, no unscored.
    annotated = tmp_path / "annotated.csv"
    frames = [(o.frame, o.stamp_ns) for o in ground_truth_objects()]
    write_csv(annotated, ground_truth_objects()[:2], frames)
    _, seq = _run_report(["run", str(rec), "--gt", str(annotated)], tmp_path / "b", capsys)
    assert seq["ground_truth"]["unscored_frames"] == 0 and seq["warnings"] == []
    assert seq["counts"]["num_frames"] == FRAMES


def test_annotated_frames_matching_no_frame_are_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A ground-truth stamp far in the future, or an hour's gap, leaves annotations unscored:
    said in a warning and counted in report.json."""
    from tests.fuzz.corpus import FAR_FUTURE_NS, gt_topic_recording
    from tests.io.conftest import PERIOD, T0

    rec = gt_topic_recording(
        tmp_path / "fut.mcap", stamp=lambda i: T0 + i * PERIOD + (FAR_FUTURE_NS if i == 1 else 0)
    )
    stderr, seq = _run_report(["run", str(rec)], tmp_path / "a", capsys)
    warning = "1 of 4 annotated frames of"
    assert warning in stderr and "match no frame of the recording" in " ".join(stderr.split())
    assert any(warning in w for w in seq["warnings"])
    assert seq["ground_truth"]["unmatched_frames"] == 1 and seq["counts"]["num_gt"] == 3

    objects = ground_truth_objects()
    gap = [
        dataclasses.replace(o, stamp_ns=o.stamp_ns + (3600 * 10**9 if o.frame >= 2 else 0))
        for o in objects
    ]
    gt = tmp_path / "gap.csv"
    write_csv(gt, gap)
    _, seq = _run_report(
        ["run", str(good_recording(tmp_path)), "--gt", str(gt)], tmp_path / "b", capsys
    )
    assert seq["ground_truth"]["unmatched_frames"] == 2
    assert seq["ground_truth"]["unscored_frames"] == 2 and len(seq["warnings"]) == 2


def test_some_implausible_depth_frames_are_dropped_and_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def swapped(fields: dict[str, Any]) -> dict[str, Any]:
        return {**fields, "is_bigendian": 1}  # the bytes stay little-endian

    rec = damaged_ros1(tmp_path / "half.bag", lambda i: i in (1, 2), image=swapped)
    stderr, seq = _run_report(["run", str(rec)], tmp_path / "out", capsys)
    warning = "2 of 4 depth frames hold implausible depth, dropped"
    assert warning in " ".join(stderr.split())
    assert any(warning in w and "frames 1, 2" in w for w in seq["warnings"])
    assert seq["scored"]


def test_ground_truth_topic_frames_without_people_are_annotated(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A GroundTruthArray with nobody in it annotates its frame: the span is not cut."""
    from tests.fuzz.corpus import gt_topic_recording

    objects = ground_truth_objects()
    rec = gt_topic_recording(tmp_path / "gt.mcap", lambda i: [objects[i]] if i == 1 else [])
    _, seq = _run_report(["run", str(rec)], tmp_path / "out", capsys)
    assert seq["ground_truth"]["unscored_frames"] == 0 and seq["warnings"] == []
    assert seq["counts"]["num_frames"] == FRAMES and seq["counts"]["num_gt"] == 1
