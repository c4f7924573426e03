"""reproduce cielniak2010: occluded share from ground truth, claims on measured numbers."""

from __future__ import annotations

from typing import Any

from rgbd_eval.config import load_config
from rgbd_eval.io.groundtruth import from_objects
from rgbd_eval.methods.cielniak2010.experiments import (
    check_claims,
    occluded_share,
    paper_values,
    plan_variants,
)
from rgbd_eval.types import Box2D, GroundTruthObject


def _gt(
    frame: int, pid: int, box: tuple[float, float, float, float], vis: float, ignore: bool = False
) -> GroundTruthObject:
    return GroundTruthObject(frame, 1000 + frame, pid, Box2D(*box), None, vis, ignore)


def test_occluded_share_by_hand() -> None:
    gt = from_objects(
        "hand",
        [
            # frame 0: 2 behind 1 (overlapping, 40% visible): 1 of 2 occluded
            _gt(0, 1, (0, 0, 50, 100), 1.0),
            _gt(0, 2, (30, 0, 50, 100), 0.4),
            # frame 1: 3 is half visible but nobody overlaps it (image border): not occluded
            _gt(1, 1, (0, 0, 50, 100), 1.0),
            _gt(1, 3, (200, 0, 50, 100), 0.5),
            # frame 2: 2 fully hidden (ignored): not an instance; 1 alone
            _gt(2, 1, (0, 0, 50, 100), 1.0),
            _gt(2, 2, (10, 0, 50, 100), 0.0, ignore=True),
        ],
    )
    # instances: 2 + 2 + 1 = 5; occluded: frame 0's person 2 only
    assert occluded_share(gt, 0.9) == (1, 5)
    # a stricter threshold: 40% visible is not under 0.3
    assert occluded_share(gt, 0.3) == (0, 5)


def _rows(**means: dict[str, float]) -> dict[str, dict[str, dict[str, float | None]]]:
    return {
        v: {m: {"mean": x, "min": x, "max": x} for m, x in ms.items()} for v, ms in means.items()
    }


def _groups(
    thermal: float, colour: float, both: float, dark_t: float, dark_c: float
) -> dict[str, Any]:
    return {
        "light": {
            "thermal": {"accuracy": thermal},
            "colour": {"accuracy": colour},
            "both": {"accuracy": both},
        },
        "dark": {
            "thermal": {"accuracy": dark_t},
            "colour": {"accuracy": dark_c},
            "both": {"accuracy": both},
        },
    }


def test_claims_on_hand_made_numbers() -> None:
    paper = paper_values()
    lit = _rows(
        thermal={"id_switches": 10.0, "idf1": 0.60, "mota": 0.7},
        colour={"id_switches": 7.0, "idf1": 0.65, "mota": 0.7},  # 7 <= 0.8 * 10 = 8: held
        occlusion={"id_switches": 6.0, "idf1": 0.66, "mota": 0.7},  # +0.01 < 0.02: not held
    )
    dark = {
        "lit": _rows(thermal={"mota": 0.70})["thermal"],
        "dark": _rows(thermal={"mota": 0.69})["thermal"],
    }
    claims = {
        c.key: c for c in check_claims(paper, lit, dark, _groups(0.95, 0.70, 0.96, 0.95, 0.5), 45.0)
    }
    assert claims["colour_fewer_switches"].held is True
    assert claims["occlusion_recovers_identities"].held is False
    assert claims["both_feature_groups"].held is True
    assert claims["thermal_in_darkness"].held is True  # |0.70 - 0.69| and |0.95 - 0.95| <= 0.03
    assert claims["real_time"].held is True  # 45 >= 30
    # colour 9 > 8: not a fifth fewer; 20 fps: not real time
    lit["colour"]["id_switches"]["mean"] = 9.0
    claims = {
        c.key: c for c in check_claims(paper, lit, dark, _groups(0.95, 0.7, 0.9, 0.8, 0.5), 20.0)
    }
    assert claims["colour_fewer_switches"].held is False
    assert claims["both_feature_groups"].held is False  # 0.90 < 0.95 - 0.01
    assert claims["thermal_in_darkness"].held is False  # classifier 0.95 -> 0.80
    assert claims["real_time"].held is False


def test_claims_without_a_variant_are_not_judged() -> None:
    lit = _rows(thermal={"id_switches": 10.0, "idf1": 0.6, "mota": 0.7})
    claims = {
        c.key: c
        for c in check_claims(paper_values(), lit, {}, _groups(0.9, 0.7, 0.9, 0.9, 0.5), 40.0)
    }
    assert claims["colour_fewer_switches"].held is None
    assert claims["occlusion_recovers_identities"].held is None
    assert claims["thermal_in_darkness"].held is None


def test_a_missing_switch_counts_as_off() -> None:
    base = load_config(method="cielniak2010").model_dump(mode="json")
    variants = {
        "off": {"tracker.no_such_switch": False, "tracker.seed": 1},
        "on": {"tracker.no_such_switch": True},
        "known": {"tracker.seed": 2},
    }
    runnable, skipped = plan_variants(base, variants)
    assert runnable == {"off": {"tracker.seed": 1}, "known": {"tracker.seed": 2}}
    assert set(skipped) == {"on"}
    assert "no_such_switch" in skipped["on"]


def test_html_page_reads_the_paper_file() -> None:
    from rgbd_eval.plugins import ReproduceResult
    from rgbd_eval.report.html.pages import reproduce_page

    claim = {"sentence": "s", "source": "section 7", "evidence": "e", "held": True}
    result = ReproduceResult(markdown="# x\n", data={"claims": [claim]}, claims=(("s", True),))
    assert "section 7" in reproduce_page(result, "cielniak2010")
