"""satake2009 tracker (seed 002, 2.3-2.4): one EKF per person in the robot frame.

The robot motion ``u`` reaches the filter through the frame's odometry: the planar pose
of the left camera (its ground projection, heading along its optical axis) at two
frames gives the arc the robot drove (:func:`~.satake2009_ekf.motion_from_poses`), the
same motion wheel speeds would give. Without odometry the robot stands still.
Detections (world frame) are moved into the robot frame, associated with the predicted
tracks by Mahalanobis distance (global nearest neighbour), and the tracks are output in
the world frame again, so that they score like every other method.
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
from rgbd_eval.plugins import DetectionContract, StreamSpec, TrackerSpec, register_tracker
from rgbd_eval.track import satake2009_ekf as ekf
from rgbd_eval.track.association import chi_square_gate, gnn_assign
from rgbd_eval.types import Box2D, Detection, Frame, Pose, TrackOutput, TrackStatus, Visibility


class Satake2009TrackerConfig(ComponentConfig):
    """The satake2009 tracker (sigma_w, sigma_v are not in the seed: see the YAML)."""

    name: Literal["satake2009"] = "satake2009"
    sigma_w: float = Field(1.0, gt=0.0, le=20.0, description="acceleration noise (m/s^2)")
    sigma_v: float = Field(0.15, gt=0.0, le=5.0, description="observation noise (m)")
    velocity: Literal["ground", "seed"] = Field("ground", description="eq. (3) variant")
    initial_speed_std: float = Field(1.0, gt=0.0, description="prior std of a new velocity")
    gate_probability: float = Field(0.99, gt=0.0, lt=1.0, description="chi^2 gate, 3 dof")
    max_missed_s: float = Field(1.0, ge=0.0, description="a track unseen this long is dropped")
    min_hits: int = Field(2, ge=1, description="matches before a track is output")
    coast_min_hits: int = Field(10, ge=1, description="matches before an unseen track is output")
    min_separation_m: float = Field(
        0.5, ge=0.0, description="no new track this near (ground) to an existing one"
    )


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
        self.cfg = config
        self.gate = chi_square_gate(config.gate_probability, dof=3)
        self.tracks: list[_Track] = []
        self.next_id = 1
        self.robot: tuple[float, float, float] | None = None
        self.stamp_ns: int | None = None
        self.last_timings: Mapping[str, float] = {}

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
        ys = [to_robot(robot, d.position) for d in detections]
        if self.tracks and ys:
            d2 = np.empty((len(self.tracks), len(ys)))
            for i, t in enumerate(self.tracks):
                Sinv = np.linalg.inv(ekf.innovation_covariance(t.P, cfg.sigma_v))
                for j, y in enumerate(ys):
                    r = y - ekf.H @ t.x
                    d2[i, j] = r @ Sinv @ r
            pairs = gnn_assign(d2, self.gate)
        else:
            pairs = []
        matched = {j for _, j in pairs}
        for i, j in pairs:
            t = self.tracks[i]
            t.x, t.P = ekf.update(t.x, t.P, ys[j], cfg.sigma_v)
            t.hits += 1
            t.last_seen_ns = stamp_ns
            t.box = detections[j].box2d
        seen = {i for i, _ in pairs}
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
        self.last_timings = {"ekf": time.perf_counter() - t0}
        return out


register_tracker(
    TrackerSpec(
        "satake2009",
        Satake2009TrackerConfig,
        Satake2009Tracker,
        needs_frame=True,
        streams=(StreamSpec("left"),),
        stages=("ekf",),
        summary="EKF per person in the robot frame, robot motion from odometry (2.3)",
    )
)
