"""The analysis plots as SVG: ticks, ranges and positions worked out by hand."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from rgbd_eval.report.html import analysis_plots as ap
from rgbd_eval.report.html.svg import Axes, data_range, nice_step, ticks

NS = "{http://www.w3.org/2000/svg}"
#: A breakdown_panels row: title, labels, metrics, intervals, GT per band, FP counted.
Row = tuple[
    str, list[str], list[dict[str, float | None]], list[dict[str, ap.Interval]], list[int], bool
]


def _svg(data: bytes) -> ET.Element:
    root = ET.fromstring(data)
    assert root.tag == f"{NS}svg"
    return root


@pytest.mark.parametrize(
    ("span", "count", "step"),
    [
        (1050.0, 10, 200.0),  # 105 per tick: 100 gives 10.5 ticks, 200 gives 5.25
        (60.0, 6, 10.0),  # exactly 6 ticks of 10
        (7.0, 6, 2.0),  # 1 gives 7 ticks, 2 gives 3.5
        (28.0, 6, 5.0),  # 1, 2, 2.5 give 28, 14, 11.2; 5 gives 5.6
        (0.7, 6, 0.2),  # 0.1 gives 7, 0.2 gives 3.5
    ],
)
def test_nice_step(span: float, count: int, step: float) -> None:
    assert nice_step(span, count) == pytest.approx(step)


def test_ticks_are_the_steps_inside_the_range() -> None:
    # -5..23 over 6: step 5 (above), multiples of 5 from ceil(-1) to floor(4.6).
    assert ticks(-5.0, 23.0, 6) == [-5.0, 0.0, 5.0, 10.0, 15.0, 20.0]


def test_data_range() -> None:
    assert data_range([2.0, 4.0]) == pytest.approx((1.9, 4.1))  # 5 % of 2 on each side
    assert data_range([2.0, 4.0], include_zero=True) == pytest.approx((0.0, 4.2))
    assert data_range([-2.0, 4.0], include_zero=True) == pytest.approx((-2.3, 4.3))
    assert data_range([3.0, 3.0]) == (2.0, 4.0)
    assert data_range([float("nan")]) == (0.0, 1.0)


def test_axes_map_data_to_pixels() -> None:
    ax = Axes(10, 20, 100, 50, 0.0, 10.0, 0.0, 5.0)
    assert (ax.x(5.0), ax.y(0.0), ax.y(5.0)) == (60.0, 70.0, 20.0)


def test_interval_point_and_bar_where_the_arithmetic_puts_them() -> None:
    svg = _svg(
        ap.interval_panels(["overall"], [("mota", "MOTA")], [{"mota": 0.5}], [{"mota": (0.4, 0.6)}])
    )
    # One series, no legend: 540 px wide (the minimum); axes 48..530 (482 px) over
    # x -0.5..0.5, 10..236 (226 px) over y 39..61 (40, 60 widened by 5 % of 20).
    # The point: x 0 -> 48 + 241 = 289.0; y 50 -> 236 - 11 * 226 / 22 = 123.0.
    (dot,) = svg.iter(f"{NS}circle")
    assert (dot.get("cx"), dot.get("cy"), dot.get("fill")) == ("289.0", "123.0", "black")
    # The interval 40..60: y 236 - 226 / 22 = 225.7 and 236 - 21 * 226 / 22 = 20.3.
    paths = [p.get("d") or "" for p in svg.iter(f"{NS}path")]
    assert any(d.startswith("M289.0,225.7V20.3") for d in paths)
    texts = [t.text for t in svg.iter(f"{NS}text")]
    assert "MOTA" in texts and "%" in texts


def test_interval_plot_leaves_out_missing_values_and_escapes_names() -> None:
    names = ["a<b>&c", "overall"]
    values: list[dict[str, float | None]] = [
        {"mota": 0.5, "idf1": None},
        {"mota": 0.6, "idf1": 0.7},
    ]
    svg = _svg(ap.interval_panels(names, [("mota", "MOTA"), ("idf1", "IDF1")], values, [{}, {}]))
    dots = list(svg.iter(f"{NS}circle"))
    # Three points plus two legend dots; the legend names the first sequence as given.
    assert len(dots) == 3 + 2
    assert "a<b>&c" in [t.text for t in svg.iter(f"{NS}text")]


def test_a_long_legend_fits_on_the_interval_plot() -> None:
    names = [f"MOT17-{k:02d}-FRCNN" for k in range(21)] + ["overall"]
    values = [{"mota": 0.5 + k / 100} for k in range(22)]
    svg = _svg(ap.interval_panels(names, [("mota", "MOTA")], values, [{}] * 22))
    # 22 legend lines of 15 px from y 10: the canvas grows from 270 to 20 + 22 * 15 = 350 px.
    assert svg.get("height") == "350"
    last = [t for t in svg.iter(f"{NS}text") if t.text == "overall"][-1]
    assert float(last.get("y") or 0) < 350


def test_breakdown_bars_and_the_fp_free_panel() -> None:
    rows: list[Row] = [
        (
            "Distance",
            ["near", "far"],
            [{"mota": 0.5, "fn_rate": 0.25, "fp_rate": 0.1}, {"mota": None}],
            [{}, {}],
            [10, 0],
            True,
        ),
        ("Occlusion", ["clear"], [{"mota": 0.9, "fn_rate": 0.1}], [{}], [5], False),
    ]
    svg = _svg(ap.breakdown_panels(rows))
    assert svg.get("height") == str(225 * 2 + 10)
    texts = [t.text for t in svg.iter(f"{NS}text")]
    assert "Distance: MOTA (%)" in texts and "Occlusion: MOTA (%)" in texts
    assert "no FP is assigned" in texts and "10 GT" in texts
    bars = [r for r in svg.iter(f"{NS}rect") if r.get("fill-opacity") == "0.8"]
    # Row 1: two bars in each of three panels (the missing value a bar of no height);
    # row 2: one bar in each of two panels.
    assert len(bars) == 2 * 3 + 2
    assert sum(float(r.get("height") or 0) == 0.0 for r in bars) == 3


def test_gap_recovery_labels_each_gap() -> None:
    svg = _svg(ap.gap_recovery(["1-5", "6-15"], [4, 0], [3, 0]))
    texts = [t.text for t in svg.iter(f"{NS}text")]
    assert "3/4" in texts and "none" in texts
    (bar,) = [r for r in svg.iter(f"{NS}rect") if r.get("fill-opacity") == "0.8"]
    # 75 % on 0..105 over 192 px (252 - 10 - 50): 75 * 192 / 105 = 137.14 px.
    assert float(bar.get("height") or 0) == pytest.approx(137.1, abs=0.06)


def test_threshold_curve_breaks_at_missing_values() -> None:
    summaries = [
        {"mota": 0.5, "hota": 0.4, "idf1": 0.6 if k != 1 else None, "fp": 10 - k, "fn": k}
        for k in range(4)
    ]
    svg = _svg(
        ap.threshold_curve(
            [0.0, 0.1, 0.2, 0.3], summaries, {"mota": 0.2, "hota": None, "idf1": None}
        )
    )
    cyan = [c for c in svg.iter(f"{NS}circle") if c.get("fill") == "#17becf"]
    assert len(cyan) == 3  # idf1 at thresholds 0, 0.2, 0.3
    squares = [r for r in svg.iter(f"{NS}rect") if r.get("width") == "6"]
    assert len(squares) == 2 * 4 + 0  # FP and FN at every threshold
    dotted = [line for line in svg.iter(f"{NS}line") if line.get("stroke-dasharray")]
    assert len(dotted) == 1  # only MOTA has a best threshold


def test_same_input_same_bytes() -> None:
    args = (["s"], [("mota", "MOTA")], [{"mota": 1 / 3}], [{"mota": (0.1, 0.5)}])
    assert ap.interval_panels(*args) == ap.interval_panels(*args)
