"""`run --rerun` and `view`: the .rrd read back with the Rerun SDK's own reader."""

from __future__ import annotations

import csv
import json
import shutil
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.report.rerun import MAX_CLOUD_POINTS
from rgbd_eval.sim import load_scenario, synthesize

pytest.importorskip("rerun")  # the `rerun` extra, installed with `dev`

#: Frames of the demo: people are detected, tracked and missed in them.
FRAMES = 20
runner = CliRunner()


def _cli(*args: str, code: int = 0) -> str:
    result = runner.invoke(app, list(args))
    assert result.exit_code == code, result.output
    return result.output


def rrd_rows(path: Path) -> dict[str, list[dict[str, Any]]]:
    """Every row of every entity of a .rrd, as the SDK's reader gives them back."""
    from rerun.chunk import RrdReader

    out: dict[str, list[dict[str, Any]]] = {}
    for chunk in RrdReader(path).stream():
        out.setdefault(chunk.entity_path, []).extend(chunk.to_record_batch().to_pylist())
    for rows in out.values():
        rows.sort(key=lambda r: r.get("frame", -1))
    return out


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("rerun_rec") / "demo.mcap"
    return synthesize(
        load_scenario(scenarios_dir() / "demo.yaml"), out, max_frames=FRAMES
    ).recording


@pytest.fixture(scope="module")
def run_dir(recording: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("rerun_run") / "run"
    output = _cli("run", str(recording), "--out", str(out), "--rerun", str(out / "run.rrd"))
    assert f"rerun {out / 'run.rrd'}" in output
    return out


def _tracks(run_dir: Path) -> list[dict[str, str]]:
    with (run_dir / "demo.tracks.csv").open() as handle:
        return [r for r in csv.DictReader(handle) if r["status"] == "validated"]


def test_run_rerun_holds_the_run(run_dir: Path) -> None:
    rows = rrd_rows(run_dir / "run.rrd")
    for entity in (
        "/world",
        "/world/robot/path",
        "/world/colour",
        "/world/colour/image",
        "/world/colour/image/rgb",
        "/world/colour/image/detections",
        "/world/colour/image/tracks",
        "/world/colour/image/ground_truth",
        "/world/depth",
        "/world/depth/image/depth",
        "/world/cloud",
        "/world/detections",
        "/world/tracks",
        "/world/tracks/trails",
        "/world/ground_truth",
        "/world/ground_truth/trails",
        "/errors/fp",
        "/errors/fn",
        "/errors/id_switches",
        "/events",
    ):
        assert entity in rows, entity
    for entity in ("/world/colour/image/rgb", "/world/depth/image/depth", "/world/cloud"):
        assert [r["frame"] for r in rows[entity]] == list(range(FRAMES)), entity
    assert all(len(r["Points3D:positions"]) <= MAX_CLOUD_POINTS for r in rows["/world/cloud"])
    # Track boxes and positions per frame, as tracks.csv has them.
    tracks = _tracks(run_dir)
    boxes = rows["/world/colour/image/tracks"]
    logged = sorted((r["frame"], label.split()[1]) for r in boxes for label in r["Boxes2D:labels"])
    assert logged == sorted((int(t["frame"]), t["id"]) for t in tracks if t["bb_left"])
    assert logged  # the demo's people are tracked
    frame, track_id = logged[-1]
    row = next(t for t in tracks if int(t["frame"]) == frame and t["id"] == track_id)
    points = rows["/world/tracks"][frame]
    i = points["Points3D:labels"].index(f"id {track_id}")
    assert np.allclose(
        points["Points3D:positions"][i][:2], [float(row["x"]), float(row["y"])], atol=1e-4
    )
    # Errors on the timeline: per frame counts summing to the report's, a text where any.
    counts = json.loads((run_dir / "report.json").read_text())["sequences"][0]["counts"]
    for entity, key in (("fp", "fp"), ("fn", "fn"), ("id_switches", "id_switches")):
        values = [r["Scalars:scalars"][0] for r in rows[f"/errors/{entity}"] if "frame" in r]
        assert len(values) == FRAMES and sum(values) == counts[key]
    with (run_dir / "demo.events.csv").open() as handle:
        erring = {
            int(e["frame"])
            for e in csv.DictReader(handle)
            if e["event"] in ("fp", "miss", "switch")
        }
    assert {r["frame"] for r in rows["/events"]} == erring
    assert len(rows["/world/robot/path"][0]["LineStrips3D:strips"][0]) == FRAMES


def test_view_writes_the_same_without_running(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "view.rrd"
    _cli("view", str(run_dir), "-o", str(out))
    ran, viewed = rrd_rows(run_dir / "run.rrd"), rrd_rows(out)
    assert set(ran) == set(viewed)
    for entity in ("/world/colour/image/tracks", "/world/colour/image/ground_truth", "/events"):
        columns = [c for c in ran[entity][0] if c.endswith(("labels", "text"))]
        for a, b in zip(ran[entity], viewed[entity], strict=True):
            assert [a[c] for c in columns] == [b[c] for c in columns], entity
    for entity in ("/world/cloud", "/world/colour"):  # from the recording: the same values
        for a, b in zip(ran[entity], viewed[entity], strict=True):
            assert {k: v for k, v in a.items() if k != "rerun.controls.RowId"} == {
                k: v for k, v in b.items() if k != "rerun.controls.RowId"
            }
    # Default output: <name>.rrd in the run folder.
    _cli("view", str(run_dir))
    assert (run_dir / "demo.rrd").is_file()


def test_view_refuses_a_moved_or_changed_recording(
    recording: Path, run_dir: Path, tmp_path: Path
) -> None:
    copy = tmp_path / "copy.mcap"
    shutil.copy(recording, copy)
    folder = tmp_path / "run"
    shutil.copytree(run_dir, folder)
    report = json.loads((folder / "report.json").read_text())
    report["sequences"][0]["path"] = str(copy)
    (folder / "report.json").write_text(json.dumps(report))
    with copy.open("ab") as handle:
        handle.write(b"\0")
    output = _cli("view", str(folder), "-o", str(tmp_path / "a.rrd"), code=3)
    assert output.startswith(f"error: {copy}: changed since the run")
    copy.unlink()
    output = _cli("view", str(folder), "-o", str(tmp_path / "a.rrd"), code=3)
    assert "is not there (moved?)" in output
    assert not (tmp_path / "a.rrd").exists()
    output = _cli("view", str(tmp_path), code=3)
    assert "holds no report.json" in output
    report["sequences"][0]["path"] = str(recording)
    report["sequences"][0]["ground_truth"]["source"] = str(tmp_path / "gone.gt.csv")
    (folder / "report.json").write_text(json.dumps(report))
    output = _cli("view", str(folder), "-o", str(tmp_path / "a.rrd"), code=5)
    assert output.startswith(
        f"error: {tmp_path / 'gone.gt.csv'}: the run's ground truth is not there"
    )


def test_without_the_sdk_the_options_say_how_to_get_it(
    recording: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun fails
    out = tmp_path / "out"
    output = _cli(
        "run", str(recording), "--out", str(out), "--rerun", str(tmp_path / "a.rrd"), code=2
    )
    assert output.strip() == (
        "error: the Rerun SDK (rerun-sdk) is not installed; pip install 'rgbd-eval[rerun]' adds it"
    )
    assert not out.exists()  # refused before any work
    assert "pip install 'rgbd-eval[rerun]'" in _cli("view", str(tmp_path), code=2)


def test_rerun_takes_one_recording(recording: Path, tmp_path: Path) -> None:
    other = tmp_path / "other.mcap"
    shutil.copy(recording, other)
    output = _cli("run", str(recording), str(other), "--rerun", str(tmp_path / "a.rrd"), code=2)
    assert "'--rerun'" in output and "takes one recording" in output
    output = _cli("run", str(recording), "--rerun", str(tmp_path / "a.json"), code=7)
    assert "name a .rrd file" in output
