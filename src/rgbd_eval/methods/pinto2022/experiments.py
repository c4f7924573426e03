"""Seed 001's experiments (V-C, V-D) on the synthetic Re-ID scenarios (``rgbd-eval reproduce pinto2022``).

- Table II: the default parameters on the seven dataset scenarios (Table I), per sequence
  and in total (counts summed, then ratios derived);
- Table III: the five (T_lower, T_upper) pairs, mapped from TriNet units to the embedder's;
- Figures 9 and 10: sweeps of T_recover and S_max (the seed plots five values of each and
  prints none; the values here are ours, around the seed's choice);
- Table IV: the held-out test scenario beside the dataset total;
- the claims of V-C, V-D, V-F and VI, each checked against the measured numbers.

Everything runs on every scenario seed of ``paper.yaml`` (``seeds``): each seed re-renders
the eight scenes with other people and noise (beside the given recordings, named
``<scene>-seed<seed>.mcap``). Each claim is judged on every seed and the verdict taken over
them (:func:`rgbd_eval.verdicts.over_runs`: held on every seed, failed on every seed, else
inconclusive), with the spread of what it measured.

Detections are computed once per scenario and cached; every sweep point re-runs tracking
and scoring only (:mod:`rgbd_eval.sweep`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rgbd_eval.components import create_detector, create_tracker
from rgbd_eval.config import load_config, load_paper
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.errors import ConfigError
from rgbd_eval.machine import machine_info
from rgbd_eval.methods.pinto2022 import DATASET, TEST
from rgbd_eval.methods.pinto2022.tracker_config import Pinto2022TrackerConfig
from rgbd_eval.metrics import Counts, summarize, total
from rgbd_eval.pipeline import open_for, sequence_name
from rgbd_eval.plugins import ReproduceOptions, ReproduceResult
from rgbd_eval.recordings import Job, ensure_recordings
from rgbd_eval.sweep import point_configs, run_sweep
from rgbd_eval.verdicts import (
    ClaimOverSeeds,
    Spread,
    Verdict,
    claims_over_seeds,
    spreads_json,
    tally,
)

if TYPE_CHECKING:
    from distributed import Client

#: Table III's pairs, TriNet units (V-C2).
TRINET_PAIRS = ((100, 700), (100, 1000), (300, 700), (300, 1000), (400, 600))
#: Figure 9: T_recover values (TriNet units; ours: the seed plots five without printing them).
TRINET_RECOVER = (200, 300, 400, 500, 600)
#: Figure 10: S_max values (ours, around the seed's 0.05).
S_MAX_VALUES = (0.01, 0.025, 0.05, 0.1, 0.2)
#: The seed's values (eqs. 17-18), TriNet units.
SEED_T_LOWER, SEED_T_RECOVER, SEED_T_UPPER = 300.0, 400.0, 700.0
#: The seed's frame rate with a GPU (V-C1).
SEED_FPS = 33.0


def trinet_to_units(value: float, t_lower: float, t_recover: float, t_upper: float) -> float:
    """Map a TriNet distance into the embedder's units, piecewise linearly through
    (0, 0), (300, t_lower), (400, t_recover), (700, t_upper), extrapolated with the last slope."""
    xs = (0.0, SEED_T_LOWER, SEED_T_RECOVER, SEED_T_UPPER)
    ys = (0.0, t_lower, t_recover, t_upper)
    for k in range(1, len(xs)):
        if value <= xs[k] or k == len(xs) - 1:
            x0, x1, y0, y1 = xs[k - 1], xs[k], ys[k - 1], ys[k]
            return y0 + (y1 - y0) * (value - x0) / (x1 - x0)
    return value  # not reached: the loop returns at its last segment


@dataclass(frozen=True)
class Claim:
    """One claim judged on one seed's tables; ``measured`` names the values it compared."""

    key: str
    source: str
    text: str
    held: bool
    evidence: str
    measured: dict[str, float] = field(default_factory=dict)


def _spread(rows: Mapping[Any, Mapping[str, Any]], key: str) -> float:
    values = [float(r[key]) for r in rows.values() if r.get(key) is not None]
    return max(values) - min(values) if values else 0.0


def _errors(row: Mapping[str, Any]) -> int:
    return int(row["id_switches"] or 0) + int(row["recall_errors"] or 0)


def _relative_range(values: Sequence[float]) -> float:
    """``(max - min) / mean`` (0 when there is nothing to compare)."""
    mean = sum(values) / len(values) if values else 0.0
    return (max(values) - min(values)) / mean if mean > 0 else 0.0


def _strictly_fewest(errors: Mapping[str, int], key: str) -> bool:
    return key in errors and all(v > errors[key] for k, v in errors.items() if k != key)


def check_claims(paper: Mapping[str, Any], tables: Mapping[str, Mapping[str, Any]]) -> list[Claim]:
    """The seed's claims (``paper.yaml``: ``claims``, thresholds beside each sentence, and the
    published ``tables``) judged on one seed's measured tables: ``9`` (T_recover sweep),
    ``10`` (S_max), ``III`` (pairs), ``II`` (per scenario and ``total``) and, when the test
    scenario ran, ``IV`` (without it, the claims that need it are left out)."""
    spec: Mapping[str, Mapping[str, Any]] = paper["claims"]
    published = paper["tables"]
    out: list[Claim] = []

    def claim(key: str, held: bool, evidence: str, **measured: float) -> None:
        c = spec[key]
        out.append(Claim(key, str(c["source"]), str(c["sentence"]), held, evidence, measured))

    recover, s_max, pairs = tables["9"], tables["10"], tables["III"]
    c = spec["barely_move"]
    spreads = {
        name: (_spread(rows, "mota"), _spread(rows, "motp"))
        for name, rows in (("T_recover", recover), ("S_max", s_max))
    }
    claim(
        "barely_move",
        all(
            mota <= float(c["max_mota_spread"]) and motp <= float(c["max_motp_spread_m"])
            for mota, motp in spreads.values()
        ),
        "; ".join(
            f"{n}: MOTA range {100 * mota:.2f} pp, MOTP range {100 * motp:.2f} cm"
            for n, (mota, motp) in spreads.items()
        ),
        mota_range=max(m for m, _ in spreads.values()),
        motp_range_m=max(p for _, p in spreads.values()),
    )
    c = spec["errors_move"]
    need = float(c["min_relative_range"])
    recall = [float(r["recall_errors"] or 0) for r in recover.values()]
    errors = {
        n: [float(_errors(r)) for r in rows.values()]
        for n, rows in (("T_recover", recover), ("S_max", s_max))
    }
    claim(
        "errors_move",
        _relative_range(recall) >= need
        and all(_relative_range(v) >= need for v in errors.values()),
        f"recall errors over T_recover {[int(v) for v in recall]} (range {_relative_range(recall):.2f} "
        f"of the mean); ID switches + recall errors "
        + "; ".join(
            f"{n} {[int(x) for x in v]} (range {_relative_range(v):.2f})" for n, v in errors.items()
        )
        + f"; needed >= {need:g} of the mean",
        recall_range=_relative_range(recall),
        errors_range=min(_relative_range(v) for v in errors.values()),
    )
    pair_errors = {k: _errors(v) for k, v in pairs.items()}
    claim(
        "chosen_pair",
        _strictly_fewest(pair_errors, "300,700"),
        ", ".join(f"({k}): {v}" for k, v in pair_errors.items()),
        errors=float(pair_errors.get("300,700", math.nan)),
    )
    for key, rows, value in (("recover_best", recover, "400"), ("s_max_best", s_max, "0.05")):
        errs = {k: _errors(v) for k, v in rows.items()}
        claim(
            key,
            _strictly_fewest(errs, value),
            ", ".join(f"{k}: {v}" for k, v in errs.items()),
            errors=float(errs.get(value, math.nan)),
        )
    for key, row, paper_mota in (
        (
            "table_ii_total",
            tables["II"].get("total"),
            published["II"]["rows"]["total"]["mota_pct"] / 100.0,
        ),
        (
            "table_iv_test",
            tables.get("IV", {}).get("test_sequence"),
            published["IV"]["rows"]["test_sequence"]["mota_pct"] / 100.0,
        ),
    ):
        gap = float(spec[key]["max_gap"])
        if row is None or row.get("mota") is None:
            continue  # not measured (the test scenario was not given): no verdict
        mota = float(row["mota"])
        claim(
            key,
            abs(mota - paper_mota) <= gap,
            f"MOTA {100 * mota:.2f} % against the paper's {100 * paper_mota:.2f} % (within "
            f"{100 * gap:g} points needed)",
            mota=mota,
        )
    _check_more(spec, published, tables, claim)
    return out


def _check_more(
    spec: Mapping[str, Mapping[str, Any]],
    published: Mapping[str, Any],
    tables: Mapping[str, Mapping[str, Any]],
    claim: Callable[..., None],
) -> None:
    """Tables II and IV row by row, V-D's comparison of the test with the dataset, VI's
    bounds and V-F's changed clothes (claims without a measured row are left out)."""
    ii, rows_ii = tables["II"], published["II"]["rows"]
    test = tables.get("IV", {}).get("test_sequence")
    total = ii.get("total")
    c = spec["table_ii_sequences"]
    gaps = {
        n: float(ii[n]["mota"]) - rows_ii[n]["mota_pct"] / 100.0
        for n in DATASET
        if n in ii and ii[n].get("mota") is not None
    }
    if gaps:
        worst = max(gaps.values(), key=abs)
        claim(
            "table_ii_sequences",
            all(abs(g) <= float(c["max_gap"]) for g in gaps.values()),
            ", ".join(
                f"{n} {100 * float(ii[n]['mota']):.2f} % (paper {rows_ii[n]['mota_pct']:.2f})"
                for n in gaps
            )
            + f"; within {100 * float(c['max_gap']):g} points needed",
            worst_gap=worst,
        )
    for key, row, paper_row in (
        ("table_ii_motp", total, rows_ii["total"]),
        ("table_iv_motp", test, published["IV"]["rows"]["test_sequence"]),
    ):
        if row is None or row.get("motp") is None:
            continue
        motp, theirs = float(row["motp"]), float(paper_row["motp_m"])
        gap = float(spec[key]["max_gap_m"])
        claim(
            key,
            abs(motp - theirs) <= gap,
            f"MOTP {motp:.3f} m against the paper's {theirs:.3f} m (within {gap:g} m needed)",
            motp_m=motp,
        )
    if test is not None and total is not None and test.get("mota") is not None:
        gap = float(spec["test_close_to_dataset"]["max_gap"])
        diff = float(test["mota"]) - float(total["mota"])
        claim(
            "test_close_to_dataset",
            abs(diff) <= gap,
            f"test {100 * float(test['mota']):.2f} % against the dataset's "
            f"{100 * float(total['mota']):.2f} % ({100 * diff:+.2f} points; within "
            f"{100 * gap:g} needed)",
            difference=diff,
        )
        if test.get("motp") is not None and total.get("motp") is not None:
            diff_m = float(test["motp"]) - float(total["motp"])
            claim(
                "test_motp_lower",
                diff_m < 0.0,
                f"test {float(test['motp']):.3f} m against the dataset's "
                f"{float(total['motp']):.3f} m",
                difference_m=diff_m,
            )
    if total is not None and total.get("mota") is not None:
        floor = float(spec["mota_above_85"]["min_mota"])
        motas = {"dataset": float(total["mota"])}
        if test is not None and test.get("mota") is not None:
            motas["test"] = float(test["mota"])
        claim(
            "mota_above_85",
            all(m > floor for m in motas.values()),
            ", ".join(f"{n} {100 * m:.2f} %" for n, m in motas.items())
            + f"; above {100 * floor:g} % needed (KTP not reproduced)",
            lowest=min(motas.values()),
        )
        ceiling = float(spec["motp_below_0_4"]["max_motp_m"])
        motps = {n: float(r["motp"]) for n, r in ii.items() if r.get("motp") is not None}
        if test is not None and test.get("motp") is not None:
            motps["test_sequence"] = float(test["motp"])
        worst_motp = max(motps.values()) if motps else math.nan
        claim(
            "motp_below_0_4",
            bool(motps) and worst_motp < ceiling,
            f"largest MOTP {worst_motp:.3f} m ("
            + ", ".join(f"{n} {m:.3f}" for n, m in motps.items())
            + f"); below {ceiling:g} m needed",
            largest_m=worst_motp,
        )
    clothes = {
        n: float(ii[n]["id_switch_rate"])
        for n in ("changing_clothes_1", "changing_clothes_2")
        if n in ii and ii[n].get("id_switch_rate") is not None
    }
    if clothes:
        top = float(spec["clothes_id_switches"]["max_rate"])
        claim(
            "clothes_id_switches",
            all(r <= top for r in clothes.values()),
            ", ".join(f"{n} {100 * r:.2f} %" for n, r in clothes.items())
            + f" of objects seen; at most {100 * top:g} % needed",
            largest=max(clothes.values()),
        )


def _summary(counts: Counts) -> dict[str, Any]:
    return dict(summarize(counts))


def _sweep(
    recordings: Mapping[str, Path],
    points: Sequence[dict[str, Any]],
    base: Mapping[str, Any],
    options: ReproduceOptions,
) -> list[dict[str, Counts]]:
    """Counts per point (in order) and scenario name."""
    configs = point_configs(base, [], points)
    result = run_sweep(list(recordings.values()), points, configs, options.client, options.cache)
    names = {sequence_name(p): n for n, p in recordings.items()}
    out: list[dict[str, Counts]] = [{} for _ in points]
    for r in result.records:
        out[points.index(r.point)][names[r.sequence]] = r.counts
    return out


@dataclass(frozen=True)
class FrameRate:
    """Detection + tracking speed on a few frames of one recording, in this process.

    ``cpu_fps`` is from the CPU time of the thread that detects and tracks (OpenCV held to that
    one thread meanwhile; onnxruntime runs there with one intra-op thread): what the pipeline
    gives with a core to itself, whatever else loads the machine or runs in this process (a
    Dask worker's threads); ``wall_fps`` falls with that load.
    """

    frames: int
    cpu_fps: float
    wall_fps: float


def frame_rate(recording: Path, frames: int = 60) -> FrameRate:
    """Frames per second of detection + tracking on ``frames`` frames, in this thread."""
    import cv2

    config = load_config(method="pinto2022")
    detector = create_detector(config)
    tracker = create_tracker(config)
    cpu = wall = 0.0
    done = 0
    cv_threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        for frame in open_for(recording, config).frames():
            start, start_cpu = time.perf_counter(), time.thread_time()
            tracker.update(frame.stamp_ns, detector.detect(frame))
            wall += time.perf_counter() - start
            cpu += time.thread_time() - start_cpu
            done += 1
            if done == frames:
                break
    finally:
        cv2.setNumThreads(cv_threads)
    return FrameRate(done, done / cpu if cpu > 0 else 0.0, done / wall if wall > 0 else 0.0)


def seeded_recordings(
    recordings: Mapping[str, Path],
    seed: int,
    say: Callable[[str], None],
    client: Client | None = None,
) -> dict[str, Path]:
    """The given scenes rendered with scenario seed ``seed`` beside their recordings
    (:func:`rgbd_eval.sim.synth.ensure_scenario`: ``<scene>-seed<seed>.mcap``, rendered
    only when absent or out of date; on ``client``'s workers when given)."""
    jobs: list[Job] = [
        (scenarios_dir() / "pinto2022" / f"{name}.yaml", path.parent, seed)
        for name, path in recordings.items()
    ]
    return dict(zip(recordings, ensure_recordings(jobs, client, say), strict=True))


def measure(
    recordings: Mapping[str, Path], options: ReproduceOptions, say: Callable[[str], None]
) -> dict[str, Any]:
    """Tables II, III, IV and Figures 9 and 10 on one seed's recordings."""
    config = load_config(method="pinto2022")
    base = config.model_dump(mode="json")
    t = config.tracker
    if not isinstance(t, Pinto2022TrackerConfig):
        raise ConfigError(f"method pinto2022 has tracker {t.name!r}, expected pinto2022")

    def units(v: float) -> float:
        return round(trinet_to_units(v, t.t_lower, t.t_recover, t.t_upper), 4)

    dataset = {n: recordings[n] for n in DATASET if n in recordings}
    tables: dict[str, Any] = {}
    say("Table II: default parameters on the dataset scenarios")
    (default,) = _sweep(dataset, [{}], base, options)
    tables["II"] = {n: _summary(default[n]) for n in DATASET if n in default}
    tables["II"]["total"] = _summary(total(default.values()))
    say("Table III: (T_lower, T_upper) pairs mapped from TriNet units")
    pairs = [{"tracker.t_lower": units(a), "tracker.t_upper": units(b)} for a, b in TRINET_PAIRS]
    tables["III"] = {
        f"{a},{b}": {
            **_summary(total(c.values())),
            "t_lower": p["tracker.t_lower"],
            "t_upper": p["tracker.t_upper"],
        }
        for (a, b), p, c in zip(
            TRINET_PAIRS, pairs, _sweep(dataset, pairs, base, options), strict=True
        )
    }
    say("Figure 9: T_recover sweep")
    recover = [{"tracker.t_recover": units(v)} for v in TRINET_RECOVER]
    tables["9"] = {
        str(v): {**_summary(total(c.values())), "t_recover": p["tracker.t_recover"]}
        for v, p, c in zip(
            TRINET_RECOVER, recover, _sweep(dataset, recover, base, options), strict=True
        )
    }
    say("Figure 10: S_max sweep")
    s_points = [{"tracker.s_max": v} for v in S_MAX_VALUES]
    tables["10"] = {
        str(v): _summary(total(c.values()))
        for v, c in zip(S_MAX_VALUES, _sweep(dataset, s_points, base, options), strict=True)
    }
    if TEST in recordings:
        say("Table IV: the held-out test scenario")
        (test,) = _sweep({TEST: recordings[TEST]}, [{}], base, options)
        tables["IV"] = {
            "test_sequence": _summary(test[TEST]),
            "reid_dataset": tables["II"]["total"],
        }
    return tables


#: One claim of the paper over the seeds.
ClaimVerdict = ClaimOverSeeds[Claim]


def verdicts(per_seed: Mapping[int, Sequence[Claim]]) -> list[ClaimVerdict]:
    """Each claim over the seeds (:func:`rgbd_eval.verdicts.claims_over_seeds`), with the
    spread of each value it measured. A claim judged on only some seeds (its row missing on
    others) is inconclusive."""
    return claims_over_seeds(per_seed, lambda c: c.key)


def mean_tables(per_seed: Sequence[Mapping[str, Mapping[str, Any]]]) -> dict[str, Any]:
    """Every table row's numbers as their mean over the seeds, with ``<key>_min`` and
    ``<key>_max`` beside MOTA and MOTP (a row missing on a seed is averaged where present)."""
    values: dict[str, dict[str, dict[str, list[float]]]] = {}
    for tables in per_seed:
        for tab, rows in tables.items():
            for row, cells in rows.items():
                cell = values.setdefault(tab, {}).setdefault(row, {})
                for key, v in cells.items():
                    if isinstance(v, int | float) and not isinstance(v, bool):
                        cell.setdefault(key, []).append(float(v))
    result: dict[str, Any] = {}
    for tab, rows in values.items():
        result[tab] = {}
        for row, cell in rows.items():
            out: dict[str, float] = {}
            for key, vs in cell.items():
                sp = Spread.of(vs)
                out[key] = sp.mean
                if key in ("mota", "motp"):
                    out[f"{key}_min"], out[f"{key}_max"] = sp.low, sp.high
            result[tab][row] = out
    return result


def _prefixed(say: Callable[[str], None], prefix: str) -> Callable[[str], None]:
    return lambda message: say(prefix + message)


def run(recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    """Every experiment of seed 001 section V that the given scenarios allow, on every
    scenario seed of ``paper.yaml``; each claim judged over the seeds."""
    say = options.progress
    start = time.perf_counter()
    paper = paper_values()
    seeds = [int(s) for s in paper["seeds"]]
    per_seed: dict[int, dict[str, Any]] = {}
    first: dict[str, Path] = {}
    for k, seed in enumerate(seeds):
        say(f"scenario seed {seed} ({k + 1} of {len(seeds)})")
        seeded = seeded_recordings(recordings, seed, say, options.client)
        first = first or seeded
        per_seed[seed] = measure(seeded, options, _prefixed(say, f"seed {seed}: "))
    say("frame rate: detection + tracking on one process")
    dataset = [first[n] for n in DATASET if n in first]
    rate = frame_rate(first.get(TEST) or dataset[0])
    judged = {s: check_claims(paper, tables) for s, tables in per_seed.items()}
    over = verdicts(judged)
    timing = {
        "frame_rate_hz": rate.cpu_fps,
        "frame_rate_wall_hz": rate.wall_fps,
        "machine": machine_info()["cpu"] or "unknown CPU",
        "paper_frame_rate_hz": SEED_FPS,
        "paper_hardware": "GTX 1060 GPU (V-A)",
    }
    data = {
        "seeds": seeds,
        "tables": mean_tables(list(per_seed.values())),
        "tables_per_seed": {str(s): t for s, t in per_seed.items()},
        "frame_rate_hz": rate.cpu_fps,
        "frame_rate_wall_hz": rate.wall_fps,
        "timing": timing,
        "claims": [
            {
                "key": c.key,
                "text": c.judged.text,
                "source": c.judged.source,
                "verdict": c.verdict.value,
                "held": c.verdict is Verdict.HELD,
                "per_seed": {str(s): j.held for s, j in c.per_seed.items()},
                "evidence": (f"{_spreads(c)} | " if c.spreads else "")
                + "; ".join(
                    f"seed {s}: {'held' if j.held else 'failed'}: {j.evidence}"
                    for s, j in c.per_seed.items()
                ),
                "measured": spreads_json(c.spreads, {s: j.measured for s, j in c.per_seed.items()}),
            }
            for c in over
        ],
        "seconds": time.perf_counter() - start,
    }
    return ReproduceResult(
        markdown=render(per_seed, over, paper, timing),
        data=data,
        claims=tuple((c.judged.text, c.verdict) for c in over),
    )


def paper_values() -> dict[str, Any]:
    """The published numbers (``methods/pinto2022/paper.yaml``)."""
    return load_paper("pinto2022")


#: Columns of the tables: (title, summary key, paper key, scale, decimals).
_COLUMNS = (
    ("MOTA %", "mota", "mota_pct", 100.0, 2),
    ("MOTP m", "motp", "motp_m", 1.0, 3),
    ("misses %", "fn_rate", "misses_pct", 100.0, 2),
    ("FP %", "fp_rate", "false_positives_pct", 100.0, 2),
    ("ID sw.", "id_switches", "id_switches", 1.0, 0),
    ("recall err.", "recall_errors", "recall_errors", 1.0, 0),
)


def _fmt(value: Any, scale: float, decimals: int) -> str:
    if value is None:
        return "-"
    return f"{float(value) * scale:.{decimals}f}"


def _table(
    title: str, rows: Mapping[str, Mapping[str, Any]], paper: Mapping[str, Any]
) -> list[str]:
    lines = [
        f"### {title}",
        "",
        "| row | " + " | ".join(f"{c[0]} (paper / ours)" for c in _COLUMNS) + " |",
    ]
    lines.append("|---" * (len(_COLUMNS) + 1) + "|")
    for name, ours in rows.items():
        theirs = paper.get(name, {})
        cells = [
            f"{_fmt(theirs.get(pk), 1.0, d)} / {_fmt(ours.get(k), scale, d)}"
            for _, k, pk, scale, d in _COLUMNS
        ]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return [*lines, ""]


def _spreads(c: ClaimVerdict) -> str:
    return "; ".join(f"{name} {sp.text('.4g')}" for name, sp in c.spreads.items())


def render(
    per_seed: Mapping[int, Mapping[str, Any]],
    claims: Sequence[ClaimVerdict],
    paper: Mapping[str, Any],
    timing: Mapping[str, Any] | None = None,
) -> str:
    """Markdown: the claims over the seeds (verdict, spread, each seed's evidence), then each
    seed's tables, paper beside measured (the sweeps measured only: the seed prints no values)."""
    published = paper.get("tables", {})
    seeds = list(per_seed)
    out = [
        "# pinto2022: seed 001 section V on the synthetic Re-ID scenarios",
        "",
        f"{len(seeds)} scenario seeds ({', '.join(map(str, seeds))}): each draws other people, "
        "paths and sensor noise for the eight scenes. A claim is held when it holds on every seed, "
        "failed when it fails on every seed, else inconclusive; the spread (mean [min, max]) "
        "of what it measured is beside it.",
        "",
        "## Claims (over the seeds)",
        "",
        "| claim | verdict | measured: mean [min, max] | per seed |",
        "|---|---|---|---|",
    ]
    for c in claims:
        per = ", ".join(f"{s}: {'held' if j.held else 'failed'}" for s, j in c.per_seed.items())
        out.append(
            f'| {c.judged.source}: "{c.judged.text}" | {c.verdict.value} | '
            f"{_spreads(c) or '-'} | {per} |"
        )
    out += ["", f"claims: {tally([c.verdict for c in claims])}", ""]
    for c in claims:
        out.append(f"- {c.key} ({c.verdict.value}):")
        out += [f"  - seed {s}: {j.evidence}" for s, j in c.per_seed.items()]
    out.append("")
    if timing is not None:
        out += [
            "## Frame rate: a measurement, not a claim",
            "",
            "| | paper | ours |",
            "|---|---|---|",
            f"| detection + tracking | {timing['paper_frame_rate_hz']:g} Hz "
            f"({timing['paper_hardware']}) | {timing['frame_rate_hz']:.1f} frames per CPU "
            f"second, one core ({timing['machine']}) |",
            "",
        ]
    for seed, tables in per_seed.items():
        out += [f"## Seed {seed}", ""]
        out += _table(
            "Table II (per scenario)", tables["II"], published.get("II", {}).get("rows", {})
        )
        if "III" in tables:
            out += _table(
                "Table III ((T_lower, T_upper) in TriNet units, mapped)",
                tables["III"],
                published.get("III", {}).get("rows", {}),
            )
        for key, title in (
            ("9", "Figure 9 (T_recover, TriNet units)"),
            ("10", "Figure 10 (S_max)"),
        ):
            if key in tables:
                out += _table(title, tables[key], {})
        if "IV" in tables:
            out += _table(
                "Table IV (held-out test scenario)",
                {
                    k: tables["IV"][k]
                    for k in ("test_sequence", "reid_dataset")
                    if k in tables["IV"]
                },
                published.get("IV", {}).get("rows", {}),
            )
    return "\n".join(out) + "\n"
