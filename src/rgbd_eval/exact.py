"""Arithmetic whose every bit is the same on every x86-64 CPU.

IEEE 754 fixes the result of ``+ - * /`` and ``sqrt`` to the last bit, and numpy's
elementwise ufuncs for them (and ``floor``, ``rint``, ``ldexp``, ``frexp``, comparisons)
give those results whatever SIMD code a CPU runs. Much else that looks as innocent does
not; each of these was seen to change the bytes of a rendered recording:

- BLAS: ``@``, ``np.dot``, ``np.linalg.norm`` of a vector, ``np.linalg.inv``. OpenBLAS
  picks its kernels by CPU (Zen, Haswell, SkylakeX with AVX-512, Sandybridge); they sum
  in different orders and fuse multiply-adds differently.
- glibc's libm (``math.sin``, ``math.exp``, ``x ** y`` on floats): its FMA and its
  non-FMA variants disagree in the last bit for many arguments.
- numpy's transcendental ufuncs (``np.sin``, ``np.exp``, ``np.power``, ...): AVX-512
  CPUs run other implementations than AVX2 ones.
- numpy's Gaussian sampler, which calls libm in the tails of its ziggurat.

This module gives what the simulator needs from those, built only from the exact
operations and in a fixed order: small matrix products, norms, cross products, the
elementary functions (to within a few units in the last place of the correctly
rounded value), and normal samples. Every function takes a Python float or a numpy
array and returns the same kind; the scalar and the array paths do the same
operations, so they agree bit for bit.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, TypeVar, overload

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
X = TypeVar("X", float, F64)

# ----------------------------------------------------------------------------- constants

#: pi to 60 decimal places (a mathematical constant; the splits below are derived from it).
_PI = Fraction("3.141592653589793238462643383279502884197169399375105820974944")
#: ln 2 to 60 decimal places.
_LN2 = Fraction("0.693147180559945309417232121458176568075500134360255254120680")


def _split(value: Fraction, bits: int) -> tuple[float, Fraction]:
    """``value`` cut to its first ``bits`` significant bits (a float), and the rest."""
    exponent = math.frexp(float(abs(value)))[1] - 1  # frexp is exact; log2 is libm
    scale = Fraction(2) ** (bits - 1 - exponent)
    head = Fraction(math.floor(value * scale)) / scale
    return float(head), value - head


PI = float(_PI)
HALF_PI = float(_PI / 2)
QUARTER_PI = float(_PI / 4)
TWO_OVER_PI = float(2 / _PI)
#: pi/2 in three parts of 33 bits: k * part is exact for |k| < 2**20.
_PIO2_1, _rest = _split(_PI / 2, 33)
_PIO2_2, _rest = _split(_rest, 33)
_PIO2_3 = float(_rest)
INV_LN2 = float(1 / _LN2)
_LN2_HI, _rest = _split(_LN2, 33)
_LN2_LO = float(_rest)
_SQRT_HALF = math.sqrt(0.5)  # sqrt is exact (IEEE), so this constant is CPU-independent

# Taylor coefficients, exact rationals rounded once to the nearest float.
_SIN = [float(Fraction((-1) ** n, math.factorial(2 * n + 1))) for n in range(1, 9)]  # r^3..r^17
_COS = [float(Fraction((-1) ** n, math.factorial(2 * n))) for n in range(1, 10)]  # r^2..r^18
_EXP = [float(Fraction(1, math.factorial(n))) for n in range(0, 14)]  # r^0..r^13
_ATANH = [float(Fraction(1, 2 * n + 1)) for n in range(0, 13)]  # s^0..s^24 (log)
_ATAN = [float(Fraction((-1) ** n, 2 * n + 1)) for n in range(0, 13)]  # u^1..u^25


def _horner(coefficients: list[float], x: Any) -> Any:
    """``c0 + x (c1 + x (c2 + ...))``, innermost first (a fixed order of exact operations)."""
    acc: Any = coefficients[-1]
    for c in reversed(coefficients[:-1]):
        acc = acc * x + c
    return acc


def _is_scalar(x: object) -> bool:
    return isinstance(x, float | int)


def _array(x: Any) -> F64:
    return np.asarray(x, dtype=np.float64)


# ----------------------------------------------------------------------------- trigonometry


def _reduce(x: F64) -> tuple[F64, F64]:
    """``x = k pi/2 + r`` with ``|r| <= pi/4`` (about): (r, k mod 4 as 0..3)."""
    k = np.rint(x * TWO_OVER_PI)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3
    quadrant = k - 4.0 * np.floor(k * 0.25)
    return r, quadrant


def _sin_cos_reduced(r: F64) -> tuple[F64, F64]:
    r2 = r * r
    s = r + r * (r2 * _horner(_SIN, r2))
    c = 1.0 + r2 * _horner(_COS, r2)
    return s, c


def _sincos_array(x: F64) -> tuple[F64, F64]:
    r, q = _reduce(x)
    s, c = _sin_cos_reduced(r)
    sin = np.where(q == 0, s, np.where(q == 1, c, np.where(q == 2, -s, -c)))
    cos = np.where(q == 0, c, np.where(q == 1, -s, np.where(q == 2, -c, s)))
    return sin, cos


def _sincos_scalar(x: float) -> tuple[float, float]:
    # the operations of _reduce, _sin_cos_reduced and _sincos_array, on one float
    k = float(round(x * TWO_OVER_PI))
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3
    q = k - 4.0 * math.floor(k * 0.25)
    r2 = r * r
    s = r + r * (r2 * _horner(_SIN, r2))
    c = 1.0 + r2 * _horner(_COS, r2)
    if q == 0:
        return s, c
    if q == 1:
        return c, -s
    if q == 2:
        return -s, -c
    return -c, s


@overload
def sincos(x: float) -> tuple[float, float]: ...
@overload
def sincos(x: F64) -> tuple[F64, F64]: ...
def sincos(x: float | F64) -> tuple[float, float] | tuple[F64, F64]:
    """(sin x, cos x), within a few ulp for |x| < 1e6."""
    if _is_scalar(x):
        return _sincos_scalar(float(x))
    return _sincos_array(_array(x))


def sin(x: X) -> X:
    """sin x (see :func:`sincos`)."""
    return sincos(x)[0]


def cos(x: X) -> X:
    """cos x (see :func:`sincos`)."""
    return sincos(x)[1]


def tan(x: X) -> X:
    """tan x = sin x / cos x."""
    s, c = sincos(x)
    return s / c


def _atan_array(x: F64) -> F64:
    a = np.abs(x)
    big = a > 1.0
    with np.errstate(divide="ignore"):
        t = np.where(big, 1.0 / np.where(big, a, 1.0), a)
    # two half-angle steps, atan t = 2 atan(t / (1 + sqrt(1 + t^2))): |u| <= tan(pi/16)
    u = t / (1.0 + np.sqrt(1.0 + t * t))
    u = u / (1.0 + np.sqrt(1.0 + u * u))
    small = 4.0 * (u * _horner(_ATAN, u * u))
    out = np.where(big, HALF_PI - small, small)
    return np.asarray(np.where(x < 0, -out, out), dtype=np.float64)


def _atan_scalar(x: float) -> float:
    # the operations of _atan_array, on one float
    a = abs(x)
    big = a > 1.0
    t = 1.0 / a if big else a
    u = t / (1.0 + math.sqrt(1.0 + t * t))
    u = u / (1.0 + math.sqrt(1.0 + u * u))
    small = 4.0 * (u * _horner(_ATAN, u * u))
    out = HALF_PI - small if big else small
    return float(-out if x < 0 else out)


def atan(x: X) -> X:
    """arctan x."""
    if _is_scalar(x):
        return _atan_scalar(float(x))  # type: ignore[return-value]
    return _atan_array(_array(x))  # type: ignore[return-value]


def _atan2_scalar(y: float, x: float) -> float:
    if x > 0:
        return _atan_scalar(y / x)
    if x < 0:
        base = _atan_scalar(y / x)
        return base + PI if y >= 0 else base - PI
    return HALF_PI if y > 0 else -HALF_PI if y < 0 else 0.0


def atan2(y: X, x: X) -> X:
    """The angle of (x, y) in [-pi, pi], as ``math.atan2`` (signed zeros aside)."""
    if _is_scalar(x) and _is_scalar(y):
        return _atan2_scalar(float(y), float(x))  # type: ignore[return-value]
    ya, xa = _array(y), _array(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(xa != 0, ya / np.where(xa != 0, xa, 1.0), 0.0)
    base = _atan_array(ratio)
    upper = ya >= 0
    out = np.where(
        xa > 0,
        base,
        np.where(
            xa < 0,
            np.where(upper, base + PI, base - PI),
            np.where(ya > 0, HALF_PI, np.where(ya < 0, -HALF_PI, 0.0)),
        ),
    )
    return out  # type: ignore[return-value]


# ----------------------------------------------------------------------------- exp and log


def _exp_array(x: F64) -> F64:
    x = np.clip(x, -746.0, 710.0)
    k = np.rint(x * INV_LN2)
    r = (x - k * _LN2_HI) - k * _LN2_LO
    p = _horner(_EXP, r)
    with np.errstate(over="ignore", under="ignore"):
        out: F64 = np.ldexp(p, k.astype(np.int64))
    return out


def _exp_scalar(x: float) -> float:
    # the operations of _exp_array, on one float
    x = min(max(x, -746.0), 710.0)
    k = float(round(x * INV_LN2))
    r = (x - k * _LN2_HI) - k * _LN2_LO
    p = _horner(_EXP, r)
    try:
        return math.ldexp(p, int(k))
    except OverflowError:
        return math.inf


def exp(x: X) -> X:
    """e**x (0 below -745, inf above 709.8)."""
    if _is_scalar(x):
        return _exp_scalar(float(x))  # type: ignore[return-value]
    return _exp_array(_array(x))  # type: ignore[return-value]


def _log_array(x: F64) -> F64:
    m, e = np.frexp(x)
    low = m < _SQRT_HALF
    m = np.where(low, m * 2.0, m)
    ef = e.astype(np.float64) - np.where(low, 1.0, 0.0)
    s = (m - 1.0) / (m + 1.0)
    log_m = 2.0 * (s * _horner(_ATANH, s * s))
    out = ef * _LN2_HI + (ef * _LN2_LO + log_m)
    out = np.where(x == 0, -np.inf, out)
    out = np.where(x < 0, np.nan, out)
    return np.where(np.isposinf(x), np.inf, out)


def _log_scalar(x: float) -> float:
    # the operations of _log_array, on one float
    if x != x or x < 0:
        return math.nan
    if x == 0:
        return -math.inf
    if x == math.inf:
        return math.inf
    m, e = math.frexp(x)
    ef = float(e)
    if m < _SQRT_HALF:
        m, ef = m * 2.0, ef - 1.0
    s = (m - 1.0) / (m + 1.0)
    log_m = 2.0 * (s * _horner(_ATANH, s * s))
    return float(ef * _LN2_HI + (ef * _LN2_LO + log_m))


def log(x: X) -> X:
    """Natural logarithm (-inf at 0, NaN below)."""
    if _is_scalar(x):
        return _log_scalar(float(x))  # type: ignore[return-value]
    with np.errstate(invalid="ignore", divide="ignore"):
        return _log_array(_array(x))  # type: ignore[return-value]


def power(x: X, y: float) -> X:
    """x**y for x >= 0, as exp(y log x) (0**y = 0 for y > 0, 1 for y = 0)."""
    if _is_scalar(x):
        xs = float(x)
        if y == 0:
            return 1.0  # type: ignore[return-value]
        if xs < 0 or xs != xs:
            return math.nan  # type: ignore[return-value]
        if xs == 0:
            return 0.0 if y > 0 else math.inf  # type: ignore[return-value]
        return _exp_scalar(y * _log_scalar(xs))  # type: ignore[return-value]
    xa = _array(x)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(xa == 0, 0.0 if y > 0 else np.inf, _exp_array(y * _log_array(xa)))
    out = np.where((xa < 0) | np.isnan(xa), np.nan, out)
    if y == 0:
        out = np.ones_like(out)
    return out  # type: ignore[return-value]


def cbrt(x: X) -> X:
    """The real cube root (negative for negative x): power(|x|, 1/3), one Newton step, sign."""
    if _is_scalar(x):
        xs = float(x)
        a = abs(xs)
        r = power(a, 1.0 / 3.0)
        if 0.0 < r < math.inf:
            r = r - (r * r * r - a) / (3.0 * (r * r))
        return -r if xs < 0 else r  # type: ignore[return-value]
    xa = _array(x)
    aa: F64 = np.abs(xa)
    ra: F64 = power(aa, 1.0 / 3.0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        step = ra - (ra * ra * ra - aa) / (3.0 * (ra * ra))
    ra = np.where((ra > 0.0) & np.isfinite(ra), step, ra)
    out: F64 = np.where(xa < 0, -ra, ra)
    return out  # type: ignore[return-value]


def hypot(x: X, y: X) -> X:
    """sqrt(x^2 + y^2) (no care for overflow: the simulator's lengths are metres)."""
    if _is_scalar(x) and _is_scalar(y):
        return math.sqrt(float(x) * float(x) + float(y) * float(y))  # type: ignore[return-value]
    xa, ya = _array(x), _array(y)
    return np.sqrt(xa * xa + ya * ya)  # type: ignore[return-value]


# ----------------------------------------------------------------------------- linear algebra


#: From this many rows on, :func:`matmul` runs its compiled kernel (same bits, less memory).
_COMPILED_ROWS = 4096


def matmul(a: F64, b: F64) -> F64:
    """``a @ b`` for a (..., K) stack of rows and a (K, M) matrix, summing k = 0, 1, ... in order."""
    A = np.asarray(a, dtype=np.float64)
    B = np.asarray(b, dtype=np.float64)
    if A.shape[-1] != B.shape[0] or B.ndim != 2:
        raise ValueError(f"cannot multiply {A.shape} by {B.shape}")
    if A.ndim == 2 and A.shape[0] >= _COMPILED_ROWS:  # the same sums, compiled
        from rgbd_eval.exact_kernels import matmul_rows

        result = np.empty((A.shape[0], B.shape[1]))
        matmul_rows(np.ascontiguousarray(A), np.ascontiguousarray(B), result)
        return result
    out: F64 = A[..., 0:1] * B[0]
    for k in range(1, B.shape[0]):
        out = out + A[..., k : k + 1] * B[k]
    return out


def transform(points: F64, rotation: F64, translation: F64 | tuple[float, ...]) -> F64:
    """``points @ rotation.T + translation`` for (..., 3) points (the rotation applied first)."""
    return matmul(points, np.asarray(rotation, dtype=np.float64).T) + np.asarray(
        translation, dtype=np.float64
    )


def dot(a: F64, b: F64) -> F64:
    """Sum of products along the last axis, in index order."""
    A = np.asarray(a, dtype=np.float64)
    B = np.asarray(b, dtype=np.float64)
    out = A[..., 0] * B[..., 0]
    for k in range(1, A.shape[-1]):
        out = out + A[..., k] * B[..., k]
    return out


def norm(a: F64) -> F64:
    """Euclidean norm along the last axis."""
    return np.sqrt(dot(a, a))


def cross(a: F64, b: F64) -> F64:
    """Cross product of (..., 3) vectors."""
    A = np.asarray(a, dtype=np.float64)
    B = np.asarray(b, dtype=np.float64)
    return np.stack(
        [
            A[..., 1] * B[..., 2] - A[..., 2] * B[..., 1],
            A[..., 2] * B[..., 0] - A[..., 0] * B[..., 2],
            A[..., 0] * B[..., 1] - A[..., 1] * B[..., 0],
        ],
        axis=-1,
    )


def det3(m: F64) -> float:
    """Determinant of a 3x3 matrix (rule of Sarrus, in a fixed order)."""
    M = np.asarray(m, dtype=np.float64)
    return float(dot(M[0], cross(M[1], M[2])))


def inv3(m: F64) -> F64:
    """Inverse of a 3x3 matrix by its adjugate."""
    M = np.asarray(m, dtype=np.float64)
    d = det3(M)
    if d == 0.0:
        raise ValueError("matrix is singular")
    # rows of the inverse are the cross products of the columns, divided by the determinant
    c0, c1, c2 = M[:, 0], M[:, 1], M[:, 2]
    return np.stack([cross(c1, c2), cross(c2, c0), cross(c0, c1)]) / d


def rotation_z(yaw: float) -> F64:
    """Rotation about z by ``yaw`` radians."""
    s, c = sincos(float(yaw))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_y(pitch: float) -> F64:
    """Rotation about y by ``pitch`` radians."""
    s, c = sincos(float(pitch))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_x(roll: float) -> F64:
    """Rotation about x by ``roll`` radians."""
    s, c = sincos(float(roll))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


# ----------------------------------------------------------------------------- sampling


def standard_normal(
    rng: np.random.Generator, shape: int | tuple[int, ...], dtype: type = np.float64
) -> NDArray[Any]:
    """Standard normal samples by Marsaglia's polar method on ``rng.random`` doubles.

    ``rng.random`` turns the generator's integers into doubles exactly; the transform
    uses :func:`log` and ``sqrt``, so the samples are the same on every CPU (numpy's
    own sampler calls libm). Each call draws whole batches, so the stream advances by
    an amount that depends only on the seed and ``shape``.
    """
    dims = (shape,) if isinstance(shape, int) else tuple(shape)
    n = int(np.prod(dims, dtype=np.int64))
    out = np.empty(n, dtype=np.float64)
    filled = 0
    while filled < n:
        pairs = (n - filled) // 2 + 1
        pairs += pairs // 4 + 8  # 1 - pi/4 of the pairs fall outside the unit disc
        u = rng.random((pairs, 2)) * 2.0 - 1.0
        s = u[:, 0] * u[:, 0] + u[:, 1] * u[:, 1]
        ok = (s > 0.0) & (s < 1.0)
        u, s = u[ok], s[ok]
        f = np.sqrt((-2.0 * _log_array(s)) / s)
        z = (u * f[:, None]).reshape(-1)
        take = min(n - filled, z.size)
        out[filled : filled + take] = z[:take]
        filled += take
    return out.reshape(dims).astype(dtype, copy=False)


def gaussian_kernel(sigma: float, truncate: float = 4.0) -> F64:
    """Normalised 1-D Gaussian weights of radius ``int(truncate sigma + 0.5)`` (as scipy's)."""
    if not sigma > 0:
        raise ValueError(f"sigma={sigma} must be positive")
    radius = int(truncate * sigma + 0.5)
    x = np.arange(-radius, radius + 1, dtype=np.float64)
    w = _exp_array((-0.5 / (sigma * sigma)) * (x * x))
    total = 0.0
    for value in w:  # a fixed order of summation
        total += float(value)
    return w / total


def gaussian_filter(image: F64, sigma: float) -> F64:
    """A 2-D image blurred by a Gaussian of ``sigma`` pixels (edges repeated), as scipy's
    ``gaussian_filter(image, sigma, mode="nearest")`` but with weights from :func:`exp`.

    scipy's own builds its weights with ``np.exp``, which AVX-512 CPUs compute differently;
    its correlation is plain C that sums in a fixed order.
    """
    from scipy import ndimage

    w = gaussian_kernel(sigma)
    out = np.asarray(image, dtype=np.float64)
    for axis in range(out.ndim):
        out = ndimage.correlate1d(out, w, axis=axis, mode="nearest")
    return out
