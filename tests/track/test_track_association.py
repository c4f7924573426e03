"""Gating and assignment: chi-square table, Mahalanobis by hand, textbook GNN cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.track.association import (
    chi_square_gate,
    gnn_assign,
    mahalanobis_sq,
    score_assign,
)

G = 13.815510557964274  # chi^2(2) quantile at 0.999 = -2 ln(0.001)


@pytest.mark.parametrize(
    ("p", "dof", "table"),
    [  # printed chi-square table values (3 decimals)
        (0.95, 2, 5.991),
        (0.99, 2, 9.210),
        (0.999, 2, 13.816),  # Table 6.1 default gate_distance_probability
        (0.95, 1, 3.841),
        (0.99, 4, 13.277),
    ],
)
def test_gate_matches_chi_square_table(p: float, dof: int, table: float) -> None:
    assert chi_square_gate(p, dof) == pytest.approx(table, abs=5e-4)


@given(st.floats(1e-6, 1 - 1e-9))
def test_two_dof_gate_closed_form(p: float) -> None:
    # for 2 degrees of freedom the CDF is 1 - exp(-G/2), so G = -2 ln(1 - p)
    assert chi_square_gate(p) == pytest.approx(-2.0 * math.log1p(-p), rel=1e-9)


@pytest.mark.parametrize("p", [0.0, 1.0, -0.1, 1.5])
def test_bad_gate_probability_raises(p: float) -> None:
    with pytest.raises(ValueError, match=f"probability={p}"):
        chi_square_gate(p)


def test_mahalanobis_by_hand() -> None:
    # Pzz = diag(1, 4), residual (1, 2): r = 0 -> 1/1 + 4/4 = 2; r = 1 -> 1/2 + 4/5 = 1.3
    d2 = mahalanobis_sq(
        np.zeros((1, 2)),
        np.diag([1.0, 4.0])[None],
        np.array([[1.0, 2.0], [1.0, 2.0]]),
        np.array([0.0, 1.0]),
    )
    assert np.allclose(d2, [[2.0, 1.3]])


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 4), st.integers(1, 4))
def test_mahalanobis_matches_linear_algebra(seed: int, T: int, D: int) -> None:
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(T, 2, 2))
    Pzz = A @ np.swapaxes(A, 1, 2) + 0.01 * np.eye(2)
    zp, z, r = rng.normal(size=(T, 2)), rng.normal(size=(D, 2)), rng.uniform(0, 1, D)
    d2 = mahalanobis_sq(zp, Pzz, z, r)
    for i in range(T):
        for j in range(D):
            y = z[j] - zp[i]
            assert d2[i, j] == pytest.approx(
                float(y @ np.linalg.solve(Pzz[i] + r[j] * np.eye(2), y))
            )
    assert (d2 >= 0).all()


def test_crossing_targets_take_the_global_optimum() -> None:
    # two tracks crossing: greedy takes (0,0)=1 then (1,1)=10, total 11;
    # the global optimum (0,1)+(1,0) = 2+2 = 4
    d2 = np.array([[1.0, 2.0], [2.0, 10.0]])
    assert sorted(gnn_assign(d2, G)) == [(0, 1), (1, 0)]


def test_gated_out_far_detection_stays_unassigned() -> None:
    assert gnn_assign(np.array([[1.0, 50.0]]), G) == [(0, 0)]
    assert gnn_assign(np.array([[50.0]]), G) == []
    assert gnn_assign(np.zeros((0, 3)), G) == []


def test_more_detections_than_tracks() -> None:
    # track 0 is nearest to detection 2, track 1 to detection 0; detection 1 stays free
    d2 = np.array([[9.0, 8.0, 0.5], [0.3, 7.0, 6.0]])
    assert sorted(gnn_assign(d2, G)) == [(0, 2), (1, 0)]


def test_gate_prefers_more_valid_pairs() -> None:
    # (0,0)=1 alone leaves track 1 gated out (100); (0,1)+(1,0) = 5+2 keeps both
    d2 = np.array([[1.0, 5.0], [2.0, 100.0]])
    assert sorted(gnn_assign(d2, G)) == [(0, 1), (1, 0)]


def test_score_assignment_maximises_sum_above_threshold() -> None:
    # (0,0)+(1,1) = 10 + (2 below 9: dropped); (0,1)+(1,0) = 12 + 11 = 23
    assert sorted(score_assign(np.array([[10.0, 12.0], [11.0, 2.0]]), 9.0)) == [(0, 1), (1, 0)]
    assert score_assign(np.array([[8.9, -20.0]]), 9.0) == []
    # a negative threshold: valid negative scores are still assigned
    assert score_assign(np.array([[-1.0], [-3.0]]), -2.0) == [(0, 0)]


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5), st.integers(1, 5))
def test_gnn_pairs_are_unique_and_gated(seed: int, T: int, D: int) -> None:
    d2 = np.random.default_rng(seed).exponential(10.0, size=(T, D))
    pairs = gnn_assign(d2, G)
    assert len({i for i, _ in pairs}) == len(pairs) == len({j for _, j in pairs})
    assert all(d2[i, j] < G for i, j in pairs)
    # no valid pair is left with both ends free
    used_t, used_d = {i for i, _ in pairs}, {j for _, j in pairs}
    assert not any(
        d2[i, j] < G for i in range(T) for j in range(D) if i not in used_t and j not in used_d
    )
