"""Blob splitting (seed 003, section 3.3, Fig. 4): merged blobs and their Voronoi partition.

After the Hungarian assignment, a track left without a detection whose prediction falls
close to a blob is taken to have merged with that blob. Such a blob is split by a Euclidean
Voronoi partition of its cells among the predictions of the tracks that share it: each cell
goes to the nearest prediction, and each part's mean is that track's detection.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def nearest_blob(point: F64, blobs_cells: list[F64], near_m: float) -> int | None:
    """The blob with a cell nearest to ``point``, if that cell lies within ``near_m``; else None."""
    best, best_d2 = None, near_m * near_m
    p = np.asarray(point, dtype=np.float64).reshape(2)
    for k, cells in enumerate(blobs_cells):
        if cells.shape[0] == 0:
            continue
        diff = cells - p
        d2 = float(np.einsum("ij,ij->i", diff, diff).min())
        if d2 <= best_d2:
            best, best_d2 = k, d2
    return best


def voronoi_split(cells: F64, seeds: F64) -> list[F64]:
    """Partition ``cells (N, 2)`` among ``seeds (K, 2)`` by nearest seed (ties: lower index).

    Returns one ``(n_k, 2)`` array per seed, possibly empty.
    """
    c = np.asarray(cells, dtype=np.float64).reshape(-1, 2)
    s = np.asarray(seeds, dtype=np.float64).reshape(-1, 2)
    if s.shape[0] == 0:
        raise ValueError("voronoi_split needs at least one seed")
    diff = c[:, None, :] - s[None, :, :]
    owner = np.argmin(np.einsum("nkj,nkj->nk", diff, diff), axis=1)
    return [c[owner == k] for k in range(s.shape[0])]


def split_centroids(cells: F64, seeds: F64) -> list[tuple[float, float] | None]:
    """Each seed's part centroid after :func:`voronoi_split`; None for an empty part."""
    out: list[tuple[float, float] | None] = []
    for part in voronoi_split(cells, seeds):
        if part.shape[0] == 0:
            out.append(None)
        else:
            m = part.mean(axis=0)
            out.append((float(m[0]), float(m[1])))
    return out
