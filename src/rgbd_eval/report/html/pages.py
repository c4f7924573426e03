"""The HTML pages: a run's ``report.html`` and the pages of sweep, compare, reproduce and bench.

Each ``*_page`` function returns the HTML text of one self-contained page (no
file access); :func:`write_run_html` also reads the frames it draws and writes
the files of a run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.atomic import write_bytes, write_text
from rgbd_eval.compare import flatten
from rgbd_eval.config import Gating, RunConfig, config_to_dict, load_config
from rgbd_eval.metrics import SequenceScores, Summary, summarize
from rgbd_eval.pipeline import SequenceResult
from rgbd_eval.report.html import plots
from rgbd_eval.report.html.analysis_view import AnalysisView, analysis_view
from rgbd_eval.report.html.events import busiest_frames, frame_errors, markers, worst_frames
from rgbd_eval.report.html.overlay import drawn_tracks, rgb_frames
from rgbd_eval.report.html.render import data_uri, jpeg_uri, render
from rgbd_eval.report.html.video import Progress, overlay, write_overlay_video
from rgbd_eval.report.run import COLUMNS, format_value, run_notes, table_header, table_rows
from rgbd_eval.types import GroundTruthObject, TrackOutput
from rgbd_eval.verdicts import Verdict

if TYPE_CHECKING:
    from rgbd_eval.bench import BenchResult
    from rgbd_eval.compare import Comparison
    from rgbd_eval.plugins import ReproduceResult
    from rgbd_eval.report.analysis import Analysis
    from rgbd_eval.report.scoring import ScoredSequence
    from rgbd_eval.sweep import Point, SweepResult

#: Frames in the worst-frame strip of each sequence.
WORST_FRAMES = 6
#: Frames shown of a sequence without ground truth (no worst frames): the tracks on the image.
TRACK_FRAMES = 4
#: Columns of the short metric tables (sweep, reproduce): those of the thesis' Tables 7.2-7.6.
SHORT_COLUMNS = COLUMNS[:7]


# ----------------------------------------------------------------------------- run


@dataclass(frozen=True)
class Shot:
    """One frame of the strip: the worst frames, or without ground truth the tracks' frames."""

    frame: int
    uri: str
    caption: str


@dataclass(frozen=True)
class SequenceView:
    """What the pictures of one sequence need, from a run or from ``score``."""

    name: str
    world_frame: str
    ground_truth: Sequence[Sequence[GroundTruthObject]] | None
    tracks: Sequence[Sequence[TrackOutput]]
    scores: SequenceScores | None

    @staticmethod
    def of_run(r: SequenceResult) -> SequenceView:
        gt = r.ground_truth.frames if r.ground_truth is not None else None
        return SequenceView(r.name, r.info.world_frame, gt, r.tracks, r.scores)


@dataclass(frozen=True)
class SequenceSection:
    """Everything the page shows of one sequence."""

    name: str
    birds_eye: str | None
    timeline: str | None
    shots: tuple[Shot, ...]
    error_frames: int
    video: str | None
    #: Frames of the strip that could not be shown: the recording was read without colour.
    no_colour: int = 0


def config_diff(config: RunConfig) -> list[tuple[str, Any, Any]]:
    """``(key, method default, used)`` for every config value that differs from the method's file."""
    defaults: dict[str, Any] = {}
    used: dict[str, Any] = {}
    flatten("", config_to_dict(load_config(method=config.method)), defaults)
    flatten("", config_to_dict(config), used)
    return [
        (k, defaults.get(k), used.get(k))
        for k in sorted(set(defaults) | set(used))
        if defaults.get(k) != used.get(k)
    ]


def strip_frames(
    tracks: Sequence[Sequence[TrackOutput]], scores: SequenceScores | None
) -> list[int]:
    """The frames a sequence's strip shows: the worst, or without scores the busiest."""
    if scores is not None:
        return worst_frames(frame_errors(scores.frames), WORST_FRAMES)
    return busiest_frames([len(drawn_tracks(t)) for t in tracks], TRACK_FRAMES)


def _section(
    folder: Path,
    view: SequenceView,
    images: Mapping[int, NDArray[np.uint8]],
    shown: Sequence[int],
    video: str | None,
    birds_eye: bool = True,
) -> SequenceSection:
    """The section of one sequence; with ``birds_eye`` also writes ``<name>.birdseye.png``.

    ``shown`` are the frames of the strip (:func:`strip_frames`), ``images`` those drawn.
    """
    scores = view.scores
    marks = markers(scores.frames, scores.counts.convention) if scores is not None else []
    uri = None
    if birds_eye:
        png = plots.birds_eye(view.name, view.world_frame, view.ground_truth, view.tracks, marks)
        (folder / f"{view.name}.birdseye.png").write_bytes(png)
        uri = data_uri(png)
    shots = []
    errors = frame_errors(scores.frames) if scores is not None else []
    for i in shown:
        if i not in images:
            continue
        if scores is not None:
            e = errors[i]
            caption = f"frame {i}: {e.fp} FP, {e.fn} FN, {e.id_switches} ID switch(es)"
        else:
            n = len(drawn_tracks(view.tracks[i]))
            caption = f"frame {i}: {n} track{'' if n == 1 else 's'}"
        shots.append(Shot(i, jpeg_uri(images[i]), caption))
    return SequenceSection(
        view.name,
        uri,
        data_uri(plots.timeline(errors, shown), "image/svg+xml") if scores is not None else None,
        tuple(shots),
        sum(e.total > 0 for e in errors),
        video,
        no_colour=len(shown) - len(shots),
    )


def run_page(
    results: Sequence[SequenceResult],
    config: RunConfig,
    report: Mapping[str, Any],
    sections: Sequence[SequenceSection],
    analysis: AnalysisView | None = None,
) -> str:
    """``report.html`` of a run: where it fails, header, metrics table, the analysis
    (:mod:`rgbd_eval.report.html.analysis_view`), then one section per sequence."""
    scored = any(r.scores is not None for r in results)
    return render(
        "run.html.j2",
        title=f"rgbd-eval run: {config.method}",
        kind="run",
        method=config.method,
        evaluation=report["evaluation"],
        diff=config_diff(config),
        sequences=report["sequences"],
        tool=report["tool"],
        libraries=report["libraries"],
        header=table_header() if scored else [],
        rows=table_rows(results, config.evaluation.gating) if scored else [],
        notes=run_notes(results),
        sections=sections,
        analysis=analysis,
    )


def write_run_html(
    folder: Path,
    results: Sequence[SequenceResult],
    config: RunConfig,
    report: Mapping[str, Any],
    video: bool = False,
    progress: Progress | None = None,
    analysis: Analysis | None = None,
) -> None:
    """Write ``report.html``, a ``<name>.birdseye.png`` per sequence and, with ``video``, a
    ``<name>.overlay.mp4`` per sequence into ``folder`` (a run's staged output folder);
    with ``analysis``, the page shows it.

    The recordings are read again for the RGB images: with ``video`` every frame,
    else only up to the last frame of the strip (:func:`strip_frames`).
    """
    sections = []
    for r in results:
        shown = strip_frames(r.tracks, r.scores)
        video_name = None
        if video:
            video_name = f"{r.name}.overlay.mp4"
            made = write_overlay_video(folder / video_name, r, config, shown, progress)
            images = made.kept
        else:
            images = {
                i: overlay(r, i, rgb)
                for i, rgb in rgb_frames(Path(r.path), config, shown)
                if rgb is not None
            }
        sections.append(_section(folder, SequenceView.of_run(r), images, shown, video_name))
    view = None if analysis is None else analysis_view(analysis, report)
    write_text(folder / "report.html", run_page(results, config, report, sections, view))


def write_score_html(
    folder: Path,
    sequences: Sequence[ScoredSequence],
    report: Mapping[str, Any],
    gating: Gating,
    analysis: Analysis | None = None,
) -> None:
    """Write ``report.html`` of ``rgbd-eval score`` into ``folder``: as a run's, without images.

    There is no recording to draw on; the bird's-eye plot is drawn where the
    ground truth has world positions.
    """
    from rgbd_eval.report.scoring import table_rows as score_rows

    sections = []
    for s in sequences:
        view = SequenceView(s.name, "world", s.aligned.gt, s.aligned.tracks, s.scores)
        has_world = any(o.world_xyz is not None for frame in s.aligned.gt for o in frame)
        sections.append(_section(folder, view, {}, [], None, birds_eye=has_world))
    page = render(
        "run.html.j2",
        title="rgbd-eval score",
        kind="score",
        method=str(report["method"]),
        evaluation=report["evaluation"],
        diff=None,
        sequences=report["sequences"],
        tool=report["tool"],
        libraries=report["libraries"],
        header=table_header(),
        rows=score_rows(sequences, gating),
        notes=[f"{s.name}: warning: {w}" for s in sequences for w in s.warnings],
        sections=sections,
        analysis=None if analysis is None else analysis_view(analysis, report),
    )
    write_text(folder / "report.html", page)


# ----------------------------------------------------------------------------- sweep


def _short_cells(summary: Mapping[str, Any], gating: Gating) -> list[str]:
    return [format_value(dict(summary), k, kind, gating) for k, _, kind in SHORT_COLUMNS]


def best_point(overall: Sequence[tuple[Point, Summary]]) -> Point:
    """The grid point of highest MOTA (the first of equals); points without MOTA rank last."""
    return max(
        overall, key=lambda ps: -math.inf if ps[1]["mota"] is None else float(ps[1]["mota"])
    )[0]


def sweep_figures(result: SweepResult) -> tuple[list[bytes], bytes | None]:
    """PNGs: per parameter its indicator curves (the other parameters held at the best
    point), and for a two-parameter grid the MOTA heat map."""
    overall = [(point, summarize(counts)) for point, counts in result.overall()]
    best = best_point(overall)
    curves = []
    for param in result.params:
        others = {k: v for k, v in best.items() if k != param}
        line = [(p, s) for p, s in overall if all(p[k] == v for k, v in others.items())]
        held = ", ".join(f"{k}={v}" for k, v in others.items())
        title = "all sequences summed" + (f"; {held} (the best point)" if held else "")
        curves.append(
            plots.indicator_curves(param, [p[param] for p, _ in line], [s for _, s in line], title)
        )
    heat = None
    if len(result.params) == 2:
        a, b = result.params
        rows = list(dict.fromkeys(p[a] for p, _ in overall))
        cols = list(dict.fromkeys(p[b] for p, _ in overall))
        mota = {(p[a], p[b]): s["mota"] for p, s in overall}
        grid = [[_float_or_none(mota.get((r, c))) for c in cols] for r in rows]
        heat = plots.heat_map(a, rows, b, cols, grid, "MOTA (%), all sequences summed")
    return curves, heat


def sweep_page(
    result: SweepResult,
    method: str,
    datasets: Sequence[str],
    fixed: Sequence[str],
    gating: Gating,
    figures: tuple[list[bytes], bytes | None],
) -> str:
    """``sweep.html``: the :func:`sweep_figures`, the best point, the records."""
    overall = [(point, summarize(counts)) for point, counts in result.overall()]
    best = best_point(overall)
    curves, heat = figures
    records = [
        (
            [str(r.point[p]) for p in result.params],
            r.sequence,
            _short_cells(summarize(r.counts), gating),
        )
        for r in result.records
    ]
    return render(
        "sweep.html.j2",
        title=f"rgbd-eval sweep: {', '.join(result.params)}",
        method=method,
        params=result.params,
        datasets=datasets,
        fixed=fixed,
        best=best,
        curves=[data_uri(c) for c in curves],
        heat=None if heat is None else data_uri(heat),
        columns=[h for _, h, _ in SHORT_COLUMNS],
        overall=[
            ([str(p[k]) for k in result.params], _short_cells(s, gating), p == best)
            for p, s in overall
        ],
        records=records,
        cache=(result.cache_hits, result.cache_misses),
    )


def write_sweep_html(
    out_dir: Path,
    result: SweepResult,
    method: str,
    datasets: Sequence[str],
    fixed: Sequence[str],
    gating: Gating,
) -> None:
    """Write ``sweep.html`` and, for a one-parameter sweep, its curves as ``sweep.png``."""
    figures = sweep_figures(result)
    if len(result.params) == 1:
        write_bytes(out_dir / "sweep.png", figures[0][0])
    write_text(out_dir / "sweep.html", sweep_page(result, method, datasets, fixed, gating, figures))


def _float_or_none(value: Any) -> float | None:
    return None if value is None else float(value)


# ----------------------------------------------------------------------------- compare


def compare_page(comparison: Comparison, baseline: str, current: str) -> str:
    """``compare.html``: the per-sequence deltas, coloured by improvement or regression."""
    from rgbd_eval.compare import HEADER
    from rgbd_eval.compare import table_rows as delta_rows

    rows = delta_rows(comparison)
    sequences = list(dict.fromkeys(r[0] for r in rows))
    metrics = list(dict.fromkeys(r[1] for r in rows))
    # (sequence, metric, baseline, current, change, interval, status) -> the change, by status
    cells = {(r[0], r[1]): (r[4], r[-1]) for r in rows}
    return render(
        "compare.html.j2",
        title="rgbd-eval compare",
        baseline=baseline,
        current=current,
        header=HEADER,
        rows=rows,
        regressions=len(comparison.regressions),
        gate=comparison.gate,
        config_changes=comparison.config_changes,
        notes=comparison.notes,
        chart=data_uri(plots.delta_grid(sequences, metrics, cells)),
    )


# ----------------------------------------------------------------------------- reproduce


def _paper_row(rows: Mapping[Any, Any], key: str) -> Mapping[str, Any] | None:
    """The row of ``rows`` named ``key``: by name, ignoring case, or by numeric value.

    The paper's YAML keys may be numbers or booleans (``-1.0``, ``true``), ours are strings.
    """
    for k, v in rows.items():
        if str(k).lower() == key.lower():
            return dict(v)
        try:
            if float(k) == float(key):
                return dict(v)
        except (TypeError, ValueError):
            continue
    return None


def _cell(value: Any, key: str) -> str:
    if value is None:
        return "-"
    return str(int(value)) if key == "id_switches" else f"{100 * float(value):.1f}%"


@dataclass(frozen=True)
class ClaimRow:
    """One claim of the paper on the page."""

    text: str
    verdict: Verdict
    source: str = ""
    evidence: str = ""


def paper_file(method: str) -> dict[str, Any] | None:
    """The published numbers of ``method``'s paper (its ``paper.yaml``), if any."""
    from rgbd_eval.config import load_paper, paper_path

    path = paper_path(method)
    if path is None or not path.is_file():
        return None
    return load_paper(method, mappings=("tables", "figures", "claims"), path=path)


def _claims(result: ReproduceResult) -> list[ClaimRow]:
    """The result's claims, with source and evidence where its data records them."""
    details: dict[str, Mapping[str, Any]] = {}
    for c in result.data.get("claims", []):
        if isinstance(c, Mapping):
            for key in ("text", "sentence"):  # a claim is named by either
                if c.get(key):
                    details[str(c[key])] = c
    rows = []
    for text, verdict in result.verdicts():
        d = details.get(text, {})
        rows.append(ClaimRow(text, verdict, str(d.get("source", "")), str(d.get("evidence", ""))))
    return rows


def reproduce_page(
    result: ReproduceResult,
    method: str,
    paper: Mapping[str, Any] | None = None,
    cpu_line: str = "",
) -> str:
    """``reproduce.html``: per table the paper's value beside ours, the claims, the figures redrawn.

    Reads the result's JSON data: ``tables`` (table -> row -> measured summary) beside
    the paper's tables of the same keys (``paper``, by default the method's ``paper.yaml``);
    ``track_lengths`` and ``voxel_timing_ms`` where the paper has those figures (basso2012's
    Figures 7.7 and 7.9). ``cpu_line`` says where the CPU time went (rendering, method).
    """
    paper = paper if paper is not None else (paper_file(method) or {})
    data = result.data
    tables = []
    for tab, measured in dict(data.get("tables", {})).items():
        spec = paper.get("tables", {}).get(tab)
        if spec is None:
            continue
        tables.append(_reproduced_table(spec, measured))
    figures = []
    lengths = data.get("track_lengths") or {}
    if lengths:
        by_memory = {
            name: {float(m): list(v) for m, v in per.items()} for name, per in lengths.items()
        }
        figures.append(
            (
                "Figure 7.7: frames each distinct track remains",
                data_uri(plots.track_lengths(by_memory)),
                paper.get("figures", {}).get("7.7", ""),
            )
        )
    timing = data.get("voxel_timing_ms") or {}
    if timing:
        stages = [s for s in next(iter(timing.values())) if s != "total_detect"]
        figure = plots.stacked_stages(
            [f"{float(v):.2f}" for v in timing],
            stages,
            [[t[s] for s in stages] for t in timing.values()],
            "voxel size (m)",
            "detection time per stage (one core); the line is one frame at 30 Hz",
            limit_ms=1000.0 / 30.0,
        )
        figures.append(
            (
                "Figure 7.9: detection time against voxel size",
                data_uri(figure),
                paper.get("figures", {}).get("7.9", ""),
            )
        )
    return render(
        "reproduce.html.j2",
        title=f"rgbd-eval reproduce {method}",
        method=method,
        source=paper.get("source", ""),
        seconds=float(data.get("seconds", 0.0)),
        cpu_line=cpu_line,
        tables=tables,
        figures=figures,
        claims=_claims(result),
    )


def _reproduced_table(
    spec: Mapping[str, Any], measured: Mapping[str, Any]
) -> tuple[str, list[str], list[tuple[str, list[tuple[str, str]]]], str]:
    """(title, column headers, rows of (name, [(paper, measured)]), figure) of one table.

    The figure: indicator curves, paper dashed, for a swept number (three rows or more
    with numeric names, as Table 7.6 / Figure 7.10); else MOTA bars, paper beside measured.
    """
    names = [str(k).lower() for k in spec["rows"]]
    names += [n for n in measured if _paper_row(spec["rows"], n) is None]
    cols = [(k, h) for k, h, _ in SHORT_COLUMNS if any(k in dict(v) for v in spec["rows"].values())]
    rows = []
    for name in names:
        p, o = _paper_row(spec["rows"], name) or {}, _paper_row(measured, name) or {}
        rows.append((name, [(_cell(p.get(k), k), _cell(o.get(k), k)) for k, _ in cols]))
    if _all_numeric(names) and len(names) >= 3:
        figure = plots.indicator_curves(
            str(spec.get("param", "value")),
            [float(n) for n in names],
            [dict(_paper_row(measured, n) or {}) for n in names],
            "paper (dashed) and measured (solid)",
            paper=[_paper_row(spec["rows"], n) for n in names],
        )
    else:
        figure = plots.paper_vs_measured(
            names,
            [_float_or_none((_paper_row(spec["rows"], n) or {}).get("mota")) for n in names],
            [_float_or_none((_paper_row(measured, n) or {}).get("mota")) for n in names],
            "MOTA",
            spec["title"],
        )
    return spec["title"], [h for _, h in cols], rows, data_uri(figure)


def _all_numeric(names: Sequence[str]) -> bool:
    try:
        [float(n) for n in names]
    except ValueError:
        return False
    return True


# ----------------------------------------------------------------------------- bench


def bench_page(result: BenchResult, labels: Mapping[str, str]) -> str:
    """``bench.html``: per-stage bars against the decode floor, and the figures as a table."""
    stage_ms = {labels.get(s, s): ms for s, ms in result.stage_ms.items()}
    (rw, rh), (dw, dh) = result.rgb_size, result.depth_size
    title = (
        f"{result.method} on {Path(result.path).name}: {result.frames} frames, RGB {rw}x{rh}, depth {dw}x{dh}; "
        f"pipeline {result.fps:.1f} fps, floor {result.floor_fps:.1f} fps"
    )
    rows = [
        (
            name,
            f"{ms:.3f}",
            f"{100.0 * ms / result.total_ms:.1f}%",
            "-" if ms <= 0 else f"{1e3 / ms:.0f}",
        )
        for name, ms in stage_ms.items()
    ]
    return render(
        "bench.html.j2",
        title=f"rgbd-eval bench: {Path(result.path).name}",
        result=result,
        chart=data_uri(plots.stage_bars(stage_ms, result.total_ms, result.floor_ms, title)),
        rows=rows,
    )
