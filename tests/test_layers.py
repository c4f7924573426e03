"""The package's import graph: no circle, and every import runs down the layer order below.

Imports at module level and inside functions count; those under ``if TYPE_CHECKING:`` do
not (they never run). ``tools/import_graph.py`` prints the graph, the layers and what breaks
them. A new module must be placed in ``LAYERS`` (the most specific pattern that matches a
module places it; the order is the layer order, lowest first).
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

from tests.tools import load_tool

ROOT = Path(__file__).resolve().parents[1]

#: Lowest first: a module may import modules of its own layer and of the layers before it.
LAYERS = [
    (
        "base: records, errors, exact maths, files",
        [
            "rgbd_eval",
            "rgbd_eval.types",
            "rgbd_eval.errors",
            "rgbd_eval.exact",
            "rgbd_eval.exact_kernels",
            "rgbd_eval.verdicts",
            "rgbd_eval.tuning",
            "rgbd_eval.machine",
            "rgbd_eval.files",
            "rgbd_eval.atomic",
            "rgbd_eval.outdir",
            "rgbd_eval.data",
            "rgbd_eval.data.*",
        ],
    ),
    ("registry of names and specs", ["rgbd_eval.plugins"]),
    (
        "config",
        ["rgbd_eval.config", "rgbd_eval.components", "rgbd_eval.datasets"],
    ),
    ("io", ["rgbd_eval.io", "rgbd_eval.io.*"]),
    ("metrics", ["rgbd_eval.metrics", "rgbd_eval.metrics.*"]),
    ("sim: scenario model", ["rgbd_eval.sim.scenario", "rgbd_eval.sim.rig_config"]),
    (
        "sim: motion and bodies",
        [
            "rgbd_eval.sim.motion",
            "rgbd_eval.sim.variation",
            "rgbd_eval.sim.odometry",
            "rgbd_eval.sim.meshes",
            "rgbd_eval.sim.body",
            "rgbd_eval.sim.people",
        ],
    ),
    ("sim: world", ["rgbd_eval.sim.world", "rgbd_eval.sim.raster", "rgbd_eval.sim.render"]),
    (
        "sim: sensors",
        [
            "rgbd_eval.sim.rig",
            "rgbd_eval.sim.sensor",
            "rgbd_eval.sim.annotate",
            "rgbd_eval.sim.stereo_rig",
            "rgbd_eval.sim.thermal_camera",
            "rgbd_eval.sim.rig_sensors",
        ],
    ),
    ("sim: simulator", ["rgbd_eval.sim.simulate", "rgbd_eval.sim.tof"]),
    (
        "sim: writers",
        [
            "rgbd_eval.sim",
            "rgbd_eval.sim.synth",
            "rgbd_eval.sim.preview",
            "rgbd_eval.sim.occlusion_pairs",
        ],
    ),
    (
        "building blocks",
        ["rgbd_eval.detect", "rgbd_eval.detect.*", "rgbd_eval.track", "rgbd_eval.track.*"],
    ),
    ("methods", ["rgbd_eval.methods", "rgbd_eval.methods.*"]),
    (
        "run: pipeline, caches, sweeps, engine",
        [
            "rgbd_eval.pipeline",
            "rgbd_eval.chunked",
            "rgbd_eval.cache",
            "rgbd_eval.engine",
            "rgbd_eval.sweep",
            "rgbd_eval.recordings",
            "rgbd_eval.bench",
            "rgbd_eval.annotate",
        ],
    ),
    ("experiments of reproduce", ["rgbd_eval.methods.*.experiments"]),
    (
        "report",
        ["rgbd_eval.report", "rgbd_eval.report.*", "rgbd_eval.compare", "rgbd_eval.significance"],
    ),
    ("cli", ["rgbd_eval.cli", "rgbd_eval.cli.*", "rgbd_eval.__main__"]),
]


def _tool() -> ModuleType:
    return load_tool("tools/import_graph.py", "import_graph")


TOOL = _tool()
GRAPH = TOOL.build_graph(ROOT / "src")


def test_no_import_circles() -> None:
    assert TOOL.circles(GRAPH.successors()) == []


def test_every_module_has_a_layer() -> None:
    unplaced = [m for m in GRAPH.modules if TOOL.layer_of(m, LAYERS) is None]
    assert unplaced == [], "add these to LAYERS in tests/test_layers.py"


def test_imports_run_down_the_layers() -> None:
    up = [f"{e.source} -> {e.target} (line {e.line})" for e in TOOL.up_edges(GRAPH, LAYERS)]
    assert up == []


def test_the_tool_sees_circles_and_up_edges(tmp_path: Path) -> None:
    pkg = tmp_path / "rgbd_eval"
    (pkg / "low").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "low" / "__init__.py").write_text("")
    (pkg / "low" / "a.py").write_text("def f():\n    from rgbd_eval.high import g\n")
    (pkg / "low" / "b.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from rgbd_eval.high import g\n"
    )
    (pkg / "high.py").write_text("from rgbd_eval.low import a\nfrom rgbd_eval.low.b import x\n")
    graph = TOOL.build_graph(tmp_path)
    layers = [("low", ["rgbd_eval", "rgbd_eval.low*"]), ("high", ["rgbd_eval.high"])]
    # a -> high inside a function counts, and high -> a closes a circle; b's import does not run
    assert TOOL.circles(graph.successors()) == [["rgbd_eval.high", "rgbd_eval.low.a"]]
    up = TOOL.up_edges(graph, layers)
    assert [(e.source, e.target, e.lazy) for e in up] == [
        ("rgbd_eval.low.a", "rgbd_eval.high", True)
    ]
