"""Small scenarios shared by the sim tests (tiny images keep the suite fast)."""

from __future__ import annotations

from typing import Any

import pytest

from rgbd_eval.sim.scenario import Scenario, parse_scenario


def tiny_scenario(**overrides: Any) -> Scenario:
    """A 160x120, 6-frame scenario: two people, a coat stand, a slowly driving robot."""
    data: dict[str, Any] = {
        "name": "tiny",
        "duration_s": 0.2,
        "obstacles": [{"kind": "coat_stand", "x": 4.0, "y": 1.5}],
        "people": [
            {"id": 1, "path": [{"x": 4.0, "y": -1.0}, {"x": 4.0, "y": 1.0, "speed": 1.2}]},
            {"id": 2, "height": 1.6, "bag": True, "path": [{"x": 6.0, "y": 0.5}]},
        ],
        "robot": {"path": [{"x": 1.0, "y": 0.0, "speed": 0.5}]},
        "sensor": {"width": 160, "height": 120, "depth_decimation": 2},
        "recording": {"rgb_format": "raw", "depth_encoding": "32FC1"},
    }
    data.update(overrides)
    return parse_scenario(data, "tiny")


@pytest.fixture
def tiny() -> Scenario:
    return tiny_scenario()
