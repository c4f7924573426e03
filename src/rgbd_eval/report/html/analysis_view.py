"""What ``report.html`` shows of the analysis (:mod:`rgbd_eval.report.analysis`): tables and plots."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rgbd_eval.metrics import bootstrap as boot
from rgbd_eval.metrics import breakdowns as bd
from rgbd_eval.report import analysis as an
from rgbd_eval.report.html import analysis_plots
from rgbd_eval.report.html.render import data_uri

#: The MIME type of the analysis plots (:mod:`rgbd_eval.report.html.analysis_plots`).
SVG = "image/svg+xml"

#: The metrics of the interval plot (shares, drawn in %): (metric, label).
INTERVAL_PANELS = (
    ("mota", "MOTA"),
    ("idf1", "IDF1"),
    ("hota", "HOTA"),
    ("main_tr", "Main Tr."),
    ("fn_rate", "FN"),
    ("fp_rate", "FP"),
)


@dataclass(frozen=True)
class BreakdownView:
    title: str
    available: bool
    reason: str
    rule: str
    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    unassigned: str


@dataclass(frozen=True)
class CurveView:
    available: bool
    reason: str
    rows: tuple[tuple[str, ...], ...]
    best: tuple[tuple[str, str], ...]
    figure: str | None


@dataclass(frozen=True)
class AnalysisView:
    """The analysis' part of the page."""

    worst: tuple[tuple[str, ...], ...]
    bootstrap: str
    interval_header: tuple[str, ...]
    #: Per sequence: name, block length, and per metric (value, its interval) as text.
    interval_rows: tuple[tuple[str, str, tuple[tuple[str, str], ...]], ...]
    interval_figure: str | None
    summary_title: str
    breakdowns: tuple[BreakdownView, ...]
    breakdown_figure: str | None
    gap_rows: tuple[tuple[str, ...], ...]
    gap_figure: str | None
    person_rows: tuple[tuple[str, ...], ...]
    curve: CurveView | None


def _breakdown_view(b: bd.Breakdown, part: an.Part, analysis: an.Analysis) -> BreakdownView:
    title = an.BREAKDOWN_TITLES[b.kind]
    header = ("band", "frames", "GT", "MOTA [95 %]", "FN", "FP", "ID Sw.", "MOTP", "errors/frame")
    if not b.available:
        return BreakdownView(title, False, b.reason, bd.FP_RULES[b.kind], header, (), "")
    rows = []
    for band in b.bands:
        s = band.counts.summary(b.with_fp)
        iv = part.band_intervals.get((b.kind, band.label), {})
        per_frame = s["errors_per_frame"]
        rows.append(
            (
                band.label,
                str(band.counts.frames),
                str(band.counts.num_gt),
                an.interval_text("mota", s["mota"], iv.get("mota"), analysis.gating),
                f"{an.pct(s['fn_rate'])} ({band.counts.fn})",
                "-" if not b.with_fp else f"{an.pct(s['fp_rate'])} ({band.counts.fp})",
                str(band.counts.id_switches),
                an.interval_text("motp", s["motp"], None, analysis.gating),
                "-" if per_frame is None else f"{float(per_frame):.2f}",
            )
        )
    unassigned = ""
    if b.unassigned_gt or b.unassigned_fp:
        unassigned = (
            f"In no band: {b.unassigned_gt} ground-truth instance(s), "
            f"{b.unassigned_fp} false positive(s)."
        )
    return BreakdownView(
        title, True, b.reason, bd.FP_RULES[b.kind], header, tuple(rows), unassigned
    )


def _breakdown_figure(part: an.Part) -> str | None:
    rows = []
    for b in part.breakdowns:
        if not b.available:
            continue
        labels = [band.label for band in b.bands]
        metrics = [band.counts.summary(b.with_fp) for band in b.bands]
        intervals = [part.band_intervals.get((b.kind, label), {}) for label in labels]
        gt = [band.counts.num_gt for band in b.bands]
        rows.append((an.BREAKDOWN_TITLES[b.kind], labels, metrics, intervals, gt, b.with_fp))
    return data_uri(analysis_plots.breakdown_panels(rows), SVG) if rows else None


def _curve_view(analysis: an.Analysis) -> CurveView | None:
    curve = analysis.curve
    if curve is None:
        return None
    if not curve.points:
        return CurveView(False, curve.reason, (), (), None)
    summaries = [p.summary() for p in curve.points]
    rows = tuple(
        (
            f"{p.threshold:.4g}",
            an.pct(s["mota"]),
            an.pct(s["hota"]),
            an.pct(s["idf1"]),
            str(s["fp"]),
            str(s["fn"]),
        )
        for p, s in zip(curve.points, summaries, strict=True)
    )
    best = tuple(
        (metric.upper(), "-" if value is None else f"{value:.4g}")
        for metric, value in curve.best.items()
    )
    figure = analysis_plots.threshold_curve(
        [p.threshold for p in curve.points], summaries, curve.best
    )
    return CurveView(True, "", rows, best, data_uri(figure, SVG))


def _split(text: str) -> tuple[str, str]:
    """``72.5% [54.7, 86.8]`` -> ``("72.5%", "[54.7, 86.8]")``."""
    value, _, interval = text.partition(" [")
    return value, f"[{interval}" if interval else ""


def analysis_view(analysis: an.Analysis, report: Mapping[str, Any]) -> AnalysisView:
    """Tables and figures of ``analysis``; ``report`` gives the metrics (``report.json``)."""
    from rgbd_eval.report.run import sequence_summaries

    metrics = sequence_summaries(dict(report))
    g = analysis.gating
    worst = tuple(
        (
            an.BREAKDOWN_TITLES[w["breakdown"]].lower(),
            w["band"],
            f"{w['errors_per_frame']:.2f}",
            str(w["frames"]),
            str(w["fn"]),
            "-" if w["fp"] is None else str(w["fp"]),
            str(w["id_switches"]),
        )
        for w in analysis.worst
    )
    parts = [*analysis.sequences, *([analysis.overall] if analysis.overall else [])]
    interval_rows: tuple[tuple[str, str, tuple[tuple[str, str], ...]], ...] = ()
    figure = None
    if analysis.replicates > 0 and parts:
        interval_rows = tuple(
            (
                p.name,
                "-" if p.block_length is None else str(p.block_length),
                tuple(
                    _split(
                        an.interval_text(
                            k, (metrics.get(p.name) or {}).get(k), p.intervals.get(k), g
                        )
                    )
                    for k, _ in an.INTERVAL_COLUMNS
                ),
            )
            for p in parts
        )
        figure = data_uri(
            analysis_plots.interval_panels(
                [p.name for p in parts],
                INTERVAL_PANELS,
                [metrics.get(p.name) or {} for p in parts],
                [p.intervals for p in parts],
            ),
            SVG,
        )
    bootstrap = (
        f"{100 * boot.CONFIDENCE:.0f} % intervals: circular block bootstrap over frames, "
        f"{analysis.replicates} replicates, seed {analysis.seed}; the block length (frames) "
        "is chosen per sequence from its errors per frame (Politis & White)."
        if analysis.replicates > 0
        else "No intervals (evaluation.bootstrap_replicates is 0)."
    )
    part = analysis.overall or (analysis.sequences[0] if analysis.sequences else None)
    breakdowns: tuple[BreakdownView, ...] = ()
    breakdown_figure = gap_figure = None
    gap_rows: tuple[tuple[str, ...], ...] = ()
    title = ""
    if part is not None:
        title = "all sequences summed" if analysis.overall else part.name
        breakdowns = tuple(_breakdown_view(b, part, analysis) for b in part.breakdowns)
        breakdown_figure = _breakdown_figure(part)
        gap_rows = tuple(
            (gap.label, str(gap.gaps), str(gap.recovered), an.pct(gap.rate)) for gap in part.gaps
        )
        if any(gap.gaps for gap in part.gaps):
            gap_figure = data_uri(
                analysis_plots.gap_recovery(
                    [gap.label for gap in part.gaps],
                    [gap.gaps for gap in part.gaps],
                    [gap.recovered for gap in part.gaps],
                ),
                SVG,
            )
    person_rows = tuple(
        (
            p.name,
            str(person.gt_id),
            str(person.frames),
            an.pct(person.coverage),
            " ".join(str(i) for i in person.track_ids) or "-",
            str(person.id_switches),
            str(person.fragmentations),
            ", ".join(f"{s.gap} ({s.unseen})" for s in person.switches) or "-",
        )
        for p in analysis.sequences
        for person in p.persons
    )
    return AnalysisView(
        worst,
        bootstrap,
        ("sequence", "block", *(h for _, h in an.INTERVAL_COLUMNS)),
        interval_rows,
        figure,
        title,
        breakdowns,
        breakdown_figure,
        gap_rows,
        gap_figure,
        person_rows,
        _curve_view(analysis),
    )
