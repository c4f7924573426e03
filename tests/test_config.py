"""Config: thesis defaults, unknown keys rejected, typed --set overrides."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.config import Gating, build_config, load_config, parse_overrides
from rgbd_eval.errors import ConfigError


def test_defaults_are_the_thesis_tables() -> None:
    c = load_config(method="basso2012")
    # Table 5.1 (voxel 0.06 m)
    d = c.detector
    assert (d.voxel_size, d.min_height, d.max_height, d.min_confidence) == (0.06, 1.4, 2.3, -1.5)
    assert (d.max_distance, d.min_points, d.max_points) == (6.5, 30, 600)
    assert d.publish_all and d.head_centroid
    # Table 6.1
    t = c.tracker
    assert (t.gate_distance_probability, t.acceleration_variance) == (0.999, 4.0)
    assert (t.weak_classifiers, t.selectors, t.min_prediction, t.min_confidence) == (
        250,
        50,
        9.0,
        -0.5,
    )
    assert (
        t.frames_before_old,
        t.frames_before_fake,
        t.frames_remain_new,
        t.detections_to_validate,
    ) == (
        90,
        60,
        30,
        3,
    )
    assert t.seconds(t.frames_before_old) == 3.0  # 90 frames at the Kinect's 30 Hz
    assert c.evaluation.gating is Gating.IOU and c.evaluation.effective_threshold() == 0.5
    # The YAML restates exactly the model defaults.
    assert c == build_config({"method": "basso2012"})


def test_overrides_are_typed() -> None:
    c = build_config({}, parse_overrides(["tracker.min_confidence=-1", "evaluation.gating=metric"]))
    assert c.tracker.min_confidence == -1.0
    assert c.evaluation.effective_threshold() == 1.0
    with pytest.raises(ConfigError, match=r"tracker.min_confidence: .*\(got 'abc'\)"):
        build_config({}, parse_overrides(["tracker.min_confidence=abc"]))
    with pytest.raises(
        ConfigError, match=r"unknown key 'min_conf' in tracker \(known: .*min_confidence"
    ):
        build_config({}, parse_overrides(["tracker.min_conf=1"]))
    with pytest.raises(ConfigError, match="expected KEY=VALUE"):
        parse_overrides(["tracker.min_confidence"])
    with pytest.raises(ConfigError, match=r"tracker\.min_confidence is not a section"):
        build_config({}, parse_overrides(["tracker.min_confidence.x=1"]))


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"tracker": {"bogus": 1}}, r"tracker.bogus: unknown key"),
        ({"detector": {"min_height": 2.5}}, "min_height=2.5 must be below max_height=2.3"),
        (
            {"detector": {"voxel_size": 0}},
            r"detector.voxel_size: Input should be greater than or equal to 0.01 \(got 0; "
            r"allowed: 0.01 <= voxel_size <= 0.5\)",
        ),
        (
            {"tracker": {"weak_classifiers": 10**9}},
            r"allowed: 1 <= weak_classifiers <= 2500",
        ),
        ({"io": {"max_sync_gap_ms": 5000}}, r"allowed: 0 < max_sync_gap_ms <= 1000"),
        ({"tracker": {"gate_distance_probability": 1.0}}, "gate_distance_probability"),
        ({"tracker": {"selectors": 300}}, "selectors=300 must not exceed weak_classifiers=250"),
        (
            {"evaluation": {"gating": "iou", "threshold": 1.5}},
            r"IoU threshold=1.5 must be in \(0, 1\]",
        ),
        ({"detector": {"ground_mode": "points"}}, "ground_mode 'points' needs"),
        # Sizes of the bootstrap's arrays (replicates x columns): bounded, as other sizes are.
        (
            {"evaluation": {"bootstrap_replicates": 10**9}},
            r"allowed: 0 <= bootstrap_replicates <= 100000",
        ),
        ({"evaluation": {"distance_bands": list(range(1, 200))}}, r"at most 50 items"),
    ],
)
def test_invalid_values_are_named(data: dict[str, object], match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        build_config(data)


def test_yaml_errors(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("tracker: [1, 2\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_config(bad)
    lst = tmp_path / "list.yaml"
    lst.write_text("- 1\n")
    with pytest.raises(ConfigError, match="expected a mapping"):
        load_config(lst)
    with pytest.raises(ConfigError, match="cannot read config"):
        load_config(tmp_path / "missing.yaml")


def test_a_changed_gating_takes_its_own_threshold(tmp_path: Path) -> None:
    """Issue 28: pinto2022's metric 1.0 m must not become an IoU threshold of 1.0."""
    iou = load_config(None, ["evaluation.gating=iou"], method="pinto2022").evaluation
    assert iou.gating is Gating.IOU and iou.effective_threshold() == 0.5
    # Switching to metric takes the method's metric threshold (dmtbs: 0.5 m), else 1.0 m.
    basso = load_config(None, ["evaluation.gating=metric"], method="basso2012").evaluation
    assert basso.effective_threshold() == 1.0
    back = load_config(None, ["evaluation.gating=iou", "evaluation.gating=metric"], method="dmtbs")
    assert back.evaluation.effective_threshold() == 0.5
    # The same gating as the defaults keeps their threshold; an explicit threshold wins.
    same = load_config(None, ["evaluation.gating=metric"], method="dmtbs").evaluation
    assert same.effective_threshold() == 0.5
    explicit = ["evaluation.threshold=0.3", "evaluation.gating=iou"]
    assert load_config(None, explicit, method="pinto2022").evaluation.threshold == 0.3
    # A config file's own gating and threshold are kept unless the gating is overridden.
    path = tmp_path / "c.yaml"
    path.write_text("method: pinto2022\nevaluation:\n  gating: metric\n  threshold: 0.7\n")
    assert load_config(path).evaluation.threshold == 0.7
    assert load_config(path, ["evaluation.gating=iou"]).evaluation.effective_threshold() == 0.5
    # A sweep over the gating from a method's resolved config (threshold 1.0 in it).
    from rgbd_eval.sweep import SweepParam, expand_grid, point_configs

    base = load_config(method="pinto2022").model_dump(mode="json")
    grid = expand_grid([SweepParam("evaluation.gating", ("iou", "metric"))])
    thresholds = [c.evaluation.effective_threshold() for c in point_configs(base, [], grid)]
    assert thresholds == [0.5, 1.0]


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        (["evaluation.threshold=1.5"], r"IoU threshold=1.5 must be in \(0, 1\]"),
        (["evaluation.threshold=0"], "greater than or equal to 0.001"),
        (["evaluation.gating=metric", "evaluation.threshold=.inf"], "finite number"),
        (["evaluation.gating=metric", "evaluation.threshold=-1"], "greater than or equal to 0.001"),
    ],
)
def test_a_threshold_outside_its_gating_range_is_refused(overrides: list[str], match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        load_config(None, overrides, method="basso2012")
