"""Write small EPFL-RGBD sequence folders in the published layout (see rgbd_eval.io.epfl_rgbd).

The scene: a Kinect v2 (the dataset's intrinsics and lens distortion) ``height_m`` above a flat
floor, looking along the floor-frame x axis and pitched down by ``pitch_deg``; a far wall at
x = 6 m; one "person", a flat board facing the camera (0.5 m wide, 1.8 m tall) standing at
x = ``board_x``, centred on y = ``board_y`` (y to the left). Depth is the exact ray
intersection, stored in millimetres.
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import yaml
from numpy.typing import NDArray

from rgbd_eval.io.epfl_rgbd import EPFL_KINECT2

BOARD_WIDTH_M = 0.5
BOARD_HEIGHT_M = 1.8
WALL_X_M = 6.0
TAG = "20140804_160621_00"


def optical_to_floor(pitch_deg: float) -> NDArray[np.float64]:
    """Columns: the optical x (right), y (down), z (forward) axes in the floor frame."""
    t = math.radians(pitch_deg)
    z = np.array([math.cos(t), 0.0, -math.sin(t)])
    x = np.array([0.0, -1.0, 0.0])
    return np.stack([x, np.cross(z, x), z], axis=1)


def render_depth_m(
    height_m: float, pitch_deg: float, board: tuple[float, float] | None
) -> NDArray[np.float64]:
    """Optical depth (m) of floor, wall and board; NaN where a ray hits nothing."""
    cam = EPFL_KINECT2
    R = optical_to_floor(pitch_deg)
    d = cam.rays() @ R.T  # world direction per unit of optical depth (lens distortion undone)
    best = np.full(d.shape[:2], np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_floor = np.where(d[..., 2] < 0, height_m / -d[..., 2], np.inf)
        best = np.minimum(best, t_floor)
        t_wall = np.where(d[..., 0] > 0, WALL_X_M / d[..., 0], np.inf)
        best = np.minimum(best, t_wall)
        if board is not None:
            bx, by = board
            t_b = np.where(d[..., 0] > 0, bx / d[..., 0], np.inf)
            hy = t_b * d[..., 1]
            hz = height_m + t_b * d[..., 2]
            on = (np.abs(hy - by) <= BOARD_WIDTH_M / 2) & (hz >= 0) & (hz <= BOARD_HEIGHT_M)
            best = np.minimum(best, np.where(on, t_b, np.inf))
    return np.where(np.isfinite(best), best, np.nan)


def board_box(height_m: float, pitch_deg: float, board: tuple[float, float]) -> list[int]:
    """The board's image box ``[x, y, w, h]`` (integers, as the dataset stores them)."""
    cam = EPFL_KINECT2
    R = optical_to_floor(pitch_deg)
    bx, by = board
    corners = np.array(
        [[bx, by + sy * BOARD_WIDTH_M / 2, z] for sy in (-1, 1) for z in (0.0, BOARD_HEIGHT_M)]
    )
    optical = (corners - np.array([0.0, 0.0, height_m])) @ R  # R^T (p - t), row-wise
    uv = cam.project(optical)
    u0, v0 = np.floor(uv.min(axis=0))
    u1, v1 = np.ceil(uv.max(axis=0))
    return [int(u0), int(v0), int(u1 - u0), int(v1 - v0)]


def write_sequence(
    root: Path,
    boards: list[tuple[float, float] | None],
    *,
    height_m: float = 2.0,
    pitch_deg: float = 0.0,
    rgb: bool = True,
    annotate: bool = True,
) -> Path:
    """``root/epfl_lab/<TAG>/`` with one frame per entry of ``boards`` (None: nobody there).

    The annotation file gets person id 1 with the board's box in every frame with a board.
    Colour is a fixed pattern per frame, so that a round trip can compare it exactly.
    """
    env = root / "epfl_lab"
    folder = env / TAG
    folder.mkdir(parents=True)
    frames: dict[int, dict[int, list[int]]] = {}
    for n, board in enumerate(boards):
        depth = render_depth_m(height_m, pitch_deg, board)
        mm = np.where(np.isfinite(depth), np.round(depth * 1000.0), 0).astype(np.uint16)
        assert cv2.imwrite(str(folder / f"depth{n:06d}.png"), mm)
        if rgb:
            assert cv2.imwrite(str(folder / f"rgb{n:06d}.png"), colour(n))
        if board is not None:
            frames[n] = {1: board_box(height_m, pitch_deg, board)}
    if annotate:
        (env / "ground_truth_image_plane.yaml").write_text(
            yaml.safe_dump({TAG: frames}), encoding="utf-8"
        )
    return folder


def colour(n: int) -> NDArray[np.uint8]:
    """A BGR test pattern for frame ``n`` (as cv2 writes it)."""
    cam = EPFL_KINECT2
    image = np.zeros((cam.height, cam.width, 3), dtype=np.uint8)
    image[..., 0] = (np.arange(cam.width) % 256).astype(np.uint8)[None, :]
    image[..., 1] = (np.arange(cam.height) % 256).astype(np.uint8)[:, None]
    image[..., 2] = (10 * n) % 256
    return image
