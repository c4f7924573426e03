"""The plots of the analysis on ``report.html``: intervals, breakdowns, gaps, threshold curve.

Each returns PNG bytes (matplotlib, Agg). Fixed margins instead of ``tight_layout``
(which costs more than the drawing), one figure per kind of plot.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from rgbd_eval.report.html.render import figure_png, pyplot

DPI = 90
#: Band panels: (metric, title, scale to percent).
BAND_PANELS = (
    ("mota", "MOTA (%)"),
    ("fn_rate", "FN (% of GT)"),
    ("fp_rate", "FP (% of GT)"),
)

Interval = tuple[float, float] | None


def _errors(
    values: Sequence[float | None], intervals: Sequence[Interval], scale: float
) -> tuple[np.ndarray, np.ndarray]:
    """Bar heights and asymmetric error bars (NaN where missing)."""
    ys = np.array([np.nan if v is None else scale * float(v) for v in values])
    err = np.zeros((2, len(values)))
    for k, (y, iv) in enumerate(zip(ys, intervals, strict=True)):
        if iv is not None and not np.isnan(y):
            err[0, k] = max(0.0, y - scale * iv[0])
            err[1, k] = max(0.0, scale * iv[1] - y)
    return ys, err


def interval_panels(
    names: Sequence[str],
    panels: Sequence[tuple[str, str]],
    values: Sequence[Mapping[str, Any]],
    intervals: Sequence[Mapping[str, Interval]],
) -> bytes:
    """One axes: per metric (``panels``: metric, label; shares, drawn in %) a group of
    points, one per sequence (the overall row black), each with its 95 % interval."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(panels) + 1.5), 3.0), dpi=DPI)
    width = 0.8 / max(len(names), 1)
    for k, name in enumerate(names):
        xs = np.arange(len(panels)) - 0.4 + width * (k + 0.5)
        ys, err = _errors(
            [values[k].get(m) for m, _ in panels],
            [intervals[k].get(m) for m, _ in panels],
            100.0,
        )
        colour = "black" if name == "overall" else f"C{k % 10}"
        ax.errorbar(xs, ys, yerr=err, fmt="o", ms=4, color=colour, capsize=3, lw=1, label=name)
    ax.set_xticks(np.arange(len(panels)), [label for _, label in panels], fontsize=8)
    ax.set_ylabel("%", fontsize=8)
    ax.tick_params(axis="y", labelsize=7)
    ax.grid(True, axis="y", alpha=0.3)
    if len(names) > 1:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.subplots_adjust(left=0.07, right=0.85 if len(names) > 1 else 0.98, top=0.95, bottom=0.12)
    return figure_png(fig)


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
    plt = pyplot()
    height = 2.5 * len(rows) + 0.3  # inches; margins below fixed in inches too
    fig, axes = plt.subplots(
        len(rows), len(BAND_PANELS), figsize=(10.5, height), dpi=DPI, squeeze=False
    )
    for r, (title, labels, metrics, intervals, gt, with_fp) in enumerate(rows):
        xs = np.arange(len(labels))
        ticks = [f"{label}\n{n} GT" for label, n in zip(labels, gt, strict=True)]
        for c, (metric, panel) in enumerate(BAND_PANELS):
            ax = axes[r, c]
            if metric == "fp_rate" and not with_fp:
                ax.text(
                    0.5,
                    0.5,
                    "FP-free bands:\nno FP is assigned",
                    ha="center",
                    va="center",
                    fontsize=8,
                    color="0.4",
                    transform=ax.transAxes,
                )
                ax.set_xticks([])
                ax.set_yticks([])
            else:
                ys, err = _errors(
                    [m.get(metric) for m in metrics], [i.get(metric) for i in intervals], 100.0
                )
                colour = "tab:blue" if metric == "mota" else "tab:orange"
                ax.bar(
                    xs,
                    np.nan_to_num(ys),
                    yerr=err,
                    color=colour,
                    alpha=0.8,
                    ecolor="0.3",
                    capsize=3,
                )
                ax.set_xticks(xs, ticks, fontsize=7)
                ax.tick_params(axis="y", labelsize=7)
                ax.grid(True, axis="y", alpha=0.3)
                ax.axhline(0, color="0.3", lw=0.6)
            ax.set_title(
                f"{title}: {panel}" if c == 0 else panel,
                fontsize=8.5,
                loc="left" if c == 0 else "center",
            )
    fig.subplots_adjust(
        left=0.05, right=0.99, top=1 - 0.3 / height, bottom=0.6 / height, hspace=0.6, wspace=0.25
    )
    return figure_png(fig)


def gap_recovery(labels: Sequence[str], gaps: Sequence[int], recovered: Sequence[int]) -> bytes:
    """Share of gaps after which the same id came back, per gap length."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.0, 2.8), dpi=DPI)
    xs = np.arange(len(labels))
    rates = [100.0 * r / g if g else np.nan for g, r in zip(gaps, recovered, strict=True)]
    ax.bar(xs, np.nan_to_num(rates), color="tab:green", alpha=0.8)
    for x, g, r in zip(xs, gaps, recovered, strict=True):
        ax.text(x, 2, f"{r}/{g}" if g else "none", ha="center", va="bottom", fontsize=8)
    ax.set_xticks(xs, list(labels), fontsize=8)
    ax.set_xlabel("gap without a match (frames)", fontsize=8)
    ax.set_ylabel("same id recovered (%)", fontsize=8)
    ax.set_ylim(0, 105)
    ax.grid(True, axis="y", alpha=0.3)
    fig.subplots_adjust(left=0.12, right=0.97, top=0.95, bottom=0.2)
    return figure_png(fig)


def threshold_curve(
    thresholds: Sequence[float],
    summaries: Sequence[Mapping[str, Any]],
    best: Mapping[str, float | None],
) -> bytes:
    """MOTA, HOTA, IDF1 (%) and FP, FN (counts) against the confidence threshold."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.0, 3.6), dpi=DPI)
    ax2 = ax.twinx()
    colours = {"mota": "tab:blue", "hota": "tab:green", "idf1": "tab:cyan"}
    for key, colour in colours.items():
        ys = [np.nan if s.get(key) is None else 100.0 * float(s[key]) for s in summaries]
        ax.plot(thresholds, ys, "-o", ms=3, color=colour, label=f"{key.upper()} (%)")
        if best.get(key) is not None:
            ax.axvline(float(best[key]), color=colour, ls=":", lw=1)  # type: ignore[arg-type]
    for key, colour in (("fp", "tab:purple"), ("fn", "tab:orange")):
        ax2.plot(
            thresholds,
            [s[key] for s in summaries],
            "--s",
            ms=3,
            color=colour,
            label=f"{key.upper()} (count)",
        )
    ax.set_xlabel("confidence threshold (tracks kept at >= threshold)", fontsize=8)
    ax.set_ylabel("%", fontsize=8)
    ax2.set_ylabel("count", fontsize=8)
    ax2.set_ylim(bottom=0)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=5)
    ax.grid(True, alpha=0.3)
    ax.set_title("dotted: the best threshold of MOTA, HOTA, IDF1", fontsize=8)
    fig.subplots_adjust(left=0.08, right=0.92, top=0.9, bottom=0.3)
    return figure_png(fig)
