"""Synthetic RGB-D recordings with exact ground truth (see DESIGN.md, "Synthetic recordings").

Public API (used by ``rgbd-eval synth``)::

    scenario = load_scenario("configs/scenarios/demo.yaml")
    result = synthesize(scenario, "datasets/demo.mcap", seed=0, progress=callback)
    write_preview(scenario, "demo.png")
    results = synthesize_all("mcap")  # every scenario to datasets/ (synth --all)
    demo = demo_recording()  # datasets/demo.mcap, generated on first use
"""

import rgbd_eval.sim.stereo_rig  # noqa: F401 - registers the stereo_pair rig sensor kind
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
