"""On-line boosting with selectors on colour-histogram features (seed 000, 6.2 and 6.5.3).

A reusable two-class classifier, independent of tracking. It follows Grabner and
Bischof's on-line boosting for feature selection (seed 000 ref. [13]), built on
Oza and Russell's on-line boosting (ref. [20]):

- A shared pool of ``weak_classifiers`` weak hypotheses, each a threshold on one
  feature: the histogram mass inside a random axis-aligned parallelepiped of the
  blob's 3D RGB histogram (6.2.2, step 3). A weak hypothesis keeps running means
  of the feature for positives and negatives and says "positive" on the positive
  side of their midpoint.
- ``selectors`` selectors. On each sample with importance ``lambda`` (1 at the
  start), selector ``n`` adds ``lambda`` to the correct or wrong weight of every
  weak hypothesis, picks the one with the lowest weighted error ``e_n`` among those
  no earlier selector has taken (so the votes come from distinct features), gets the
  vote ``alpha_n = 1/2 ln((1 - e_n)/e_n)`` (0 when ``e_n >= 1/2``), and passes
  ``lambda / (2 (1 - e_n))`` (correct) or ``lambda / (2 e_n)`` (wrong) to the next.
- Feature exchange: after each update the weak hypothesis with the highest mean
  error that no selector uses is replaced by a fresh random one, which starts
  with its selectors' mean weights.
- The strong classifier is ``H(x) = sum_n alpha_n h_n(x)`` (its confidence is
  compared against ``min_prediction``, Table 6.1).

Speed: the importance recursion over the selectors is sequential, one selector
after the other over the whole pool, so numpy can only vectorise each step and
pays its call overhead ``selectors`` times per sample. The per-weight part of an
update (running means, the weak hypotheses' verdicts, the selector recursion with
its weight and importance updates) is one loop compiled with numba
(:func:`_learn_step`); so are the exchange's choice and bookkeeping
(:func:`_exchange`) and the integral histograms (:func:`_integrate`). They are
compiled without ``fastmath`` and compute every value by the same floating-point
operations in the same order as the plain numpy implementation, so the results
are those of the plain implementation, bit for bit
(``tests/track/test_boosting_speed_equivalence.py`` keeps it as the reference).
What numpy computes with BLAS or its own reductions (the features, the exchange's
mean errors and new weights, the votes' logarithms) and the random draws stay in
numpy, so their rounding and the random streams are unchanged. The kernels compile
on first use (about a second) and are cached on disk (``cache=True``). The
integral histogram of a sample does not depend on the classifier:
:meth:`OnlineBoostingClassifier.learn` and
:meth:`OnlineBoostingClassifier.predict_integrals` take it precomputed, so a
tracker computes it once per detection for all its classifiers.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba
import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
#: Histograms given to the classifier, any float dtype.
Histograms = NDArray[np.floating[Any]]

#: Initial correct and wrong weights of a weak hypothesis (Grabner and Bischof start at 1).
_INITIAL_WEIGHT = 1.0


def random_boxes(rng: np.random.Generator, count: int, bins: int) -> IntArray:
    """``count`` random parallelepipeds ``(count, 3, 2)``: inclusive bin ranges per channel."""
    ends = rng.integers(0, bins, size=(count, 3, 2))
    return np.sort(ends, axis=-1).astype(np.int64)


def box_masks(boxes: IntArray, bins: int) -> NDArray[np.float32]:
    """Indicator matrix ``(bins**3, count)`` of the boxes over a C-order flattened histogram."""
    idx = np.arange(bins)
    inside = (idx[None, None, :] >= boxes[:, :, 0:1]) & (idx[None, None, :] <= boxes[:, :, 1:2])
    cube = inside[:, 0, :, None, None] & inside[:, 1, None, :, None] & inside[:, 2, None, None, :]
    return np.ascontiguousarray(cube.reshape(len(boxes), bins**3).T, dtype=np.float32)


#: Which face (0 lower, 1 upper) each of the 8 corners takes on the r, g, b axes.
_CORNER_FACES = np.array([[(k >> (2 - axis)) & 1 for axis in range(3)] for k in range(8)])
#: Inclusion-exclusion signs of the corners: + when an even number take the lower face.
CORNER_SIGNS = np.where((3 - _CORNER_FACES.sum(axis=1)) % 2 == 0, 1.0, -1.0)


def box_corners(boxes: IntArray, bins: int) -> IntArray:
    """Flat indices ``(count, 8)`` of each box's corners in the zero-padded integral histogram.

    With ``I`` the ``(bins+1)**3`` cumulative histogram (a zero layer first on each
    axis), the mass in ``[lo, hi]`` is ``sum_k CORNER_SIGNS[k] * I.flat[corners[k]]``.
    """
    side = bins + 1
    lo, hi = boxes[:, None, :, 0], boxes[:, None, :, 1] + 1
    c = np.where(_CORNER_FACES[None] == 1, hi, lo)  # (count, 8, 3)
    return np.asarray((c[..., 0] * side + c[..., 1]) * side + c[..., 2], dtype=np.int64)


def integral_histograms(histograms: NDArray[np.float64], bins: int) -> NDArray[np.float64]:
    """Zero-padded cumulative sums ``(..., (bins+1)**3)`` of flattened ``bins**3`` histograms.

    The sums of numpy's ``cube.cumsum(-1).cumsum(-2).cumsum(-3)``, in the same order
    (compiled: :func:`_integrate`).
    """
    lead = histograms.shape[:-1]
    flat = np.ascontiguousarray(histograms, dtype=np.float64).reshape(-1, bins**3)
    out = np.zeros((len(flat), (bins + 1) ** 3))
    _integrate_kernel(flat, bins, out)
    return out.reshape(*lead, (bins + 1) ** 3)


def _integrate(histograms: Array, bins: int, out: Array) -> None:
    """Cumulative sums of ``histograms`` ``(D, bins**3)`` into the zeroed ``out[:, 1:, 1:, 1:]``.

    ``out`` is ``(D, (bins+1)**3)``, a zero layer first on each axis. The sums run
    along b, then g, then r, each from the second entry on: ``s[i] = s[i-1] + x[i]``,
    the additions of numpy's cumulative sums.
    """
    s = bins + 1
    for d in range(histograms.shape[0]):
        h, o = histograms[d], out[d]
        for r in range(bins):
            for g in range(bins):
                src, dst = (r * bins + g) * bins, ((r + 1) * s + g + 1) * s + 1
                acc = h[src]
                o[dst] = acc
                for b in range(1, bins):
                    acc = acc + h[src + b]
                    o[dst + b] = acc
        for r in range(1, s):  # along g
            for g in range(2, s):
                for b in range(1, s):
                    i = (r * s + g) * s + b
                    o[i] = o[i - s] + o[i]
        for r in range(2, s):  # along r
            for g in range(1, s):
                for b in range(1, s):
                    i = (r * s + g) * s + b
                    o[i] = o[i - s * s] + o[i]


def _select(
    miss: NDArray[np.bool_], wrong: Array, total: Array, selected: IntArray, errors: Array
) -> None:
    """Selectors in turn, in place: weigh the pool, take the best free hypothesis, pass lambda on.

    ``miss`` says which weak hypotheses are wrong on the sample. Selector ``n`` adds
    its importance ``lam`` to the wrong weights ``wrong[n]`` of the missing ones and
    to its total ``total[n]``, takes the first hypothesis with the lowest wrong weight
    among those no earlier selector took, stores it in ``selected[n]`` and its error
    in ``errors[n]``, and passes on Oza's importance. ``lam * miss`` is ``lam`` or
    ``0.0``, so adding ``lam`` or ``0.0`` gives the plain loop's weights.
    """
    N, M = wrong.shape
    taken = np.zeros(M)  # inf for the hypotheses earlier selectors took
    free = np.empty(M)  # this selector's weights, inf where taken
    lam = 1.0
    for n in range(N):
        for j in range(M):
            w = wrong[n, j] + (lam if miss[j] else 0.0)
            wrong[n, j] = w
            free[j] = w + taken[j]
        # the minimum by four running minima (exact in any order), then numpy's argmin:
        # the first index that holds it
        a0 = a1 = a2 = a3 = np.inf
        j = 0
        while j + 4 <= M:
            x0, x1, x2, x3 = free[j], free[j + 1], free[j + 2], free[j + 3]
            a0 = x0 if x0 < a0 else a0
            a1 = x1 if x1 < a1 else a1
            a2 = x2 if x2 < a2 else a2
            a3 = x3 if x3 < a3 else a3
            j += 4
        for i in range(j, M):
            a0 = free[i] if free[i] < a0 else a0
        a0 = a1 if a1 < a0 else a0
        a2 = a3 if a3 < a2 else a2
        best = a2 if a2 < a0 else a0
        m = 0
        while free[m] != best:
            m += 1
        e = best / (total[n] + lam)
        total[n] += lam
        taken[m] = np.inf
        selected[n] = m
        errors[n] = e
        lam = lam / (2.0 * e) if miss[m] else lam / (2.0 * (1.0 - e))


def _learn_step(
    f: Array,
    positive: bool,
    rate: float,
    mean: Array,
    count: Array,
    wrong: Array,
    total: Array,
    selected: IntArray,
    errors: Array,
    scale: Array,
) -> None:
    """One sample of features ``f`` in place: running means, verdicts, then :func:`_select`.

    The gain of the running mean is ``max(1 / (count + 1), rate)``; a weak hypothesis
    says "positive" on the positive side of the midpoint of its two means. ``scale``
    gets ``1 / (N total)``, the selectors' weights in the hypotheses' mean error.
    """
    M = f.shape[0]
    k = 1 if positive else 0
    miss = np.empty(M, dtype=np.bool_)
    for j in range(M):
        gain = 1.0 / (count[k, j] + 1.0)
        if gain < rate:
            gain = rate
        mean[k, j] += gain * (f[j] - mean[k, j])
        count[k, j] += 1.0
        neg, pos = mean[0, j], mean[1, j]
        threshold = 0.5 * (neg + pos)
        says_positive = f[j] > threshold if pos >= neg else f[j] < threshold
        miss[j] = says_positive != positive
    _select_kernel(miss, wrong, total, selected, errors)
    N = total.shape[0]
    for n in range(N):
        scale[n] = 1.0 / (N * total[n])


def _exchange(
    mean_error: Array,
    selected: IntArray,
    box: IntArray,
    bins: int,
    boxes: IntArray,
    corners: IntArray,
    mean: Array,
    count: Array,
) -> int:
    """Replace the unselected hypothesis of highest ``mean_error`` by ``box``; its index or -1.

    The first of the highest (numpy's argmax), -1 when every hypothesis is selected.
    The new hypothesis gets the box, its :func:`box_corners` and empty running means;
    ``mean_error`` is scratch.
    """
    for n in range(selected.shape[0]):
        mean_error[selected[n]] = -np.inf
    m = 0
    for j in range(1, mean_error.shape[0]):
        if mean_error[j] > mean_error[m]:
            m = j
    if mean_error[m] == -np.inf:
        return -1
    side = bins + 1
    for k in range(8):  # face of r, g, b: bits 2, 1, 0 of k (lower 0, upper 1)
        r = box[0, 0] if k & 4 == 0 else box[0, 1] + 1
        g = box[1, 0] if k & 2 == 0 else box[1, 1] + 1
        b = box[2, 0] if k & 1 == 0 else box[2, 1] + 1
        corners[m, k] = (r * side + g) * side + b
    for axis in range(3):
        boxes[m, axis, 0] = box[axis, 0]
        boxes[m, axis, 1] = box[axis, 1]
    for row in range(2):
        mean[row, m] = 0.0
        count[row, m] = 0.0
    return m


#: :func:`_integrate`, :func:`_select`, :func:`_learn_step` and :func:`_exchange` compiled
#: (on first use; cached on disk). No ``fastmath``: the operations are rounded one by one, as
#: in numpy.
_integrate_kernel: Callable[[Array, int, Array], None] = numba.njit(cache=True)(_integrate)
_select_kernel: Callable[[NDArray[np.bool_], Array, Array, IntArray, Array], None] = numba.njit(
    cache=True
)(_select)
_learn_kernel: Callable[
    [Array, bool, float, Array, Array, Array, Array, IntArray, Array, Array], None
] = numba.njit(cache=True)(_learn_step)
_exchange_kernel: Callable[
    [Array, IntArray, IntArray, int, IntArray, IntArray, Array, Array], int
] = numba.njit(cache=True)(_exchange)


class OnlineBoostingClassifier:
    """An on-line boosted classifier of flattened ``bins**3`` colour histograms.

    ``learning_rate`` is the floor of the gain of the weak hypotheses' running
    means (a plain mean for the first ``1/learning_rate`` samples, then an
    exponential average), which lets them follow a drifting appearance; seed 000
    does not give it.
    """

    def __init__(
        self,
        bins: int,
        weak_classifiers: int = 250,
        selectors: int = 50,
        seed: int | np.random.SeedSequence = 0,
        learning_rate: float = 0.05,
    ) -> None:
        if not 1 <= bins <= 64:
            raise ValueError(f"bins={bins} must be in [1, 64]")
        if weak_classifiers < 1:
            raise ValueError(f"weak_classifiers={weak_classifiers} must be >= 1")
        if not 1 <= selectors <= weak_classifiers:
            raise ValueError(
                f"selectors={selectors} must be in [1, weak_classifiers={weak_classifiers}]"
            )
        if not 0.0 < learning_rate <= 1.0:
            raise ValueError(f"learning_rate={learning_rate} must be in (0, 1]")
        self.bins = bins
        self.size = bins**3
        self._rng = np.random.default_rng(seed)
        self._rate = learning_rate
        M, N = weak_classifiers, selectors
        self._boxes = random_boxes(self._rng, M, bins)
        self._corners = box_corners(self._boxes, bins)
        self._spare_boxes = random_boxes(self._rng, M, bins)  # drawn in blocks for speed
        self._spare_next = 0
        self._mean_weights = np.full(M, 1.0 / M)
        self._mean = np.zeros((2, M))  # row 0: negatives, row 1: positives
        self._count = np.zeros((2, M))
        self._wrong = np.full((N, M), _INITIAL_WEIGHT)
        self._total = np.full(N, 2.0 * _INITIAL_WEIGHT)
        self._selected = np.zeros(N, dtype=np.int64)
        self._alpha: Array | None = np.zeros(N)  # None: derive from _errors when needed
        self._errors = np.zeros(N)  # the selectors' errors on the last sample
        self._error_scale = np.zeros(N)  # 1 / (N total): mean error = _error_scale @ _wrong
        self.positives = 0
        self.negatives = 0

    @property
    def selected(self) -> IntArray:
        """Index of the weak hypothesis each selector uses (a copy)."""
        return self._selected.copy()

    @property
    def boxes(self) -> IntArray:
        """The weak hypotheses' parallelepipeds ``(weak_classifiers, 3, 2)`` (a copy)."""
        return self._boxes.copy()

    @property
    def alpha(self) -> Array:
        """Votes of the selectors (a copy)."""
        return self._votes().copy()

    def features(self, histograms: Histograms) -> Array:
        """Feature values ``(weak_classifiers,)`` or ``(D, weak_classifiers)`` of histograms."""
        h = self._check(histograms)
        if h.ndim == 2:
            return np.stack([self._box_sums(row, self._corners) for row in h])
        return self._box_sums(h, self._corners)

    def predict(self, histograms: Histograms) -> Array:
        """Confidence ``H(x)`` for one histogram ``(bins**3,)`` or a batch ``(D, bins**3)``.

        A batch gives exactly the values of its rows one by one.
        """
        h = self._check(histograms)
        if h.ndim == 2:
            return np.array([self._confidence(integral_histograms(row, self.bins)) for row in h])
        return np.asarray(self._confidence(integral_histograms(h, self.bins)), dtype=np.float64)

    def predict_integrals(self, integrals: Array) -> Array:
        """:meth:`predict` of a batch given as :func:`integral_histograms` ``(D, (bins+1)**3)``.

        The integral of a histogram does not depend on the classifier: compute it once
        when several classifiers of the same ``bins`` look at the same histogram.
        """
        sel = self._selected
        # (D, N, 8) @ (8,) runs one matrix-vector product per row: the same sums as one by one
        f = integrals.take(self._corners[sel], axis=1) @ CORNER_SIGNS
        says = np.where(self._hypotheses(f, sel), 1.0, -1.0)
        votes = self._votes()
        # one dot product per row: a (D, N) @ (N,) product may sum in another order
        return np.array([row @ votes for row in says], dtype=np.float64)

    def update(self, histogram: Histograms, positive: bool) -> None:
        """Learn one labelled sample (importance 1)."""
        h = self._check(histogram)
        if h.ndim != 1:
            raise ValueError(f"update takes one histogram of shape ({self.size},), got {h.shape}")
        self.learn(integral_histograms(h, self.bins), positive)

    def learn(self, integral: Array, positive: bool) -> None:
        """:meth:`update` given the sample's :func:`integral_histograms` ``((bins+1)**3,)``."""
        f = np.asarray(integral.take(self._corners) @ CORNER_SIGNS, dtype=np.float64)
        _learn_kernel(
            f,
            bool(positive),
            self._rate,
            self._mean,
            self._count,
            self._wrong,
            self._total,
            self._selected,
            self._errors,
            self._error_scale,
        )
        self._alpha = None  # only predictions need the votes: derived on demand
        self._exchange_worst()
        if positive:
            self.positives += 1
        else:
            self.negatives += 1

    # ------------------------------------------------------------------ internals

    def _confidence(self, integral: Array) -> float:
        sel = self._selected
        f = np.asarray(integral.take(self._corners[sel]) @ CORNER_SIGNS, dtype=np.float64)
        says_pos = self._hypotheses(f, sel)
        return float(np.where(says_pos, 1.0, -1.0) @ self._votes())

    def _box_sums(self, h: Array, corners: IntArray) -> Array:
        """Mass of one histogram ``(bins**3,)`` in the boxes given by their corners."""
        cum = integral_histograms(h, self.bins)
        return np.asarray(cum.take(corners) @ CORNER_SIGNS, dtype=np.float64)

    def _check(self, histograms: Histograms) -> Array:
        h = np.asarray(histograms, dtype=np.float64)
        if h.shape[-1] != self.size or h.ndim > 2:
            raise ValueError(
                f"histogram shape {h.shape} does not match bins={self.bins} "
                f"(expected (..., {self.size}))"
            )
        return h

    def _hypotheses(self, f: Array, columns: IntArray) -> NDArray[np.bool_]:
        """Which weak hypotheses ``columns`` say "positive" for their features ``f``."""
        mean = self._mean[:, columns]
        neg, pos = mean[0], mean[1]
        threshold = 0.5 * (neg + pos)
        return np.asarray(np.where(pos >= neg, f > threshold, f < threshold), dtype=bool)

    def _votes(self) -> Array:
        """``alpha_n = 1/2 ln((1 - e_n)/e_n)``, 0 when ``e_n >= 1/2``, of the last sample's errors."""
        if self._alpha is None:
            err = self._errors
            self._alpha = np.where(err < 0.5, 0.5 * np.log((1.0 - err) / err), 0.0)
        return self._alpha

    def _exchange_worst(self) -> None:
        mean_error = self._error_scale @ self._wrong
        box = self._spare_boxes[self._spare_next]
        args = (self._boxes, self._corners, self._mean, self._count)
        m = _exchange_kernel(mean_error, self._selected, box, self.bins, *args)
        if m < 0:
            return  # every weak hypothesis is in use
        self._wrong[:, m] = self._wrong @ self._mean_weights
        self._spare_next += 1
        if self._spare_next == len(self._spare_boxes):  # draw the next block
            self._spare_boxes = random_boxes(self._rng, len(self._boxes), self.bins)
            self._spare_next = 0
