"""Distance-template search of satake2009 (seed 002, 2.2 and 2.4): whole image and around a track.

Both searches score the templates of :mod:`.satake2009_templates` on a depth image
resampled so that the tallest template is about ``template_rows`` tall at the searched
distance (a depth pyramid level per distance: the agreement maps are averaged down with
``INTER_AREA``, so a coarse cell holds the share of agreeing pixels). The whole-image
search (2.4 step 3, new people) runs over a geometric grid of distances; the search
around a track (2.4 step 2.2) covers a window around the track's predicted head top at
three distances around its predicted distance, on a finer level. The best template wins.

Depth of a frame (:func:`frame_depth`) is computed once and shared by the detector and
the tracker that reads the same frame (a one-entry memo per thread, keyed by the
identity of the frame's images and the SGBM settings); a tracker replayed on a fresh
read of the recording computes it again.
"""

from __future__ import annotations

import functools
import math
import threading
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import cv2
import numba
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect import stereo
from rgbd_eval.methods.satake2009 import templates as st
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.types import Frame


@dataclass(frozen=True)
class MatchParams:
    """How a template agrees with depth (see :mod:`.satake2009_templates`)."""

    band_m: float
    gap_m: float
    min_score: float


_LOCAL = threading.local()


def _matcher(params: stereo.SgbmParams) -> cv2.StereoSGBM:
    matchers: dict[stereo.SgbmParams, cv2.StereoSGBM] = _LOCAL.__dict__.setdefault("matchers", {})
    if params not in matchers:
        matchers[params] = stereo.make_matcher(params)
    return matchers[params]


#: The streams satake2009 reads: the left image, and the right one or a DisparityImage.
STREAMS = (
    StreamSpec("left"),
    StreamSpec("right", required=False),
    StreamSpec("disparity", required=False),
)


def frame_depth(
    frame: Frame, size: tuple[int, int], params: stereo.SgbmParams
) -> stereo.StereoDepth:
    """Depth of the left view at ``size``, computed once per frame.

    From a ``stereo_msgs/DisparityImage`` (``disparity`` stream, already depth) when the
    recording has one, else SGBM on the ``left``/``right`` pair. InputError-free: a frame
    with neither is a ValueError naming what is missing.
    """
    if "disparity" in frame.streams:
        given = frame.stream("disparity")
        if (given.camera.width, given.camera.height) == size:
            return stereo.StereoDepth(given.image, given.camera)
        depth = cv2.resize(given.image, size, interpolation=cv2.INTER_NEAREST)
        return stereo.StereoDepth(np.asarray(depth, np.float32), given.camera.scaled(*size))
    if "right" not in frame.streams:
        raise ValueError(
            f"frame {frame.index} has no right image and no DisparityImage: satake2009 needs "
            "a stereo pair (--topic right=/name) or a disparity (--topic disparity=/name)"
        )
    left, right = frame.stream("left"), frame.stream("right")
    key = (size, params)
    memo: tuple[Any, ...] | None = getattr(_LOCAL, "memo", None)
    if memo is not None and memo[0] == key and memo[1]() is left.image and memo[2]() is right.image:
        cached: stereo.StereoDepth = memo[3]
        return cached
    sd = stereo.stereo_depth(
        left.image, right.image, left.camera, stereo.baseline_of(right.camera), size,
        _matcher(params),
    )  # fmt: skip
    _LOCAL.memo = (key, weakref.ref(left.image), weakref.ref(right.image), sd)
    return sd


def _tallest(templates: list[st.DistanceTemplate]) -> int:
    return max(int(t.mask.shape[0]) for t in templates)


def level(templates: list[st.DistanceTemplate], distance: float, fx: float, rows: int) -> int:
    """Integer reduction ``n``: every ``n``-th pixel makes the tallest template about ``rows`` tall.

    Integer factors keep OpenCV's area averaging on its fast path (a fractional one costs
    ~10x more).
    """
    tall = _tallest(templates) * (fx / st.F_REF) * (st.D_REF / distance)
    return max(1, round(float(tall) / rows))


def _cells(
    depth: NDArray[np.float32],
    lo: np.float32,
    hi: np.float32,
    beyond: np.float32,
    n: int,
    share: NDArray[np.float32],
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """The maps ``near - free`` and ``free`` over ``n x n`` cells, in one pass over ``depth``.

    A pixel is near when ``lo <= z <= hi`` and free when ``z > beyond`` (float32 bounds, as
    :func:`cv2.inRange` and :func:`cv2.compare` take a scalar for a float32 image); a cell
    with ``k`` of them has the share ``share[k]`` (:func:`area_shares`). Integer counts:
    nothing depends on the order of the loop.
    """
    rows, cols = depth.shape[0] // n, depth.shape[1] // n
    m = cols * n
    diff = np.empty((rows, cols), np.float32)
    free = np.empty((rows, cols), np.float32)
    near_px = np.zeros(m, np.int32)  # per pixel column: counts over the cell's rows
    free_px = np.zeros(m, np.int32)
    for i in range(rows):
        for x in range(m):
            near_px[x] = 0
            free_px[x] = 0
        for y in range(i * n, i * n + n):
            row = depth[y]
            for x in range(m):
                z = row[x]
                near_px[x] += np.int32(1) if (z >= lo) & (z <= hi) else np.int32(0)
                free_px[x] += np.int32(1) if z > beyond else np.int32(0)
        for j in range(cols):
            a = 0
            b = 0
            for x in range(j * n, j * n + n):
                a += near_px[x]
                b += free_px[x]
            f = share[b]
            diff[i, j] = share[a] - f
            free[i, j] = f
    return diff, free


_cells_kernel: Callable[
    [NDArray[np.float32], np.float32, np.float32, np.float32, int, NDArray[np.float32]],
    tuple[NDArray[np.float32], NDArray[np.float32]],
] = numba.njit(cache=True)(_cells)


@functools.cache
def area_shares(n: int) -> NDArray[np.float32]:
    """The share :meth:`.satake2009_templates.Agreement.of` gives an ``n x n`` cell of 0/255
    pixels averaged with ``cv2.resize(..., INTER_AREA)``, ``k`` of them 255, for ``k = 0 .. n^2``.

    On an integer factor OpenCV sums the cell exactly and rounds the mean once, so its
    output depends on the count alone; asking OpenCV itself keeps its rounding.
    """
    k = n * n
    cells = np.zeros((n, n * (k + 1)), np.uint8)
    for c in range(1, k + 1):
        cell = np.zeros(k, np.uint8)
        cell[:c] = 255
        cells[:, c * n : (c + 1) * n] = cell.reshape(n, n)
    if n > 1:
        cells = np.asarray(cv2.resize(cells, (k + 1, 1), interpolation=cv2.INTER_AREA), np.uint8)
    share: NDArray[np.float32] = st.Agreement.of(cells[:1], cells[:1], 255.0).free[0].copy()
    share.flags.writeable = False
    return share


def _reduced(
    depth: NDArray[np.float32], distance: float, n: int, params: MatchParams
) -> st.Agreement:
    """The agreement maps at ``distance``, averaged over ``n x n`` cells (a partial last cell dropped).

    ``depth`` has no NaN: no depth is +inf (:func:`.satake2009_templates.no_depth_far`).
    The same maps as :func:`.satake2009_templates.agreement_u8_far`, each averaged down with
    ``INTER_AREA`` and put through :meth:`.satake2009_templates.Agreement.of`, in one pass.
    """
    h, w = depth.shape
    if h < n or w < n:
        empty = np.zeros((0, 0), np.float32)
        return st.Agreement(empty, empty)
    diff, free = _cells_kernel(
        depth,
        np.float32(distance - params.band_m),
        np.float32(distance + params.band_m),
        np.float32(distance + params.gap_m),
        n,
        area_shares(n),
    )
    return st.Agreement(diff, free)


def suppress(matches: list[st.Match], iou: float) -> list[st.Match]:
    """Best first; a match overlapping a kept one by more than ``iou`` is dropped."""
    if not matches:
        return []
    order = np.argsort([-m.score for m in matches], kind="stable")
    boxes = np.array([matches[i].box for i in order], dtype=np.float64)
    x0, y0 = boxes[:, 0], boxes[:, 1]
    x1, y1 = x0 + boxes[:, 2], y0 + boxes[:, 3]
    area = boxes[:, 2] * boxes[:, 3]
    alive = np.ones(len(order), dtype=bool)
    kept: list[st.Match] = []
    for k in range(len(order)):
        if not alive[k]:
            continue
        kept.append(matches[int(order[k])])
        w = np.minimum(x1[k], x1) - np.maximum(x0[k], x0)
        h = np.minimum(y1[k], y1) - np.maximum(y0[k], y0)
        inter = np.maximum(w, 0.0) * np.maximum(h, 0.0)
        alive &= inter / (area[k] + area - inter) <= iou
    return kept


def search_whole(
    depth: NDArray[np.float32],
    fx: float,
    templates: list[st.DistanceTemplate],
    distances: list[float],
    rows: int,
    params: MatchParams,
    per_template: int = 20,
    cache: dict[tuple[float, float], list[st.DistanceTemplate]] | None = None,
    far: NDArray[np.float32] | None = None,
) -> list[st.Match]:
    """Matches above ``min_score`` anywhere, at each distance, before suppression.

    ``cache`` keeps the scaled templates between calls (the distances are a fixed grid);
    ``far`` is ``depth`` with NaN as +inf when the caller has it (:attr:`StereoDepth.far`).
    """
    found: list[st.Match] = []
    cache = {} if cache is None else cache
    filled = st.no_depth_far(depth) if far is None else far
    for D in distances:
        n = level(templates, D, fx, rows)
        maps = _reduced(filled, D, n, params)
        key = (D, fx / n)
        if key not in cache:
            cache[key] = [st.scale_template(t0, D, fx / n) for t0 in templates]
        usable = [t for t in cache[key] if t.mask.shape[0] >= 8]
        for t, scores in zip(usable, maps.score_all(usable), strict=True):
            if scores is None:
                continue  # larger than the image
            th, tw = t.mask.shape
            if cv2.minMaxLoc(scores)[1] < params.min_score:
                continue  # nothing to collect (the common case: one C pass, no allocation)
            ys, xs = np.nonzero(scores >= params.min_score)
            values = scores[ys, xs]
            order = np.argsort(-values, kind="stable")[:per_template]
            ys, xs = ys[order], xs[order]
            us, vs = (xs + t.anchor[0]) * n, (ys + t.anchor[1]) * n  # the head top
            size = (tw * n, th * n)
            for u, v, score, x0, y0 in zip(
                us, vs, values[order].tolist(), (xs * n).tolist(), (ys * n).tolist(), strict=True
            ):
                found.append(st.Match(u, v, D, score, t.orientation_deg, (x0, y0, *size)))
    return found


def search_around(
    depth: NDArray[np.float32],
    fx: float,
    templates: list[st.DistanceTemplate],
    head: tuple[float, float],
    distances: list[float],
    radius_px: float,
    rows: int,
    params: MatchParams,
    cache: dict[tuple[float, float], list[st.DistanceTemplate]] | None = None,
    far: NDArray[np.float32] | None = None,
) -> st.Match | None:
    """The best template whose head top lies within ``radius_px`` of ``head`` (None: none fits).

    Only the window the templates can cover is scored, so the cost does not grow with
    the image. The winner may score below ``min_score``: the caller decides. ``cache``
    keeps scaled templates (worth it when the caller quantises the distances); ``far``
    is as for :func:`search_whole`.
    """
    H, W = depth.shape
    u0, v0 = head
    best: st.Match | None = None
    cache = {} if cache is None else cache
    for D in distances:
        n = level(templates, D, fx, rows)
        k = 1.0 / n
        key = (D, fx * k)
        if key not in cache:
            cache[key] = [st.scale_template(t0, D, fx * k) for t0 in templates]
        scaled = cache[key]
        # full-resolution window covering every template whose anchor is within the radius
        left = max(0, math.floor(u0 - radius_px - max(t.anchor[0] for t in scaled) / k))
        top = max(0, math.floor(v0 - radius_px - max(t.anchor[1] for t in scaled) / k))
        right = min(
            W, math.ceil(u0 + radius_px + max(t.mask.shape[1] - t.anchor[0] for t in scaled) / k)
        )
        bottom = min(H, math.ceil(v0 + radius_px + max(t.mask.shape[0] - t.anchor[1] for t in scaled) / k))  # fmt: skip
        if right - left < 2 or bottom - top < 2:
            continue
        window = (slice(top, bottom), slice(left, right))
        maps = _reduced(
            st.no_depth_far(depth[window]) if far is None else far[window], D, n, params
        )
        for t in scaled:
            th, tw = t.mask.shape
            if th > maps.diff.shape[0] or tw > maps.diff.shape[1]:
                continue
            scores = maps.score(t)
            # only placements whose head top is within the radius of the prediction
            xs = (np.arange(scores.shape[1]) + t.anchor[0]) * n + left - u0
            ys = (np.arange(scores.shape[0]) + t.anchor[1]) * n + top - v0
            inside = (ys[:, None] ** 2 + xs[None, :] ** 2) <= radius_px**2
            if not inside.any():
                continue
            masked = np.where(inside, scores, -1.0)
            y, x = np.unravel_index(int(np.argmax(masked)), masked.shape)
            score = float(masked[y, x])
            if best is None or score > best.score:
                best = st.Match(
                    left + (x + t.anchor[0]) * n, top + (y + t.anchor[1]) * n, D, score,
                    t.orientation_deg, (left + int(x) * n, top + int(y) * n, tw * n, th * n),
                )  # fmt: skip
    return best


def quantised(distance: float, step: float = 1.02) -> float:
    """``distance`` rounded to the geometric grid ``step^k`` (so scaled templates can be reused)."""
    return float(step ** round(math.log(distance) / math.log(step)))


def body_distance(depth: NDArray[np.float32], m: st.Match, band_m: float) -> float:
    """Median depth of the box's pixels within ``band_m`` of the match's distance (D refined)."""
    x, y, w, h = m.box
    patch = depth[max(0, y) : y + h, max(0, x) : x + w]
    with np.errstate(invalid="ignore"):
        body = patch[np.abs(patch - m.distance) < band_m]
    return float(np.median(body)) if body.size else m.distance
