"""Breakdowns, intervals and threshold curves of a scored run, for ``report.json``/``.md``/``.html``.

:func:`analyse` computes, per scored sequence and over all of them:

- the 95 % interval of every headline metric (:mod:`rgbd_eval.metrics.bootstrap`);
- the breakdowns by distance, visibility and robot motion, per person and per gap
  (:mod:`rgbd_eval.metrics.breakdowns`), each band with its intervals;
- the "where it fails" summary: the three bands with the most errors per frame;
- with ``--curve``, the scores against the confidence threshold (:mod:`rgbd_eval.metrics.curves`).

:func:`annotate` adds it to a report's JSON (new keys only: ``intervals``,
``breakdowns``, ``persons``, ``gaps``, ``block_length`` and ``frames_file`` per
sequence; ``intervals``, ``breakdowns`` and ``gaps`` in ``overall``; ``analysis`` at the
top), :func:`markdown` gives its Markdown sections, and :func:`frames_files` the
``<name>.frames.npz`` per sequence (the per-frame table ``compare --significance`` needs).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from rgbd_eval.config import EvaluationConfig, Gating
from rgbd_eval.metrics import bootstrap as boot
from rgbd_eval.metrics import breakdowns as bd
from rgbd_eval.metrics import curves
from rgbd_eval.metrics.clear import SequenceScores
from rgbd_eval.types import GroundTruthObject, Pose, TrackOutput

if TYPE_CHECKING:
    from rgbd_eval.pipeline import SequenceResult
    from rgbd_eval.report.scoring import ScoredSequence

#: The suffix of the per-frame table beside a report.
FRAMES_SUFFIX = ".frames.npz"
#: How many bands the "where it fails" summary names.
WORST_BANDS = 3
#: The metrics whose intervals the tables show, with their headers.
INTERVAL_COLUMNS: tuple[tuple[str, str], ...] = (
    ("mota", "MOTA"),
    ("motp", "MOTP"),
    ("idf1", "IDF1"),
    ("hota", "HOTA"),
    ("fp_rate", "FP"),
    ("fn_rate", "FN"),
    ("main_tr", "Main Tr."),
    ("all_tr", "All Tr."),
    ("id_switches", "ID Sw."),
)
#: The band metrics with intervals.
BAND_METRICS = ("mota", "fn_rate", "fp_rate", "id_switch_rate")
BREAKDOWN_TITLES = {
    bd.DISTANCE: "Distance from the camera",
    bd.VISIBILITY: "Visibility of the person",
    bd.MOTION: "Robot motion",
}

Interval = tuple[float, float] | None


@dataclass(frozen=True)
class SequenceInput:
    """One scored sequence as the analysis needs it."""

    name: str
    scores: SequenceScores
    gt_frames: Sequence[Sequence[GroundTruthObject]]
    track_frames: Sequence[Sequence[TrackOutput]]
    camera: bd.CameraPath | None
    #: Why there is no camera path (when ``camera`` is None).
    camera_note: str = ""
    #: The recording frame of the first scored frame (frame ``k`` of the table is
    #: ``first_frame + k``; ``run`` scores only the annotated span).
    first_frame: int = 0


def inputs_of_run(results: Sequence[SequenceResult]) -> list[SequenceInput]:
    """The scored sequences of a run (camera from the recording's odometry and tf), each cut
    to the frames it was scored on: the ground truth's annotated span
    (:class:`~rgbd_eval.pipeline.GroundTruthMatch`), as its per-frame table is."""
    out = []
    for r in results:
        if r.scores is None or r.ground_truth is None:
            continue
        gt = r.ground_truth
        first, last = gt.span if gt.span is not None else (0, len(gt.frames) - 1)
        scored = slice(first, last + 1)
        poses = r.detections.camera_poses
        camera = None
        if poses:
            camera = bd.CameraPath.from_poses(
                r.detections.stamps_ns[scored],
                list(poses[scored]),
                f"the recording's odometry and tf ({r.info.world_frame})",
                odometry=r.info.has_odometry,
            )
        note = "" if camera is not None else "no camera poses were kept"
        out.append(
            SequenceInput(
                r.name, r.scores, gt.frames[scored], r.tracks[scored], camera, note, first
            )
        )
    return out


def inputs_of_score(sequences: Sequence[ScoredSequence]) -> list[SequenceInput]:
    """The sequences of ``score`` (a camera only for tracks recorded in a sensor's frame)."""
    out = []
    for s in sequences:
        poses: Sequence[Pose | None] = s.aligned.sensor_poses
        camera, note = None, ""
        if not poses:
            note = "tracker output in a text file has no camera pose"
        elif all(p is None for p in poses):
            note = "the tracks are published in the world frame: no sensor pose in the tf"
        else:
            camera = bd.CameraPath.from_poses(
                s.aligned.stamps_ns, poses, "the tf of the tracks' frame"
            )
        out.append(SequenceInput(s.name, s.scores, s.aligned.gt, s.aligned.tracks, camera, note))
    return out


@dataclass(frozen=True)
class Part:
    """The analysis of one sequence, or of all summed (``name`` 'overall')."""

    name: str
    intervals: dict[str, Interval]
    breakdowns: tuple[bd.Breakdown, ...]
    band_intervals: dict[tuple[str, str], dict[str, Interval]]
    gaps: tuple[bd.GapBin, ...]
    persons: tuple[bd.Person, ...] = ()
    block_length: int | None = None
    frames: int = 0


@dataclass(frozen=True)
class Analysis:
    """Everything :func:`analyse` found."""

    settings: bd.Settings
    replicates: int
    seed: int
    sequences: tuple[Part, ...]
    overall: Part | None
    worst: tuple[dict[str, Any], ...]
    curve: curves.Curve | None
    tables: tuple[tuple[str, bytes], ...]
    gating: Gating
    #: The cap of the curve's thresholds (None: no curve asked for).
    curve_points: int | None = None


def _band_intervals(
    replicates: boot.Replicates | None, breakdowns: Sequence[bd.Breakdown]
) -> dict[tuple[str, str], dict[str, Interval]]:
    """The intervals of every band that has ground truth, all bands at once."""
    bands = [
        (b.kind, band.label, b.with_fp)
        for b in breakdowns
        if b.available
        for band in b.bands
        if band.counts.num_gt > 0
    ]
    if replicates is None or not bands:
        return {}
    metrics = bd.band_replicate_metrics(
        lambda field: replicates.sums([f"{kind}/{label}/{field}" for kind, label, _ in bands]),
        np.array([with_fp for _, _, with_fp in bands]),
    )
    values = {
        f"{kind}/{label}/{name}": series[:, j]
        for j, (kind, label, with_fp) in enumerate(bands)
        for name, series in metrics.items()
        if with_fp or name != "fp_rate"
    }
    out: dict[tuple[str, str], dict[str, Interval]] = {}
    for key, interval in boot.intervals_of(values).items():
        kind, label, metric = key.split("/")
        out.setdefault((kind, label), {})[metric] = interval
    return out


def _series(b: bd.SequenceBreakdowns, settings: bd.Settings, frames: int) -> dict[str, Any]:
    """Every band's per-frame counts as bootstrap columns, zeros for unavailable ones."""
    zero = np.zeros(frames, dtype=np.int64)
    labels = {
        bd.DISTANCE: bd.distance_labels(settings.distance_bands),
        bd.VISIBILITY: list(bd.VISIBILITY_LABELS),
        bd.MOTION: list(bd.MOTION_STATES),
    }
    present = bd.band_series(b)
    return {
        f"{kind}/{label}/{field}": present.get(f"{kind}/{label}/{field}", zero)
        for kind, names in labels.items()
        for label in names
        for field in ("num_gt", "num_matches", "fp", "id_switches")
    }


def analyse(
    items: Sequence[SequenceInput],
    evaluation: EvaluationConfig,
    curve_points: int | None = None,
) -> Analysis:
    """Breakdowns and intervals of every sequence and of all summed; the curve when
    ``curve_points`` is given (its cap of thresholds)."""
    settings = bd.Settings.of(evaluation)
    count, seed = evaluation.bootstrap_replicates, evaluation.bootstrap_seed
    parts: list[Part] = []
    all_replicates: list[boot.Replicates] = []
    all_breakdowns: list[bd.SequenceBreakdowns] = []
    tables: list[tuple[str, bytes]] = []
    for item in items:
        table = item.scores.table
        b = bd.breakdowns(
            table,
            item.gt_frames,
            item.track_frames,
            item.camera,
            settings,
            item.scores.counts.convention,
        )
        if item.camera is None:
            b = bd.SequenceBreakdowns(
                bd.not_available(bd.DISTANCE, item.camera_note),
                b.visibility,
                bd.not_available(bd.MOTION, item.camera_note),
                b.persons,
                b.gaps,
            )
        reps = None
        block = boot.block_length(boot.frame_errors(table))
        if count > 0:
            extra = _series(b, settings, table.num_frames)
            reps = boot.replicates(table, item.name, count, seed, extra, block)
            all_replicates.append(reps)
        all_breakdowns.append(b)
        parts.append(
            Part(
                item.name,
                boot.intervals(reps) if reps is not None else {},
                b.all(),
                _band_intervals(reps, b.all()),
                b.gaps,
                _shifted(b.persons, item.first_frame),
                block,
                table.num_frames,
            )
        )
        tables.append((item.name, table.save()))
    overall = None
    if len(items) > 1:
        summed = [_sum_breakdowns([x.all()[k] for x in all_breakdowns]) for k in range(3)]
        reps = boot.total_replicates(all_replicates) if all_replicates else None
        gaps = tuple(sum(g[1:], g[0]) for g in zip(*(x.gaps for x in all_breakdowns), strict=True))
        overall = Part(
            "overall",
            boot.intervals(reps) if reps is not None else {},
            tuple(summed),
            _band_intervals(reps, summed),
            gaps,
            frames=sum(p.frames for p in parts),
        )
    curve = None
    if curve_points is not None:
        curve = curves.sweep(
            [(i.gt_frames, i.track_frames) for i in items], evaluation, curve_points
        )
    summary = overall if overall is not None else (parts[0] if parts else None)
    worst = worst_bands(summary.breakdowns) if summary is not None else ()
    return Analysis(
        settings,
        count,
        seed,
        tuple(parts),
        overall,
        worst,
        curve,
        tuple(tables),
        evaluation.gating,
        curve_points,
    )


def _shifted(persons: Sequence[bd.Person], first: int) -> tuple[bd.Person, ...]:
    """``persons`` with their switches' frames counted from the recording's first frame."""
    if not first:
        return tuple(persons)
    return tuple(
        replace(p, switches=tuple(replace(s, frame=s.frame + first) for s in p.switches))
        for p in persons
    )


def _sum_breakdowns(items: Sequence[bd.Breakdown]) -> bd.Breakdown:
    available = [b for b in items if b.available]
    if not available:
        reasons = sorted({b.reason for b in items})
        return bd.not_available(items[0].kind, "; ".join(reasons))
    out = available[0]
    for b in available[1:]:
        out = out + b
    if len(available) < len(items):
        missing = len(items) - len(available)
        out = bd.Breakdown(
            out.kind,
            out.bands,
            out.with_fp,
            True,
            f"summed over the {len(available)} sequences that have it ({missing} have not)",
            out.unassigned_gt,
            out.unassigned_fp,
        )
    return out


def worst_bands(breakdowns: Sequence[bd.Breakdown]) -> tuple[dict[str, Any], ...]:
    """The :data:`WORST_BANDS` bands with the most errors per frame (at least
    :data:`~rgbd_eval.metrics.breakdowns.MIN_BAND_FRAMES` frames and one error)."""
    rows: list[dict[str, Any]] = []
    for b in breakdowns:
        if not b.available:
            continue
        for band in b.bands:
            s = band.counts.summary(b.with_fp)
            rate = s["errors_per_frame"]
            if band.counts.frames < bd.MIN_BAND_FRAMES or not rate:
                continue
            rows.append(
                {
                    "breakdown": b.kind,
                    "band": band.label,
                    "errors_per_frame": rate,
                    "frames": band.counts.frames,
                    "num_gt": band.counts.num_gt,
                    "fn": band.counts.fn,
                    "fp": s["fp"],
                    "id_switches": band.counts.id_switches,
                    "mota": s["mota"],
                    "fp_free": not b.with_fp,
                }
            )
    rows.sort(key=lambda r: (-float(r["errors_per_frame"]), r["breakdown"], r["band"]))
    return tuple(rows[:WORST_BANDS])


# ----------------------------------------------------------------------------- JSON


def _interval_json(values: Mapping[str, Interval]) -> dict[str, list[float] | None]:
    return {k: None if v is None else [v[0], v[1]] for k, v in values.items()}


def _breakdown_json(
    b: bd.Breakdown, intervals: Mapping[tuple[str, str], Mapping[str, Interval]]
) -> dict[str, Any]:
    out: dict[str, Any] = {
        "available": b.available,
        "reason": b.reason,
        "fp_rule": bd.FP_RULES[b.kind],
        "mota_includes_fp": b.with_fp,
    }
    if not b.available:
        return out
    out["unassigned_gt"] = b.unassigned_gt
    out["unassigned_fp"] = b.unassigned_fp
    out["bands"] = [
        {
            "band": band.label,
            "counts": {
                "frames": band.counts.frames,
                "num_gt": band.counts.num_gt,
                "num_matches": band.counts.num_matches,
                "fn": band.counts.fn,
                "fp": band.counts.fp if b.with_fp else None,
                "id_switches": band.counts.id_switches,
                "similarity_sum": band.counts.similarity_sum,
            },
            "metrics": band.counts.summary(b.with_fp),
            "intervals": _interval_json(intervals.get((b.kind, band.label), {})),
        }
        for band in b.bands
    ]
    return out


def _gaps_json(gaps: Sequence[bd.GapBin]) -> list[dict[str, Any]]:
    return [
        {"frames": g.label, "gaps": g.gaps, "recovered": g.recovered, "rate": g.rate} for g in gaps
    ]


def _part_json(part: Part) -> dict[str, Any]:
    return {
        "intervals": _interval_json(part.intervals) if part.intervals else None,
        "breakdowns": {b.kind: _breakdown_json(b, part.band_intervals) for b in part.breakdowns},
        "gaps": _gaps_json(part.gaps),
    }


def _persons_json(persons: Sequence[bd.Person]) -> list[dict[str, Any]]:
    return [
        {
            "gt_id": p.gt_id,
            "frames": p.frames,
            "matched": p.matched,
            "coverage": p.coverage,
            "track_ids": list(p.track_ids),
            "id_switches": p.id_switches,
            "fragmentations": p.fragmentations,
            "switches": [
                {
                    "frame": s.frame,
                    "from_track": s.from_track,
                    "to_track": s.to_track,
                    "gap": s.gap,
                    "unseen": s.unseen,
                }
                for s in p.switches
            ],
        }
        for p in persons
    ]


def curve_json(curve: curves.Curve, points: int) -> dict[str, Any]:
    """The curve's JSON: per threshold the summed counts and the curve's metrics."""
    return {
        "available": bool(curve.points),
        "reason": curve.reason,
        "max_points": points,
        "best": curve.best,
        "points": [
            {
                "threshold": p.threshold,
                "metrics": {m: p.summary()[m] for m, _ in curves.CURVE_METRICS},
                "counts": p.overall.to_dict(),
                "sequence_counts": [c.to_dict() for c in p.sequences],
            }
            for p in curve.points
        ],
    }


def frames_files(analysis: Analysis) -> dict[str, tuple[str, bytes]]:
    """Per sequence: the file name and bytes of its per-frame table."""
    return {name: (f"{name}{FRAMES_SUFFIX}", data) for name, data in analysis.tables}


def annotate(report: dict[str, Any], analysis: Analysis) -> None:
    """Add the analysis to ``report`` (the dict of ``report.json``), in place."""
    by_name = {p.name: p for p in analysis.sequences}
    files = frames_files(analysis)
    for record in report["sequences"]:
        part = by_name.get(record["name"])
        if part is None:
            continue
        record.update(_part_json(part))
        record["block_length"] = part.block_length
        record["persons"] = _persons_json(part.persons)
        name, data = files[part.name]
        record["frames_file"] = {"name": name, "sha256": hashlib.sha256(data).hexdigest()}
    if report.get("overall") is not None:
        summary = analysis.overall or (analysis.sequences[0] if analysis.sequences else None)
        if summary is not None:
            report["overall"].update(_part_json(summary))
    s = analysis.settings
    report["analysis"] = {
        "bootstrap": {
            "method": "circular block bootstrap over frames; percentile intervals; several "
            "sequences resampled each on its own, their replicates summed",
            "replicates": analysis.replicates,
            "seed": analysis.seed,
            "confidence": boot.CONFIDENCE,
            "block_length": "per sequence, by the rule of Politis & White (2004, corrected "
            "2009) on its errors per frame (FN + FP + IDSW): see block_length per sequence",
        },
        "breakdowns": {
            "distance_bands": list(s.distance_bands),
            "visibility_bands": list(bd.VISIBILITY_LABELS),
            "driving_speed": s.driving_speed,
            "turning_rate": s.turning_rate,
            "motion_window_s": bd.MOTION_WINDOW_S,
            "fp_rules": dict(bd.FP_RULES),
        },
        "where_it_fails": list(analysis.worst),
        "curve": None
        if analysis.curve is None
        else curve_json(analysis.curve, analysis.curve_points or curves.DEFAULT_POINTS),
    }


# ----------------------------------------------------------------------------- Markdown


def pct(value: float | int | None) -> str:
    return "-" if value is None else f"{100.0 * float(value):.1f}%"


def _metric_text(metric: str, value: float | int | None, gating: Gating) -> str:
    if value is None:
        return "-"
    if metric == "motp" and gating is Gating.METRIC:
        return f"{float(value):.3f} m"
    if metric in ("id_switches", "recall_errors", "fp", "fn"):
        return f"{float(value):g}"
    return pct(value)


def interval_text(metric: str, value: Any, interval: Interval, gating: Gating) -> str:
    """``72.5% [65.1, 79.0]``: a value and its interval, in the value's unit."""
    text = _metric_text(metric, value, gating)
    if interval is None:
        return text
    lo, hi = interval
    if metric == "motp" and gating is Gating.METRIC:
        return f"{text} [{lo:.3f}, {hi:.3f}]"
    if metric in ("id_switches", "recall_errors"):
        return f"{text} [{lo:g}, {hi:g}]"
    return f"{text} [{100 * lo:.1f}, {100 * hi:.1f}]"


def markdown(analysis: Analysis, metrics: Mapping[str, Mapping[str, Any] | None]) -> list[str]:
    """Markdown sections; ``metrics`` maps each sequence (and 'overall') to its summary."""
    g = analysis.gating
    lines = ["", "## Where it fails", ""]
    if analysis.worst:
        lines += [
            "The bands with the most errors (FN + FP + ID switches) per frame:",
            "",
            "| breakdown | band | errors per frame | frames | FN | FP | ID Sw. |",
            "|---|---|---|---|---|---|---|",
        ]
        for w in analysis.worst:
            fp = "-" if w["fp"] is None else str(w["fp"])
            lines.append(
                f"| {w['breakdown']} | {w['band']} | {w['errors_per_frame']:.2f} | "
                f"{w['frames']} | {w['fn']} | {fp} | {w['id_switches']} |"
            )
    else:
        lines.append("No band has errors (or none is available).")
    parts = [*analysis.sequences, *([analysis.overall] if analysis.overall else [])]
    if analysis.replicates > 0 and parts:
        lines += [
            "",
            f"## Intervals ({100 * boot.CONFIDENCE:.0f} %, circular block bootstrap over frames, "
            f"{analysis.replicates} replicates, seed {analysis.seed})",
            "",
            "| sequence | block | " + " | ".join(h for _, h in INTERVAL_COLUMNS) + " |",
            "|---|---|" + "---|" * len(INTERVAL_COLUMNS),
        ]
        for p in parts:
            summary = metrics.get(p.name) or {}
            cells = [
                interval_text(k, summary.get(k), p.intervals.get(k), g) for k, _ in INTERVAL_COLUMNS
            ]
            block = "-" if p.block_length is None else str(p.block_length)
            lines.append(f"| {p.name} | {block} | " + " | ".join(cells) + " |")
    summary_part = analysis.overall or (analysis.sequences[0] if analysis.sequences else None)
    if summary_part is not None:
        title = "all sequences summed" if analysis.overall else summary_part.name
        lines += ["", f"## Breakdowns ({title})"]
        for b in summary_part.breakdowns:
            lines += ["", f"### {BREAKDOWN_TITLES[b.kind]}", ""]
            if not b.available:
                lines.append(f"Not available: {b.reason}.")
                continue
            lines.append(f"False positives: {bd.FP_RULES[b.kind]}.")
            if b.reason:
                lines.append(f"({b.reason}.)")
            lines += [
                "",
                "| band | frames | GT | MOTA | FN | FP | ID Sw. | MOTP |",
                "|---|---|---|---|---|---|---|---|",
            ]
            for band in b.bands:
                s = band.counts.summary(b.with_fp)
                iv = summary_part.band_intervals.get((b.kind, band.label), {})
                lines.append(
                    f"| {band.label} | {band.counts.frames} | {band.counts.num_gt} | "
                    f"{interval_text('mota', s['mota'], iv.get('mota'), g)} | "
                    f"{pct(s['fn_rate'])} ({band.counts.fn}) | "
                    + ("-" if not b.with_fp else f"{pct(s['fp_rate'])} ({band.counts.fp})")
                    + f" | {band.counts.id_switches} | {_metric_text('motp', s['motp'], g)} |"
                )
            if b.unassigned_gt or b.unassigned_fp:
                lines.append(
                    f"\nIn no band: {b.unassigned_gt} ground-truth instance(s), "
                    f"{b.unassigned_fp} false positive(s)."
                )
        lines += [
            "",
            "## Recovery after a gap",
            "",
            "A gap: frames without a match between two matches of a person; recovered when "
            "the same track id comes back.",
            "",
            "| gap (frames) | gaps | recovered | rate |",
            "|---|---|---|---|",
            *(
                f"| {gap.label} | {gap.gaps} | {gap.recovered} | {pct(gap.rate)} |"
                for gap in summary_part.gaps
            ),
        ]
    if any(p.persons for p in analysis.sequences):
        lines += [
            "",
            "## Per person",
            "",
            "| sequence | person | frames | coverage | track ids | ID Sw. | Frag. | "
            "frames since the last match before each switch (unseen) |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for p in analysis.sequences:
            for person in p.persons:
                gaps = ", ".join(f"{s.gap} ({s.unseen})" for s in person.switches) or "-"
                ids = " ".join(str(i) for i in person.track_ids) or "-"
                lines.append(
                    f"| {p.name} | {person.gt_id} | {person.frames} | {pct(person.coverage)} | "
                    f"{ids} | {person.id_switches} | {person.fragmentations} | {gaps} |"
                )
    if analysis.curve is not None:
        lines += curve_markdown(analysis.curve)
    return lines


def curve_markdown(curve: curves.Curve) -> list[str]:
    lines = ["", "## Confidence threshold curve", ""]
    if not curve.points:
        return [*lines, f"Not available: {curve.reason}."]
    lines += [
        "Tracks of confidence >= threshold kept, all sequences summed.",
        "",
        "| threshold | MOTA | HOTA | IDF1 | FP | FN |",
        "|---|---|---|---|---|---|",
    ]
    for p in curve.points:
        s = p.summary()
        lines.append(
            f"| {p.threshold:.4g} | {pct(s['mota'])} | {pct(s['hota'])} | {pct(s['idf1'])} | "
            f"{s['fp']} | {s['fn']} |"
        )
    best = ", ".join(
        f"{m.upper()} {'-' if v is None else f'{v:.4g}'}" for m, v in curve.best.items()
    )
    return [*lines, "", f"Best threshold per metric: {best}."]
