"""The plug-in seam: a method defined only in tests/ runs through run, sweep, bench and reproduce.

``tests/plugins/toy_method.py`` registers a depth-only detector and a tracker that reads
frames; the CLI loads it through ``$RGBD_EVAL_PLUGINS``, in a subprocess, exactly as a
user's own method would load. Nothing in the package names it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rgbd_eval import plugins

HERE = Path(__file__).resolve().parent
PLUGINS = HERE / "plugins"


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {
        **os.environ,
        "RGBD_EVAL_PLUGINS": "toy_method",
        "PYTHONPATH": os.pathsep.join([str(PLUGINS), os.environ.get("PYTHONPATH", "")]),
        "RGBD_EVAL_CACHE": str(cwd / "cache"),
    }
    return subprocess.run(
        [sys.executable, "-m", "rgbd_eval", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )


@pytest.fixture(scope="module")
def toy_recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from rgbd_eval.sim import load_scenario, synthesize

    path = tmp_path_factory.mktemp("toy") / "toy_scene.mcap"
    synthesize(load_scenario(PLUGINS / "toy_scene.yaml"), path)
    return path


@pytest.mark.slow
def test_outside_method_runs_through_every_command(toy_recording: Path, tmp_path: Path) -> None:
    methods = _cli("methods", "--json", cwd=tmp_path)
    assert methods.returncode == 0, methods.stderr
    toy = next(m for m in json.loads(methods.stdout)["methods"] if m["method"] == "toy")
    assert toy["streams"] == [{"role": "depth", "required": True, "multiple": False}]
    assert toy["tracker_reads_frames"] and toy["gating"] == "metric"

    run = _cli("run", str(toy_recording), "--method", "toy", "--out", "out", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["config"]["detector"]["name"] == "toy"
    seq = report["sequences"][0]
    assert seq["metrics"] is not None and seq["counts"]["num_gt"] > 0
    # two people, clean synthetic depth: the toy finds and follows both most of the time
    assert seq["metrics"]["mota"] > 0.5
    # report.html has no colour image to draw the worst frames on, and says so
    assert "the method reads no colour stream" in (tmp_path / "out" / "report.html").read_text()

    sweep = _cli(
        "sweep", "tracker.gate_m", "0.25", "1.0", "--method", "toy",
        "--dataset", str(toy_recording), "--cluster", "local:1", "--out", "sw", cwd=tmp_path,
    )  # fmt: skip
    assert sweep.returncode == 0, sweep.stderr
    rows = json.loads((tmp_path / "sw" / "sweep.json").read_text())["records"]
    assert [r["tracker.gate_m"] for r in rows] == [0.25, 1.0]

    bench = _cli("bench", str(toy_recording), "--method", "toy", "--repeat", "1", "--json",
                 "--all-cores", cwd=tmp_path)  # fmt: skip
    assert bench.returncode == 0, bench.stderr
    stages = list(json.loads(bench.stdout)["stage_ms"])
    assert stages[:4] == ["index", "decode", "segment", "blobs"], stages

    rep = _cli("reproduce", "toy", "--data", str(toy_recording.parent), "--cluster", "local:1",
               "--out", "rep", cwd=tmp_path)  # fmt: skip
    assert rep.returncode == 0, rep.stderr
    data = json.loads((tmp_path / "rep" / "reproduce.json").read_text())
    assert data["method"] == "toy" and set(data["mota"]) == {"0.25", "1.0"}
    # The CPU time of the whole command, split (the toy experiments render nothing).
    cpu = data["cpu_total_s"]
    assert set(cpu) == {"generate", "experiments", "rendered_in_experiments"}
    assert cpu["experiments"] > 0.0 and cpu["rendered_in_experiments"] == 0.0
    assert "CPU time: " in (tmp_path / "rep" / "reproduce.md").read_text()
    assert "CPU time: " in (tmp_path / "rep" / "reproduce.html").read_text()
    listing = _cli("reproduce", cwd=tmp_path)
    assert "toy: the toy experiment" in listing.stdout and "basso2012" in listing.stdout


def test_unknown_method_exits_4_naming_the_known_ones(tmp_path: Path) -> None:
    res = _cli("run", "--method", "nonesuch", cwd=tmp_path)
    assert res.returncode == 4
    # one line naming every registered method, sorted (the package's and the toy)
    known = ", ".join(sorted({*plugins.known("methods"), "toy"}))
    assert res.stderr.strip().splitlines() == [f"error: unknown method 'nonesuch' (known: {known})"]
    assert not (tmp_path / "runs").exists()


def test_discovery_loads_no_simulator() -> None:
    """Every CLI call and Dask worker runs plug-in discovery; it must not pull in the renderer.

    A method's experiments (reproduce only) are named by its package, not imported; importing
    ``rgbd_eval.sim`` there cost every call ~1.3 CPU s of open3d before it moved.
    """
    code = (
        "import sys\n"
        "from rgbd_eval import plugins\n"
        "plugins.load_plugins()\n"
        "assert len(plugins.known('methods')) >= 5, plugins.known('methods')\n"
        "print(sorted(m for m in ('open3d', 'rgbd_eval.sim', 'scipy.stats') if m in sys.modules))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.strip() == "[]", out.stdout + out.stderr
