"""Synthetic RGB-D recordings with exact ground truth (see DESIGN.md, "Synthetic recordings").

A one-way stack, each module importing only those of the layers before it:

1. scenario model: ``scenario`` (rooms, people, robot, sensor), ``rig_config`` (the rig's
   extra sensors as config);
2. motion and bodies: ``motion``, ``odometry``, ``meshes``, ``body``;
3. world: ``world`` (static scene and people meshes), ``raster``, ``render`` (ray casting);
4. sensors: ``rig`` (camera models, tf, the view a sensor renders from), ``sensor`` (noise
   models), ``annotate`` (ground truth from the id buffer), ``stereo_rig``,
   ``thermal_camera``, ``rig_sensors`` (every kind's sensor);
5. simulator: ``simulate`` (one frame of everything), ``tof`` (static depth cameras in memory);
6. writers: ``synth`` (recordings and sidecars), ``preview``, ``occlusion_pairs``.

Public API (used by ``rgbd-eval synth``)::

    scenario = load_scenario("configs/scenarios/demo.yaml")
    result = synthesize(scenario, "datasets/demo.mcap", seed=0, progress=callback)
    write_preview(scenario, "demo.png")
    results = synthesize_all("mcap")  # every scenario to datasets/ (synth --all)
    demo = demo_recording()  # datasets/demo.mcap, generated on first use

The names are imported on first use (this ``__init__`` imports no submodule: importing
one submodule loads only what it needs).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rgbd_eval.sim.preview import write_preview
    from rgbd_eval.sim.scenario import Scenario, load_scenario, parse_scenario, scenario_paths
    from rgbd_eval.sim.simulate import SimFrame, Simulator
    from rgbd_eval.sim.synth import (
        SynthResult,
        dataset_path,
        demo_recording,
        ensure_scenario,
        ground_truth_path,
        synthesize,
        synthesize_all,
    )

#: Public name -> the submodule that defines it.
_EXPORTS = {
    "Scenario": "scenario",
    "load_scenario": "scenario",
    "parse_scenario": "scenario",
    "scenario_paths": "scenario",
    "SimFrame": "simulate",
    "Simulator": "simulate",
    "SynthResult": "synth",
    "dataset_path": "synth",
    "demo_recording": "synth",
    "ensure_scenario": "synth",
    "ground_truth_path": "synth",
    "synthesize": "synth",
    "synthesize_all": "synth",
    "write_preview": "preview",
}

__all__ = [
    "Scenario",
    "SimFrame",
    "Simulator",
    "SynthResult",
    "dataset_path",
    "demo_recording",
    "ensure_scenario",
    "ground_truth_path",
    "load_scenario",
    "parse_scenario",
    "scenario_paths",
    "synthesize",
    "synthesize_all",
    "write_preview",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)
