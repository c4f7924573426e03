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
