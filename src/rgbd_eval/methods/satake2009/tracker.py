"""satake2009 tracker (seed 002, 2.3-2.4): one EKF per person in the robot frame.

The robot motion ``u`` reaches the filter through the frame's odometry: the planar pose
of the left camera (its ground projection, heading along its optical axis) at two
frames gives the arc the robot drove (:func:`~.satake2009_ekf.motion_from_poses`), the
same motion wheel speeds would give. The odometry is ``nav_msgs/Odometry``, ``/tf``, or
the wheels' ``sensor_msgs/JointState`` integrated by the reader (``io.wheels``, 2.3.1's
arcs: between two frames the arc recovered from the poses is the wheels' own when their
speeds hold). Without odometry the robot stands still.

Per frame (2.4 step 2): each track is predicted (eq. 5), its head top projected into
the left image with eq. (1), and the distance templates, made for its predicted distance
(2.4 step 2.2), are searched around it
(:func:`rgbd_eval.methods.satake2009.search.search_around`: a window of
``search_sigmas`` predicted standard deviations, best template wins; ``search_steps``
adds distances around the predicted one); a match above the detector's ``min_score``
that passes its colour test (:mod:`rgbd_eval.methods.satake2009.colour`) inside the
chi-square gate is the track's observation ``y_t`` (eq. 4), nearest tracks first so that
an occluder is claimed by its own track. Tracks the search misses are then associated
with the detector's whole-image detections (world frame, moved into the robot frame)
by Mahalanobis distance (global nearest neighbour); detections left over start tracks
(2.4 step 3). Tracks are output in the world frame again, so that they score like every
other method.

This is the tracker reading the frame (``needs_frame``), not a detector taking hints:
the detector's output stays a pure function of the frame, so it caches, and the search
that depends on the tracks lives with them. The depth image is the detector's
(shared per frame, :func:`~rgbd_eval.methods.satake2009.search.frame_depth`) and the
template settings come with the detector's contract
(:class:`~rgbd_eval.methods.satake2009.detector.Satake2009Contract`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from rgbd_eval.config import ComponentConfig
from rgbd_eval.detect import stereo
from rgbd_eval.methods.satake2009 import colour as colour
from rgbd_eval.methods.satake2009 import ekf as ekf
from rgbd_eval.methods.satake2009 import search as search
from rgbd_eval.methods.satake2009 import templates as st
from rgbd_eval.methods.satake2009.detector import (
    Satake2009Contract,
    Satake2009DetectorConfig,
    head_point,
)
from rgbd_eval.plugins import DetectionContract, TrackerSpec, register_tracker
from rgbd_eval.track.association import chi_square_gate, gnn_assign
from rgbd_eval.types import (
    Box2D,
    CameraModel,
    Detection,
    Frame,
    Pose,
    TrackOutput,
    TrackStatus,
    Visibility,
)


class Satake2009TrackerConfig(ComponentConfig):
    """The satake2009 tracker (sigma_w, sigma_v are not in the seed: see the YAML)."""

    name: Literal["satake2009"] = "satake2009"
    sigma_w: float = Field(1.0, gt=0.0, le=20.0, description="acceleration noise (m/s^2)")
    sigma_v: float = Field(0.15, ge=0.001, le=5.0, description="observation noise (m)")
    velocity: Literal["ground", "seed"] = Field("ground", description="eq. (3) variant")
    initial_speed_std: float = Field(
        1.0, gt=0.0, le=10.0, description="prior std of a new velocity (m/s)"
    )
    gate_probability: float = Field(0.99, gt=0.0, lt=1.0, description="chi^2 gate, 3 dof")
    max_missed_s: float = Field(
        1.0, ge=0.0, le=3600.0, description="a track unseen this long is dropped"
    )
    min_hits: int = Field(2, ge=1, description="matches before a track is output")
    coast_min_hits: int = Field(10, ge=1, description="matches before an unseen track is output")
    min_separation_m: float = Field(
        0.5, ge=0.0, description="no new track this near (ground) to an existing one"
    )
    local_search: bool = Field(True, description="search templates around each prediction")
    search_sigmas: float = Field(3.0, gt=0.0, le=10.0, description="window: predicted stds")
    min_search_radius_px: float = Field(6.0, ge=1.0, description="smallest window radius")
    max_search_radius_px: float = Field(48.0, ge=1.0, description="largest window radius")
    search_rows: int = Field(
        40, ge=8, le=512, description="search where the tallest template is this tall"
    )
    search_distance_ratio: float = Field(
        1.08, gt=1.0, le=1.5, description="step r of the distances D r^k around the predicted D"
    )
    search_steps: int = Field(
        0, ge=0, le=3, description="k = -steps..steps: distances searched around D (0: D only)"
    )


def check_contract(_cfg: Satake2009TrackerConfig, contract: DetectionContract) -> str | None:
    """The tracker searches templates itself: it needs the satake2009 detector's settings."""
    if not isinstance(contract, Satake2009Contract) or contract.detector is None:
        return (
            "the satake2009 tracker searches distance templates around its predictions "
            "in the satake2009 detector's stereo depth: pair it with detector satake2009"
        )
    return None


def planar_pose(pose: Pose) -> tuple[float, float, float]:
    """``(x, y, yaw)`` of a camera's ground projection, yaw along its optical axis."""
    R = pose.rotation_matrix()
    axis = R[:, 2]
    return (float(pose.translation[0]), float(pose.translation[1]), math.atan2(axis[1], axis[0]))


def to_robot(robot: tuple[float, float, float], p: tuple[float, float, float]) -> ekf.Array:
    """A world point in the robot frame of planar pose ``robot`` (height kept)."""
    x0, y0, a = robot
    c, s = math.cos(a), math.sin(a)
    dx, dy = p[0] - x0, p[1] - y0
    return np.array([c * dx + s * dy, -s * dx + c * dy, p[2]])


def to_world(robot: tuple[float, float, float], x: ekf.Array) -> tuple[float, float]:
    """Ground position of robot-frame state ``x`` in the world."""
    x0, y0, a = robot
    c, s = math.cos(a), math.sin(a)
    return (x0 + c * float(x[0]) - s * float(x[1]), y0 + s * float(x[0]) + c * float(x[1]))


@dataclass(frozen=True)
class _Observation:
    y: ekf.Array
    box: Box2D


@dataclass
class _Track:
    track_id: int
    x: ekf.Array
    P: ekf.Array
    hits: int
    last_seen_ns: int
    box: Box2D | None


class Satake2009Tracker:
    """EKF per person in the robot frame, GNN association, output in the world frame."""

    def __init__(self, config: Satake2009TrackerConfig, contract: DetectionContract) -> None:
        if not isinstance(contract, Satake2009Contract) or contract.detector is None:
            raise ValueError(check_contract(config, contract))
        self.cfg = config
        self.det: Satake2009DetectorConfig = contract.detector
        self.templates = st.load_templates()
        self._scaled: dict[tuple[float, float], list[st.DistanceTemplate]] = {}
        self.gate = chi_square_gate(config.gate_probability, dof=3)
        self.tracks: list[_Track] = []
        self.next_id = 1
        self.robot: tuple[float, float, float] | None = None
        self.stamp_ns: int | None = None
        self.last_timings: Mapping[str, float] = {}

    def _observe(
        self, frame: Frame, robot: tuple[float, float, float], pending: list[int]
    ) -> tuple[dict[int, _Observation], float]:
        """Template search around the predictions of tracks ``pending`` (2.4 step 2.2).

        Returns the observations by track index and the seconds spent on depth.
        """
        t0 = time.perf_counter()
        left = frame.stream("left")
        sd = search.frame_depth(frame, self.det.size, self.det.sgbm)
        depth_s = time.perf_counter() - t0
        cam = sd.camera
        to_cam = left.pose.inverse()
        heads = {}
        for i in pending:
            t = self.tracks[i]
            wx, wy = to_world(robot, t.x)
            heads[i] = to_cam.transform_points(np.array([[wx, wy, float(t.x[2])]]))[0]
        found: dict[int, _Observation] = {}
        claimed: list[ekf.Array] = []
        rgb: np.ndarray | None = None
        for i in sorted(pending, key=lambda i: float(heads[i][2])):  # nearest first
            t, p = self.tracks[i], heads[i]
            if not p[2] > self.det.min_distance_m * 0.5:
                continue
            m = self._search(sd, cam, t, p)
            if m is None:
                continue
            D = search.body_distance(sd.depth, m, self.det.band_m)
            if self.det.min_head_torso_chroma > 0:
                if rgb is None:
                    rgb = stereo.resized(left.image, self.det.size)
                if not colour.passes(
                    rgb, sd.depth, m, D, self.det.band_m, self.det.min_head_torso_chroma
                ):
                    continue
            head = head_point(cam, m, D)[None, :]
            world = left.pose.transform_points(head)[0]
            y = to_robot(robot, (float(world[0]), float(world[1]), float(world[2])))
            r = y - ekf.H @ t.x
            S = ekf.innovation_covariance(t.P, self.cfg.sigma_v)
            if float(r @ np.linalg.solve(S, r)) > self.gate:
                continue
            if any(math.hypot(*(y[:2] - c[:2])) < self.cfg.min_separation_m for c in claimed):
                continue
            claimed.append(y)
            sx, sy = left.camera.width / cam.width, left.camera.height / cam.height
            x, yy, w, h = m.box
            found[i] = _Observation(y, Box2D(x * sx, yy * sy, w * sx, h * sy))
        return found, depth_s

    def _search(
        self, sd: stereo.StereoDepth, cam: CameraModel, t: _Track, head: ekf.Array
    ) -> st.Match | None:
        """The best template around one track's projected head top, if it scores enough."""
        cfg, D = self.cfg, float(head[2])
        u, v = (float(c) for c in cam.project(head[None, :])[0])
        S = ekf.innovation_covariance(t.P, cfg.sigma_v)
        sigma = math.sqrt(float(np.linalg.eigvalsh(S[:2, :2])[-1]))
        radius = min(
            cfg.max_search_radius_px,
            max(cfg.min_search_radius_px, cam.fx * cfg.search_sigmas * sigma / D),
        )
        r = cfg.search_distance_ratio
        k = cfg.search_steps
        distances = [search.quantised(D * r**i) for i in range(-k, k + 1)]
        m = search.search_around(
            sd.depth, cam.fx, self.templates, (u, v), distances, radius, cfg.search_rows,
            self.det.match, cache=self._scaled, far=sd.far,
        )  # fmt: skip
        return m if m is not None and m.score >= self.det.min_score else None

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        t0 = time.perf_counter()
        cfg = self.cfg
        robot = planar_pose(frame.stream("left").pose) if frame is not None else (0.0, 0.0, 0.0)
        if self.robot is not None and self.stamp_ns is not None and stamp_ns > self.stamp_ns:
            dt = (stamp_ns - self.stamp_ns) * 1e-9
            m = ekf.motion_from_poses(self.robot, robot, dt)
            for t in self.tracks:
                t.x, t.P = ekf.predict(t.x, t.P, m, dt, cfg.sigma_w, cfg.velocity)
        self.robot, self.stamp_ns = robot, stamp_ns
        t1 = time.perf_counter()
        observed: dict[int, _Observation] = {}
        depth_s = 0.0
        if frame is not None and cfg.local_search and self.tracks:
            observed, depth_s = self._observe(frame, robot, list(range(len(self.tracks))))
        t2 = time.perf_counter()
        for i, o in observed.items():
            t = self.tracks[i]
            t.x, t.P = ekf.update(t.x, t.P, o.y, cfg.sigma_v)
            t.hits += 1
            t.last_seen_ns = stamp_ns
            t.box = o.box
        ys = [to_robot(robot, d.position) for d in detections]
        # a detection on a body a track has just observed is that track's, not a new person
        claimed = {
            j
            for j, y in enumerate(ys)
            for o in observed.values()
            if math.hypot(*(y[:2] - o.y[:2])) < cfg.min_separation_m
        }
        rest = [i for i in range(len(self.tracks)) if i not in observed]
        free = [j for j in range(len(ys)) if j not in claimed]
        if rest and free:
            d2 = np.empty((len(rest), len(free)))
            for a, i in enumerate(rest):
                t = self.tracks[i]
                Sinv = np.linalg.inv(ekf.innovation_covariance(t.P, cfg.sigma_v))
                for b, j in enumerate(free):
                    r = ys[j] - ekf.H @ t.x
                    d2[a, b] = r @ Sinv @ r
            pairs = [(rest[a], free[b]) for a, b in gnn_assign(d2, self.gate)]
        else:
            pairs = []
        matched = claimed | {j for _, j in pairs}
        for i, j in pairs:
            t = self.tracks[i]
            t.x, t.P = ekf.update(t.x, t.P, ys[j], cfg.sigma_v)
            t.hits += 1
            t.last_seen_ns = stamp_ns
            t.box = detections[j].box2d
        seen = set(observed) | {i for i, _ in pairs}
        for i, t in enumerate(self.tracks):
            if i not in seen:
                t.box = None
        keep_ns = cfg.max_missed_s * 1e9
        self.tracks = [t for t in self.tracks if stamp_ns - t.last_seen_ns <= keep_ns]
        for j, y in enumerate(ys):
            if j in matched or any(
                math.hypot(*(t.x[:2] - y[:2])) < cfg.min_separation_m for t in self.tracks
            ):
                continue
            P = np.diag([cfg.sigma_v**2] * 3 + [cfg.initial_speed_std**2] * 2)
            self.tracks.append(
                _Track(self.next_id, np.array([*y, 0.0, 0.0]), P, 1, stamp_ns, detections[j].box2d)
            )
            self.next_id += 1
        out = []
        for t in self.tracks:
            visible = t.last_seen_ns == stamp_ns
            if t.hits < (cfg.min_hits if visible else cfg.coast_min_hits):
                continue
            wx, wy = to_world(robot, t.x)
            vis = Visibility.VISIBLE if visible else Visibility.OCCLUDED
            out.append(
                TrackOutput(t.track_id, wx, wy, float(t.x[2]), t.box, vis, TrackStatus.VALIDATED)
            )
        t3 = time.perf_counter()
        self.last_timings = {
            "stereo": depth_s,
            "search": t2 - t1 - depth_s,
            "ekf": (t1 - t0) + (t3 - t2),
        }
        return out


register_tracker(
    TrackerSpec(
        "satake2009",
        Satake2009TrackerConfig,
        Satake2009Tracker,
        needs_frame=True,
        streams=search.STREAMS,
        check=check_contract,
        stages=("stereo", "search", "ekf"),
        summary="EKF per person in the robot frame, robot motion from odometry (2.3)",
    )
)
