"""The compiled classifier update gives the same results, bit for bit, as the plain one.

``ReferenceBoostingClassifier`` below is the implementation of
:class:`~rgbd_eval.track.boosting.OnlineBoostingClassifier` before the speed-ups
(issue 8), kept verbatim: plain numpy, its selector loop runs Oza's importance
recursion one selector at a time. The fast one runs the running means and the
selector recursion in one numba-compiled loop; the tests drive both with the same
samples and compare every piece of state and every prediction exactly, and run the
basso2012 tracker with either classifier on the same streams.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray
from scipy.linalg import blas

import rgbd_eval.methods.basso2012.tracker as basso2012
import rgbd_eval.track.boosting as boosting
from rgbd_eval.components import create_tracker
from rgbd_eval.config import build_config
from rgbd_eval.track.boosting import (
    _INITIAL_WEIGHT,
    CORNER_SIGNS,
    OnlineBoostingClassifier,
    _exchange_kernel,
    _learn_kernel,
    box_corners,
    integral_histograms,
    random_boxes,
)
from rgbd_eval.track.synthetic import THREE_PEOPLE, colour_histogram, walking_stream
from rgbd_eval.types import Detection, TrackOutput

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
Histograms = NDArray[np.floating[Any]]

COLOURS = [(200.0, 40.0, 40.0), (40.0, 40.0, 200.0), (40.0, 200.0, 40.0), (120.0, 120.0, 60.0)]


def reference_integrals(histograms: NDArray[np.float64], bins: int) -> NDArray[np.float64]:
    """:func:`~rgbd_eval.track.boosting.integral_histograms` by numpy's cumulative sums."""
    lead = histograms.shape[:-1]
    cube = histograms.reshape(*lead, bins, bins, bins)
    out = np.zeros((*lead, bins + 1, bins + 1, bins + 1))
    out[..., 1:, 1:, 1:] = cube.cumsum(-1).cumsum(-2).cumsum(-3)
    return out.reshape(*lead, (bins + 1) ** 3)


class ReferenceBoostingClassifier:
    """The sequential implementation, as it was before the speed-up (kept verbatim).

    An on-line boosted classifier of flattened ``bins**3`` colour histograms.

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
        self._alpha = np.zeros(N)
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
        return self._alpha.copy()

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
            return np.array([self._confidence(row) for row in h])
        return np.asarray(self._confidence(h), dtype=np.float64)

    def update(self, histogram: Histograms, positive: bool) -> None:
        """Learn one labelled sample (importance 1)."""
        f = self.features(histogram)
        if f.ndim != 1:
            raise ValueError(f"update takes one histogram of shape ({self.size},), got {f.shape}")
        k = 1 if positive else 0
        gain = np.maximum(1.0 / (self._count[k] + 1.0), self._rate)
        self._mean[k] += gain * (f - self._mean[k])
        self._count[k] += 1.0
        correct = self._hypotheses(f, None) == positive
        self._boost(correct)
        self._exchange_worst()
        if positive:
            self.positives += 1
        else:
            self.negatives += 1

    # ------------------------------------------------------------------ internals

    def _confidence(self, h: Array) -> float:
        sel = self._selected
        says_pos = self._hypotheses(self._box_sums(h, self._corners[sel]), sel)
        return float(np.where(says_pos, 1.0, -1.0) @ self._alpha)

    def _box_sums(self, h: Array, corners: IntArray) -> Array:
        """Mass of one histogram ``(bins**3,)`` in the boxes given by their corners."""
        cum = reference_integrals(h, self.bins)
        return np.asarray(cum.take(corners) @ CORNER_SIGNS, dtype=np.float64)

    def _check(self, histograms: Histograms) -> Array:
        h = np.asarray(histograms, dtype=np.float64)
        if h.shape[-1] != self.size or h.ndim > 2:
            raise ValueError(
                f"histogram shape {h.shape} does not match bins={self.bins} "
                f"(expected (..., {self.size}))"
            )
        return h

    def _hypotheses(self, f: Array, columns: IntArray | None) -> NDArray[np.bool_]:
        """Which weak hypotheses say "positive" for features ``f`` (of ``columns``)."""
        mean = self._mean if columns is None else self._mean[:, columns]
        neg, pos = mean[0], mean[1]
        threshold = 0.5 * (neg + pos)
        return np.asarray(np.where(pos >= neg, f > threshold, f < threshold), dtype=bool)

    def _boost(self, correct: NDArray[np.bool_]) -> None:
        """Selectors in turn: weigh the pool, take the best free hypothesis, pass lambda on."""
        N = self._wrong.shape[0]
        miss = (~correct).astype(np.float64)
        is_correct = correct.tolist()
        # scratch copy: row n becomes the wrong weights after this sample; hypotheses taken
        # by earlier selectors are inf. miss is 0/1, so lam * miss + w is exact in any order.
        work = self._wrong.copy()
        rows = list(work)
        chosen = [0] * N
        errors = [0.0] * N
        lams = [0.0] * N
        total = self._total.tolist()
        lam = 1.0
        for n in range(N):  # Oza's importance recursion; each step vectorised over the pool
            row = blas.daxpy(miss, rows[n], a=lam)  # in place: row += lam * miss
            m = int(row.argmin())
            e = float(row[m]) / (total[n] + lam)
            work[n + 1 :, m] = np.inf
            chosen[n], errors[n], lams[n] = m, e, lam
            lam = lam / (2.0 * (1.0 - e)) if is_correct[m] else lam / (2.0 * e)
        lam_arr = np.asarray(lams)
        self._wrong += np.multiply.outer(lam_arr, miss)
        self._total += lam_arr
        err = np.asarray(errors)
        self._selected = np.asarray(chosen, dtype=np.int64)
        self._alpha = np.where(err < 0.5, 0.5 * np.log((1.0 - err) / err), 0.0)

    def _exchange_worst(self) -> None:
        mean_error = (1.0 / (len(self._total) * self._total)) @ self._wrong
        mean_error[self._selected] = -math.inf
        m = int(mean_error.argmax())
        if mean_error[m] == -math.inf:
            return  # every weak hypothesis is in use
        if self._spare_next >= len(self._spare_boxes):
            self._spare_boxes = random_boxes(self._rng, len(self._boxes), self.bins)
            self._spare_next = 0
        box = self._spare_boxes[self._spare_next]
        self._spare_next += 1
        self._boxes[m] = box
        self._corners[m] = box_corners(box[None], self.bins)[0]
        self._mean[:, m] = 0.0
        self._count[:, m] = 0.0
        self._wrong[:, m] = self._wrong @ self._mean_weights


class _ReferenceForTracker(ReferenceBoostingClassifier):
    """The reference behind the tracker's calls; the tracker's integrals are patched to the
    histograms themselves (see :func:`_reference_tracker`), so these are the old calls."""

    def learn(self, integral: Array, positive: bool) -> None:
        self.update(integral, positive)

    def predict_integrals(self, integrals: Array) -> Array:
        return self.predict(integrals)


def _same_state(fast: OnlineBoostingClassifier, ref: ReferenceBoostingClassifier) -> None:
    assert np.array_equal(fast._wrong, ref._wrong)
    assert np.array_equal(fast._total, ref._total)
    assert np.array_equal(fast.selected, ref.selected)
    assert np.array_equal(fast.alpha, ref.alpha)
    assert np.array_equal(fast.boxes, ref.boxes)
    assert np.array_equal(fast._corners, ref._corners)
    assert np.array_equal(fast._mean, ref._mean)
    assert np.array_equal(fast._count, ref._count)
    assert (fast.positives, fast.negatives) == (ref.positives, ref.negatives)


def _samples(seed: int, n: int, bins: int, colours: int) -> Iterator[tuple[Histograms, bool]]:
    """``n`` labelled histograms: colour 0 positive, the others negative, with drift."""
    rng = np.random.default_rng(seed)
    for k in range(n):
        c = int(rng.integers(colours))
        base = np.array(COLOURS[c]) + 30.0 * math.sin(k / 7.0)
        yield colour_histogram(rng, tuple(base.tolist()), bins), c == 0


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.sampled_from([(2, 6, 3), (4, 30, 10), (4, 12, 12), (8, 60, 20), (8, 250, 50)]),
    st.integers(2, 4),
)
def test_same_state_and_predictions_after_every_update(
    seed: int, sizes: tuple[int, int, int], colours: int
) -> None:
    bins, M, N = sizes
    fast = OnlineBoostingClassifier(bins, M, N, seed=seed)
    ref = ReferenceBoostingClassifier(bins, M, N, seed=seed)
    probe = np.stack([h for h, _ in _samples(seed + 1, 4, bins, colours)])
    for h, label in _samples(seed, 40, bins, colours):
        fast.update(h, label)
        ref.update(h, label)
        _same_state(fast, ref)
        assert np.array_equal(fast.predict(probe), ref.predict(probe))
        assert np.array_equal(fast.features(h), ref.features(h))


def test_same_results_over_a_long_training_with_changing_choices() -> None:
    fast = OnlineBoostingClassifier(8, seed=3)  # Table 6.1 sizes: 250 weak, 50 selectors
    ref = ReferenceBoostingClassifier(8, seed=3)
    changed = 0
    for h, label in _samples(11, 400, 8, 3):
        before = fast.selected
        fast.update(h, label)
        ref.update(h, label)
        changed += not np.array_equal(before, fast.selected)
    _same_state(fast, ref)
    probe = np.stack([h for h, _ in _samples(12, 20, 8, 4)])
    assert np.array_equal(fast.predict(probe), ref.predict(probe))
    # the selectors' choices both stayed and changed from one sample to the next
    assert 0 < changed < 400


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 8), st.integers(0, 8), st.booleans())
def test_compiled_kernel_equals_its_python_source(
    seed: int, N: int, extra: int, positive: bool
) -> None:
    """numba's loops round like the same loops run by Python (ties included: coarse weights)."""
    rng = np.random.default_rng(seed)
    M = N + extra
    state = [
        rng.integers(0, 4, (2, M)) / 4.0,  # mean
        rng.integers(0, 30, (2, M)).astype(np.float64),  # count
        rng.integers(1, 8, (N, M)) / 2.0,  # wrong
        rng.uniform(8.0, 12.0, N),  # total
        np.zeros(N, dtype=np.int64),  # selected
        np.zeros(N),  # errors
        np.zeros(N),  # error scale
    ]
    f = rng.integers(0, 4, M) / 4.0
    copy = [a.copy() for a in state]
    _learn_kernel(f, positive, 0.05, *state)
    with pytest.MonkeyPatch.context() as patch:  # the compiled kernel is already built
        patch.setattr(boosting, "_select_kernel", boosting._select)
        boosting._learn_step(f, positive, 0.05, *copy)
    for a, b in zip(state, copy, strict=True):
        assert np.array_equal(a, b)
    selected = state[4]
    assert sorted(set(selected.tolist())) == sorted(selected.tolist())  # distinct choices
    # the exchange: ties in the mean error, and no free hypothesis when extra == 0
    mean_error = rng.integers(0, 3, M) / 2.0
    box = random_boxes(rng, 1, 4)[0]
    boxes = random_boxes(rng, M, 4)
    pool = [mean_error, boxes, box_corners(boxes, 4), state[0], state[1]]
    copy = [a.copy() for a in pool]
    m = _exchange_kernel(pool[0], selected, box, 4, *pool[1:])
    assert m == boosting._exchange(copy[0], selected, box, 4, *copy[1:])
    for a, b in zip(pool, copy, strict=True):
        assert np.array_equal(a, b)
    if extra == 0:
        assert m == -1
    else:
        free = np.setdiff1d(np.arange(M), selected)
        assert m == free[np.argmax(mean_error[free])]  # the first of the highest
        assert np.array_equal(pool[2][m], box_corners(box[None], 4)[0])


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(1, 9),
    st.sampled_from([(), (1,), (5,), (2, 3)]),
    st.sampled_from([np.float32, np.float64]),
)
def test_integral_histograms_equal_numpy_cumulative_sums(
    seed: int, bins: int, lead: tuple[int, ...], dtype: type[np.floating[Any]]
) -> None:
    rng = np.random.default_rng(seed)
    h = rng.random((*lead, bins**3)).astype(dtype).astype(np.float64)
    h[rng.random(h.shape) < 0.3] = 0.0  # empty bins, as in real histograms
    got, want = integral_histograms(h, bins), reference_integrals(h, bins)
    assert got.shape == want.shape == (*lead, (bins + 1) ** 3)
    assert np.array_equal(got, want)
    assert np.array_equal(np.signbit(got), np.signbit(want))


def test_predict_integrals_equals_predict() -> None:
    c = OnlineBoostingClassifier(8, seed=5)
    for h, label in _samples(5, 30, 8, 3):
        c.update(h, label)
    hists = np.stack([h for h, _ in _samples(6, 5, 8, 4)])
    cums = np.stack([integral_histograms(h.astype(np.float64), 8) for h in hists])
    assert np.array_equal(c.predict_integrals(cums), c.predict(hists))


def _with_gaps(stream: list[tuple[int, list[Detection]]]) -> list[tuple[int, list[Detection]]]:
    """Person 2 missing for a second, then person 1: classifier association and recovery."""
    out = []
    for k, (stamp, dets) in enumerate(stream):
        drop = 1 if 60 <= k < 90 else 0 if 150 <= k < 190 else None
        out.append((stamp, [d for i, d in enumerate(dets) if i != drop]))
    return out


def _run(stream: list[tuple[int, list[Detection]]]) -> list[list[TrackOutput]]:
    tracker = create_tracker(build_config({"tracker": {"classifier": True}}))
    return [tracker.update(stamp, dets) for stamp, dets in stream]


@pytest.mark.parametrize("seed", [0, 1])
def test_tracker_outputs_match_the_reference_bit_for_bit(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    stream = _with_gaps(walking_stream(THREE_PEOPLE, 260, seed=seed))
    predictions = []
    predict = OnlineBoostingClassifier.predict_integrals

    def counting_predict(self: OnlineBoostingClassifier, integrals: Array) -> Array:
        predictions.append(len(integrals))
        return predict(self, integrals)

    with monkeypatch.context() as patch:
        patch.setattr(OnlineBoostingClassifier, "predict_integrals", counting_predict)
        fast = _run(stream)
    assert predictions  # the gaps made the tracker ask its classifiers
    with monkeypatch.context() as patch:
        # the old tracker: every classifier call gets the histograms themselves
        patch.setattr(basso2012, "OnlineBoostingClassifier", _ReferenceForTracker)
        patch.setattr(basso2012, "integral_histograms", lambda h, bins: h)
        ref = _run(stream)
    assert fast == ref
