"""The DMT-BS tracker (seed 003, sections 3.3-3.4): 2D constant-velocity Kalman filters on the
floor, Hungarian assignment on Euclidean distance, and blob splitting.

Per frame:

1. predict every track with the constant-velocity model over the stamp difference;
2. assign detections (blob centroids) to predictions by the Hungarian method on the Euclidean
   distance, refusing pairs farther apart than ``gate_m``;
3. blob splitting: a track without a detection, in view for at least ``min_split_age_s``,
   whose prediction lies within ``split_near_m`` of a blob's cell, has merged with that blob.
   When two or more tracks share a blob (those merged tracks plus the track assigned to it)
   and all of them are old enough, the blob's cells are split among their predictions by the
   Voronoi partition and each track takes its part's centroid. Younger tracks are never
   split, so objects that enter the view merged are tracked as one (the seed's 1 s rule).
   "In view" (the seed: "only blobs that have been in view for enough frames will be
   split") is the track's age less the time it spent without a blob of its own (coasting,
   or fed by a split): a track started on a passing fragment of someone's blob (an arm, the
   far side seen by a second camera) and then coasting beside that person does not become
   old by coasting, so it is not kept alive by splitting the person's blob with it (on
   scene 2 with two cameras such a duplicate lived for 144 of 420 frames when age counted
   from the track's start);
4. update the measured tracks; start a track on every detection left over;
5. a track is confirmed after ``confirm_hits`` measured frames; a track that misses a frame
   before it is confirmed is dropped; a confirmed track coasts on its prediction (output as
   occluded) and is dropped after ``max_missed_s`` without a measurement.

A detection's blob is its ``footprint`` (world x, y of its cells, ``(N, 2)``); a detection
without one is a blob of one cell at its centroid.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from rgbd_eval.config import ComponentConfig
from rgbd_eval.methods.dmtbs.blob_split import nearest_blob, split_centroids
from rgbd_eval.plugins import DetectionContract, TrackerSpec, register_tracker
from rgbd_eval.track import kalman
from rgbd_eval.track.association import gnn_assign
from rgbd_eval.track.motion import H, process_noise, transition_matrix
from rgbd_eval.types import Detection, Frame, TrackOutput, TrackStatus, Visibility

F64 = NDArray[np.float64]


#: The tracker's timed stages (the pipeline reports the whole call as "tracking").
TRACK_STAGES = ("kalman predict", "assignment + blob splitting", "kalman update + management")


class DmtbsTrackerConfig(ComponentConfig):
    """The DMT-BS tracker's parameters; the seed's table was lost, see methods/dmtbs/method.yaml."""

    name: Literal["dmtbs"] = "dmtbs"

    gate_m: float = Field(1.0, gt=0.0, description="largest prediction-detection distance (m)")
    min_split_age_s: float = Field(
        1.0,
        ge=0.0,
        le=3600.0,
        description="only tracks at least this old are split (seed 003, 3.3: 1 s)",
    )
    split_near_m: float = Field(
        0.1, ge=0.0, description="a prediction this close (m) to a blob's cell falls on it"
    )
    measurement_sigma_m: float = Field(
        0.1, gt=0.0, le=10.0, description="std of a blob centroid around the person's axis (m)"
    )
    acceleration_variance: float = Field(
        4.0, gt=0.0, description="white-acceleration variance of the CV model (m^2/s^4)"
    )
    initial_speed_sigma: float = Field(
        1.5, gt=0.0, description="std of a new track's velocity (m/s): walking speed"
    )
    confirm_hits: int = Field(3, ge=1, description="measured frames that confirm a track")
    max_missed_s: float = Field(
        1.0,
        ge=0.0,
        le=3600.0,
        description="a confirmed track without measurement this long is dropped (s)",
    )


@dataclass
class _Track:
    """Book-keeping of one track; its filter state lives in the tracker's arrays."""

    track_id: int
    created_ns: int
    last_seen_ns: int
    hits: int
    confirmed: bool
    height: float
    #: time since its start without a blob of its own (ns): age in view = age - this
    unseen_ns: int = 0


@dataclass(frozen=True)
class _Measurement:
    xy: tuple[float, float]
    height: float


@dataclass(frozen=True)
class _Blob:
    centroid: tuple[float, float]
    cells: F64
    height: float


def _blob(det: Detection) -> _Blob:
    if det.footprint is not None:
        cells = np.asarray(det.footprint, dtype=np.float64).reshape(-1, 2)
    else:
        cells = np.asarray([det.ground_xy], dtype=np.float64)
    return _Blob(det.ground_xy, cells, det.height)


class DmtbsTracker:
    """Density-map blob tracking with blob splitting (seed 003); one instance per sequence."""

    def __init__(
        self, config: DmtbsTrackerConfig, contract: DetectionContract | None = None
    ) -> None:
        problem = None if contract is None else check_contract(config, contract)
        if problem is not None:
            raise ValueError(problem)
        self._cfg = config
        self._last_timings: dict[str, float] = dict.fromkeys(TRACK_STAGES, 0.0)
        self._x = np.zeros((0, 4))
        self._P = np.zeros((0, 4, 4))
        self._tracks: list[_Track] = []
        self._last_ns: int | None = None
        self._next_id = 1
        self._R = np.eye(2) * config.measurement_sigma_m**2
        self.splits = 0  # blobs split so far (for tests and reports)

    @property
    def last_timings(self) -> Mapping[str, float]:
        """Seconds of the last :meth:`update`."""
        return self._last_timings

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        """Consume one frame's detections; return every maintained track, ordered by id."""
        if self._last_ns is not None and stamp_ns <= self._last_ns:
            raise ValueError(f"stamp_ns={stamp_ns} must increase (previous frame: {self._last_ns})")
        t0 = time.perf_counter()
        dt_ns = 0 if self._last_ns is None else stamp_ns - self._last_ns
        dt = dt_ns * 1e-9
        self._last_ns = stamp_ns
        blobs = [_blob(d) for d in detections]
        if dt > 0.0 and self._tracks:
            F = transition_matrix(dt)
            self._x, self._P = kalman.predict(
                self._x, self._P, F, process_noise(dt, self._cfg.acceleration_variance)
            )
        t1 = time.perf_counter()
        measurements, used = self._associate(stamp_ns, dt_ns, blobs)
        t2 = time.perf_counter()
        self._correct(stamp_ns, blobs, measurements, used)
        outputs = self._outputs(stamp_ns)
        self._last_timings = dict(
            zip(TRACK_STAGES, (t1 - t0, t2 - t1, time.perf_counter() - t2), strict=True)
        )
        return outputs

    # ------------------------------------------------------------------ steps

    def _associate(
        self, stamp_ns: int, dt_ns: int, blobs: list[_Blob]
    ) -> tuple[dict[int, _Measurement], set[int]]:
        """Track index -> its measurement this frame, and the indices of the blobs used up."""
        cfg = self._cfg
        pred = self._x[:, :2]
        z = np.array([b.centroid for b in blobs], dtype=np.float64).reshape(-1, 2)
        dist = np.sqrt(((pred[:, None, :] - z[None, :, :]) ** 2).sum(axis=-1))
        pairs = gnn_assign(dist, cfg.gate_m)
        track_of_blob = {j: i for i, j in pairs}
        out = {i: _Measurement(blobs[j].centroid, blobs[j].height) for i, j in pairs}
        used = set(track_of_blob)
        min_age_ns = round(cfg.min_split_age_s * 1e9)
        old = [stamp_ns - t.created_ns - t.unseen_ns >= min_age_ns for t in self._tracks]
        for i, t in enumerate(self._tracks):
            if i not in out:
                t.unseen_ns += dt_ns
        # Step 3: merged tracks, grouped by the blob their prediction falls on.
        sharing: dict[int, list[int]] = {}
        cells = [b.cells for b in blobs]
        for i in range(len(self._tracks)):
            if i in out or not old[i]:
                continue
            k = nearest_blob(pred[i], cells, cfg.split_near_m)
            if k is not None:
                sharing.setdefault(k, []).append(i)
        for k, merged in sorted(sharing.items()):
            owner = track_of_blob.get(k)
            tracks = merged if owner is None else [owner, *merged]
            if len(tracks) < 2 or not all(old[i] for i in tracks):
                continue
            parts = split_centroids(blobs[k].cells, pred[tracks])
            for i, c in zip(tracks, parts, strict=True):
                if c is not None:
                    out[i] = _Measurement(c, blobs[k].height)
                elif i in out:
                    del out[i]
            used.add(k)
            self.splits += 1
        return out, used

    def _correct(
        self,
        stamp_ns: int,
        blobs: list[_Blob],
        measurements: dict[int, _Measurement],
        used: set[int],
    ) -> None:
        cfg = self._cfg
        rows = sorted(measurements)
        if rows:
            z = np.array([measurements[i].xy for i in rows], dtype=np.float64)
            x, P = kalman.update(self._x[rows], self._P[rows], z, H, self._R)
            self._x[rows], self._P[rows] = x, P
            for i in rows:
                t = self._tracks[i]
                t.last_seen_ns = stamp_ns
                t.height = measurements[i].height
                t.hits += 1
                t.confirmed = t.confirmed or t.hits >= cfg.confirm_hits
        max_missed_ns = round(cfg.max_missed_s * 1e9)
        keep = [
            i
            for i, t in enumerate(self._tracks)
            if i in measurements or (t.confirmed and stamp_ns - t.last_seen_ns <= max_missed_ns)
        ]
        self._tracks = [self._tracks[i] for i in keep]
        self._x, self._P = self._x[keep], self._P[keep]
        new = [j for j in range(len(blobs)) if j not in used]
        if new:
            x0 = np.zeros((len(new), 4))
            x0[:, :2] = [blobs[j].centroid for j in new]
            P0 = np.zeros((len(new), 4, 4))
            P0[:, :2, :2] = self._R
            P0[:, 2:, 2:] = np.eye(2) * cfg.initial_speed_sigma**2
            self._x = np.concatenate([self._x, x0])
            self._P = np.concatenate([self._P, P0])
            for j in new:
                self._tracks.append(
                    _Track(
                        self._next_id, stamp_ns, stamp_ns, 1, cfg.confirm_hits <= 1, blobs[j].height
                    )
                )
                self._next_id += 1

    def _outputs(self, stamp_ns: int) -> list[TrackOutput]:
        out = []
        for i, t in enumerate(self._tracks):
            seen = t.last_seen_ns == stamp_ns
            out.append(
                TrackOutput(
                    track_id=t.track_id,
                    x=float(self._x[i, 0]),
                    y=float(self._x[i, 1]),
                    height=t.height if math.isfinite(t.height) else 0.0,
                    box2d=None,
                    visibility=Visibility.VISIBLE if seen else Visibility.OCCLUDED,
                    status=TrackStatus.VALIDATED if t.confirmed else TrackStatus.NEW,
                )
            )
        return sorted(out, key=lambda o: o.track_id)


def check_contract(config: DmtbsTrackerConfig, contract: DetectionContract) -> str | None:
    """Why detections of ``contract`` cannot feed this tracker (None: they can)."""
    if not contract.world_position:
        return "dmtbs tracks floor positions, which these detections do not carry"
    return None


SPEC = register_tracker(
    TrackerSpec(
        name="dmtbs",
        config_model=DmtbsTrackerConfig,
        factory=DmtbsTracker,
        check=check_contract,
        stages=TRACK_STAGES,
        summary="2D constant-velocity Kalman filters, Hungarian, blob splitting (seed 003, 3.3-3.4)",
    )
)
