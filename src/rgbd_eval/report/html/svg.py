"""A small SVG kit for the pages' plots: a canvas, axes with 1-2-5 ticks, points, bars,
error bars, lines and legends, written as text.

Drawn with matplotlib, the analysis plots cost ``score`` about half a second of CPU on a
MOT17-sized folder (22.06 s against 21.51 s without, side by side), most of it importing
pyplot. SVG is also sharp at any zoom. Coordinates are written with one decimal, so the same
values give the same bytes on every machine.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from xml.sax.saxutils import escape

#: matplotlib's "tab10" cycle (C0-C9), so that the pages keep their colours.
TAB10 = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)
BLUE, ORANGE, GREEN, RED, PURPLE, CYAN = (TAB10[k] for k in (0, 1, 2, 3, 4, 9))
GRID, AXIS, MUTED = "#e4e4e4", "#4d4d4d", "#666666"
#: Rough advance of one character, as a share of the font size (sans-serif, mixed case).
CHAR_WIDTH = 0.6
#: The height of a legend's line at its default 9 px font: the font and 6 px (:func:`legend`).
LEGEND_LINE = 15


def nice_step(span: float, ticks: int) -> float:
    """A step of 1, 2, 2.5 or 5 times a power of ten giving at most ``ticks`` ticks over
    ``span`` (> 0)."""
    step = 10.0 ** math.floor(math.log10(span / ticks)) if span > 0 else 1.0
    for k in (1.0, 2.0, 2.5, 5.0, 10.0):
        if span / (step * k) <= ticks:
            return step * k
    return step * 10.0  # pragma: no cover - the loop ends at k = 10, which always fits


def ticks(low: float, high: float, count: int) -> list[float]:
    """At most ``count`` + 1 multiples of a :func:`nice_step` inside ``low..high``."""
    step = nice_step(high - low, count)
    first = math.ceil(low / step - 1e-9)
    last = math.floor(high / step + 1e-9)
    return [k * step + 0.0 for k in range(first, last + 1)]


def text_width(text: str, size: float) -> float:
    """An estimate of the width of ``text`` at font ``size`` (px)."""
    return CHAR_WIDTH * size * len(text)


def _f(v: float) -> str:
    """A coordinate with one decimal (``-0.0`` written as ``0.0``)."""
    return f"{v + 0.0:.1f}"


@dataclass
class Canvas:
    """An SVG document being written: elements are appended as text."""

    width: int
    height: int
    parts: list[str] = field(default_factory=list)

    def add(self, element: str) -> None:
        self.parts.append(element)

    def text(
        self,
        x: float,
        y: float,
        text: str,
        *,
        anchor: str = "middle",
        size: float = 11.0,
        colour: str | None = None,
        rotate: bool = False,
    ) -> None:
        """``text`` with its baseline at ``y``; ``rotate``: turned to read bottom-up."""
        extra = f' fill="{colour}"' if colour else ""
        if rotate:
            extra += f' transform="rotate(-90 {_f(x)} {_f(y)})"'
        self.add(
            f'<text x="{_f(x)}" y="{_f(y)}" text-anchor="{anchor}" font-size="{size:g}"'
            f"{extra}>{escape(text)}</text>"
        )

    def line(
        self,
        x1: float,
        y1: float,
        x2: float,
        y2: float,
        colour: str,
        width: float = 1.0,
        dash: str = "",
    ) -> None:
        """A straight line; ``dash``: an SVG ``stroke-dasharray`` (e.g. ``"1.5,2.5"``)."""
        dashes = f' stroke-dasharray="{dash}"' if dash else ""
        self.add(
            f'<line x1="{_f(x1)}" y1="{_f(y1)}" x2="{_f(x2)}" y2="{_f(y2)}" stroke="{colour}" '
            f'stroke-width="{width:g}"{dashes}/>'
        )

    def svg(self) -> bytes:
        """The document as UTF-8 bytes."""
        head = (
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{self.width}" '
            f'height="{self.height}" viewBox="0 0 {self.width} {self.height}" '
            f'font-family="sans-serif" font-size="11"><rect width="{self.width}" '
            f'height="{self.height}" fill="white"/>'
        )
        return (head + "".join(self.parts) + "</svg>").encode("utf-8")


def data_range(values: Sequence[float], include_zero: bool = False) -> tuple[float, float]:
    """The y range of finite ``values`` widened by 5 % on each side (matplotlib's margin);
    ``(0, 1)`` when there are none, one unit around a single value."""
    finite = [v for v in values if math.isfinite(v)]
    if include_zero:
        finite.append(0.0)
    if not finite:
        return 0.0, 1.0
    low, high = min(finite), max(finite)
    if high == low:
        return low - 1.0, high + 1.0
    pad = 0.05 * (high - low)
    return (low if include_zero and low == 0 else low - pad), high + pad


@dataclass(frozen=True)
class Axes:
    """A plot area at ``(left, top)`` of ``width`` x ``height`` px over data ``x0..x1`` and
    ``y0..y1`` (y upwards)."""

    left: float
    top: float
    width: float
    height: float
    x0: float
    x1: float
    y0: float
    y1: float

    def x(self, v: float) -> float:
        return self.left + (v - self.x0) * self.width / (self.x1 - self.x0)

    def y(self, v: float) -> float:
        return self.top + self.height - (v - self.y0) * self.height / (self.y1 - self.y0)

    @property
    def right(self) -> float:
        return self.left + self.width

    @property
    def bottom(self) -> float:
        return self.top + self.height

    def y_ticks(self, count: int = 6) -> list[float]:
        """Values of 1-2-5 steps inside ``y0..y1``."""
        return ticks(self.y0, self.y1, count)

    def draw_y_axis(
        self,
        canvas: Canvas,
        label: str = "",
        *,
        right: bool = False,
        grid: bool = True,
        size: float = 9.0,
    ) -> None:
        """Ticks with labels (on the right edge when ``right``), horizontal grid lines, and
        the axis ``label`` turned on its side."""
        for v in self.y_ticks():
            y = self.y(v)
            if grid:
                canvas.line(self.left, y, self.right, y, GRID)
            if right:
                canvas.line(self.right, y, self.right + 4, y, AXIS)
                canvas.text(self.right + 6, y + size / 3, f"{v:g}", anchor="start", size=size)
            else:
                canvas.line(self.left - 4, y, self.left, y, AXIS)
                canvas.text(self.left - 6, y + size / 3, f"{v:g}", anchor="end", size=size)
        if label:
            widest = max((text_width(f"{v:g}", size) for v in self.y_ticks()), default=0.0)
            x = self.right + widest + 18 if right else self.left - widest - 12
            canvas.text(x, self.top + self.height / 2, label, size=size + 1, rotate=True)

    def draw_x_ticks(
        self, canvas: Canvas, positions: Sequence[float], labels: Sequence[str], size: float = 9.0
    ) -> None:
        """Tick marks at ``positions`` with ``labels`` below (``\\n`` starts a new line)."""
        for v, label in zip(positions, labels, strict=True):
            x = self.x(v)
            canvas.line(x, self.bottom, x, self.bottom + 4, AXIS)
            for k, line in enumerate(label.split("\n")):
                canvas.text(x, self.bottom + 6 + size + k * (size + 2), line, size=size)

    def frame(self, canvas: Canvas) -> None:
        """The plot area's outline."""
        canvas.add(
            f'<rect x="{_f(self.left)}" y="{_f(self.top)}" width="{_f(self.width)}" '
            f'height="{_f(self.height)}" fill="none" stroke="{AXIS}"/>'
        )

    def error_bar(
        self, canvas: Canvas, x: float, low: float, high: float, colour: str, cap: float = 3.0
    ) -> None:
        """A vertical bar from ``low`` to ``high`` at data ``x``, with caps ``cap`` px wide."""
        px, y0, y1 = self.x(x), self.y(low), self.y(high)
        canvas.add(
            f'<path d="M{_f(px)},{_f(y0)}V{_f(y1)}M{_f(px - cap)},{_f(y0)}H{_f(px + cap)}'
            f'M{_f(px - cap)},{_f(y1)}H{_f(px + cap)}" stroke="{colour}" fill="none"/>'
        )

    def point(self, canvas: Canvas, x: float, y: float, colour: str, radius: float = 3.0) -> None:
        canvas.add(
            f'<circle cx="{_f(self.x(x))}" cy="{_f(self.y(y))}" r="{radius:g}" fill="{colour}"/>'
        )

    def bar(
        self, canvas: Canvas, x: float, value: float, width: float, colour: str, opacity: float
    ) -> None:
        """A bar from 0 to ``value`` centred on data ``x``, ``width`` in data units."""
        left, right = self.x(x - width / 2), self.x(x + width / 2)
        top, bottom = sorted((self.y(value), self.y(0.0)))
        canvas.add(
            f'<rect x="{_f(left)}" y="{_f(top)}" width="{_f(right - left)}" '
            f'height="{_f(bottom - top)}" fill="{colour}" fill-opacity="{opacity:g}"/>'
        )

    def polyline(
        self,
        canvas: Canvas,
        xs: Sequence[float],
        ys: Sequence[float],
        colour: str,
        *,
        dashed: bool = False,
        marker: str = "circle",
    ) -> None:
        """A line through the finite points (broken at the others), each marked with a
        circle or a square."""
        runs: list[list[tuple[float, float]]] = [[]]
        for x, y in zip(xs, ys, strict=True):
            if math.isfinite(x) and math.isfinite(y):
                runs[-1].append((self.x(x), self.y(y)))
            elif runs[-1]:
                runs.append([])
        dash = ' stroke-dasharray="5,3"' if dashed else ""
        for run in runs:
            if len(run) > 1:
                d = "M" + "L".join(f"{_f(px)},{_f(py)}" for px, py in run)
                canvas.add(
                    f'<path d="{d}" fill="none" stroke="{colour}" stroke-width="1.5"{dash}/>'
                )
            for px, py in run:
                if marker == "square":
                    canvas.add(
                        f'<rect x="{_f(px - 3)}" y="{_f(py - 3)}" width="6" height="6" '
                        f'fill="{colour}"/>'
                    )
                else:
                    canvas.add(f'<circle cx="{_f(px)}" cy="{_f(py)}" r="3" fill="{colour}"/>')


def legend(
    canvas: Canvas,
    x: float,
    y: float,
    entries: Sequence[tuple[str, str]],
    *,
    size: float = 9.0,
    columns: int = 1,
    marker: str = "point",
) -> None:
    """Entries ``(label, colour)`` from ``(x, y)`` (top-left), in ``columns`` columns; each
    with a dot or, for ``marker="line"``, a short line."""
    widest = max((text_width(label, size) for label, _ in entries), default=0.0)
    column = widest + 34
    for k, (label, colour) in enumerate(entries):
        cx = x + (k % columns) * column
        cy = y + (k // columns) * (size + 6) + size / 2
        if marker == "line":
            canvas.line(cx, cy, cx + 16, cy, colour, 1.5)
        else:
            canvas.add(f'<circle cx="{_f(cx + 8)}" cy="{_f(cy)}" r="3" fill="{colour}"/>')
        canvas.text(cx + 20, cy + size / 3, label, anchor="start", size=size)
