"""Seed 004's evaluation (section 7) on the synthetic thermal scenarios (``reproduce cielniak2010``).

- The data: the share of person instances occluded by another person, per scenario, from
  the ground truth, beside the paper's 1289 of 10,256 (about 13%).
- The tracker ablation of issue 16: thermal only, plus the colour model, plus occlusion
  handling (``ablations`` in ``methods/cielniak2010/paper.yaml``), on every scenario for
  several particle-filter seeds; counts are summed over the scenarios per seed, the ratios
  derived, then mean and spread (min .. max) over the seeds.
- The occlusion classifier per feature group (section 5) on held-out rendered pairs, in
  light and in darkness.
- Real time: the tracker's CPU time per frame on one core with three people.
- The claims, each judged on the measured numbers with the thresholds of the paper file.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rgbd_eval.components import create_tracker
from rgbd_eval.config import build_config, load_config, load_paper
from rgbd_eval.errors import ConfigError, TaskError
from rgbd_eval.io.groundtruth import GroundTruth
from rgbd_eval.metrics import Counts, summarize, total
from rgbd_eval.pipeline import ground_truth_file, open_for, sequence_name
from rgbd_eval.plugins import ReproduceOptions, ReproduceResult
from rgbd_eval.sweep import point_configs, run_sweep
from rgbd_eval.types import Box2D
from rgbd_eval.verdicts import Verdict

#: The summary measures shown per ablation variant.
MEASURES = ("mota", "motp", "idf1", "id_switches", "fn_rate", "fp_rate")


@dataclass(frozen=True)
class Claim:
    """One statement of the seed and whether it held on our numbers."""

    key: str
    source: str
    sentence: str
    held: bool | None  # None: not judged (a variant could not run)
    evidence: str


def paper_values(path: Path | None = None) -> dict[str, Any]:
    """The seed's facts, the ablation and the claim thresholds (``methods/cielniak2010/paper.yaml``)."""
    required = ("dataset", "scenarios", "ablations", "seeds", "classifier", "claims")
    return load_paper("cielniak2010", present=required, path=path)


def _overlaps(a: Box2D, b: Box2D) -> bool:
    return min(a.right, b.right) > max(a.left, b.left) and min(a.bottom, b.bottom) > max(
        a.top, b.top
    )


def occluded_share(gt: GroundTruth, max_visibility: float) -> tuple[int, int]:
    """(occluded, all) person instances: an instance is occluded when under ``max_visibility``
    of it is visible and another person's box overlaps its box (ignored instances skipped)."""
    occluded = instances = 0
    for _, _, objects in gt.frames:
        seen = [o for o in objects if not o.ignore and o.box2d is not None]
        for o in seen:
            instances += 1
            box = o.box2d
            if box is None:  # pragma: no cover - filtered above
                continue
            if o.visibility < max_visibility and any(
                p is not o and p.box2d is not None and _overlaps(box, p.box2d) for p in seen
            ):
                occluded += 1
    return occluded, instances


def _stats(values: Sequence[float | None]) -> dict[str, float | None]:
    v = [float(x) for x in values if x is not None]
    if not v:
        return {"mean": None, "min": None, "max": None}
    return {"mean": statistics.fmean(v), "min": min(v), "max": max(v)}


def plan_variants(
    base: Mapping[str, Any], variants: Mapping[str, Mapping[str, Any]]
) -> tuple[dict[str, dict[str, Any]], dict[str, str]]:
    """The overrides of the variants that can run, and why the others cannot.

    A switch the tracker config does not have counts as off: set to false it is dropped,
    set to anything else its variant is not run.
    """
    runnable: dict[str, dict[str, Any]] = {}
    skipped: dict[str, str] = {}
    for name, overrides in variants.items():
        kept: dict[str, Any] = {}
        for key, value in overrides.items():
            try:
                build_config(base, [(key, value)], source=f"ablation {name}")
            except ConfigError as err:
                if value is False:
                    continue
                skipped[name] = str(err)
                break
            kept[key] = value
        else:
            runnable[name] = kept
    return runnable, skipped


def ablation(
    recordings: Mapping[str, Path],
    variants: Mapping[str, Mapping[str, Any]],
    seeds: Sequence[int],
    options: ReproduceOptions,
) -> tuple[dict[str, dict[int, dict[str, Counts]]], dict[str, str]]:
    """Counts per variant, seed and scenario; and the variants that cannot run, with why."""
    base = load_config(method="cielniak2010").model_dump(mode="json")
    runnable, skipped = plan_variants(base, variants)
    points = [{**kept, "tracker.seed": s} for kept in runnable.values() for s in seeds]
    labels = [(name, s) for name in runnable for s in seeds]
    out: dict[str, dict[int, dict[str, Counts]]] = {}
    if not points:
        return out, skipped
    configs = point_configs(base, [], points)
    result = run_sweep(list(recordings.values()), points, configs, options.client, options.cache)
    if result.failures:
        first = result.failures[0]
        label = ", ".join(f"{k}={v}" for k, v in first.point.items())
        raise TaskError(f"ablation {label} on {first.sequence}: {first.error}", first.exit_code)
    names = {sequence_name(p): n for n, p in recordings.items()}
    for r in result.records:
        name, seed = labels[points.index(r.point)]
        out.setdefault(name, {}).setdefault(seed, {})[names[r.sequence]] = r.counts
    return out, skipped


def summarise_ablation(
    counts: Mapping[str, Mapping[int, Mapping[str, Counts]]], scenarios: Sequence[str]
) -> dict[str, dict[str, dict[str, float | None]]]:
    """Per variant and measure: mean, min, max over seeds of the summed ``scenarios``."""
    out: dict[str, dict[str, dict[str, float | None]]] = {}
    for variant, per_seed in counts.items():
        summaries = [
            summarize(total(c for n, c in by_scenario.items() if n in scenarios))
            for by_scenario in per_seed.values()
        ]
        out[variant] = {m: _stats([s[m] for s in summaries]) for m in MEASURES}
    return out


def classifier_groups(classifier: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """Held-out accuracy per feature group of the shipped classifiers, in light and darkness."""
    from rgbd_eval.methods.cielniak2010.occlusion import load_classifiers
    from rgbd_eval.methods.cielniak2010.occlusion_training import evaluate, render_features

    models = load_classifiers()
    seed, pairs, jitter = (
        int(classifier["seed"]),
        int(classifier["pairs"]),
        float(classifier["jitter"]),
    )
    light = evaluate(models, render_features(seed, pairs, jitter))
    dark = evaluate(
        models, render_features(seed, pairs, jitter, float(classifier["dark_illumination"]))
    )
    return {"light": light, "dark": dark}


def tracker_fps(recording: Path, frames: int) -> dict[str, float]:
    """CPU seconds per frame of the tracker (``time.process_time``) over ``frames`` frames."""
    config = load_config(method="cielniak2010")
    tracker = create_tracker(config)
    cpu = 0.0
    done = 0
    for frame in open_for(recording, config).frames():
        start = time.process_time()
        tracker.update(frame.stamp_ns, [], frame)
        cpu += time.process_time() - start
        done += 1
        if done == frames:
            break
    return {
        "frames": done,
        "cpu_s_per_frame": cpu / done if done else 0.0,
        "fps": done / cpu if cpu > 0 else 0.0,
    }


def _mean(
    table: Mapping[str, Mapping[str, Mapping[str, float | None]]], variant: str, measure: str
) -> float | None:
    row = table.get(variant)
    return None if row is None else row[measure]["mean"]


def check_claims(
    paper: Mapping[str, Any],
    lit: Mapping[str, Mapping[str, Mapping[str, float | None]]],
    light_vs_dark: Mapping[str, Mapping[str, Mapping[str, float | None]]],
    groups: Mapping[str, Mapping[str, Mapping[str, Any]]],
    fps: float,
) -> list[Claim]:
    """Each claim of ``paper['claims']`` judged on the measured numbers."""
    c = paper["claims"]
    out = []

    def claim(key: str, held: bool | None, evidence: str) -> None:
        out.append(Claim(key, c[key]["source"], c[key]["sentence"], held, evidence))

    sw_t, sw_c = _mean(lit, "thermal", "id_switches"), _mean(lit, "colour", "id_switches")
    if sw_t is None or sw_c is None:
        claim("colour_fewer_switches", None, "a variant did not run")
    else:
        limit = (1.0 - float(c["colour_fewer_switches"]["min_reduction"])) * sw_t
        claim(
            "colour_fewer_switches",
            sw_c <= limit and sw_c < sw_t,
            f"mean ID switches thermal {sw_t:.1f}, + colour {sw_c:.1f} (needed <= {limit:.1f})",
        )
    f_c, f_o = _mean(lit, "colour", "idf1"), _mean(lit, "occlusion", "idf1")
    sw_o = _mean(lit, "occlusion", "id_switches")
    if f_c is None or f_o is None or sw_c is None or sw_o is None:
        claim("occlusion_recovers_identities", None, "a variant did not run")
    else:
        gain = float(c["occlusion_recovers_identities"]["min_gain"])
        claim(
            "occlusion_recovers_identities",
            f_o - f_c >= gain and sw_o <= sw_c,
            f"mean IDF1 + colour {f_c:.3f}, + occlusion handling {f_o:.3f} (needed +{gain}); "
            f"ID switches {sw_c:.1f} -> {sw_o:.1f}",
        )
    acc = {g: r["accuracy"] for g, r in groups["light"].items()}
    tol = float(c["both_feature_groups"]["tolerance"])
    best_single = max(acc["thermal"], acc["colour"])
    claim(
        "both_feature_groups",
        acc["both"] >= best_single - tol,
        f"held-out accuracy thermal {acc['thermal']:.3f}, colour {acc['colour']:.3f}, "
        f"both {acc['both']:.3f}",
    )
    gap = float(c["thermal_in_darkness"]["max_gap"])
    m_lit = _mean(light_vs_dark, "lit", "mota")
    m_dark = _mean(light_vs_dark, "dark", "mota")
    a_lit, a_dark = acc["thermal"], groups["dark"]["thermal"]["accuracy"]
    if m_lit is None or m_dark is None:
        claim("thermal_in_darkness", None, "thermal only did not run")
    else:
        claim(
            "thermal_in_darkness",
            abs(m_lit - m_dark) <= gap and abs(a_lit - a_dark) <= gap,
            f"thermal-only MOTA lit {m_lit:.3f}, dark {m_dark:.3f}; thermal classifier "
            f"{a_lit:.3f} lit, {a_dark:.3f} dark; colour classifier "
            f"{groups['dark']['colour']['accuracy']:.3f} dark (max gap {gap})",
        )
    need = float(c["real_time"]["min_fps"])
    claim("real_time", fps >= need, f"{fps:.1f} frames per CPU second (needed {need:g})")
    return out


def run(recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    """Every experiment above on the given recordings."""
    say = options.progress
    start = time.perf_counter()
    paper = paper_values()
    names: Mapping[str, str] = paper["scenarios"]
    missing = [n for n in names.values() if n not in recordings]
    if missing:
        raise ConfigError(f"reproduce cielniak2010 needs the scenarios {missing}")
    say("occluded share per scenario (ground truth)")
    max_vis = float(paper["occlusion_count"]["max_visibility"])
    occlusion: dict[str, dict[str, Any]] = {}
    for n in names.values():
        gt = ground_truth_file(recordings[n], None)
        if gt is None:
            raise ConfigError(f"{recordings[n]}: no ground truth beside the recording")
        occ, inst = occluded_share(gt, max_vis)
        occlusion[n] = {"occluded": occ, "instances": inst, "share": occ / inst if inst else None}
    say("tracker ablation: " + ", ".join(paper["ablations"]) + f" x seeds {paper['seeds']}")
    counts, skipped = ablation(
        {n: recordings[n] for n in names.values()},
        paper["ablations"],
        [int(s) for s in paper["seeds"]],
        options,
    )
    lit_names = [names[k] for k in ("corridor", "crossings", "stationary")]
    per_scenario = {n: summarise_ablation(counts, [n]) for n in names.values()}
    lit = summarise_ablation(counts, lit_names)
    light_vs_dark = {
        "lit": per_scenario[names["crossings"]].get("thermal", {}),
        "dark": per_scenario[names["darkness"]].get("thermal", {}),
    }
    say("occlusion classifier per feature group (held-out rendered pairs, light and dark)")
    groups = classifier_groups(paper["classifier"])
    say("real time: tracker CPU time per frame")
    rt = paper["realtime"]
    fps = tracker_fps(recordings[names[rt["scenario"]]], int(rt["frames"]))
    claims = check_claims(
        paper, lit, {k: v for k, v in light_vs_dark.items() if v}, groups, fps["fps"]
    )
    data = {
        "occlusion": occlusion,
        "ablation": {"lit_total": lit, "per_scenario": per_scenario, "not_run": skipped},
        "classifier": groups,
        "real_time": fps,
        "claims": [c.__dict__ for c in claims],
        "seconds": time.perf_counter() - start,
    }
    return ReproduceResult(
        markdown=render(paper, data, claims),
        data=data,
        claims=tuple(
            (c.sentence, Verdict.INCONCLUSIVE if c.held is None else Verdict.of(c.held))
            for c in claims
        ),
    )


def _f(value: Any, scale: float = 1.0, digits: int = 3) -> str:
    return "-" if value is None else f"{float(value) * scale:.{digits}f}"


def _ablation_table(
    title: str, rows: Mapping[str, Mapping[str, Mapping[str, float | None]]]
) -> list[str]:
    head = "| variant | " + " | ".join(f"{m} mean [min, max]" for m in MEASURES) + " |"
    lines = [f"### {title}", "", head, "|---" * (len(MEASURES) + 1) + "|"]
    for variant, row in rows.items():
        cells = [
            f"{_f(row[m]['mean'])} [{_f(row[m]['min'])}, {_f(row[m]['max'])}]" for m in MEASURES
        ]
        lines.append(f"| {variant} | " + " | ".join(cells) + " |")
    return [*lines, ""]


def render(paper: Mapping[str, Any], data: Mapping[str, Any], claims: Sequence[Claim]) -> str:
    """Markdown: the seed's data-set facts beside ours, the ablation, the classifier, the claims."""
    ds = paper["dataset"]
    out = ["# cielniak2010: seed 004 section 7 on synthetic thermal scenarios", ""]
    out += [
        "### Occluded person instances (section 7)",
        "",
        "| scenario | occluded | instances | share |",
        "|---|---|---|---|",
        f"| paper (all 53 tracks) | {ds['occluded_instances']} | {ds['person_instances']} | "
        f"{_f(ds['occluded_share'])} |",
    ]
    for n, r in data["occlusion"].items():
        out.append(f"| {n} | {r['occluded']} | {r['instances']} | {_f(r['share'])} |")
    out.append("")
    ab = data["ablation"]
    out += _ablation_table(
        "Tracker ablation, lit scenarios summed (mean [min, max] over seeds)", ab["lit_total"]
    )
    for n, rows in ab["per_scenario"].items():
        out += _ablation_table(f"Tracker ablation: {n}", rows)
    for name, why in ab["not_run"].items():
        out.append(f"- variant {name} not run: {why}")
    out += ["", "### Occlusion classifier per feature group (section 5), held-out pairs", ""]
    out += ["| group | accuracy (light) | back half hidden (light) | accuracy (dark) | stumps |"]
    out += ["|---|---|---|---|---|"]
    for g, r in data["classifier"]["light"].items():
        d = data["classifier"]["dark"][g]
        out.append(
            f"| {g} | {_f(r['accuracy'])} ({r['pairs']} pairs) | {_f(r['accuracy_half_hidden'])} "
            f"({r['pairs_half_hidden']}) | {_f(d['accuracy'])} | {r['stumps']} |"
        )
    rt = data["real_time"]
    out += [
        "",
        f"Real time: {rt['fps']:.1f} frames per CPU second "
        f"({1000 * rt['cpu_s_per_frame']:.1f} ms per frame over {rt['frames']} frames).",
        "",
        "### Claims",
        "",
    ]
    for c in claims:
        state = "not judged" if c.held is None else ("held" if c.held else "NOT held")
        out.append(f"- [{state}] {c.sentence} ({c.source}): {c.evidence}")
    return "\n".join(out) + "\n"
