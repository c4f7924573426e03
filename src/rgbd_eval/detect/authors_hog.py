"""The thesis authors' person classifier: Dollár's HOG and their linear SVM (seed 000, 5.4.2).

The thesis scores each cluster with "Dollár's HOG implementation" and an SVM its
authors trained the Dalal-Triggs way; the trained model ships with this package
(``rgbd_eval/data/pcl_people``, BSD, from the Point Cloud Library's people module).
Its confidences are the units of the thesis' thresholds (Tables 5.1, 6.1, 7.4, 7.6).

Pipeline for one window (the facts in ``data/pcl_people/README.md``):

1. the window: ``height = round(h / 0.75)`` and ``width = round(h / 1.5)`` pixels for a
   person ``h`` pixels tall, centred on the person's projected mid point; the part
   outside the image is black;
2. resized to 64 x 128 with the authors' bilinear rule (source pixel ``i * H / 128``,
   no half-pixel shift, truncated to 8 bits; output pixels whose upper neighbour
   falls off the source stay black), RGB scaled to [0, 1];
3. gradients per channel (central differences, one-sided at the window edge), the
   channel of largest magnitude per pixel; orientation in [0, pi) looked up in
   Dollár's 25000-entry arc-cosine table;
4. 8 x 8 cells, 9 orientations, trilinear (orientation + both spatial axes) voting of
   magnitude / 64;
5. each cell normalised by its four 2 x 2 blocks (L2, clipped at 0.2); the inner
   6 x 14 cells kept: 4 x 9 x 84 = 3024 values, ordered normalisation, orientation,
   cell column, cell row;
6. confidence = ``weights . descriptor - b``.

Arithmetic is float32 where the authors' C++ uses ``float``, so the quantisations
(8-bit resize, table look-up, orientation bin) fall the same way. The C++ takes
``1/sqrt`` and ``1/x`` from the SSE approximations (12 bits); here they are exact,
which moves confidences by well under 1e-3 (see tests/detect/test_authors_hog.py).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numba
import numpy as np
import yaml
from numpy.typing import NDArray

from rgbd_eval.errors import ConfigError

F32 = np.float32
Float32Array = NDArray[np.float32]
FloatArray = NDArray[np.float64]

WINDOW_WIDTH = 64
WINDOW_HEIGHT = 128
CELL = 8
ORIENTATIONS = 9
CLIP = 0.2
#: A person fills this share of the window's height (the authors' training crops).
PERSON_IN_WINDOW = 0.75
#: Dollár's arc-cosine table: 25000 entries over cosines in [-1.01, 1.01].
_ACOS_ENTRIES = 25000
_ACOS_SPAN = F32(2.02)
_CELLS_Y = WINDOW_HEIGHT // CELL  # 16
_CELLS_X = WINDOW_WIDTH // CELL  # 8
DESCRIPTOR_SIZE = 4 * ORIENTATIONS * (_CELLS_X - 2) * (_CELLS_Y - 2)  # 3024

MODEL_FILE = "trainedLinearSVMForPeopleDetectionWithHOG.yaml"


@dataclass(frozen=True, eq=False)
class LinearSvm:
    """A linear SVM over HOG windows: ``confidence = weights . x - offset``."""

    window_height: int
    window_width: int
    weights: FloatArray
    offset: float


@dataclass(frozen=True)
class PersonWindow:
    """Where the classifier looks: a person ``height`` pixels tall centred at ``(xc, yc)``."""

    height: float
    xc: float
    yc: float


def load_svm(path: Path | None = None) -> LinearSvm:
    """Read a model in the authors' YAML format; ``None`` reads the shipped model.

    Raises :class:`ConfigError` naming the file when it cannot be read or does not
    describe a 64 x 128 window with 3024 weights.
    """
    if path is None:
        text = resources.files("rgbd_eval.data.pcl_people").joinpath(MODEL_FILE).read_text()
        where = f"rgbd_eval/data/pcl_people/{MODEL_FILE}"
    else:
        where = str(path)
        try:
            text = Path(path).read_text()
        except OSError as err:
            raise ConfigError(f"{where}: cannot read the SVM model ({err.strerror})") from err
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise ConfigError(f"{where}: not a YAML SVM model ({err})") from err
    if not isinstance(doc, dict) or not {"window_height", "window_width", "b", "weights"} <= set(
        doc
    ):
        raise ConfigError(f"{where}: needs window_height, window_width, b and weights")
    try:
        weights = np.asarray(doc["weights"], dtype=np.float32).astype(np.float64)
        offset = float(np.float32(doc["b"]))
        size = (int(doc["window_height"]), int(doc["window_width"]))
    except (TypeError, ValueError) as err:
        raise ConfigError(f"{where}: SVM model values must be numbers ({err})") from err
    if size != (WINDOW_HEIGHT, WINDOW_WIDTH) or weights.shape != (DESCRIPTOR_SIZE,):
        raise ConfigError(
            f"{where}: expected a {WINDOW_WIDTH}x{WINDOW_HEIGHT} window and {DESCRIPTOR_SIZE} "
            f"weights, got {size[1]}x{size[0]} and {weights.size}"
        )
    if not np.all(np.isfinite(weights)) or not math.isfinite(offset):
        raise ConfigError(f"{where}: SVM model holds non-finite values")
    return LinearSvm(size[0], size[1], weights, offset)


@lru_cache(maxsize=1)
def shipped_svm() -> LinearSvm:
    """The authors' trained model, read once."""
    return load_svm(None)


# ------------------------------------------------------------------ window sampling


def window_bounds(window: PersonWindow) -> tuple[int, int, int, int]:
    """``(xmin, ymin, width, height)`` of the image crop for ``window`` (integer pixels)."""
    h = F32(window.height)
    # float32 products, then double division, as the C++.
    span = PERSON_IN_WINDOW * WINDOW_HEIGHT
    height = math.floor(float(h * F32(WINDOW_HEIGHT)) / span + 0.5)
    width = math.floor(float(h * F32(WINDOW_WIDTH)) / span + 0.5)
    # C integer halving (towards zero), then rounding; centre in float32 as the C++.
    xmin = math.floor(float(F32(window.xc) - F32(int(width / 2))) + 0.5)
    ymin = math.floor(float(F32(window.yc) - F32(int(height / 2))) + 0.5)
    return xmin, ymin, width, height


def _sample_loop(
    rgb: NDArray[np.uint8], xmin: int, ymin: int, width: int, height: int, out: Float32Array
) -> None:
    """Fill ``out`` (128, 64, 3), zeroed, with the window's sample scaled to [0, 1].

    The crop ``[ymin, ymin + height) x [xmin, xmin + width)`` is black outside the image.
    Output row ``i`` reads crop row ``a = i * (1 / (128 / height))`` (float32): floor
    ``f1``, ceiling ``c1``, ``w1 = a - f1``; columns likewise (``b``, ``f2``, ``c2``,
    ``w2``). The value is the authors' ``(1 - w1) * ((1 - w2) * g(c1, f2) + w2 * g(f1, c2))
    + w1 * ((1 - w2) * g(f1, f2) + w2 * g(f1, c2))``, truncated to 8 bits; pixels whose
    ceiling row or column leaves the crop stay black.
    """
    one = np.float32(1.0)
    img_h, img_w = rgb.shape[0], rgb.shape[1]
    inv_y = one / (np.float32(WINDOW_HEIGHT) / np.float32(height))
    inv_x = one / (np.float32(WINDOW_WIDTH) / np.float32(width))
    # Per output column: floor/ceiling crop column, weight, whether in the image.
    k_lo = np.empty(WINDOW_WIDTH, dtype=np.int64)
    k_hi = np.empty(WINDOW_WIDTH, dtype=np.int64)
    w2s = np.empty(WINDOW_WIDTH, dtype=np.float32)
    cols = 0
    for j in range(WINDOW_WIDTH):
        b = np.float32(j) * inv_x
        f2 = math.floor(b)
        c2 = math.ceil(b)
        if c2 >= width:
            break  # and every later column (c2 grows with j)
        w2s[j] = b - np.float32(f2)
        k_lo[j], k_hi[j] = xmin + f2, xmin + c2
        cols = j + 1
    zero = np.float32(0.0)
    for i in range(WINDOW_HEIGHT):
        a = np.float32(i) * inv_y
        f1 = math.floor(a)
        c1 = math.ceil(a)
        if c1 >= height:
            break  # and every later row
        w1 = a - np.float32(f1)
        r_lo, r_hi = ymin + f1, ymin + c1
        lo_in = 0 <= r_lo < img_h
        hi_in = 0 <= r_hi < img_h
        for j in range(cols):
            w2 = w2s[j]
            lo_c = 0 <= k_lo[j] < img_w
            hi_c = 0 <= k_hi[j] < img_w
            for ch in range(3):
                g1 = np.float32(rgb[r_hi, k_lo[j], ch]) if hi_in and lo_c else zero
                g3 = np.float32(rgb[r_lo, k_lo[j], ch]) if lo_in and lo_c else zero
                g4 = np.float32(rgb[r_lo, k_hi[j], ch]) if lo_in and hi_c else zero
                v = (one - w1) * ((one - w2) * g1 + w2 * g4) + w1 * ((one - w2) * g3 + w2 * g4)
                out[i, j, ch] = np.float32(int(v)) / np.float32(255.0)


_sample_kernel: Callable[[NDArray[np.uint8], int, int, int, int, Float32Array], None] = numba.njit(
    cache=True
)(_sample_loop)


def window_sample(rgb: NDArray[np.uint8], window: PersonWindow) -> Float32Array:
    """The ``(128, 64, 3)`` float32 sample in [0, 1] that the classifier sees for ``window``.

    Black outside the image; the resize is the authors' rule (:func:`_sample_loop`),
    which mixes rows as ``(1 - w1) * row(ceil) + w1 * row(floor)`` and takes the
    right-hand column from the upper row only: kept, since the SVM was trained on
    samples made this way.
    """
    _check_rgb(rgb)
    out = np.zeros((WINDOW_HEIGHT, WINDOW_WIDTH, 3), dtype=np.float32)
    xmin, ymin, width, height = window_bounds(window)
    if width > 0 and height > 0:
        _sample_kernel(rgb, xmin, ymin, width, height, out)
    return out


def _check_rgb(rgb: NDArray[np.uint8]) -> None:
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"rgb must be an HxWx3 uint8 image, got {rgb.dtype} {rgb.shape}")


# ------------------------------------------------------------------ SSE reciprocals

SSE_TABLES = "sse_reciprocal.npz"
_FLT_MIN = float(np.finfo(np.float32).tiny)


@lru_cache(maxsize=1)
def _sse_tables() -> tuple[Float32Array, Float32Array]:
    """``rsqrt`` (2, 4096) and ``rcp`` (4096,) results for the 12-bit mantissa prefixes."""
    ref = resources.files("rgbd_eval.data.pcl_people").joinpath(SSE_TABLES)
    with ref.open("rb") as fh, np.load(fh) as doc:
        rsqrt = np.asarray(doc["rsqrt"], dtype=np.float32)
        rcp = np.asarray(doc["rcp"], dtype=np.float32)
    if rsqrt.shape != (2, 4096) or rcp.shape != (4096,):
        raise ConfigError(f"rgbd_eval/data/pcl_people/{SSE_TABLES}: malformed tables")
    return rsqrt, rcp


def _split(x: Float32Array) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Unbiased exponent and top-12-bit mantissa index of positive normal float32s."""
    bits = np.ascontiguousarray(x, dtype=np.float32).view(np.uint32).astype(np.int64)
    return ((bits >> 23) & 0xFF) - 127, (bits >> 11) & 0xFFF


def sse_rsqrt(x: Float32Array) -> Float32Array:
    """``_mm_rsqrt_ps`` as the project's AMD Zen CPUs compute it (``inf`` for 0 and denormals).

    The result depends only on the exponent's parity and the mantissa's top 12 bits
    (measured by ``bench/peers/make_sse_tables.py``), scaled by the exponent.
    """
    x = np.asarray(x, dtype=np.float32)
    table = _sse_tables()[0]
    safe = np.where(x >= _FLT_MIN, x, F32(1.0))
    exp, idx = _split(safe)
    odd = exp & 1
    out = np.ldexp(table[odd, idx].astype(np.float64), -(exp - odd) // 2).astype(np.float32)
    return np.where(x >= _FLT_MIN, out, F32(np.inf))


def sse_rcp(x: Float32Array) -> Float32Array:
    """``_mm_rcp_ps`` as the project's AMD Zen CPUs compute it, for positive normal inputs."""
    x = np.asarray(x, dtype=np.float32)
    exp, idx = _split(x)
    return np.ldexp(_sse_tables()[1][idx].astype(np.float64), -exp).astype(np.float32)


# ------------------------------------------------------------------ descriptor


@lru_cache(maxsize=1)
def _acos_table() -> Float32Array:
    """Dollár's arc-cosine table, index 0 at cosine -1.01; angles within 1e-5 of pi become 0."""
    n = _ACOS_ENTRIES
    step = _ACOS_SPAN / F32(n)
    t = np.arange(n, dtype=np.float32) * step - F32(1.01)
    t = np.clip(t, F32(-1.0), F32(1.0))
    a = np.arccos(t).astype(np.float32)
    limit = math.pi - float(F32(1e-5))
    return np.where(a.astype(np.float64) <= limit, a, F32(0.0)).astype(np.float32)


def _histogram_loop(
    img: Float32Array,
    table: Float32Array,
    rsqrt: NDArray[np.uint32],
    rcp: NDArray[np.uint32],
    approximate: bool,
    hist: Float32Array,
) -> None:
    """Add the cell histograms of one ``(128, 64, 3)`` sample to ``hist`` (9, 8, 16), zeroed.

    Per pixel: per-channel gradients (central differences, one-sided at the edges),
    the channel of largest squared magnitude (the first on ties); magnitude ``m``;
    orientation from the table at ``trunc(gx / m * 25000 / 2.02)``, the cosine's sign
    flipped where ``gy < 0``; orientation bin ``o = angle * 9 / pi`` split between
    ``floor(o)`` and the next bin (cyclic); magnitude / 64 split bilinearly between the
    four nearest cell centres (cell ``k`` centred at pixel ``8k + 3.5``). Pixel order
    and float32 arithmetic are the C++'s, so sums round the same way. With
    ``approximate``, ``1 / sqrt(m^2)`` and ``m = 1 / that`` come from the SSE tables
    ``rsqrt``/``rcp`` (their float32 bits; as :func:`sse_rsqrt`, :func:`sse_rcp`);
    else they are exact.
    """
    half = np.float32(0.5)
    one = np.float32(1.0)
    zero = np.float32(0.0)
    cap = np.float32(1e10)
    ac_mult = np.float32(_ACOS_ENTRIES) / _ACOS_SPAN
    o_mult = np.float32(ORIENTATIONS / math.pi)
    norm = one / np.float32(CELL) / np.float32(CELL)
    s_inv = one / np.float32(CELL)
    init = (zero + half) * s_inv - half
    centre = _ACOS_ENTRIES // 2
    flt_min = np.float32(_FLT_MIN)
    buf = np.empty(1, dtype=np.float32)
    bits = buf.view(np.uint32)
    h, w = WINDOW_HEIGHT, WINDOW_WIDTH
    hb, wb = _CELLS_Y, _CELLS_X
    xb = init
    for x in range(w):
        xp, xn = max(x - 1, 0), min(x + 1, w - 1)
        rx = half if 0 < x < w - 1 else one
        has_lf = xb >= zero
        xb0 = int(xb) if has_lf else -1
        has_rt = xb0 < wb - 1
        xd = xb - np.float32(xb0)
        xb += s_inv
        yb = init
        for y in range(h):
            yp, yn = max(y - 1, 0), min(y + 1, h - 1)
            ry = half if 0 < y < h - 1 else one
            gx_best = zero
            gy_best = zero
            m2_best = zero
            for c in range(3):
                gx = (img[y, xn, c] - img[y, xp, c]) * rx
                gy = (img[yn, x, c] - img[yp, x, c]) * ry
                m2 = gx * gx + gy * gy
                if c == 0 or m2 > m2_best:
                    gx_best, gy_best, m2_best = gx, gy, m2
            if approximate:
                # Table entry for the mantissa's top 12 bits, its exponent field shifted
                # by the input's (halved, for rsqrt): exact powers of two.
                if m2_best >= flt_min:
                    buf[0] = m2_best
                    b = np.int64(bits[0])
                    e = ((b >> 23) & 0xFF) - 127
                    odd = e & 1
                    r = np.int64(rsqrt[odd, (b >> 11) & 0xFFF]) - (((e - odd) // 2) << 23)
                    bits[0] = np.uint32(r)
                    inv = min(buf[0], cap)
                else:
                    inv = cap
                buf[0] = inv
                b = np.int64(bits[0])
                e = ((b >> 23) & 0xFF) - 127
                bits[0] = np.uint32(np.int64(rcp[(b >> 11) & 0xFFF]) - (e << 23))
                mag = buf[0]
            else:
                inv = min(one / np.float32(math.sqrt(m2_best)), cap) if m2_best > zero else cap
                mag = one / inv
            cos = (gx_best * inv) * ac_mult
            if gy_best < zero:
                cos = -cos
            o = table[int(cos) + centre] * o_mult
            bin0 = int(o)
            od = o - np.float32(bin0)
            bin1 = bin0 + 1 if bin0 + 1 < ORIENTATIONS else 0
            m = mag * norm
            m1 = od * m
            m0 = m - m1
            yb0 = int(yb) if yb >= zero else -1
            yd = yb - np.float32(yb0)
            yb += s_inv
            xyd = xd * yd
            w00 = one - xd - yd + xyd  # (xb0, yb0)
            w01 = yd - xyd  # (xb0, yb0 + 1)
            w10 = xd - xyd  # (xb0 + 1, yb0)
            w11 = xyd  # (xb0 + 1, yb0 + 1)
            for ob, mb in ((bin0, m0), (bin1, m1)):
                if has_lf:
                    if yb0 >= 0:
                        hist[ob, xb0, yb0] += w00 * mb
                    if yb0 + 1 < hb:
                        hist[ob, xb0, yb0 + 1] += w01 * mb
                if has_rt:
                    if yb0 >= 0:
                        hist[ob, xb0 + 1, yb0] += w10 * mb
                    if yb0 + 1 < hb:
                        hist[ob, xb0 + 1, yb0 + 1] += w11 * mb


_histogram_kernel: Callable[
    [Float32Array, Float32Array, NDArray[np.uint32], NDArray[np.uint32], bool, Float32Array], None
] = numba.njit(cache=True)(_histogram_loop)


def _normalise(hist: Float32Array) -> Float32Array:
    """Four clipped L2 block normalisations of the inner cells, in the SVM's order.

    ``hist`` is ``(N, 9, 8 columns, 16 rows)``. The block with top-left cell
    ``(column, row)`` has ``1 / sqrt(sum of its 4 x 9 squares + eps)``; cell ``(c, r)``
    is normalised by blocks ``(c, r)``, ``(c, r - 1)``, ``(c - 1, r)``, ``(c - 1, r - 1)``
    in that order, clipped at 0.2. Output ``(N, 3024)``: normalisation, orientation,
    column 1..6, row 1..14.
    """
    energy = np.zeros(hist.shape[:1] + hist.shape[2:], dtype=np.float32)
    for o in range(ORIENTATIONS):  # the C++ summation order
        energy += hist[:, o] * hist[:, o]
    eps = F32(1e-4) / F32(4) / F32(CELL) / F32(CELL) / F32(CELL) / F32(CELL)
    block = energy[:, :-1, :-1] + energy[:, :-1, 1:] + energy[:, 1:, :-1] + energy[:, 1:, 1:]
    inv = F32(1.0) / np.sqrt(block + eps)  # (N, 7, 15)
    inner = hist[:, :, 1:-1, 1:-1]  # (N, 9, 6, 14)
    norms = (inv[:, 1:, 1:], inv[:, 1:, :-1], inv[:, :-1, 1:], inv[:, :-1, :-1])
    feats = np.stack([np.minimum(F32(CLIP), inner * k[:, None]) for k in norms], axis=1)
    out: Float32Array = feats.reshape(feats.shape[0], -1)
    return out


def hog_descriptors(samples: Float32Array, approximate: bool = True) -> Float32Array:
    """Dollár HOG descriptors ``(N, 3024)`` of ``(N, 128, 64, 3)`` float32 samples in [0, 1].

    ``approximate``: take the gradient magnitude's reciprocals from the SSE tables,
    as the authors' C++ does on the project's CPUs (default); else exact.
    """
    if samples.ndim != 4 or samples.shape[1:] != (WINDOW_HEIGHT, WINDOW_WIDTH, 3):
        raise ValueError(f"samples must be (N, 128, 64, 3), got {samples.shape}")
    table = _acos_table()
    rsqrt, rcp = (t.view(np.uint32) for t in _sse_tables())
    hist = np.zeros((samples.shape[0], ORIENTATIONS, _CELLS_X, _CELLS_Y), dtype=np.float32)
    for k in range(samples.shape[0]):
        sample = np.ascontiguousarray(samples[k], dtype=np.float32)
        _histogram_kernel(sample, table, rsqrt, rcp, approximate, hist[k])
    return _normalise(hist)


def person_confidences(
    rgb: NDArray[np.uint8],
    windows: Sequence[PersonWindow],
    svm: LinearSvm | None = None,
    approximate: bool = True,
) -> FloatArray:
    """The authors' classifier confidence for each window (``svm``: default the shipped model).

    ``weights . descriptor - b`` with float32 products summed in float64, as the C++;
    ``approximate`` as in :func:`hog_descriptors`.
    """
    _check_rgb(rgb)
    if len(windows) == 0:
        return np.zeros(0, dtype=np.float64)
    model = shipped_svm() if svm is None else svm
    samples = np.stack([window_sample(rgb, w) for w in windows])
    products = hog_descriptors(samples, approximate) * model.weights.astype(np.float32)
    scores: FloatArray = products.astype(np.float64).sum(axis=1) - model.offset
    return scores
