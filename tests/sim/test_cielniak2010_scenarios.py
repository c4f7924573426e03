"""The cielniak2010 scenarios (seed 004 section 7): corridor, crossings, darkness."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.sim.rig_config import ThermalCameraConfig
from rgbd_eval.sim.scenario import load_scenario
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.sim.thermal_camera import ThermalCamera

FOLDER = scenarios_dir() / "cielniak2010"


def test_scenarios_load_with_a_thermal_camera() -> None:
    for name in ("thermal_corridor", "thermal_crossings", "thermal_darkness"):
        sc = load_scenario(FOLDER / f"{name}.yaml")
        assert sc.name == name
        assert [r.kind for r in sc.rig] == ["thermal"]
    assert load_scenario(FOLDER / "thermal_corridor.yaml").robot.path  # the robot moves


def test_darkness_is_the_crossings_scene_with_the_lights_off() -> None:
    lit = load_scenario(FOLDER / "thermal_crossings.yaml").model_dump()
    dark = load_scenario(FOLDER / "thermal_darkness.yaml").model_dump()
    for key in ("name", "description"):
        lit.pop(key), dark.pop(key)
    lit_sensor, dark_sensor = lit.pop("sensor"), dark.pop("sensor")
    assert lit == dark
    assert dark_sensor["illumination"] == pytest.approx(0.04)
    assert {k for k in lit_sensor if lit_sensor[k] != dark_sensor[k]} == {
        "illumination",
        "rgb_noise_std",
    }


def test_darkness_darkens_colour_and_leaves_thermal_unchanged() -> None:
    lit = Simulator(load_scenario(FOLDER / "thermal_crossings.yaml"))
    dark = Simulator(load_scenario(FOLDER / "thermal_darkness.yaml"))
    index = 90  # persons 1 and 2 are in view
    f_lit, f_dark = lit.frame(index), dark.frame(index)
    # light at 4%: the mean level falls from ~85 to ~4 (noise of 6 levels, clipped at 0)
    assert f_dark.rgb.mean() < 0.1 * f_lit.rgb.mean()
    cfg = lit.scenario.rig[0]
    assert isinstance(cfg, ThermalCameraConfig)
    camera = ThermalCamera(cfg, "world")
    np.testing.assert_array_equal(
        camera.render_counts(lit.scene_view(index, 0)),
        camera.render_counts(dark.scene_view(index, 0)),
    )
