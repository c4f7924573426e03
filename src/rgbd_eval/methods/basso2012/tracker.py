"""The basso2012 tracker (seed 000, chapter 6): UKF, two-step GNN, on-line boosted recovery.

Per frame, in the world frame of odometry (6.5.1):

1. predict every track with the constant-velocity UKF over the stamp difference (6.1, 6.5.2);
2. associate tracks and detections by gated Mahalanobis distance, Hungarian method (6.3);
3. associate the leftovers by classifier score above ``min_prediction`` (6.3); these
   tracks restart their filter at the detection, which their motion model missed;
4. update the filters with the theoretical centroids, and the classifiers with the
   non-occluded detections: own detection positive, other tracks' negative (6.2.2, 6.4.2);
5. create tracks from leftover detections with HOG confidence above ``min_confidence``,
   validate them after ``detections_to_validate`` confident detections within
   ``frames_before_fake``, else discard them (6.4.1, 6.5.4);
6. recovery: while a track is new (``frames_remain_new``), the classifier of a missing
   track that accepts its histogram takes it back under the old id (6.4.3);
7. a track not visible for ``frames_before_old`` leaves the output; its classifier is
   kept for ``classifier_memory_s`` (Figure 7.7) for steps 3 and 6, then dropped (6.4.4).

Beyond the thesis, off by default (``static_devalidation_s``): a validated track whose
detections over that window all scored below the detector's person threshold
(``static_max_confidence``, as ``detector.min_confidence`` in Table 5.1: -1.5, "not a person") and stayed within
``static_motion_m`` of their mean is discarded, as a fake track is. People walk or
score above that threshold; a coat stand or a plant that once got three confident
detections stays put and scores low. The cost: a person who stands still while
hidden from HOG (sitting, cut by the image border) loses the track.

Frame counts are turned into seconds at ``reference_rate_hz`` and compared with
stamp differences, so dropped frames and other rates keep their meaning in time.

Choices the thesis leaves open: the innovation covariance of a pair is the track's
predicted measurement covariance plus the detection's own noise (6.7 makes ``R``
depend on the detection's distance); new (unvalidated) tracks are output with
status NEW; only validated tracks are recovery targets; the training negatives of a
track are the non-occluded detections of the other tracks of the frame, learned
after its positive, in track order; the output height is the last associated
detection's height.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.methods.basso2012.tracker_config import Basso2012TrackerConfig, ClusterSelection
from rgbd_eval.plugins import DetectionContract, TrackerSpec, register_tracker
from rgbd_eval.track import ukf
from rgbd_eval.track.association import (
    chi_square_gate,
    gnn_assign,
    mahalanobis_sq,
    score_assign,
)
from rgbd_eval.track.boosting import OnlineBoostingClassifier, integral_histograms
from rgbd_eval.track.motion import (
    apply_measurement,
    apply_transition,
    measurement_variance,
    process_noise,
)
from rgbd_eval.types import Box2D, Detection, Frame, TrackOutput, TrackStatus, Visibility

Array = NDArray[np.float64]

#: Slack (ns) when comparing stamp differences with durations, for rounded stamps.
STAMP_TOLERANCE_NS = 1_000_000

_SIGMA = ukf.sigma_weights(4)
_EYE2 = np.eye(2)
_EMPTY = np.zeros(0)


def _ns(seconds: float) -> int:
    return round(seconds * 1e9)


@dataclass
class _Track:
    """Book-keeping of one track; its filter state lives in the tracker's arrays."""

    track_id: int
    created_ns: int
    last_seen_ns: int
    confident: int
    validated: bool
    height: float
    classifier: OnlineBoostingClassifier | None
    detection: int | None = None  # index into this frame's detections, or None
    by_classifier: bool = False  # this frame's detection came from the classifier step
    # (stamp, x, y, confidence) of recent detections, for static_devalidation_s only
    recent: deque[tuple[int, float, float, float]] | None = None


class Basso2012Tracker:
    """Tracking by detection with an UKF and on-line boosted re-identification (seed 000, ch. 6).

    ``contract`` says what the detections carry: the position quantum (the voxel side)
    enters the measurement noise (6.7), and the classifier learns the colour histograms
    (6.2.2), whose bins per channel follow from their length.
    """

    #: No sub-stages: ``bench`` shows the whole update as ``track``.
    last_timings: Mapping[str, float] = {}

    def __init__(self, cfg: Basso2012TrackerConfig, contract: DetectionContract) -> None:
        problem = check_contract(cfg, contract)
        if problem is not None:
            raise ValueError(problem)
        self._cfg = cfg
        self._bins = _histogram_bins(contract.appearance_size) if cfg.classifier else 8
        self._voxel = contract.position_resolution_m
        self._gate = chi_square_gate(cfg.gate_distance_probability, 2)
        self._old_ns = _ns(cfg.seconds(cfg.frames_before_old))
        self._fake_ns = _ns(cfg.seconds(cfg.frames_before_fake))
        self._new_ns = _ns(cfg.seconds(cfg.frames_remain_new))
        memory_s = (
            cfg.classifier_memory_s
            if cfg.classifier_memory_s is not None
            else cfg.seconds(cfg.frames_before_old)
        )
        self._memory_ns = _ns(memory_s)
        static_s = cfg.static_devalidation_s
        self._static_ns = None if static_s is None else _ns(static_s)
        self._not_person = cfg.static_max_confidence  # Table 5.1 ~people/min_confidence
        self._x = np.zeros((0, 4))
        self._P = np.zeros((0, 4, 4))
        self._tracks: list[_Track] = []
        # step 1's measurement prediction: rows, z_hat, Pzz, Pxz (reused by the update)
        self._prediction: tuple[list[int], Array, Array, Array] = ([], _EMPTY, _EMPTY, _EMPTY)
        self._last_ns: int | None = None
        self._next_id = 1
        # this frame's integral histograms, one row per detection (see _integrals)
        self._cums: Array | None = None
        self._Q_dt, self._Q = 0.0, _EMPTY  # process noise of the last time step

    # ------------------------------------------------------------------ public

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        """Consume one frame's detections; return every maintained track, ordered by id."""
        if self._last_ns is not None and stamp_ns <= self._last_ns:
            raise ValueError(f"stamp_ns={stamp_ns} must increase (previous frame: {self._last_ns})")
        dets = self._select(detections)
        self._cums = None
        dt = 0.0 if self._last_ns is None else (stamp_ns - self._last_ns) * 1e-9
        self._last_ns = stamp_ns
        z = np.array([d.ground_xy for d in dets], dtype=np.float64).reshape(-1, 2)
        r = measurement_variance(
            self._voxel,
            np.array([d.distance for d in dets], dtype=np.float64),
            self._cfg.depth_noise_coefficient,
        ).reshape(-1)

        if dt > 0.0 and self._tracks:
            self._predict(dt)
        for t in self._tracks:
            t.detection = None
            t.by_classifier = False
        free = self._associate(stamp_ns, dets, z, r)
        self._correct(stamp_ns, dets, z, r)
        self._create(stamp_ns, dets, z, r, free)
        if self._cfg.classifier:
            self._recover(stamp_ns, dets)
            self._train(dets)
        self._manage(stamp_ns)
        return self._outputs(stamp_ns, dets)

    # ------------------------------------------------------------------ steps

    def _select(self, detections: Sequence[Detection]) -> list[Detection]:
        """Clusters passed to the tracker: all (height-selected) or HOG-selected (Table 7.4)."""
        size = self._bins**3
        for d in detections:
            if not (math.isfinite(d.position[0]) and math.isfinite(d.position[1])):
                raise ValueError(f"detection position {d.position} is not finite")
            if not (math.isfinite(d.distance) and d.distance >= 0.0):
                raise ValueError(f"detection distance={d.distance} must be finite and >= 0")
            if self._cfg.classifier and d.appearance is not None and d.appearance.shape != (size,):
                raise ValueError(
                    f"detection appearance has shape {d.appearance.shape}, expected ({size},) "
                    f"for histogram_bins={self._bins}"
                )
        if self._cfg.selection is ClusterSelection.CONFIDENCE:
            threshold = self._cfg.selection_confidence
            return [d for d in detections if d.confidence > threshold]
        return list(detections)

    def _predict(self, dt: float) -> None:
        if dt != self._Q_dt:  # the frame period rarely changes: reuse Q
            self._Q_dt, self._Q = dt, process_noise(dt, self._cfg.acceleration_variance)
        Q = self._Q
        self._x, self._P = ukf.predict(
            self._x, self._P, lambda X: apply_transition(X, dt), Q, _SIGMA
        )

    def _associate(self, stamp_ns: int, dets: list[Detection], z: Array, r: Array) -> list[int]:
        """Steps 1 and 2 of 6.3; marks ``track.detection``; returns the free detections."""
        free = list(range(len(dets)))
        self._prediction = ([], _EMPTY, _EMPTY, _EMPTY)
        if not dets or not self._tracks:
            return free
        rows = [i for i, t in enumerate(self._tracks) if not self._dormant(t, stamp_ns)]
        if rows:
            idx = np.asarray(rows)
            z_pred, Pzz, Pxz = ukf.measurement_prediction(
                self._x[idx], self._P[idx], apply_measurement, _SIGMA
            )
            self._prediction = (rows, z_pred, Pzz, Pxz)
            for i, j in gnn_assign(mahalanobis_sq(z_pred, Pzz, z, r), self._gate):
                self._tracks[rows[i]].detection = j
        taken = {t.detection for t in self._tracks if t.detection is not None}
        free = [j for j in free if j not in taken]
        if not self._cfg.classifier or not free:
            return free
        candidates = [
            t for t in self._tracks if t.detection is None and self._remembers(t, stamp_ns)
        ]
        seen = [j for j in free if dets[j].appearance is not None]
        if not candidates or not seen:
            return free
        cums = self._integrals(dets, seen)
        scores = np.stack([_classifier(t).predict_integrals(cums) for t in candidates])
        for i, j in score_assign(scores, self._cfg.min_prediction):
            candidates[i].detection = seen[j]
            candidates[i].by_classifier = True
        taken = {t.detection for t in self._tracks if t.detection is not None}
        return [j for j in free if j not in taken]

    def _correct(self, stamp_ns: int, dets: list[Detection], z: Array, r: Array) -> None:
        """Filter update of the associated tracks (6.4.2), one batched UKF call.

        A track associated by its classifier (step 2) restarts its filter at the
        detection: the detection fell outside the motion model's gate, or the track
        was lost, so its prediction is not to be blended with the measurement.
        """
        rows = [i for i, t in enumerate(self._tracks) if t.detection is not None]
        if not rows:
            return
        restart = [i for i in rows if self._tracks[i].by_classifier]
        if restart:
            cols = [_det(self._tracks[i]) for i in restart]
            self._x[restart], self._P[restart] = self._initial_state(z[cols], r[cols])
        update = [i for i in rows if i not in restart]
        if update:
            # every Kalman-associated track was predicted in step 1: reuse that prediction
            predicted, z_pred, Pzz, Pxz = self._prediction
            k = np.searchsorted(predicted, update)
            cols = [_det(self._tracks[i]) for i in update]
            idx = np.asarray(update)
            R = r[cols][:, None, None] * _EYE2
            self._x[idx], self._P[idx] = ukf.correct(
                self._x[idx], self._P[idx], z[cols], z_pred[k], Pzz[k], Pxz[k], R
            )
        for i in rows:
            t = self._tracks[i]
            self._mark_seen(t, dets[_det(t)], stamp_ns)

    def _initial_state(self, z: Array, r: Array) -> tuple[Array, Array]:
        """State at rest on the measurements, velocity variance from the config."""
        x0 = np.zeros((len(z), 4))
        x0[:, :2] = z
        P0 = np.zeros((len(z), 4, 4))
        P0[:, 0, 0] = P0[:, 1, 1] = r
        P0[:, 2, 2] = P0[:, 3, 3] = self._cfg.initial_velocity_variance
        return x0, P0

    def _mark_seen(self, track: _Track, det: Detection, stamp_ns: int) -> None:
        track.last_seen_ns = stamp_ns
        track.height = det.height
        if self._static_ns is not None:
            if track.recent is None:
                track.recent = deque()
            x, y = det.ground_xy
            track.recent.append((stamp_ns, x, y, det.confidence))
            # keep one detection at or before the window's start: it shows the window is covered
            start = stamp_ns - self._static_ns
            while len(track.recent) > 1 and track.recent[1][0] <= start:
                track.recent.popleft()
        if det.confidence > self._cfg.min_confidence:
            track.confident += 1
            if track.confident >= self._cfg.detections_to_validate:
                track.validated = True

    def _create(
        self, stamp_ns: int, dets: list[Detection], z: Array, r: Array, free: list[int]
    ) -> None:
        """New tracks from unassociated confident detections (6.4.1, 6.5.4)."""
        new = [j for j in free if dets[j].confidence > self._cfg.min_confidence]
        if not new:
            return
        x0, P0 = self._initial_state(z[new], r[new])
        self._x = np.concatenate([self._x, x0])
        self._P = np.concatenate([self._P, P0])
        for j in new:
            track_id = self._next_id
            self._next_id += 1
            track = _Track(
                track_id=track_id,
                created_ns=stamp_ns,
                last_seen_ns=stamp_ns,
                confident=0,
                validated=False,
                height=dets[j].height,
                classifier=self._new_classifier(track_id),
                detection=j,
            )
            self._tracks.append(track)
            self._mark_seen(track, dets[j], stamp_ns)

    def _recover(self, stamp_ns: int, dets: list[Detection]) -> None:
        """6.4.3: a missing track's classifier claims a still-new track; the old id survives."""
        young = [
            i
            for i, t in enumerate(self._tracks)
            if t.detection is not None
            and t.created_ns != stamp_ns
            and stamp_ns - t.created_ns + STAMP_TOLERANCE_NS < self._new_ns
            and dets[t.detection].appearance is not None
        ]
        if not young:
            return
        lost = [
            i
            for i, t in enumerate(self._tracks)
            if t.detection is None and t.validated and self._remembers(t, stamp_ns)
        ]
        if not lost:
            return
        cums = self._integrals(dets, [_det(self._tracks[i]) for i in young])
        scores = np.stack([_classifier(self._tracks[i]).predict_integrals(cums) for i in lost])
        drop: list[int] = []
        for a, b in score_assign(scores, self._cfg.min_prediction):
            old, new = self._tracks[lost[a]], self._tracks[young[b]]
            self._x[lost[a]] = self._x[young[b]]
            self._P[lost[a]] = self._P[young[b]]
            old.detection = new.detection
            old.last_seen_ns = stamp_ns
            old.height = new.height
            drop.append(young[b])
        self._keep([i not in drop for i in range(len(self._tracks))])

    def _train(self, dets: list[Detection]) -> None:
        """Classifier updates with non-occluded detections only (6.4.2)."""
        usable = [
            t
            for t in self._tracks
            if t.detection is not None
            and not dets[t.detection].occluded
            and dets[t.detection].appearance is not None
        ]
        if not usable:
            return
        cums = self._integrals(dets, [_det(t) for t in usable])
        for a, t in enumerate(usable):
            classifier = _classifier(t)
            classifier.learn(cums[a], True)
            for b in range(len(usable)):
                if b != a:
                    classifier.learn(cums[b], False)

    def _integrals(self, dets: list[Detection], rows: list[int]) -> Array:
        """Integral colour histograms of ``dets[rows]``, shared by every track's classifier.

        Computed at the first request of a frame for all its detections with an
        appearance, in one batched call (rows without appearance stay zero).
        """
        if self._cums is None:
            seen = [j for j, d in enumerate(dets) if d.appearance is not None]
            hists = np.zeros((len(dets), self._bins**3))
            hists[seen] = np.stack([_appearance(dets[j]) for j in seen])
            self._cums = integral_histograms(hists, self._bins)
        return self._cums[rows]

    def _manage(self, stamp_ns: int) -> None:
        """Discard unvalidated tracks past ``frames_before_fake``; drop forgotten ones (6.4.4)."""
        keep = []
        for t in self._tracks:
            age = stamp_ns - t.created_ns + STAMP_TOLERANCE_NS
            fake = not t.validated and age >= self._fake_ns
            forgotten = self._dormant(t, stamp_ns) and not self._remembers(t, stamp_ns)
            keep.append(not fake and not forgotten and not self._static(t, stamp_ns))
        self._keep(keep)

    def _static(self, t: _Track, stamp_ns: int) -> bool:
        """``static_devalidation_s``: seen, "not a person" and motionless for the whole window."""
        if self._static_ns is None or not t.validated or t.recent is None:
            return False
        recent = t.recent
        covered = recent[0][0] <= stamp_ns - self._static_ns + STAMP_TOLERANCE_NS
        if t.last_seen_ns != stamp_ns or not covered:
            return False
        if len(recent) < self._cfg.detections_to_validate:
            return False
        if max(r[3] for r in recent) >= self._not_person:
            return False
        xy = np.array([(r[1], r[2]) for r in recent])
        spread = float(np.max(np.linalg.norm(xy - xy.mean(axis=0), axis=1)))
        return spread <= self._cfg.static_motion_m

    def _outputs(self, stamp_ns: int, dets: list[Detection]) -> list[TrackOutput]:
        out = []
        for i, t in enumerate(self._tracks):
            if self._dormant(t, stamp_ns):
                continue
            box: Box2D | None = None
            visibility = Visibility.NOT_VISIBLE
            confidence = None
            if t.detection is not None:
                det = dets[t.detection]
                box = det.box2d
                visibility = Visibility.OCCLUDED if det.occluded else Visibility.VISIBLE
                confidence = det.confidence
            out.append(
                TrackOutput(
                    track_id=t.track_id,
                    x=float(self._x[i, 0]),
                    y=float(self._x[i, 1]),
                    height=t.height,
                    box2d=box,
                    visibility=visibility,
                    status=TrackStatus.VALIDATED if t.validated else TrackStatus.NEW,
                    confidence=confidence,
                )
            )
        out.sort(key=lambda o: o.track_id)
        return out

    # ------------------------------------------------------------------ helpers

    def _dormant(self, t: _Track, stamp_ns: int) -> bool:
        """Not visible for ``frames_before_old``: out of the output and of step 1."""
        missing = stamp_ns - t.last_seen_ns
        return missing > 0 and missing + STAMP_TOLERANCE_NS >= self._old_ns

    def _remembers(self, t: _Track, stamp_ns: int) -> bool:
        """The classifier of a missing track is still usable (Figure 7.7)."""
        if t.classifier is None or t.classifier.positives == 0:
            return False
        return stamp_ns - t.last_seen_ns <= self._memory_ns + STAMP_TOLERANCE_NS

    def _keep(self, keep: list[bool]) -> None:
        if all(keep):
            return
        mask = np.asarray(keep, dtype=bool)
        self._x = self._x[mask]
        self._P = self._P[mask]
        self._tracks = [t for t, k in zip(self._tracks, keep, strict=True) if k]

    def _new_classifier(self, track_id: int) -> OnlineBoostingClassifier | None:
        if not self._cfg.classifier:
            return None
        return OnlineBoostingClassifier(
            self._bins,
            self._cfg.weak_classifiers,
            self._cfg.selectors,
            seed=np.random.SeedSequence([self._cfg.seed, track_id]),
            learning_rate=self._cfg.classifier_learning_rate,
        )


def _det(track: _Track) -> int:
    if track.detection is None:
        raise RuntimeError(f"track {track.track_id} has no detection this frame")
    return track.detection


def _classifier(track: _Track) -> OnlineBoostingClassifier:
    if track.classifier is None:
        raise RuntimeError(f"track {track.track_id} has no classifier")
    return track.classifier


def _appearance(det: Detection) -> NDArray[np.float32]:
    if det.appearance is None:
        raise RuntimeError("detection without appearance used for classification")
    return det.appearance


def _histogram_bins(size: int) -> int:
    """Bins per channel of a 3D histogram of ``size`` cells (0 when not a cube)."""
    bins = round(size ** (1.0 / 3.0))
    return bins if bins >= 2 and bins**3 == size else 0


def check_contract(cfg: Basso2012TrackerConfig, contract: DetectionContract) -> str | None:
    """Why detections of ``contract`` cannot feed this tracker (None: they can)."""
    if not contract.world_position:
        return "it tracks ground-plane positions, which these detections do not carry"
    if cfg.classifier and not (
        contract.appearance == "rgb_histogram" and _histogram_bins(contract.appearance_size)
    ):
        return (
            "its on-line classifier learns 3D colour histograms (6.2.2), and these detections "
            f"carry {contract.appearance or 'no appearance'}; set tracker.classifier=false"
        )
    return None


SPEC = register_tracker(
    TrackerSpec(
        name="basso2012",
        config_model=Basso2012TrackerConfig,
        factory=Basso2012Tracker,
        check=check_contract,
        summary="UKF, GNN + on-line boosting, track management (seed 000, ch. 6)",
    )
)
