"""`rgbd-eval synth` from the command line: container choice, overrides, errors."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.io.recording import open_recording

runner = CliRunner()


def test_out_suffix_chooses_the_container_and_set_changes_the_scenario(tmp_path: Path) -> None:
    out = tmp_path / "raw.bag"
    args = ["synth", "demo", "-o", str(out), "--frames", "2", "--set", "recording.rgb_format=raw"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    rec = open_recording(out)
    assert rec.info.container == "ros1"
    assert rec.info.selected.rgb == "/camera/rgb/image_color"  # raw, not .../compressed
    assert len(rec) == 2 and (tmp_path / "raw.gt.csv").exists()


def test_bad_overrides_and_contradictions_exit_4(tmp_path: Path) -> None:
    unknown = runner.invoke(
        app, ["synth", "demo", "-o", str(tmp_path / "a.mcap"), "--set", "x.y=1"]
    )
    assert unknown.exit_code == 4 and "unknown key 'x'" in unknown.output
    clash = runner.invoke(app, ["synth", "demo", "-o", str(tmp_path / "a.mcap"), "--format", "bag"])
    assert clash.exit_code == 4 and "needs a .bag name" in clash.output
    assert not (tmp_path / "a.mcap").exists()


def test_rig_stereo_re_renders_a_scenario_through_the_pair(tmp_path: Path) -> None:
    from rgbd_eval.plugins import StreamSpec

    out = tmp_path / "moving_simple_stereo.mcap"
    args = ["synth", "moving_simple", "--rig", "stereo", "-o", str(out), "--frames", "1"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    rec = open_recording(out, streams=(StreamSpec("left"), StreamSpec("right")))
    frame = next(iter(rec.frames()))
    assert frame.stream("left").image.shape == (384, 512, 3)  # the seed's processed size
    assert frame.stream("right").camera.tx < 0  # the baseline in the right CameraInfo


def test_follow_needs_one_scenario_with_a_stereo_pair(tmp_path: Path) -> None:
    out = tmp_path / "f.mcap"
    no_pair = runner.invoke(app, ["synth", "demo", "--follow", "1", "-o", str(out)])
    assert no_pair.exit_code == 4 and "no stereo_pair" in no_pair.output
    every = runner.invoke(app, ["synth", "--all", "--follow", "1"])
    assert every.exit_code == 4 and "not --all" in every.output
    rig = runner.invoke(app, ["synth", "demo", "--rig", "thermal", "-o", str(out)])
    assert rig.exit_code == 4 and "expected stereo" in rig.output
    assert not out.exists()


@pytest.mark.slow
def test_follow_writes_the_recording_and_the_following_record(tmp_path: Path) -> None:
    import json

    out = tmp_path / "following.mcap"
    args = ["synth", "satake2009_following", "--follow", "1", "-o", str(out), "--frames", "3"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "followed person 1" in result.output
    assert len(open_recording(out)) == 3 and (tmp_path / "following.gt.csv").exists()
    rows = (tmp_path / "following.follow.csv").read_text().splitlines()
    assert rows[0].startswith("frame,stamp_ns,t,robot_x") and len(rows) == 4
    summary = json.loads((tmp_path / "following.follow.json").read_text())
    assert summary["target"] == 1 and summary["frames"] == 3
