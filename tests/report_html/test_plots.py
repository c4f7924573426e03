"""The bird's-eye plot: where every track was, a person standing still included."""

from __future__ import annotations

import cv2
import numpy as np

from rgbd_eval.report.html.overlay import track_colour
from rgbd_eval.report.html.plots import birds_eye
from rgbd_eval.types import TrackOutput, Visibility


def test_a_track_standing_still_is_drawn_where_it_stands() -> None:
    still = TrackOutput(1, 2.0, -1.0, 1.7, None, Visibility.VISIBLE)
    png = birds_eye("still", "odom", None, [(still,)] * 20, [])
    image = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)[:, :, ::-1]
    # Alone in the plot, the track's position is the middle of the axes
    # (700 x 600 px; axes from 10% to 97% of the width, 9% to 94% of the height).
    cx, cy = round(700 * (0.1 + 0.97) / 2), round(600 * (1 - (0.09 + 0.94) / 2))
    window = image[cy - 15 : cy + 15, cx - 15 : cx + 15].astype(int)
    close = np.abs(window - np.array(track_colour(1))).sum(axis=2) < 60
    assert close.sum() >= 12, close.sum()


def test_timeline_is_an_svg_of_steps_switches_and_marks() -> None:
    import xml.etree.ElementTree as ET

    from rgbd_eval.report.html.events import FrameErrors
    from rgbd_eval.report.html.plots import timeline

    # Frames 0-3: FP 0, 2, 0, 1; FN 1, 0, 0, 0; one id switch at frame 2; frame 1 shown below.
    errors = [
        FrameErrors(0, 0, 1, 0),
        FrameErrors(1, 2, 0, 0),
        FrameErrors(2, 0, 0, 1),
        FrameErrors(3, 1, 0, 0),
    ]
    svg = ET.fromstring(timeline(errors, [1]))
    ns = "{http://www.w3.org/2000/svg}"
    assert svg.tag == f"{ns}svg" and svg.get("width") == "1000"
    paths = svg.findall(f"{ns}path")
    # x: frames -0.5 .. 3.5 over 824 px from x = 56 (206 px a frame); y: 0 .. 3 (the highest
    # count 2, plus 1) over 224 px from y = 236 up (74.67 px per error: 1 at 161.3, 2 at 86.7).
    fp = next(p for p in paths if p.get("stroke") == "#9467bd").get("d")
    assert fp == "M56.0,236.0V236.0H262.0V86.7H468.0V236.0H674.0V161.3H880.0"
    fn = next(p for p in paths if p.get("stroke") == "#ff7f0e").get("d")
    assert fn == "M56.0,161.3V161.3H262.0V236.0H468.0V236.0H674.0V236.0H880.0"
    switches = [ln for ln in svg.findall(f"{ns}line") if ln.get("stroke") == "#ff0000"]
    # one in the plot at frame 2 (x = 56 + 2.5 x 206 = 571), one in the legend (56 + 824 + 10)
    assert [ln.get("x1") for ln in switches] == ["571.0", "890"]
    # the worst frame's triangle (at frame 1, x = 365) and the legend's
    marks = [p for p in paths if p.get("fill") == "black"]
    assert len(marks) == 2 and marks[0].get("d", "").startswith("M360.0,")
    assert "shown below" in "".join(t.text or "" for t in svg.findall(f"{ns}text"))


def test_timeline_of_no_frames_is_an_empty_plot() -> None:
    import xml.etree.ElementTree as ET

    from rgbd_eval.report.html.plots import timeline

    svg = ET.fromstring(timeline([], []))
    assert all(p.get("fill") != "none" for p in svg.iter("{http://www.w3.org/2000/svg}path"))
