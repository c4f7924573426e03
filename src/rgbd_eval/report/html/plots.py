"""The plots of the HTML pages, each returned as PNG bytes (matplotlib, Agg), and the error
timeline as SVG."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from rgbd_eval.report.html.events import FrameErrors, Marker, MarkerKind
from rgbd_eval.report.html.overlay import track_colour
from rgbd_eval.report.html.render import figure_png, pyplot
from rgbd_eval.report.html.svg import nice_step
from rgbd_eval.types import GroundTruthObject, TrackOutput

DPI = 100
#: The four indicators of the thesis' Figure 7.10 (seed 000, 7.3): shares in percent, then a count.
FIG_7_10 = (("mota", "MOTA"), ("fp_rate", "FP"), ("fn_rate", "FN"))


def _rgb(colour: tuple[int, int, int]) -> tuple[float, float, float]:
    return (colour[0] / 255, colour[1] / 255, colour[2] / 255)


def birds_eye(
    title: str,
    world_frame: str,
    ground_truth: Sequence[Sequence[GroundTruthObject]] | None,
    tracks: Sequence[Sequence[TrackOutput]],
    marks: Sequence[Marker],
) -> bytes:
    """PNG of ground-truth paths (grey, dashed) under track paths (colour of their id), events marked.

    Every position is a dot on its path, so a person standing still shows as one.
    Only scored tracks are drawn (validated, not ``NOT_VISIBLE``). Id switches are
    red crosses, fragmentations orange triangles, placed at the object's
    ground-truth position in that frame.
    """
    from rgbd_eval.metrics.selection import is_scored_track

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 6), dpi=DPI)
    where: dict[tuple[int, int], tuple[float, float]] = {}
    if ground_truth is not None:
        paths: dict[int, list[tuple[float, float]]] = {}
        for index, frame in enumerate(ground_truth):
            for o in frame:
                if o.world_xyz is not None and not o.ignore:
                    xy = (o.world_xyz[0], o.world_xyz[1])
                    paths.setdefault(o.object_id, []).append(xy)
                    where[index, o.object_id] = xy
        for k, (oid, pts) in enumerate(sorted(paths.items())):
            xs, ys = zip(*pts, strict=True)
            ax.plot(
                xs,
                ys,
                "--",
                color="0.55",
                lw=2.0,
                marker="o",
                ms=3,
                label="ground truth" if k == 0 else None,
            )
            ax.annotate(f"gt {oid}", pts[0], color="0.35", fontsize=8)
    track_paths: dict[int, list[tuple[float, float]]] = {}
    for frame_tracks in tracks:
        for t in frame_tracks:
            if is_scored_track(t):
                track_paths.setdefault(t.track_id, []).append((t.x, t.y))
    for tid, pts in sorted(track_paths.items()):
        xs, ys = zip(*pts, strict=True)
        ax.plot(
            xs,
            ys,
            "-",
            color=_rgb(track_colour(tid)),
            lw=1.3,
            marker="o",
            ms=2.5,
            label=f"track {tid}",
        )
    styles = {
        MarkerKind.ID_SWITCH: ("X", "red", 90),
        MarkerKind.FRAGMENTATION: ("^", "darkorange", 60),
    }
    for kind, (marker, colour, size) in styles.items():
        pts = [
            where[m.frame, m.gt_id] for m in marks if m.kind is kind and (m.frame, m.gt_id) in where
        ]
        if pts:
            xs, ys = zip(*pts, strict=True)
            ax.scatter(
                xs,
                ys,
                zorder=5,
                edgecolors="black",
                linewidths=0.6,
                label=f"{kind.value} ({len(pts)})",
                marker=marker,
                color=colour,
                s=size,
            )
    ax.set_xlabel(f"x [m] ({world_frame})")
    ax.set_ylabel(f"y [m] ({world_frame})")
    ax.set_title(f"{title}: bird's-eye view")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="best", ncol=2)
    # Fixed margins: tight_layout would cost a third of the page's time on the demo.
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.09, top=0.94)
    return figure_png(fig)


#: The timeline's size (px) and margins: left, right (the legend), top, bottom.
_TL_W, _TL_H = 1000, 280
_TL_LEFT, _TL_RIGHT, _TL_TOP, _TL_BOTTOM = 56, 120, 12, 44
#: matplotlib's tab:purple, tab:orange and red, as the other plots use.
_FP, _FN, _SWITCH = "#9467bd", "#ff7f0e", "#ff0000"


def timeline(errors: Sequence[FrameErrors], worst: Sequence[int]) -> bytes:
    """SVG of FP and FN per frame (steps), id switches (red ticks), the worst frames marked on
    top (black triangles).

    Drawn as SVG text rather than with matplotlib: a run's page has one per sequence, and
    matplotlib took ~0.2 s of CPU each (a sixth of ``score`` on MOT17-train's 21 sequences).
    """
    n = len(errors)
    top = max([1, *(max(e.fp, e.fn) for e in errors)])
    x0, x1 = -0.5, max(n - 0.5, 0.5)
    y1 = top + 1
    pw, ph = _TL_W - _TL_LEFT - _TL_RIGHT, _TL_H - _TL_TOP - _TL_BOTTOM

    def x(v: float) -> float:
        return _TL_LEFT + (v - x0) * pw / (x1 - x0)

    def y(v: float) -> float:
        return _TL_TOP + ph - v * ph / y1

    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_TL_W}" height="{_TL_H}" '
        f'viewBox="0 0 {_TL_W} {_TL_H}" font-family="sans-serif" font-size="11">',
        f'<rect width="{_TL_W}" height="{_TL_H}" fill="white"/>',
    ]
    # grid and ticks
    step = max(1.0, nice_step(x1 - x0, 10))
    tick = 0.0
    while tick <= x1:
        out.append(
            f'<line x1="{x(tick):.1f}" y1="{_TL_TOP}" x2="{x(tick):.1f}" y2="{_TL_TOP + ph}" '
            f'stroke="#ddd"/><text x="{x(tick):.1f}" y="{_TL_TOP + ph + 15}" '
            f'text-anchor="middle">{tick:g}</text>'
        )
        tick += step
    ystep = max(1.0, nice_step(y1, 6))
    tick = 0.0
    while tick <= y1:
        out.append(
            f'<line x1="{_TL_LEFT}" y1="{y(tick):.1f}" x2="{_TL_LEFT + pw}" y2="{y(tick):.1f}" '
            f'stroke="#ddd"/><text x="{_TL_LEFT - 5}" y="{y(tick) + 4:.1f}" '
            f'text-anchor="end">{tick:g}</text>'
        )
        tick += ystep
    # id switches: a red line through the plot at each frame that has one
    for e in errors:
        if e.id_switches:
            out.append(
                f'<line x1="{x(e.frame):.1f}" y1="{_TL_TOP}" x2="{x(e.frame):.1f}" '
                f'y2="{_TL_TOP + ph}" stroke="{_SWITCH}" stroke-width="1.5"/>'
            )
    # FP and FN: each frame's count held over its width
    for attr, colour in (("fp", _FP), ("fn", _FN)):
        if not errors:
            continue
        d = [f"M{x(errors[0].frame - 0.5):.1f},{y(getattr(errors[0], attr)):.1f}"]
        for e in errors:
            d.append(f"V{y(getattr(e, attr)):.1f}H{x(e.frame + 0.5):.1f}")
        out.append(f'<path d="{"".join(d)}" fill="none" stroke="{colour}" stroke-width="1.2"/>')
    for f in worst:
        cx, cy = x(f), y(top + 0.5)
        out.append(
            f'<path d="M{cx - 5:.1f},{cy - 4:.1f}H{cx + 5:.1f}L{cx:.1f},{cy + 5:.1f}Z" '
            f'fill="black"/>'
        )
    # frame, axis labels, legend
    out.append(
        f'<rect x="{_TL_LEFT}" y="{_TL_TOP}" width="{pw}" height="{ph}" fill="none" '
        f'stroke="black"/><text x="{_TL_LEFT + pw / 2:.1f}" y="{_TL_H - 8}" '
        f'text-anchor="middle" font-size="12">frame</text><text x="14" '
        f'y="{_TL_TOP + ph / 2:.1f}" text-anchor="middle" font-size="12" '
        f'transform="rotate(-90 14 {_TL_TOP + ph / 2:.1f})">errors</text>'
    )
    lx = _TL_LEFT + pw + 10
    for i, (label, colour) in enumerate((("FP", _FP), ("FN", _FN), ("ID switch", _SWITCH))):
        ly = _TL_TOP + 10 + 16 * i
        out.append(
            f'<line x1="{lx}" y1="{ly}" x2="{lx + 18}" y2="{ly}" stroke="{colour}" '
            f'stroke-width="1.5"/><text x="{lx + 24}" y="{ly + 4}">{label}</text>'
        )
    if worst:
        ly = _TL_TOP + 10 + 16 * 3
        out.append(
            f'<path d="M{lx + 4},{ly - 4}H{lx + 14}L{lx + 9},{ly + 5}Z" fill="black"/>'
            f'<text x="{lx + 24}" y="{ly + 4}">shown below</text>'
        )
    out.append("</svg>")
    return "".join(out).encode("ascii")


def _positions(values: Sequence[Any]) -> tuple[list[float], list[str] | None]:
    """x positions of swept values: the numbers themselves, or 0, 1, ... with labels."""
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return [float(v) for v in values], None
    return [float(i) for i in range(len(values))], [str(v) for v in values]


def indicator_curves(
    xlabel: str,
    values: Sequence[Any],
    summaries: Sequence[Mapping[str, Any]],
    title: str,
    paper: Sequence[Mapping[str, Any] | None] | None = None,
) -> bytes:
    """MOTA, FP, FN (%) and ID switches against a parameter, as the thesis' Figure 7.10.

    With ``paper`` (one row of published values per x, or None), the paper's
    curves are drawn dashed beside ours (solid).
    """
    plt = pyplot()
    xs, labels = _positions(values)
    fig, ax = plt.subplots(figsize=(7.5, 4.8 if paper is not None else 4.4), dpi=DPI)
    ax2 = ax.twinx()
    colours = {"mota": "tab:blue", "fp_rate": "tab:purple", "fn_rate": "tab:orange"}
    series: list[tuple[str, Sequence[Mapping[str, Any]], str]] = [("measured", summaries, "-")]
    if paper is not None:
        series.append(("paper", [p or {} for p in paper], "--"))
    for name, rows, style in series:
        suffix = "" if paper is None else f", {name}"
        for key, label in FIG_7_10:
            ys = [np.nan if r.get(key) is None else 100.0 * float(r[key]) for r in rows]
            ax.plot(xs, ys, style, marker="o", color=colours[key], label=f"{label} (%){suffix}")
        sw = [np.nan if r.get("id_switches") is None else float(r["id_switches"]) for r in rows]
        ax2.plot(xs, sw, style, marker="s", color="tab:red", label=f"ID switches{suffix}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("%")
    ax2.set_ylabel("ID switches")
    ax2.set_ylim(bottom=0)
    ax2.yaxis.get_major_locator().set_params(integer=True)
    if labels is not None:
        ax.set_xticks(xs, labels)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=4)
    ax.grid(True, alpha=0.3)
    ax.set_title(title)
    fig.tight_layout()
    return figure_png(fig)


def heat_map(
    row_label: str,
    rows: Sequence[Any],
    col_label: str,
    cols: Sequence[Any],
    values: Sequence[Sequence[float | None]],
    title: str,
) -> bytes:
    """A two-parameter grid of one share (in %), each cell annotated."""
    plt = pyplot()
    grid = np.array(
        [[np.nan if v is None else 100.0 * v for v in row] for row in values], dtype=float
    )
    fig, ax = plt.subplots(
        figsize=(max(4.5, 1.6 + 0.9 * len(cols)), max(3.0, 1.4 + 0.55 * len(rows))), dpi=DPI
    )
    image = ax.imshow(grid, cmap="viridis", aspect="auto")
    for i in range(len(rows)):
        for j in range(len(cols)):
            if not np.isnan(grid[i, j]):
                shade = image.norm(grid[i, j])
                ax.text(
                    j,
                    i,
                    f"{grid[i, j]:.1f}",
                    ha="center",
                    va="center",
                    fontsize=8,
                    color="black" if shade > 0.5 else "white",
                )
    ax.set_xticks(range(len(cols)), [str(c) for c in cols])
    ax.set_yticks(range(len(rows)), [str(r) for r in rows])
    ax.set_xlabel(col_label)
    ax.set_ylabel(row_label)
    ax.set_title(title)
    fig.colorbar(image, ax=ax, label="%")
    fig.tight_layout()
    return figure_png(fig)


#: Cell colours of the compare grid, by the comparison's status.
STATUS_COLOURS = {
    "better": "#9fd89f",
    "worse": "#f3e38a",
    "regressed": "#ef8a8a",
    "same": "#ffffff",
    "missing": "#dddddd",
}


def delta_grid(
    sequences: Sequence[str],
    metrics: Sequence[str],
    cells: Mapping[tuple[str, str], tuple[str, str]],
) -> bytes:
    """A sequences x metrics grid: each cell the change as text, coloured by its status.

    ``cells[(sequence, metric)]`` is ``(text, status)``; absent cells are ``missing``.
    """
    from matplotlib.colors import to_rgb

    plt = pyplot()
    fig, ax = plt.subplots(
        figsize=(1.6 + 1.05 * len(metrics), 0.9 + 0.42 * len(sequences)), dpi=DPI
    )
    grid = np.array(
        [
            [to_rgb(STATUS_COLOURS[cells.get((s, m), ("", "missing"))[1]]) for m in metrics]
            for s in sequences
        ]
    )
    ax.imshow(grid, aspect="auto")
    for i, s in enumerate(sequences):
        for j, m in enumerate(metrics):
            text = cells.get((s, m), ("-", "missing"))[0]
            ax.text(j, i, text, ha="center", va="center", fontsize=7)
    ax.set_xticks(range(len(metrics)), list(metrics), rotation=30, ha="right", fontsize=8)
    ax.set_yticks(range(len(sequences)), list(sequences), fontsize=8)
    ax.set_xticks(np.arange(-0.5, len(metrics)), minor=True)
    ax.set_yticks(np.arange(-0.5, len(sequences)), minor=True)
    ax.grid(which="minor", color="0.6", lw=0.5)
    ax.tick_params(which="minor", length=0)
    ax.set_title(
        "change from baseline: green better, yellow worse within tolerance, red regressed",
        fontsize=8,
    )
    fig.tight_layout()
    return figure_png(fig)


def paper_vs_measured(
    names: Sequence[str],
    paper: Sequence[float | None],
    measured: Sequence[float | None],
    label: str,
    title: str,
) -> bytes:
    """Grouped bars of one share (in %), the paper's beside ours."""
    plt = pyplot()
    xs = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(max(5.0, 1.1 * len(names) + 2), 3.4), dpi=DPI)
    for offset, vals, name, colour in (
        (-0.2, paper, "paper", "0.6"),
        (0.2, measured, "measured", "tab:blue"),
    ):
        ax.bar(
            xs + offset,
            [np.nan if v is None else 100 * v for v in vals],
            0.4,
            label=name,
            color=colour,
        )
    ax.set_xticks(xs, list(names), rotation=20, ha="right", fontsize=8)
    ax.set_ylabel(f"{label} (%)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    return figure_png(fig)


def track_lengths(lengths: Mapping[str, Mapping[float, Sequence[int]]]) -> bytes:
    """Frames each distinct track is visible, per classifier memory (the thesis' Figure 7.7).

    One panel per sequence; within it, one group of bars per memory, tracks sorted
    from longest to shortest.
    """
    plt = pyplot()
    names = list(lengths)
    fig, axes = plt.subplots(
        1,
        len(names),
        figsize=(max(6.0, 3.0 * len(names)), 3.2),
        dpi=DPI,
        squeeze=False,
        sharey=True,
    )
    for ax, name in zip(axes[0], names, strict=True):
        x = 0
        ticks, labels = [], []
        for k, (memory, tracks) in enumerate(sorted(lengths[name].items())):
            ax.bar(
                range(x, x + len(tracks)),
                tracks,
                width=1.0,
                color=f"C{k}",
                edgecolor="black",
                linewidth=0.2,
            )
            ticks.append(x + len(tracks) / 2 - 0.5)
            labels.append(f"{memory:g} s\n({len(tracks)})")
            x += len(tracks) + 2
        ax.set_xticks(ticks, labels, fontsize=7)
        ax.set_title(name, fontsize=8)
    axes[0][0].set_ylabel("frames visible")
    fig.suptitle(
        "frames each distinct track remains (classifier memory; number of tracks)", fontsize=9
    )
    fig.tight_layout()
    return figure_png(fig)


def stacked_stages(
    groups: Sequence[str],
    stages: Sequence[str],
    ms: Sequence[Sequence[float]],
    xlabel: str,
    title: str,
    limit_ms: float | None = None,
) -> bytes:
    """Stacked bars of milliseconds per stage (one bar per group), with an optional limit line."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.0), dpi=DPI)
    bottom = np.zeros(len(groups))
    for k, stage in enumerate(stages):
        vals = np.array([row[k] for row in ms])
        ax.bar(groups, vals, bottom=bottom, label=stage, color=f"C{k % 10}")
        bottom += vals
    if limit_ms is not None:
        ax.axhline(limit_ms, color="red", ls="--", lw=1, label=f"{limit_ms:.1f} ms")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("ms per frame")
    ax.set_title(title)
    ax.legend(fontsize=7, ncol=3, loc="upper left")
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    return figure_png(fig)


def stage_bars(
    stage_ms: Mapping[str, float], total_ms: float, floor_ms: float, title: str
) -> bytes:
    """Horizontal bars of ms per frame per stage, the pipeline total, and the decode floor."""
    plt = pyplot()
    names = [*stage_ms, "pipeline (total)", "decode alone (floor)"]
    vals = [*stage_ms.values(), total_ms, floor_ms]
    colours = ["tab:blue"] * len(stage_ms) + ["black", "0.55"]
    fig, ax = plt.subplots(figsize=(7.5, 0.9 + 0.32 * len(names)), dpi=DPI)
    ys = np.arange(len(names))
    ax.barh(ys, vals, color=colours)
    ax.axvline(floor_ms, color="0.55", ls="--", lw=1)
    for y, v in zip(ys, vals, strict=True):
        ax.text(v, y, f" {v:.2f}", va="center", fontsize=7)
    ax.set_yticks(ys, names, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("ms per frame (median over repeats)")
    ax.set_title(title, fontsize=9)
    ax.grid(True, axis="x", alpha=0.3)
    fig.tight_layout()
    return figure_png(fig)
