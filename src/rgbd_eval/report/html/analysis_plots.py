"""The plots of the analysis on ``report.html``: intervals, breakdowns, gaps, threshold curve.

Each returns SVG bytes, written as text with :mod:`rgbd_eval.report.html.svg` (no
matplotlib: see there). Missing values (None) are left out: no point, or a bar of zero
height.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from rgbd_eval.report.html.svg import (
    AXIS,
    BLUE,
    CYAN,
    GREEN,
    LEGEND_LINE,
    MUTED,
    ORANGE,
    PURPLE,
    TAB10,
    Axes,
    Canvas,
    data_range,
    legend,
    text_width,
    ticks,
)

#: Band panels: (metric, title, scale to percent).
BAND_PANELS = (
    ("mota", "MOTA (%)"),
    ("fn_rate", "FN (% of GT)"),
    ("fp_rate", "FP (% of GT)"),
)

Interval = tuple[float, float] | None


def _errors(
    values: Sequence[float | None], intervals: Sequence[Interval], scale: float
) -> list[tuple[float, float, float]]:
    """Per value, ``(value, low, high)`` scaled (NaN where the value is missing; the
    value itself at both ends where its interval is)."""
    out = []
    for v, iv in zip(values, intervals, strict=True):
        y = math.nan if v is None else scale * float(v)
        low, high = (y, y) if iv is None or math.isnan(y) else (scale * iv[0], scale * iv[1])
        out.append((y, min(low, y), max(high, y)))
    return out


def interval_panels(
    names: Sequence[str],
    panels: Sequence[tuple[str, str]],
    values: Sequence[Mapping[str, Any]],
    intervals: Sequence[Mapping[str, Interval]],
) -> bytes:
    """One axes: per metric (``panels``: metric, label; shares, drawn in %) a group of
    points, one per sequence (the overall row black), each with its 95 % interval."""
    series = [
        _errors(
            [values[k].get(m) for m, _ in panels], [intervals[k].get(m) for m, _ in panels], 100.0
        )
        for k in range(len(names))
    ]
    legend_width = max(text_width(n, 9.0) for n in names) + 40 if len(names) > 1 else 0.0
    width = int(max(540.0, 117.0 * len(panels) + 135.0) + legend_width)
    # Tall enough for the legend: one 15 px line per sequence (MOT17-train has 21).
    height = max(270, 20 + LEGEND_LINE * len(names)) if len(names) > 1 else 270
    canvas = Canvas(width, height)
    y0, y1 = data_range([v for s in series for e in s for v in e])
    ax = Axes(
        48, 10, width - 48 - 10 - legend_width, height - 10 - 34, -0.5, len(panels) - 0.5, y0, y1
    )
    ax.draw_y_axis(canvas, "%")
    step = 0.8 / max(len(names), 1)
    entries = []
    for k, name in enumerate(names):
        colour = "black" if name == "overall" else TAB10[k % 10]
        entries.append((name, colour))
        for j, (y, low, high) in enumerate(series[k]):
            if math.isnan(y):
                continue
            x = j - 0.4 + step * (k + 0.5)
            if high > low:
                ax.error_bar(canvas, x, low, high, colour)
            ax.point(canvas, x, y, colour)
    ax.draw_x_ticks(canvas, list(range(len(panels))), [label for _, label in panels])
    ax.frame(canvas)
    if len(names) > 1:
        legend(canvas, ax.right + 12, ax.top, entries)
    return canvas.svg()


def breakdown_panels(
    rows: Sequence[
        tuple[
            str,
            Sequence[str],
            Sequence[Mapping[str, Any]],
            Sequence[Mapping[str, Interval]],
            Sequence[int],
            bool,
        ]
    ],
) -> bytes:
    """Small multiples: a row per breakdown, a panel per band metric, a bar per band.

    Each row is ``(title, band labels, band metrics, band intervals, GT per band,
    FP counted)``; the bars carry their 95 % intervals as error bars, the ticks the GT.
    """
    row_height, width = 225, 945
    canvas = Canvas(width, row_height * len(rows) + 10)
    panel_width = (width - 20) / len(BAND_PANELS)
    for r, (title, labels, metrics, intervals, gt, with_fp) in enumerate(rows):
        tick_labels = [f"{label}\n{n} GT" for label, n in zip(labels, gt, strict=True)]
        top = 10 + r * row_height
        for c, (metric, panel) in enumerate(BAND_PANELS):
            left = 10 + c * panel_width + 40
            ax_width, ax_height = panel_width - 55, row_height - 22 - 46
            heading = f"{title}: {panel}" if c == 0 else panel
            canvas.text(
                left if c == 0 else left + ax_width / 2,
                top + 12,
                heading,
                anchor="start" if c == 0 else "middle",
                size=10,
            )
            if metric == "fp_rate" and not with_fp:
                Axes(left, top + 22, ax_width, ax_height, 0.0, 1.0, 0.0, 1.0).frame(canvas)
                for k, line in enumerate(("FP-free bands:", "no FP is assigned")):
                    canvas.text(
                        left + ax_width / 2,
                        top + 22 + ax_height / 2 + 12 * k,
                        line,
                        size=9.5,
                        colour=MUTED,
                    )
                continue
            bars = _errors(
                [m.get(metric) for m in metrics], [i.get(metric) for i in intervals], 100.0
            )
            y0, y1 = data_range([v for e in bars for v in e], include_zero=True)
            ax = Axes(left, top + 22, ax_width, ax_height, -0.6, len(labels) - 0.4, y0, y1)
            ax.draw_y_axis(canvas)
            colour = BLUE if metric == "mota" else ORANGE
            for x, (y, low, high) in enumerate(bars):
                ax.bar(canvas, x, 0.0 if math.isnan(y) else y, 0.8, colour, 0.8)
                if high > low:
                    ax.error_bar(canvas, x, low, high, AXIS)
            if y0 < 0.0 < y1:
                canvas.line(ax.left, ax.y(0.0), ax.right, ax.y(0.0), AXIS, 0.6)
            ax.draw_x_ticks(canvas, list(range(len(labels))), tick_labels, size=8.5)
            ax.frame(canvas)
    return canvas.svg()


def gap_recovery(labels: Sequence[str], gaps: Sequence[int], recovered: Sequence[int]) -> bytes:
    """Share of gaps after which the same id came back, per gap length."""
    canvas = Canvas(540, 252)
    ax = Axes(60, 10, 540 - 60 - 16, 252 - 10 - 50, -0.6, len(labels) - 0.4, 0.0, 105.0)
    ax.draw_y_axis(canvas, "same id recovered (%)")
    for x, (g, r) in enumerate(zip(gaps, recovered, strict=True)):
        if g:
            ax.bar(canvas, x, 100.0 * r / g, 0.8, GREEN, 0.8)
        canvas.text(ax.x(x), ax.y(2.0) - 3, f"{r}/{g}" if g else "none", size=9.5)
    ax.draw_x_ticks(canvas, list(range(len(labels))), list(labels), size=9.5)
    canvas.text(ax.left + ax.width / 2, 252 - 8, "gap without a match (frames)", size=10)
    ax.frame(canvas)
    return canvas.svg()


def threshold_curve(
    thresholds: Sequence[float],
    summaries: Sequence[Mapping[str, Any]],
    best: Mapping[str, float | None],
) -> bytes:
    """MOTA, HOTA, IDF1 (%) against the confidence threshold on the left axis, FP and FN
    (counts, dashed) on the right; a dotted line at each of the three's best threshold."""
    width, height = 720, 324
    canvas = Canvas(width, height)
    shares = {"mota": BLUE, "hota": GREEN, "idf1": CYAN}
    counts = {"fp": PURPLE, "fn": ORANGE}
    curves = {
        key: [math.nan if s.get(key) is None else 100.0 * float(s[key]) for s in summaries]
        for key in shares
    }
    numbers = {key: [float(s[key]) for s in summaries] for key in counts}
    xs = [float(t) for t in thresholds]
    x0, x1 = data_range(xs)
    y0, y1 = data_range([v for c in curves.values() for v in c])
    _, c1 = data_range([v for c in numbers.values() for v in c], include_zero=True)
    box = (56.0, 24.0, width - 56.0 - 64.0, height - 24.0 - 96.0)
    ax = Axes(*box, x0, x1, y0, y1)
    counts_ax = Axes(*box, x0, x1, 0.0, c1)
    ax.draw_y_axis(canvas, "%")
    counts_ax.draw_y_axis(canvas, "count", right=True, grid=False)
    for key, colour in shares.items():
        ax.polyline(canvas, xs, curves[key], colour)
        value = best.get(key)
        if value is not None:
            x = ax.x(float(value))
            canvas.line(x, ax.top, x, ax.bottom, colour, dash="1.5,2.5")
    for key, colour in counts.items():
        counts_ax.polyline(canvas, xs, numbers[key], colour, dashed=True, marker="square")
    positions = ticks(x0, x1, 8)
    ax.draw_x_ticks(canvas, positions, [f"{v:g}" for v in positions])
    ax.frame(canvas)
    canvas.text(
        ax.left + ax.width / 2, 14, "dotted: the best threshold of MOTA, HOTA, IDF1", size=10
    )
    canvas.text(
        ax.left + ax.width / 2,
        ax.bottom + 36,
        "confidence threshold (tracks kept at >= threshold)",
        size=10,
    )
    entries = [(f"{k.upper()} (%)", c) for k, c in shares.items()]
    entries += [(f"{k.upper()} (count)", c) for k, c in counts.items()]
    legend(canvas, ax.left + 10, ax.bottom + 50, entries, columns=5, marker="line")
    return canvas.svg()
