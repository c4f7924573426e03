"""Ground-plane maths (seed 000, 5.1): three-point plane, consensus refinement, RANSAC.

A plane is ``(a, b, c, d)`` with ``a x + b y + c z + d = 0``; planes returned
here are normalised (``|(a, b, c)| = 1``) and oriented so that the normal points
to the sensor's side (``d > 0``: the sensor origin is above the floor). The
signed distance ``n . p + d`` is then the height above the floor.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def normalise_plane(plane: FloatArray | tuple[float, ...]) -> FloatArray:
    """Unit normal, oriented so that the origin (the sensor) lies on the positive side."""
    p = np.asarray(plane, dtype=np.float64).reshape(-1)
    if p.shape != (4,) or not np.all(np.isfinite(p)):
        raise ValueError(f"plane must be 4 finite coefficients (a, b, c, d), got {plane!r}")
    norm = float(np.linalg.norm(p[:3]))
    if norm < 1e-12:
        raise ValueError(f"plane normal (a, b, c) must be non-zero, got {plane!r}")
    p = p / norm
    if p[3] < 0:
        p = -p
    return p


def plane_from_points(a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
    """The plane through three points (the linear system of 5.1)."""
    normal = np.cross(np.asarray(b, float) - a, np.asarray(c, float) - a)
    if float(np.linalg.norm(normal)) < 1e-9:
        raise ValueError(f"ground points {a}, {b}, {c} are collinear or coincide")
    d = -float(normal @ np.asarray(a, float))
    return normalise_plane((normal[0], normal[1], normal[2], d))


def signed_heights(points: FloatArray, plane: FloatArray) -> FloatArray:
    """Height of each point above a normalised plane (the distance of 5.3, signed)."""
    heights: FloatArray = points @ plane[:3] + plane[3]
    return heights


def cross3(a: FloatArray, b: FloatArray) -> FloatArray:
    """The cross product of two 3-vectors: ``np.cross``'s arithmetic without its overhead."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def fit_plane_least_squares(points: FloatArray) -> FloatArray:
    """Total-least-squares plane through ``(N >= 3, 3)`` points (smallest singular vector)."""
    if points.shape[0] < 3:
        raise ValueError(f"need at least 3 points to fit a plane, got {points.shape[0]}")
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    normal = vt[-1]
    return normalise_plane((normal[0], normal[1], normal[2], -float(normal @ centre)))


def angle_between_normals(p: FloatArray, q: FloatArray) -> float:
    """Angle in radians between two planes' normals (orientation ignored)."""
    cos = abs(float(p[:3] @ q[:3])) / float(np.linalg.norm(p[:3]) * np.linalg.norm(q[:3]))
    return float(np.arccos(min(1.0, cos)))


def ransac_ground_plane(
    points: FloatArray,
    up: FloatArray,
    threshold: float,
    max_tilt_rad: float,
    iterations: int = 256,
    seed: int = 0,
) -> FloatArray | None:
    """The plane with the most inliers among those whose normal is within ``max_tilt_rad`` of ``up``.

    All hypotheses are scored at once (``iterations x N`` distances). Ties go to
    the lower plane. Deterministic for a given ``seed``. Returns None when no
    hypothesis agrees with ``up``.
    """
    n = points.shape[0]
    if n < 3:
        return None
    up = np.asarray(up, dtype=np.float64) / float(np.linalg.norm(up))
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, n, size=(iterations, 3))
    a, b, c = points[idx[:, 0]], points[idx[:, 1]], points[idx[:, 2]]
    normals = np.cross(b - a, c - a)
    norms = np.linalg.norm(normals, axis=1)
    ok = norms > 1e-9
    normals = normals[ok] / norms[ok, None]
    a = a[ok]
    # Orient every normal along ``up`` and keep those that agree with gravity.
    normals *= np.sign(normals @ up)[:, None]
    ok = normals @ up >= np.cos(max_tilt_rad)
    normals, a = normals[ok], a[ok]
    if normals.shape[0] == 0:
        return None
    d = -np.einsum("ij,ij->i", normals, a)
    distances = np.abs(points @ normals.T + d[None, :])
    inliers = (distances < threshold).sum(axis=0)
    # ``d`` is how far below the sensor the plane lies: most inliers first, then the lowest.
    order = np.lexsort((-d, -inliers))
    best = int(order[0])
    plane = np.array([normals[best, 0], normals[best, 1], normals[best, 2], d[best]])
    mask = distances[:, best] < threshold
    if int(mask.sum()) >= 3:
        refined = fit_plane_least_squares(points[mask])
        if angle_between_normals(refined, plane) <= max_tilt_rad:
            return refined
    return normalise_plane(plane)
