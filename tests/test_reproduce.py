"""reproduce: paper values file, claims judged on hand-made numbers, rendering, a small real run."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

import rgbd_eval.methods.basso2012.experiments as experiments
from rgbd_eval.config import load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.basso2012.experiments import (
    THRESHOLDS,
    VOXEL_SIZES,
    Reproduction,
    SeededReproduction,
    check_claims,
    miss_counts,
    paper_seeds,
    paper_values,
    render_markdown,
    render_seeds_markdown,
    reproduce_basso2012,
    seeded_recordings,
    seeds_json,
    thesis_base,
    verdicts,
)
from rgbd_eval.plugins import ReproduceResult
from rgbd_eval.report.html.pages import reproduce_page
from rgbd_eval.sim import load_scenario, synthesize
from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, TrackStatus, Visibility
from rgbd_eval.verdicts import Verdict


def row(
    mota: float, fp: float, fn: float, idsw: int = 0, main: float = 0.8
) -> dict[str, float | int]:
    return {
        "motp": 0.8,
        "mota": mota,
        "fp_rate": fp,
        "fn_rate": fn,
        "id_switches": idsw,
        "main_tr": main,
        "all_tr": 1 - fn,
    }


def test_paper_values_are_the_thesis_tables() -> None:
    p = paper_values()["tables"]
    # Spot checks against seed 000: Table 7.2 first row, Table 7.4 HOG row, Table 7.6 at -1.
    assert p["7.2"]["rows"]["static_simple"]["mota"] == 0.931
    assert p["7.4"]["rows"]["confidence"]["mota"] == 0.388
    assert p["7.6"]["rows"][-1.0]["fn_rate"] == 0.040
    assert sorted(p["7.6"]["rows"]) == sorted(THRESHOLDS)


#: Table 7.6's FP and FN per threshold (seed 000): FP 5.7% at -1.5 -> 26.6% at -3 (+20.9
#: points), FN 5.6% at -0.5 -> 13.0% at 0.5 (+7.4), FP + FN least at -1 (4.4 + 4.0 = 8.4%).
FP_76 = {0.5: 0.042, 0.0: 0.042, -0.5: 0.042, -1.0: 0.044, -1.5: 0.057, -1.75: 0.171,
         -2.0: 0.213, -2.5: 0.265, -3.0: 0.266}  # fmt: skip
FN_76 = {0.5: 0.13, 0.0: 0.078, -0.5: 0.056, -1.0: 0.04, -1.5: 0.034, -1.75: 0.032,
         -2.0: 0.03, -2.5: 0.028, -3.0: 0.027}  # fmt: skip
#: Figure 7.9 stage times (ms) at the six voxel sizes: only clustering changes (8 -> 2 ms).
STAGES_79 = {"read": 1.0, "pointcloud": 0.5, "voxel": 2.0, "ground": 0.2, "clustering": 5.0,
             "subclustering": 1.0, "features": 2.0, "hog": 3.0}  # fmt: skip


def thesis_like() -> Reproduction:
    """Numbers for which every claim of the thesis holds (the thesis' own where it has them)."""
    paper = paper_values()["tables"]
    res = Reproduction()
    for tab in ("7.2", "7.3"):
        res.tables[tab] = {s: dict(r) for s, r in paper[tab]["rows"].items()}
    res.tables["7.4"] = {"height": row(0.891, 0.053, 0.055), "confidence": row(0.388, 0.3, 0.3)}
    res.tables["7.5"] = {
        "true": row(0.891, 0.053, 0.055, 1, 0.8),
        "false": row(0.728, 0.196, 0.071, 5, 0.6),
    }
    res.tables["7.6"] = {
        str(k): row(1 - FP_76[k] - FN_76[k], FP_76[k], FN_76[k]) for k in THRESHOLDS
    }
    res.track_lengths = {"moving_complex": {0.0: [30] * 10, 3.0: [100] * 4, 30.0: [200] * 3}}
    for i, v in enumerate(VOXEL_SIZES):
        t = dict(STAGES_79, clustering=8.0 - 1.2 * i)  # 8.0, 6.8, ..., 2.0 ms
        t["total_detect"] = sum(t[k] for k in STAGES_79 if k != "read")
        res.voxel_timing[v] = t
    return res


def judged(res: Reproduction) -> dict[str, bool]:
    return {c.sentence: c.held for c in check_claims(res, paper_values()["claims"])}


def test_every_claim_holds_on_thesis_like_numbers() -> None:
    held = judged(thesis_like())
    assert len(held) == len(paper_values()["claims"]) == 12
    assert all(held.values()), held


def _break(name: str, res: Reproduction) -> None:
    """Change ``res`` so that the claim ``name`` (and only it) should fail."""
    if name == "mota_per_sequence":  # 89.6% - 6 points: 6 > 5 points from the thesis
        res.tables["7.2"]["static_obstacles"]["mota"] = 0.836
    elif name == "main_tr_overall":  # static_simple 76.7% -> 70%: the six rows' mean 77.0% < 77.5%
        res.tables["7.2"]["static_simple"]["main_tr"] = 0.70
    elif name == "all_tr_overall":  # static_obstacles 92.5% -> 90%: the mean 95.3% < 95.5%
        res.tables["7.2"]["static_obstacles"]["all_tr"] = 0.90
    elif name == "motp_around_80":  # 70% is not 'around 80%' (below 75%)
        res.tables["7.3"]["moving_simple"]["motp"] = 0.70
    elif name == "table_7_4_drop":  # 89.1 - 79.1 = 10 points: no 'about 50' drop
        res.tables["7.4"]["confidence"]["mota"] = 0.791
    elif name == "table_7_5_mota":  # 89.1 - 87.1 = +2 points < 16.3 (min_gain)
        res.tables["7.5"]["false"]["mota"] = 0.871
    elif name == "table_7_5_main_tr":  # 80% - 75% = +5 points < 20 (min_gain)
        res.tables["7.5"]["false"]["main_tr"] = 0.75
    elif name == "table_7_6_low_threshold":  # FP 5.7% -> 6.7%: +1 point < 20.9 (min_rise)
        res.tables["7.6"]["-3.0"]["fp_rate"] = 0.067
    elif name == "table_7_6_high_threshold":  # FN 5.6% -> 6.0%: +0.4 point < 7.4 (min_rise)
        res.tables["7.6"]["0.5"]["fn_rate"] = 0.06
    elif name == "table_7_6_best_threshold":  # FP + FN 1 + 3 = 4% at -2 beats 8.4% at -1
        res.tables["7.6"]["-2.0"]["fp_rate"] = 0.01
    elif name == "figure_7_7_memory":  # 9 tracks at 3 s against 10 at 0 s: 0.9 > 0.8
        res.track_lengths["moving_complex"][3.0] = [50] * 9
    elif name == "figure_7_9_clustering":  # voxel grid 2 -> 8 ms: range 6 > 0.5 x clustering's 6
        for i, v in enumerate(VOXEL_SIZES):
            res.voxel_timing[v]["voxel"] = 8.0 - 1.2 * i
    else:
        raise AssertionError(f"no breaking case for claim {name}")


@pytest.mark.parametrize("name", list(paper_values()["claims"]))
def test_every_claim_can_fail(name: str) -> None:
    res = thesis_like()
    _break(name, res)
    sentence = paper_values()["claims"][name]["sentence"]
    failed = [s for s, held in judged(res).items() if not held]
    assert failed == [sentence]


def test_figure_7_9_time_is_a_measurement_not_a_claim() -> None:
    # 7.2's 25-29 ms under 33 ms was measured in C++ on an i5-520M: shown beside ours with
    # the hardware, never held or failed on another machine's Python.
    res = thesis_like()
    res.voxel_timing[VOXEL_SIZES[0]]["total_detect"] = 80.0
    assert all(judged(res).values())
    assert "0.025 seconds" not in " ".join(judged(res))
    timing = paper_values()["timing"]
    assert timing["detect_ms"] == [25.0, 29.0] and timing["budget_ms"] == 33.0
    assert "i5-520M" in timing["hardware"]


def test_reproduce_runs_the_thesis_configuration() -> None:
    # 5.2: plain Euclidean clusters; 5.3: the centroid is the points' mean; 5.4.1: the floor
    # is known (clicked), not fitted; 5.4.2: cut windows unscored. `run` keeps our additions.
    det = thesis_base()["detector"]
    assert det["subclustering"] is False
    assert det["surface_correction"] is False
    assert det["ground_mode"] == "world"
    assert det["hog_border"] == "skip"
    default = load_config(method="basso2012").detector.model_dump(mode="json")
    assert default["subclustering"] is True and default["surface_correction"] is True
    assert default["ground_mode"] == "auto" and default["hog_border"] == "pad"
    assert paper_seeds() == [1, 2, 3, 4, 5]


def _seeded(*broken: tuple[int, str]) -> SeededReproduction:
    """Thesis-like runs on seeds 1, 2, 3; ``broken``: (seed, claim) pairs made to fail."""
    runs = {}
    for seed in (1, 2, 3):
        res = thesis_like()
        for s, name in broken:
            if s == seed:
                _break(name, res)
        res.claims = check_claims(res, paper_values()["claims"])
        runs[seed] = res
    return SeededReproduction(runs, verdicts(runs), 12.0)


def test_a_claim_that_flips_between_seeds_is_inconclusive() -> None:
    claims = paper_values()["claims"]
    res = _seeded((2, "table_7_5_mota"), *((s, "main_tr_overall") for s in (1, 2, 3)))
    by = {v.key: v for v in res.verdicts}
    flipping = by[claims["table_7_5_mota"]["sentence"]]
    assert flipping.verdict is Verdict.INCONCLUSIVE
    assert [c.held for c in flipping.per_seed.values()] == [True, False, True]
    gain = flipping.spreads["gain_points"]  # 16.3 on seeds 1 and 3, 2.0 on seed 2
    assert (gain.low, gain.high, gain.runs) == (pytest.approx(2.0), pytest.approx(16.3), 3)
    assert by[claims["main_tr_overall"]["sentence"]].verdict is Verdict.FAILED
    held = [
        v for k, v in by.items() if k not in {flipping.key, claims["main_tr_overall"]["sentence"]}
    ]
    assert len(held) == 10 and all(v.verdict is Verdict.HELD for v in held)


def test_seeds_page_and_json_show_verdicts_spreads_statements_and_time() -> None:
    paper = paper_values()
    res = _seeded((3, "all_tr_overall"))
    text = render_seeds_markdown(res, paper)
    assert (
        "over 3 scenario seeds" in text and "**11 held, 0 failed, 1 inconclusive of 12.**" in text
    )
    assert "`detector.subclustering: false`" in text and "`detector.ground_mode: world`" in text
    # The published statements without a table row: paper value, ours, verdict.
    assert (
        '"We track 78% of every ground truth track with a single ID." | 78% | '
        "78.1% [78.1, 78.1] over 3 runs | **held** |" in text
    )
    all_tr = next(
        line for line in text.splitlines() if "raises to 96%" in line and "| 96% |" in line
    )
    assert "[95.3, 95.7] over 3 runs" in all_tr and "**inconclusive**" in all_tr
    assert "detection time, a measurement beside the thesis' (not a claim)" in text
    assert "Intel i5-520M" in text and "## Scenario seed 3" in text
    data = seeds_json(res, paper)
    assert data["seeds"] == [1, 2, 3]
    (claim,) = (c for c in data["claims"] if "raises to 96%" in c["text"])
    assert claim["verdict"] == "inconclusive"
    assert claim["per_seed"] == {"1": True, "2": True, "3": False}
    assert claim["measured"]["all_tr_pct"]["min"] == pytest.approx(95.3, abs=0.05)
    assert data["tables"]["7.2"]["static_simple"]["mota"] == pytest.approx(0.931)
    assert data["tables_spread"]["7.2"]["static_obstacles"]["all_tr"]["min"] == pytest.approx(0.90)
    assert data["detection_time"]["paper_detect_ms"] == [25.0, 29.0]
    result = ReproduceResult(text, data, tuple((v.key, v.verdict) for v in res.verdicts))
    page = reproduce_page(result, "basso2012")
    assert "inconclusive" in page and "Table 7.2" in page


def test_reproduce_judges_every_claim_over_the_paper_seeds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The entry point of `rgbd-eval reproduce basso2012`: every seed of paper.yaml gets its
    # recordings and a run with the thesis' config; each claim's verdict is over the seeds.
    seen: dict[int, tuple[dict[str, Path], dict[str, object]]] = {}

    def recordings(
        recs: object, seeds: list[int], progress: object, client: object
    ) -> dict[int, dict[str, Path]]:
        return {s: {"moving_complex": tmp_path / f"moving_complex-seed{s}.mcap"} for s in seeds}

    def run(
        recs: dict[str, Path], client: object, cache: object, say: object, base: dict[str, object]
    ) -> Reproduction:
        seed = int(next(iter(recs.values())).stem.rsplit("seed", 1)[1])
        seen[seed] = (recs, base)
        res = thesis_like()
        if seed == 4:
            _break("table_7_6_high_threshold", res)
        res.claims = check_claims(res, paper_values()["claims"])
        return res

    monkeypatch.setattr(experiments, "seeded_recordings", recordings)
    monkeypatch.setattr(experiments, "reproduce_basso2012", run)
    result = experiments.reproduce({}, experiments.ReproduceOptions())
    assert sorted(seen) == [1, 2, 3, 4, 5]
    assert all(base["detector"]["subclustering"] is False for _, base in seen.values())  # type: ignore[index]
    verdict = dict(result.verdicts())
    high = paper_values()["claims"]["table_7_6_high_threshold"]["sentence"]
    assert verdict.pop(high) is Verdict.INCONCLUSIVE
    assert set(verdict.values()) == {Verdict.HELD} and len(verdict) == 11
    assert result.data["seeds"] == [1, 2, 3, 4, 5]


def test_seeded_recordings_reuse_the_scenarios_own_seed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    made: list[tuple[str, int | None]] = []

    def fake(scenario: object, out: Path, container: str, seed: int | None = None) -> None:
        made.append((Path(out).name, seed))
        Path(out).write_bytes(b"")
        Path(out).with_name(f"{Path(out).stem}.gt.csv").write_text("")
        start = time.process_time()
        while time.process_time() - start < 0.02:  # rendering takes CPU
            pass

    import rgbd_eval.sim.synth as synth

    monkeypatch.setattr(synth, "synthesize", fake)
    # Present counts as current here (the provenance check has its own test in tests/sim).
    monkeypatch.setattr(synth, "is_current", lambda p, *_a: p.exists())
    own = tmp_path / "static_simple.mcap"  # static_simple.yaml has seed 1
    rendering = synth.rendering_cpu_s()
    got = seeded_recordings({"static_simple": own}, [1, 2])
    # the one rendering's CPU (>= 0.02 s) is counted once, as rendering (reproduce's CPU line)
    assert 0.02 <= synth.rendering_cpu_s() - rendering < 1.0
    assert got == {
        1: {"static_simple": own},
        2: {"static_simple": tmp_path / "static_simple-seed2.mcap"},
    }
    assert made == [("static_simple-seed2.mcap", 2)]
    seeded_recordings({"static_simple": own}, [1, 2])  # present: not rendered again
    assert len(made) == 1


def test_seeded_recordings_render_on_the_cluster(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # With a client the missing recordings are rendered as tasks (on 2 cores: two at once).
    import rgbd_eval.sim.synth as synth
    from rgbd_eval.engine import connect, parse_cluster

    def fake(scenario: Path, folder: Path, seed: int) -> tuple[int, float]:
        target = folder / f"{scenario.stem}-seed{seed}.mcap"
        target.write_bytes(str(seed).encode())
        target.with_name(f"{target.stem}.gt.csv").write_text("")
        # seed 2 as if rendered by a worker process (2.5 s), seed 3 in this process (whose
        # rendering ensure_scenario counted already: not again)
        return (os.getpid() + 1, 2.5) if seed == 2 else (os.getpid(), 9.0)

    monkeypatch.setattr(experiments, "render_seeded", fake)
    own = tmp_path / "moving_obstacles.mcap"  # moving_obstacles.yaml has seed 6
    rendering = synth.rendering_cpu_s()
    with connect(parse_cluster("local:1")) as client:
        got = seeded_recordings({"moving_obstacles": own}, [2, 3], client=client)
    assert [p.read_bytes() for p in (got[2]["moving_obstacles"], got[3]["moving_obstacles"])] == [
        b"2",
        b"3",
    ]
    assert synth.rendering_cpu_s() - rendering == 2.5


def test_claims_render_with_their_sentences() -> None:
    res = thesis_like()
    _break("table_7_5_mota", res)
    res.claims = check_claims(res, paper_values()["claims"])
    text = render_markdown(res, paper_values())
    assert "| height | 84.1% / 80.0% | 89.1% / 89.1%" in text
    assert '**did not hold** (7.3, Table 7.5) "the on-line person-specific classifier' in text
    assert "a drop of 50.3 points" in text


def test_claim_thresholds_are_checked() -> None:
    claims = dict(paper_values()["claims"])
    claims["table_7_4_drop"] = {**claims["table_7_4_drop"], "min_drop": "forty"}
    with pytest.raises(ConfigError, match="claim threshold 'min_drop' must be a number"):
        check_claims(thesis_like(), claims)
    del claims["table_7_4_drop"]
    with pytest.raises(ConfigError, match="claim 'table_7_4_drop' needs a mapping"):
        check_claims(thesis_like(), claims)


def test_paper_values_file_problems_are_config_errors(tmp_path: Path) -> None:
    bad = tmp_path / "paper.yaml"
    bad.write_text("tables: {}\nfigures: {}\n")
    with pytest.raises(ConfigError, match="paper values need a mapping 'claims'"):
        paper_values(bad)
    bad.write_text("- a list\n")
    with pytest.raises(ConfigError, match="expected a mapping at the top level"):
        paper_values(bad)


def test_misses_are_grouped_by_height_and_visibility() -> None:
    def person(pid: int, left: float, z: float, vis: float) -> GroundTruthObject:
        return GroundTruthObject(0, 0, pid, Box2D(left, 100, 50, 200), (3.0, 0.0, z), vis)

    def track(tid: int, left: float, status: TrackStatus = TrackStatus.VALIDATED) -> TrackOutput:
        return TrackOutput(
            tid, 3.0, 0.0, 1.7, Box2D(left, 100, 50, 200), Visibility.VISIBLE, status
        )

    frames = [
        # seated (height 2 x 0.55 = 1.1 m < 1.4 m), not covered; a standing, fully visible
        # person covered by track 1 (same box: IoU 1)
        [person(1, 0, 0.55, 1.0), person(2, 200, 0.85, 1.0)],
        # 30% visible, covered by a box 10 px off: IoU = 40x200 / (2 x 50x200 - 40x200) = 2/3;
        # 70% visible, only a NEW (unvalidated) track on it: missed
        [person(2, 200, 0.85, 0.3), person(3, 400, 0.9, 0.7)],
    ]
    tracks = [[track(1, 200)], [track(1, 210), track(5, 400, TrackStatus.NEW)]]
    got = miss_counts(frames, tracks, min_height=1.4)
    assert got == {
        "shorter than min_height": {"gt": 1, "missed": 1},
        "visible < 50%": {"gt": 1, "missed": 0},
        "visible 50-90%": {"gt": 1, "missed": 1},
        "visible >= 90%": {"gt": 1, "missed": 0},
    }
    # a box 30 px off: IoU = 20x200 / (2 x 50x200 - 20x200) = 0.25 < 0.5 -> missed
    got = miss_counts(frames[:1], [[track(1, 230)]], min_height=1.4)
    assert got["visible >= 90%"] == {"gt": 1, "missed": 1}


def test_two_scenarios_on_one_file_name_are_refused(tmp_path: Path) -> None:
    one = tmp_path / "a" / "x.mcap"
    other = tmp_path / "b" / "x.mcap"
    with pytest.raises(ConfigError, match="two scenarios share one recording file name"):
        reproduce_basso2012({"static_simple": one, "moving_simple": other})


@pytest.mark.slow
def test_small_reproduction_runs(tmp_path: Path) -> None:
    scenario = load_scenario(scenarios_dir() / "demo.yaml")
    obstacles = synthesize(scenario, tmp_path / "moving_obstacles.mcap", max_frames=25).recording
    complex_ = synthesize(scenario, tmp_path / "moving_complex.mcap", max_frames=20).recording
    clutter_sc = load_scenario(scenarios_dir() / "static_clutter.yaml")
    clutter = synthesize(clutter_sc, tmp_path / "static_clutter.mcap", max_frames=15).recording
    res = reproduce_basso2012(
        {"moving_obstacles": obstacles, "moving_complex": complex_, "static_clutter": clutter},
        cache=tmp_path / "cache",
    )
    assert set(res.tables["7.4"]) == {"height", "confidence"}
    assert len(res.tables["7.6"]) == len(THRESHOLDS)
    assert set(res.track_lengths["moving_complex"]) == {0.0, 3.0, 30.0}
    assert len(res.voxel_timing) == 6 and all(
        t["total_detect"] > 0 for t in res.voxel_timing.values()
    )
    assert set(res.clutter) == {"thesis", "static 2 s"}
    assert set(res.clutter["thesis"]) == {"static_clutter"}
    (t71,) = (v for k, v in res.frame_rates.items() if k.startswith("Table 7.1"))
    assert 0 < t71["detector_tracker_fps"] < t71["detector_fps"]
    text = render_markdown(res, paper_values())
    assert res.claims and "Table 7.2" in text and "detector + tracker fps" in text
    assert "| static 2 s | static_clutter |" in text
    assert set(res.misses) == {"moving_obstacles"}
    assert sum(g["gt"] for g in res.misses["moving_obstacles"].values()) > 0
