"""The thermal rig sensor: mono16 centikelvin on its own topic, people warm, room cool."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.errors import ConfigError
from rgbd_eval.io.groundtruth import load_ground_truth
from rgbd_eval.io.recording import open_recording
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.sim import Simulator, parse_scenario, synthesize
from rgbd_eval.sim.thermal_camera import (
    ThermalCamera,
    ThermalCameraConfig,
    celsius_to_counts,
    counts_to_celsius,
)

SCENARIO = {
    "name": "thermal_test",
    "duration_s": 0.1,
    "room": {"x_min": -1.0, "x_max": 8.0, "y_min": -3.0, "y_max": 3.0},
    # a radiator (obstacle 0) left of the person, at 50 C
    "obstacles": [{"kind": "box", "x": 4.5, "y": 1.5, "size": [0.2, 0.8, 0.6]}],
    "people": [
        {
            "id": 1,
            "height": 1.8,
            "shirt": [200, 30, 30],
            "trousers": [30, 30, 30],
            "path": [{"x": 3.0, "y": 0.0}, {"x": 3.0, "y": -0.1, "speed": 0.5}],
        },
    ],
    "sensor": {"depth_decimation": 4},
    "rig": [{"kind": "thermal", "name": "thermal", "warm_obstacles": {0: 50.0}}],
}


def test_counts_round_trip_centikelvin() -> None:
    # 34.00 C = 307.15 K = 30715 counts; back to 34.00 C
    t = np.array([[34.0, 20.0]])
    counts = celsius_to_counts(t)
    assert counts.tolist() == [[30715, 29315]]
    np.testing.assert_allclose(counts_to_celsius(counts), t, atol=1e-9)


def test_ideal_temperatures_person_skin_clothing_room_radiator() -> None:
    scenario = parse_scenario(SCENARIO)
    sim = Simulator(scenario)
    sim.frame(0)
    cfg = ThermalCameraConfig(name="thermal", warm_obstacles={0: 50.0}, limb_contrast=0.0)
    cam = ThermalCamera(cfg, "odom")
    t = cam.temperatures(sim.scene_view(0, 0))
    values = set(np.unique(t).tolist())
    # with no grazing falloff, every pixel is one of the five surface temperatures
    assert values <= {20.0, 19.0, 28.0, 34.0, 50.0}
    assert {34.0, 28.0, 50.0, 19.0} <= values  # skin, clothing, radiator, floor seen


def test_thermal_stream_is_read_back_with_the_person_warm_at_its_box(tmp_path: Path) -> None:
    out = tmp_path / "thermal.bag"
    synthesize(parse_scenario(SCENARIO), out)
    rec = open_recording(out, streams=(StreamSpec("colour"), StreamSpec("thermal")))
    assert rec.info.selected.streams["thermal"] == "/thermal/image_raw"
    frame = next(iter(rec.frames()))
    th = frame.stream("thermal")
    assert th.encoding == "mono16" and th.image.shape == (240, 320)
    temp = counts_to_celsius(th.image)
    # the thermal camera sits 6 cm right of the colour camera (tf from /tf_static)
    colour = frame.stream("colour")
    offset = colour.pose.inverse().compose(th.pose)
    np.testing.assert_allclose(offset.translation, (0.06, 0.0, 0.0), atol=1e-6)
    # the person's ground-truth centre projects onto warm (clothing) pixels: above 25 C,
    # while the room around reads about 19-20 C
    gt = load_ground_truth(out.with_name("thermal.gt.csv"))
    person = next(o for o in gt.frames[0][2] if o.object_id == 1)
    assert person.world_xyz is not None
    centre = th.pose.inverse().transform_points(np.array([person.world_xyz]))
    u, v = th.camera.project(centre)[0]
    assert temp[round(float(v)), round(float(u))] > 25.0
    assert float(np.median(temp)) == pytest.approx(20.0, abs=1.0)
    assert temp.max() > 45.0  # the radiator


def test_thermal_config_rejects_bad_values() -> None:
    bad = {**SCENARIO, "rig": [{"kind": "thermal", "name": "thermal", "netd_k": -1.0}]}
    with pytest.raises(ConfigError, match="netd_k"):
        parse_scenario(bad)
