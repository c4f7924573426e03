"""Hand-computed checks of the pinto2022 tracker (seed 001, III-C to III-E)."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.pinto2022.tracker import (
    INFINITE_COST,
    Pinto2022Params,
    Pinto2022Tracker,
    TrackState,
    associate,
    gallery_distances,
    gate_costs,
    initial_covariance,
    mahalanobis_xy_sq,
    next_state,
    predict,
    recover_id,
    transition_matrix,
    update,
)
from rgbd_eval.types import Box2D, Detection

PARAMS = Pinto2022Params()


def _det(x: float, y: float, appearance: list[float], z: float = 1.0) -> Detection:
    return Detection(
        position=(x, y, z),
        height=1.7,
        confidence=1.0,
        box2d=Box2D(0, 0, 10, 20),
        appearance=np.asarray(appearance, dtype=np.float32),
    )


# ----------------------------------------------------------------------------- Kalman filter


def test_transition_matrix_is_constant_velocity_in_xy_and_zero_velocity_in_z() -> None:
    A = transition_matrix(0.5)
    x = np.array([1.0, 2.0, 3.0, 0.5, -1.0, 0.7])
    # x + 0.5*0.5 = 1.25, y + 0.5*(-1) = 1.5, z unchanged, vz zeroed (eq. 5's last row).
    np.testing.assert_allclose(A @ x, [1.25, 1.5, 3.0, 0.5, -1.0, 0.0])


def test_predict_from_p0_adds_q() -> None:
    P0 = initial_covariance(PARAMS)
    np.testing.assert_allclose(np.diag(P0), [0.04, 0.04, 0.04, 1, 1, 1])
    x, P = predict(np.zeros(6), P0, 0.5, PARAMS)
    np.testing.assert_allclose(x, np.zeros(6))
    # P[0,0] = 0.04 + dt^2 * 1 + 0.04 (Q) = 0.33; P[0,3] = dt * 1 = 0.5; P[3,3] = 1 + 1 = 2
    # P[2,2] = 0.04 + 0.04 = 0.08 (no z velocity); P[5,5] = 0 + 1 = 1 (vz zeroed, then Q)
    assert P[0, 0] == pytest.approx(0.33)
    assert P[0, 3] == pytest.approx(0.5)
    assert P[3, 3] == pytest.approx(2.0)
    assert P[2, 2] == pytest.approx(0.08)
    assert P[2, 5] == pytest.approx(0.0)
    assert P[5, 5] == pytest.approx(1.0)


def test_update_weights_prior_and_measurement() -> None:
    _, P = predict(np.zeros(6), initial_covariance(PARAMS), 0.5, PARAMS)
    x, P_post = update(np.zeros(6), P, np.array([1.0, 0.0, 0.2]), PARAMS)
    # x: S = 0.33 + 0.04 = 0.37; K_x = 0.33/0.37, K_vx = 0.5/0.37; residual 1.
    assert x[0] == pytest.approx(0.33 / 0.37)
    assert x[3] == pytest.approx(0.5 / 0.37)
    # z: S = 0.08 + 0.04 = 0.12; K_z = 0.08/0.12 = 2/3; residual 0.2; vz has no covariance with z.
    assert x[2] == pytest.approx(0.2 * 2 / 3)
    assert x[5] == pytest.approx(0.0)
    assert x[1] == pytest.approx(0.0)
    # (I - K H) P: P_xx = 0.33 - 0.33^2/0.37
    assert P_post[0, 0] == pytest.approx(0.33 - 0.33**2 / 0.37)


# ----------------------------------------------------------------------------- Algorithm 1


def test_mahalanobis_on_xy_only() -> None:
    means = np.array([[0.0, 0.0, 5.0, 0, 0, 0]])
    cov = np.diag([0.04, 0.16, 1.0, 1, 1, 1])[None]
    # (0.2^2 / 0.04) + (0.4^2 / 0.16) = 1 + 1 = 2; z is ignored.
    S = mahalanobis_xy_sq(means, cov, np.array([[0.2, 0.4, -3.0]]))
    np.testing.assert_allclose(S, [[2.0]])


def test_gallery_distance_is_the_minimum_over_the_gallery() -> None:
    gallery = np.array([[0.0, 0.0], [3.0, 4.0], [10.0, 0.0]])
    # detection (3, 0): distances 3, 4, 7 -> 3
    C = gallery_distances(np.array([[3.0, 0.0]]), [gallery])
    np.testing.assert_allclose(C, [[3.0]])


def test_gate_costs_every_branch_of_algorithm_1() -> None:
    p = Pinto2022Params(t_lower=300, t_upper=700, s_max=0.05)
    C = np.array([[200.0, 500.0, 500.0, 700.0, 300.0, 800.0]])
    S = np.array([[10.0, 0.01, 0.1, 0.0, 1.0, 0.0]])
    out = gate_costs(C, S, p)
    # 200: below T_lower, kept however far (line 9 needs C > T_lower)
    # 500 close (S 0.01 <= S_max): kept; 500 far (S 0.1 > S_max): line 10, infinite
    # 700: C >= T_upper, line 12, infinite even at S = 0
    # 300: not strictly above T_lower, kept although far; 800: infinite
    np.testing.assert_array_equal(
        out, [[200.0, 500.0, INFINITE_COST, INFINITE_COST, 300.0, INFINITE_COST]]
    )


def test_associate_minimises_cost_and_drops_infinite_pairs() -> None:
    inf = INFINITE_COST
    # Hungarian: d0-t1 (1) + d1-t0 (2) = 3 beats d0-t0 (2) + d1-t1 (5) = 7.
    assert sorted(associate(np.array([[2.0, 1.0], [2.0, 5.0]]))) == [(0, 1), (1, 0)]
    # d1 can only take an infinite pair: it is left unmatched (lines 14-18).
    assert associate(np.array([[1.0, inf], [inf, inf]])) == [(0, 0)]
    assert associate(np.zeros((0, 3))) == []


# ----------------------------------------------------------------------------- state machine


def test_next_state_transitions() -> None:
    tent, conf, dele = TrackState.TENTATIVE, TrackState.CONFIRMED, TrackState.DELETED
    assert next_state(tent, 2, 0, PARAMS) is tent
    assert next_state(tent, 3, 0, PARAMS) is conf
    assert next_state(conf, 4, 0, PARAMS) is conf
    assert next_state(conf, 0, 1, PARAMS) is tent
    assert next_state(tent, 0, 4, PARAMS) is tent
    assert next_state(tent, 0, 5, PARAMS) is dele


def test_track_confirmed_after_three_frames_then_tentative_then_deleted() -> None:
    tracker = Pinto2022Tracker(Pinto2022Params(t_lower=1, t_upper=5, t_recover=2))
    dt = 100_000_000
    det = _det(1.0, 0.0, [0.0, 0.0])
    assert tracker.update(0, [det]) == []  # created, Tentative (1 hit)
    assert tracker.update(dt, [det]) == []  # 2 hits
    out = tracker.update(2 * dt, [det])  # 3 consecutive: Confirmed, output
    assert [o.track_id for o in out] == [1]
    assert out[0].x == pytest.approx(1.0)
    assert tracker.update(3 * dt, []) == []  # miss: Tentative, not output
    for k in range(4, 7):  # misses 2, 3, 4
        assert tracker.update(k * dt, []) == []
    assert tracker.id_dictionary == {}
    tracker.update(7 * dt, [])  # 5th miss: deleted, gallery of 3 descriptors saved
    assert list(tracker.id_dictionary) == [1]
    assert tracker.id_dictionary[1][0].shape == (3, 2)


def test_reconfirmation_needs_three_consecutive_hits_again() -> None:
    tracker = Pinto2022Tracker(Pinto2022Params(t_lower=1, t_upper=5, t_recover=2))
    det = _det(0.0, 0.0, [0.0, 0.0])
    for k in range(3):
        tracker.update(k, [det])
    tracker.update(3, [])  # miss -> Tentative
    assert tracker.update(4, [det]) == []  # 1 hit
    assert tracker.update(5, [det]) == []  # 2 hits
    assert [o.track_id for o in tracker.update(6, [det])] == [1]  # 3 hits


def _delete_track_one(tracker: Pinto2022Tracker, appearance: list[float]) -> int:
    det = _det(0.0, 0.0, appearance)
    for k in range(3):
        tracker.update(k, [det])
    for k in range(3, 8):
        tracker.update(k, [])
    assert list(tracker.id_dictionary) == [1]
    return 8


def test_recover_reuses_the_id_of_a_similar_person() -> None:
    tracker = Pinto2022Tracker(Pinto2022Params(t_lower=1, t_upper=5, t_recover=2))
    k = _delete_track_one(tracker, [0.0, 0.0])
    # Re-enters far away, distance 1.5 < T_recover = 2 to the saved gallery: ID 1 again.
    det = _det(5.0, 5.0, [0.9, 1.2])
    for j in range(3):
        out = tracker.update(k + j, [det])
    assert [o.track_id for o in out] == [1]


def test_do_not_recover_a_dissimilar_person() -> None:
    tracker = Pinto2022Tracker(Pinto2022Params(t_lower=1, t_upper=5, t_recover=2))
    k = _delete_track_one(tracker, [0.0, 0.0])
    # Distance 2.5 >= T_recover: a new ID.
    det = _det(5.0, 5.0, [1.5, 2.0])
    for j in range(3):
        out = tracker.update(k + j, [det])
    assert [o.track_id for o in out] == [2]


def test_recover_id_excludes_active_ids_and_picks_the_nearest() -> None:
    g1 = [np.array([[0.0, 0.0]])]
    g2 = [np.array([[0.0, 1.0]]), np.array([[5.0, 5.0]])]
    dictionary = {1: g1, 2: g2}
    probe = np.array([[0.0, 0.2]])
    # distances: ID 1 -> 0.2, ID 2 -> min(0.8, ~6.9) = 0.8
    assert recover_id(probe, dictionary, set(), 1.0) == 1
    assert recover_id(probe, dictionary, {1}, 1.0) == 2  # ID 1 is live: excluded
    assert recover_id(probe, dictionary, {1}, 0.5) is None  # 0.8 not below 0.5
    assert recover_id(probe, dictionary, {1, 2}, 10.0) is None


def test_appearance_gate_keeps_two_people_apart_when_they_cross() -> None:
    # Two people with distinct appearance swap sides within one frame step: spatially each
    # detection is nearer the other track, but C >= T_upper forbids the swap.
    p = Pinto2022Params(t_lower=1, t_upper=5, t_recover=2, s_max=0.05)
    tracker = Pinto2022Tracker(p)
    a, b = [0.0, 0.0], [10.0, 0.0]
    for k in range(3):
        out = tracker.update(k, [_det(0.0, 0.0, a), _det(1.0, 0.0, b)])
    ids = {round(o.x): o.track_id for o in out}
    assert ids == {0: 1, 1: 2}
    out = tracker.update(3, [_det(1.0, 0.0, a), _det(0.0, 0.0, b)])
    xs = {o.track_id: o.x for o in out}
    assert xs[1] > 0.5 and xs[2] < 0.5


def test_detections_without_appearance_are_refused() -> None:
    det = Detection(position=(0.0, 0.0, 0.0), height=1.7, confidence=1.0, box2d=Box2D(0, 0, 1, 1))
    with pytest.raises(ConfigError, match="appearance"):
        Pinto2022Tracker().update(0, [det])


def test_params_are_validated() -> None:
    with pytest.raises(ValueError, match="t_lower"):
        Pinto2022Params(t_lower=800, t_upper=700)
    with pytest.raises(ValueError, match="sigma_position"):
        Pinto2022Params(sigma_position=0)
