"""The density map: foreground points binned on a floor grid (seed 003, section 3.2, Figs. 2-3).

Foreground points go to floor coordinates (x, y on the floor, z the height above it); only
those higher than ``min_height_m`` (1 m in the seed's experiments) are kept. Each point
weighs its squared distance to the camera divided by ``fx * fy``: that is the area (m^2) its
pixel covers on a surface facing the camera, which compensates the inverse-square fall of the
point count with distance and makes the map independent of the focal length (the seed's
normalisation; its empirical constant did not survive). Dividing each cell's sum by the cell
area makes the map dimensionless: square metres of visible surface per square metre of
floor, so its threshold does not depend on the cell size either. The maps of several
cameras merge by the pixel-wise maximum (Fig. 3).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.calibration import CameraCalibration

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]


@dataclass(frozen=True)
class FloorGrid:
    """The region of interest on the floor, in cells of ``cell_m``; row = y, column = x."""

    x_min: float
    y_min: float
    x_max: float
    y_max: float
    cell_m: float

    def __post_init__(self) -> None:
        if not self.cell_m > 0:
            raise ValueError(f"cell_m={self.cell_m} must be > 0")
        if not (self.x_max > self.x_min and self.y_max > self.y_min):
            raise ValueError(
                f"region of interest x [{self.x_min}, {self.x_max}], y [{self.y_min}, "
                f"{self.y_max}] must have x_max > x_min and y_max > y_min"
            )

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, columns)``: cells along y, along x."""
        return (
            round((self.y_max - self.y_min) / self.cell_m),
            round((self.x_max - self.x_min) / self.cell_m),
        )

    def cell_centres(self, rows: NDArray[np.integer], cols: NDArray[np.integer]) -> F64:
        """Floor (x, y) of cell centres, ``(N, 2)``."""
        x = self.x_min + (np.asarray(cols, dtype=np.float64) + 0.5) * self.cell_m
        y = self.y_min + (np.asarray(rows, dtype=np.float64) + 0.5) * self.cell_m
        return np.stack([x, y], axis=1)

    def to_cell(self, xy: F64) -> F64:
        """Continuous (column, row) coordinates of floor points ``(N, 2)``; cell centres at k + 0.5."""
        p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        return np.stack(
            [(p[:, 0] - self.x_min) / self.cell_m, (p[:, 1] - self.y_min) / self.cell_m], axis=1
        )


@dataclass(frozen=True)
class CameraMap:
    """One camera's density map and the points behind it (for blob heights)."""

    density: F32
    cells: NDArray[np.int64]
    heights: F32


def point_weights(points_optical: F64, fx: float, fy: float) -> F64:
    """Each point's weight: squared distance to the camera over ``fx * fy`` (m^2 per pixel)."""
    r2: F64 = np.einsum("ij,ij->i", points_optical, points_optical) / (fx * fy)
    return r2


def camera_density(
    depth: NDArray[np.float32],
    foreground: NDArray[np.bool_],
    calibration: CameraCalibration,
    grid: FloorGrid,
    min_height_m: float,
    rays: F64 | None = None,
) -> CameraMap:
    """The density map of one camera's foreground pixels.

    ``rays`` (the camera's unit-depth rays, ``(H, W, 3)``) may be passed in to save
    recomputing them every frame.
    """
    cam = calibration.camera
    if depth.shape != (cam.height, cam.width) or foreground.shape != depth.shape:
        raise ValueError(
            f"camera {calibration.name}: depth {depth.shape} and foreground {foreground.shape} "
            f"must both be {(cam.height, cam.width)}"
        )
    r = cam.rays() if rays is None else rays
    rows_n, cols_n = grid.shape
    T = calibration.floor_from_optical.matrix()
    sums = np.zeros(rows_n * cols_n, dtype=np.float64)
    n_max = int(np.count_nonzero(foreground))
    cells = np.empty(n_max, dtype=np.int64)
    heights = np.empty(n_max, dtype=np.float32)
    n = _bin_kernel(
        np.ascontiguousarray(depth, dtype=np.float32),
        np.ascontiguousarray(foreground),
        np.ascontiguousarray(r),
        T,
        grid.x_min,
        grid.y_min,
        grid.cell_m,
        rows_n,
        cols_n,
        min_height_m,
        1.0 / (cam.fx * cam.fy),
        sums,
        cells,
        heights,
    )
    density = (sums / (grid.cell_m * grid.cell_m)).astype(np.float32).reshape(rows_n, cols_n)
    return CameraMap(density, cells[:n], heights[:n])


def _bin_points(
    depth: NDArray[np.float32],
    foreground: NDArray[np.bool_],
    rays: F64,
    T: F64,
    x_min: float,
    y_min: float,
    cell: float,
    rows_n: int,
    cols_n: int,
    min_height: float,
    inv_fxfy: float,
    sums: F64,
    cells: NDArray[np.int64],
    heights: NDArray[np.float32],
) -> int:
    """Bin the foreground points of one image (``rays``: the camera's ``(H, W, 3)`` unit-depth rays).

    Adds each kept point's weight to ``sums`` at its cell and records the cell and height;
    returns how many points were kept.
    """
    n = 0
    H, W = depth.shape
    for v in range(H):
        for u in range(W):
            if not foreground[v, u]:
                continue
            z = np.float64(depth[v, u])
            px = rays[v, u, 0] * z
            py = rays[v, u, 1] * z
            h = T[2, 0] * px + T[2, 1] * py + T[2, 2] * z + T[2, 3]
            if not h > min_height:
                continue
            col = np.floor((T[0, 0] * px + T[0, 1] * py + T[0, 2] * z + T[0, 3] - x_min) / cell)
            row = np.floor((T[1, 0] * px + T[1, 1] * py + T[1, 2] * z + T[1, 3] - y_min) / cell)
            if col < 0 or col >= cols_n or row < 0 or row >= rows_n:
                continue
            idx = int(row) * cols_n + int(col)
            sums[idx] += (px * px + py * py + z * z) * inv_fxfy
            cells[n] = idx
            heights[n] = h
            n += 1
    return n


#: Compiled on first use and cached on disk: one pass over the image, no temporaries.
_bin_kernel: Callable[..., int] = numba.njit(cache=True)(_bin_points)


def merge_maps(maps: list[F32]) -> F32:
    """The pixel-wise maximum of several cameras' density maps (seed 003, Fig. 3)."""
    if not maps:
        raise ValueError("merge_maps needs at least one map")
    shapes = {m.shape for m in maps}
    if len(shapes) != 1:
        raise ValueError(f"density maps differ in shape: {sorted(shapes)}")
    if len(maps) == 1:
        return maps[0]
    out: F32 = np.maximum.reduce(maps)
    return out
