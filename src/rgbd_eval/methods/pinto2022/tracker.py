"""The pinto2022 tracker (seed 001, III-C to III-E): 3D Kalman filters, appearance galleries.

Per frame, in the world frame:

1. predict every track's Kalman filter over the stamp difference (III-C, eqs. 4-6);
2. Algorithm 1 (III-D): appearance cost ``C`` = smallest Euclidean distance between the
   detection's descriptor and the track's gallery (eq. 15), spatial distance ``S`` = squared
   Mahalanobis distance on x, y with the track's covariance (eq. 14); pairs with
   ``T_lower < C < T_upper`` and ``S > S_max``, or with ``C >= T_upper``, get the infinite cost;
   the Hungarian method assigns, and pairs left at the infinite cost are dropped;
3. update the associated filters with the detections' 3D positions (eqs. 7-13) and append
   the descriptors to the track galleries;
4. track management (III-E): Tentative -> Confirmed after ``confirm_hits`` consecutive
   associations; Confirmed -> Tentative on a miss; deleted after ``max_misses`` consecutive
   misses, its gallery saved in the ID dictionary;
5. each unmatched detection starts a Tentative track whose ID comes from Algorithm 2:
   the closest previously seen ID not held by a live track, if nearer than ``T_recover``,
   else a new ID.

Only Confirmed tracks are output.

Choices the seed leaves open, and how they are made here: ``dt`` is the stamp difference in
seconds (eq. 5 is written for one frame step) while ``Q`` is ``P0`` per step as eq. 6 says;
``P_t`` in eq. 14 is the x, y block of the track's predicted state covariance; the infinite
cost is the seed's "10e5"; a Confirmed track that misses a frame must again be associated
``confirm_hits`` times in a row to be Confirmed (Figure 7 read literally); the IDs of live
tracks (Tentative or Confirmed) are the "active IDs" of Algorithm 2; the output height is
the last associated detection's height.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.pinto2022.tracker_config import Pinto2022TrackerConfig
from rgbd_eval.plugins import DetectionContract, TrackerSpec, register_tracker
from rgbd_eval.track import kalman
from rgbd_eval.types import Box2D, Detection, Frame, TrackOutput, TrackStatus, Visibility

Array = NDArray[np.float64]

#: The "infinite" cost of an inadmissible association (seed 001, III-D: "10e5").
INFINITE_COST = 10e5

#: Measurement matrix (eq. 7): the 3D position is observed directly.
H = np.hstack([np.eye(3), np.zeros((3, 3))])


@dataclass(frozen=True)
class Pinto2022Params:
    """Parameters of the tracker; defaults are the seed's values (III-C to III-E).

    The appearance thresholds are in the units of the embedder; the seed's 300 / 700 / 400
    are TriNet units (eqs. 17-18).
    """

    sigma_position: float = 0.2  # eq. 3, sigma_x = sigma_y = sigma_z (m)
    sigma_velocity: float = 1.0  # eq. 3, sigma_vx = sigma_vy = sigma_vz (m/s)
    sigma_measurement: float = 0.2  # eq. 9 (m)
    t_lower: float = 300.0  # eq. 17
    t_upper: float = 700.0  # eq. 17
    s_max: float = 0.05  # eq. 17
    t_recover: float = 400.0  # eq. 18
    confirm_hits: int = 3  # III-E
    max_misses: int = 5  # III-E

    def __post_init__(self) -> None:
        for name in ("sigma_position", "sigma_velocity", "sigma_measurement"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}={getattr(self, name)} must be > 0")
        if not 0 <= self.t_lower <= self.t_upper:
            raise ValueError(
                f"need 0 <= t_lower <= t_upper, got t_lower={self.t_lower}, t_upper={self.t_upper}"
            )
        if not self.s_max >= 0:
            raise ValueError(f"s_max={self.s_max} must be >= 0")
        if not self.t_recover >= 0:
            raise ValueError(f"t_recover={self.t_recover} must be >= 0")
        if self.confirm_hits < 1 or self.max_misses < 1:
            raise ValueError(
                f"confirm_hits={self.confirm_hits} and max_misses={self.max_misses} must be >= 1"
            )


# ----------------------------------------------------------------------------- Kalman filter


def initial_covariance(params: Pinto2022Params) -> Array:
    """``P0`` (eqs. 2-3); also the process noise ``Q`` (III-C)."""
    sp, sv = params.sigma_position, params.sigma_velocity
    return np.diag([sp**2, sp**2, sp**2, sv**2, sv**2, sv**2])


def measurement_covariance(params: Pinto2022Params) -> Array:
    """``R`` (eq. 9)."""
    return np.eye(3) * params.sigma_measurement**2


def transition_matrix(dt: float) -> Array:
    """``A`` (eq. 5) over ``dt`` seconds: constant velocity in x, y; zero velocity in z."""
    if not dt >= 0:
        raise ValueError(f"dt={dt} must be >= 0")
    A = np.zeros((6, 6))
    A[0, 0] = A[1, 1] = A[2, 2] = 1.0
    A[0, 3] = A[1, 4] = dt
    A[3, 3] = A[4, 4] = 1.0
    return A


def predict(x: Array, P: Array, dt: float, params: Pinto2022Params) -> tuple[Array, Array]:
    """Prior state and covariance (eqs. 4 and 6)."""
    return kalman.predict(x, P, transition_matrix(dt), initial_covariance(params))


def update(x: Array, P: Array, z: Array, params: Pinto2022Params) -> tuple[Array, Array]:
    """Posterior after observing the 3D position ``z`` (eqs. 8-13)."""
    return kalman.update(x, P, z, H, measurement_covariance(params))


# ----------------------------------------------------------------------------- Algorithm 1


def mahalanobis_xy_sq(means: Array, covariances: Array, points: Array) -> Array:
    """Squared Mahalanobis distances ``S (D, T)`` of eq. 14 on x, y only.

    ``means (T, 6)`` and ``covariances (T, 6, 6)`` are the tracks' predicted states,
    ``points (D, 3)`` the detections' positions.
    """
    m = means[:, :2]
    P = covariances[:, :2, :2]
    diff = points[:, None, :2] - m[None, :, :]  # (D, T, 2)
    a, b, d = P[:, 0, 0], P[:, 0, 1], P[:, 1, 1]
    det = a * d - b * b
    dx, dy = diff[..., 0], diff[..., 1]
    return np.asarray((d * dx * dx - 2.0 * b * dx * dy + a * dy * dy) / det, dtype=np.float64)


def gallery_distances(descriptors: Array, galleries: Sequence[Array]) -> Array:
    """Appearance costs ``C (D, T)`` of eq. 15: min Euclidean distance to each gallery."""
    C = np.empty((descriptors.shape[0], len(galleries)))
    for t, gallery in enumerate(galleries):
        diff = descriptors[:, None, :] - gallery[None, :, :]
        C[:, t] = np.sqrt(np.einsum("dgk,dgk->dg", diff, diff)).min(axis=1)
    return C


def gate_costs(C: Array, S: Array, params: Pinto2022Params) -> Array:
    """Algorithm 1, lines 7-12: the cost matrix with inadmissible pairs at the infinite cost."""
    cost, spatial = C, S
    ambiguous_and_far = (cost > params.t_lower) & (cost < params.t_upper) & (spatial > params.s_max)
    dissimilar = cost >= params.t_upper
    return np.where(ambiguous_and_far | dissimilar, INFINITE_COST, cost)


def associate(C: Array) -> list[tuple[int, int]]:
    """Algorithm 1, lines 13-18: Hungarian pairs ``(detection, track)`` below the infinite cost."""
    if C.size == 0:
        return []
    rows, cols = linear_sum_assignment(C)
    return [(int(d), int(t)) for d, t in zip(rows, cols, strict=True) if C[d, t] < INFINITE_COST]


# ----------------------------------------------------------------------------- Algorithm 2


def recover_id(
    descriptors: Array,
    id_dictionary: Mapping[int, Sequence[Array]],
    active_ids: set[int],
    t_recover: float,
) -> int | None:
    """Algorithm 2: the closest inactive previously seen ID if nearer than ``t_recover``.

    ``descriptors (n, K)`` is the new track's gallery; each dictionary entry is a list of
    galleries. Ties go to the smaller ID (``argmin`` over IDs in increasing order).
    """
    best_id: int | None = None
    best = np.inf
    for k in sorted(id_dictionary):
        if k in active_ids:
            continue
        galleries = list(id_dictionary[k])
        if not galleries:
            continue
        distance = float(gallery_distances(descriptors, galleries).min())
        if distance < best:
            best, best_id = distance, k
    if best_id is not None and best < t_recover:
        return best_id
    return None


# ----------------------------------------------------------------------------- tracks


class TrackState(enum.Enum):
    """Track state indicator (III-E, Figure 7)."""

    TENTATIVE = "tentative"
    CONFIRMED = "confirmed"
    DELETED = "deleted"


@dataclass
class _Track:
    track_id: int
    x: Array
    P: Array
    gallery: list[NDArray[np.float64]]
    state: TrackState = TrackState.TENTATIVE
    hits: int = 1  # consecutive associations, the creating detection included
    misses: int = 0  # consecutive frames without association
    height: float = 0.0
    box2d: Box2D | None = None

    def gallery_array(self) -> Array:
        return np.stack(self.gallery)


def next_state(state: TrackState, hits: int, misses: int, params: Pinto2022Params) -> TrackState:
    """Figure 7 after a frame with ``hits`` consecutive associations / ``misses`` misses."""
    if misses >= params.max_misses:
        return TrackState.DELETED
    if misses > 0:
        return TrackState.TENTATIVE
    if hits >= params.confirm_hits:
        return TrackState.CONFIRMED
    return state


class Pinto2022Tracker:
    """Stateful tracker; feed one sequence's frames in stamp order (``Tracker`` protocol)."""

    def __init__(self, params: Pinto2022Params | None = None) -> None:
        self.params = params or Pinto2022Params()
        self._timings: dict[str, float] = {}
        self._tracks: list[_Track] = []
        self._id_dictionary: dict[int, list[Array]] = {}
        self._next_id = 1
        self._last_stamp_ns: int | None = None

    @property
    def id_dictionary(self) -> Mapping[int, Sequence[Array]]:
        """The ID dictionary ``I`` (III-E): galleries of deleted tracks per ID."""
        return self._id_dictionary

    @property
    def last_timings(self) -> Mapping[str, float]:
        """The tracker does not split its work into timed stages."""
        return self._timings

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        """Consume one frame's detections (the frame is not used); return the Confirmed tracks."""
        if self._last_stamp_ns is not None and stamp_ns < self._last_stamp_ns:
            raise ValueError(f"stamps must not decrease: {stamp_ns} after {self._last_stamp_ns}")
        dt = 0.0 if self._last_stamp_ns is None else (stamp_ns - self._last_stamp_ns) * 1e-9
        self._last_stamp_ns = stamp_ns
        p = self.params

        for tr in self._tracks:
            tr.x, tr.P = predict(tr.x, tr.P, dt, p)

        descriptors = _descriptors(detections)
        positions = np.array([d.position for d in detections], dtype=np.float64).reshape(-1, 3)
        pairs: list[tuple[int, int]] = []
        if self._tracks and detections:
            C = gallery_distances(descriptors, [tr.gallery_array() for tr in self._tracks])
            S = mahalanobis_xy_sq(
                np.stack([tr.x for tr in self._tracks]),
                np.stack([tr.P for tr in self._tracks]),
                positions,
            )
            pairs = associate(gate_costs(C, S, p))

        matched_tracks = {t for _, t in pairs}
        for d, t in pairs:
            tr = self._tracks[t]
            tr.x, tr.P = update(tr.x, tr.P, positions[d], p)
            tr.gallery.append(descriptors[d])
            tr.hits += 1
            tr.misses = 0
            tr.height = detections[d].height
            tr.box2d = detections[d].box2d
        for t, tr in enumerate(self._tracks):
            if t not in matched_tracks:
                tr.hits = 0
                tr.misses += 1
                tr.box2d = None
            tr.state = next_state(tr.state, tr.hits, tr.misses, p)

        for tr in self._tracks:
            if tr.state is TrackState.DELETED:
                self._id_dictionary.setdefault(tr.track_id, []).append(tr.gallery_array())
        self._tracks = [tr for tr in self._tracks if tr.state is not TrackState.DELETED]

        matched_dets = {d for d, _ in pairs}
        for d, det in enumerate(detections):
            if d not in matched_dets:
                self._tracks.append(self._new_track(det, positions[d], descriptors[d]))

        return [
            TrackOutput(
                track_id=tr.track_id,
                x=float(tr.x[0]),
                y=float(tr.x[1]),
                height=tr.height,
                box2d=tr.box2d,
                visibility=Visibility.VISIBLE,
                status=TrackStatus.VALIDATED,
            )
            for tr in self._tracks
            if tr.state is TrackState.CONFIRMED
        ]

    def _new_track(self, det: Detection, position: Array, descriptor: Array) -> _Track:
        active = {tr.track_id for tr in self._tracks}
        track_id = recover_id(
            descriptor[None, :], self._id_dictionary, active, self.params.t_recover
        )
        if track_id is None:
            track_id = self._next_id
            self._next_id += 1
        x = np.concatenate([position, np.zeros(3)])
        state = TrackState.CONFIRMED if self.params.confirm_hits <= 1 else TrackState.TENTATIVE
        return _Track(
            track_id=track_id,
            x=x,
            P=initial_covariance(self.params),
            gallery=[descriptor],
            state=state,
            height=det.height,
            box2d=det.box2d,
        )


def _descriptors(detections: Sequence[Detection]) -> Array:
    rows = []
    for i, det in enumerate(detections):
        if det.appearance is None:
            raise ConfigError(
                f"detection {i} has no appearance descriptor; the pinto2022 tracker needs one"
            )
        rows.append(np.asarray(det.appearance, dtype=np.float64).ravel())
    if not rows:
        return np.zeros((0, 0))
    sizes = {r.shape[0] for r in rows}
    if len(sizes) != 1:
        raise ConfigError(f"appearance descriptors differ in length: {sorted(sizes)}")
    return np.stack(rows)


def params_from_config(config: Pinto2022TrackerConfig) -> Pinto2022Params:
    """The tracker parameters of a validated config."""
    return Pinto2022Params(
        sigma_position=config.sigma_position,
        sigma_velocity=config.sigma_velocity,
        sigma_measurement=config.sigma_measurement,
        t_lower=config.t_lower,
        t_upper=config.t_upper,
        s_max=config.s_max,
        t_recover=config.t_recover,
        confirm_hits=config.confirm_hits,
        max_misses=config.max_misses,
    )


def check_contract(config: Pinto2022TrackerConfig, contract: DetectionContract) -> str | None:
    """The tracker needs appearance embeddings in the units its thresholds are in."""
    if contract.appearance is None:
        return "the pinto2022 tracker needs detections with appearance embeddings"
    if contract.appearance != config.appearance:
        return (
            f"the detector's appearance is {contract.appearance!r} but tracker.t_lower/t_upper/"
            f"t_recover are in {config.appearance!r} units; recalibrate them "
            "(tools/pinto2022/calibrate_reid.py) and set tracker.appearance"
        )
    return None


def _build(config: Pinto2022TrackerConfig, contract: DetectionContract) -> Pinto2022Tracker:
    problem = check_contract(config, contract)
    if problem is not None:
        raise ConfigError(problem)
    return Pinto2022Tracker(params_from_config(config))


SPEC = register_tracker(
    TrackerSpec(
        name="pinto2022",
        config_model=Pinto2022TrackerConfig,
        factory=_build,
        check=check_contract,
        summary="3D Kalman, appearance gallery + Mahalanobis gating, Hungarian, ID memory "
        "(seed 001, III-C..E)",
    )
)
