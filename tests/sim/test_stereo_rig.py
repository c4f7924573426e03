"""The synthetic stereo pair: deterministic texture, baseline in CameraInfo, SGBM vs rendered depth."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rgbd_eval.detect import stereo
from rgbd_eval.io.recording import open_recording
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.sim import Simulator, parse_scenario, synthesize
from rgbd_eval.sim.rig_config import StereoPairConfig
from rgbd_eval.sim.stereo_rig import StereoPair, value_noise

PAIR: dict[str, Any] = {"kind": "stereo_pair", "name": "stereo", "width": 320, "height": 240}
SCENARIO: dict[str, Any] = {
    "name": "stereo_test",
    "duration_s": 0.1,
    "room": {"x_min": -1.0, "x_max": 7.0, "y_min": -3.0, "y_max": 3.0},
    "people": [
        {
            "id": 1,
            "height": 1.75,
            "shirt": [60, 90, 160],
            "trousers": [40, 40, 40],
            "path": [{"x": 2.5, "y": 0.3}, {"x": 2.5, "y": -0.3, "speed": 0.5}],
        },
    ],
    "sensor": {"depth_decimation": 4},
    "rig": [PAIR],
}


def test_value_noise_is_deterministic_smooth_and_bounded() -> None:
    rng = np.random.default_rng(0)
    pts = rng.uniform(-5, 5, size=(2000, 3))
    a = value_noise(pts, 0.05, 3)
    assert np.array_equal(a, value_noise(pts, 0.05, 3))
    assert not np.array_equal(a, value_noise(pts, 0.05, 4))
    assert a.min() >= 0.0 and a.max() <= 1.0 and a.std() > 0.1
    # smooth: 1 mm away (1/50 of a feature) changes little
    b = value_noise(pts + np.array([0.001, 0.0, 0.0]), 0.05, 3)
    assert np.abs(a - b).max() < 0.1


def test_pair_round_trips_with_its_baseline(tmp_path: Path) -> None:
    out = tmp_path / "stereo.mcap"
    synthesize(parse_scenario(SCENARIO), out)
    rec = open_recording(out, streams=(StreamSpec("left"), StreamSpec("right")))
    frame = next(iter(rec.frames()))
    left, right = frame.stream("left"), frame.stream("right")
    assert left.image.shape == (240, 320, 3) and left.encoding == "rgb8"
    assert stereo.baseline_of(right.camera) == pytest.approx(0.12)
    # right optical = left optical shifted 0.12 m along the left camera's x (to the right)
    offset = left.pose.inverse().transform_points(np.array([right.pose.translation]))[0]
    np.testing.assert_allclose(offset, (0.12, 0.0, 0.0), atol=1e-6)


def test_sgbm_depth_agrees_with_the_rendered_depth() -> None:
    sim = Simulator(parse_scenario(SCENARIO), seed=0)
    pair = StereoPair(StereoPairConfig.model_validate(PAIR), "odom")
    view = sim.scene_view(0, 0)
    left = pair.render(view, pair.left, pair.base_to_left)
    right = pair.render(view, pair.right, pair.base_to_right)
    truth = view.render(pair.left, view.base_pose.compose(pair.base_to_left)).depth
    # fx = 160 / tan(50 deg) = 134.3 px; fx B = 16.1 px m: 64 disparities reach 0.25 m.
    got = stereo.stereo_depth(
        left, right, pair.left, 0.12, (320, 240), stereo.make_matcher(stereo.SgbmParams())
    ).depth
    both = np.isfinite(got) & np.isfinite(truth) & (truth < 6.0)
    both[:, :64] = False  # no disparity search range at the left border
    rel = np.abs(got[both] - truth[both]) / truth[both]
    coverage = both.sum() / (np.isfinite(truth[:, 64:]) & (truth[:, 64:] < 6.0)).sum()
    assert coverage > 0.8
    assert np.median(rel) < 0.03
    assert np.mean(rel < 0.1) > 0.9
