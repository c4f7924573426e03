"""ensure_recordings: what is missing is rendered once, on the cluster when there is one."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest

import rgbd_eval.sim.synth as synth
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.engine import connect, parse_cluster
from rgbd_eval.recordings import ensure_recordings


def _fake_render(
    log: Path, pid_offset: int, seconds: float
) -> Callable[[Path, Path | None, int | None], tuple[int, float]]:
    """A renderer that writes the recording and a line to ``log`` (it may run in a worker
    process: what it did is read from the disk)."""

    def render(scenario: Path, folder: Path | None, seed: int | None) -> tuple[int, float]:
        assert folder is not None
        target = synth.recording_path(scenario, folder, seed)
        target.write_bytes(b"x")
        with log.open("a") as f:
            f.write(f"{target.name} {seed}\n")
        return os.getpid() + pid_offset, seconds

    return render


def _calls(log: Path) -> list[str]:
    return log.read_text().splitlines() if log.exists() else []


def test_missing_recordings_rendered_once_and_counted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(synth, "is_current", lambda p, *_a: p.exists())
    scenario = scenarios_dir() / "static_simple.yaml"
    (tmp_path / "static_simple-seed3.mcap").write_bytes(b"present")
    log = tmp_path / "renders.log"
    said: list[str] = []
    rendering = synth.rendering_cpu_s()
    # seed 2 twice (one render), seed 3 present (none): one render, by "another process"
    jobs = [(scenario, tmp_path, 2), (scenario, tmp_path, 3), (scenario, tmp_path, 2)]
    with connect(parse_cluster("local:1")) as client:
        paths = ensure_recordings(jobs, client, said.append, _fake_render(log, 1, 1.5))
    assert paths == [
        tmp_path / "static_simple-seed2.mcap",
        tmp_path / "static_simple-seed3.mcap",
        tmp_path / "static_simple-seed2.mcap",
    ]
    assert _calls(log) == ["static_simple-seed2.mcap 2"]
    # another process's CPU is counted here; this process's own rendering counted itself
    assert synth.rendering_cpu_s() - rendering == 1.5
    assert said[0] == "generating 1 recording(s) on the cluster's workers ..."
    assert said[1].endswith("static_simple-seed2.mcap (1 of 1)")
    # all present: nothing rendered, nothing said
    said.clear()
    assert ensure_recordings(jobs, None, said.append, _fake_render(log, 0, 9.0)) == paths
    assert len(_calls(log)) == 1 and said == []


def test_without_a_cluster_one_by_one_in_this_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(synth, "is_current", lambda p, *_a: p.exists())
    scenario = scenarios_dir() / "static_simple.yaml"
    log = tmp_path / "renders.log"
    rendering = synth.rendering_cpu_s()
    jobs = [(scenario, tmp_path, 4), (scenario, tmp_path, 5)]
    ensure_recordings(jobs, None, None, _fake_render(log, 0, 7.0))
    assert _calls(log) == ["static_simple-seed4.mcap 4", "static_simple-seed5.mcap 5"]
    # rendered in this process: ensure_scenario counts it there, not again here
    assert synth.rendering_cpu_s() == rendering
