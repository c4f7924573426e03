"""Person following as a closed-loop simulation (seed 002, section 3; ``synth --follow``).

The robot of a scenario that carries a stereo pair is driven, frame by frame, by the
path-C law of section 3 toward the satake2009 track of one person:

    v_L = v (1 - k 2dY / (X^2 + Y^2)),   v_R = v (1 + k 2dY / (X^2 + Y^2)),

with (X, Y) the tracked target in the robot frame (X forward, Y left, as the EKF of 2.3).
Each frame is rendered from the robot's current pose, the pair's images go through the
satake2009 detector and tracker online (the robot's motion reaches the tracker through
the drifting odometry, as in a recording), and the wheel speeds move the true robot
until the next frame (the kinematics of 2.3.1). Rendering and tracking therefore
interleave: the robot's path depends on the tracker.

The seed gives none of v, k, d nor a stopping rule; :class:`FollowControl` states ours.
The robot locks onto the first track within ``lock_m`` of the chosen person's true
position, then follows that track id only; when the id is no longer output it stops.
Per frame it records the true distance and bearing to the target (the following error)
and whether the followed id is still on the target. Same scenario and seed, same numbers.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import time
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.atomic import write_json, write_text
from rgbd_eval.components import create_detector, create_tracker
from rgbd_eval.config import RunConfig, config_to_dict, load_config
from rgbd_eval.errors import ConfigError
from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.writer import RecordingWriter
from rgbd_eval.sim import rig
from rgbd_eval.sim.rig_config import StereoPairConfig
from rgbd_eval.sim.rig_sensors import make_rig_sensor
from rgbd_eval.sim.scenario import Scenario
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.sim.stereo_rig import StereoPair
from rgbd_eval.sim.synth import (
    OWNER,
    SynthContainer,
    ground_truth_path,
    provenance,
    stream_options,
    write_frame,
    write_static,
)
from rgbd_eval.types import Frame, GroundTruthObject, Pose, Stream, TrackOutput

Status = Literal["searching", "following", "wrong", "lost"]


@dataclass(frozen=True)
class FollowControl:
    """The path-C controller (seed 002, section 3). The seed prints no values: these are ours.

    - ``v`` 0.6 m/s: a walking pace, under the PeopleBot's 0.9 m/s maximum (section 4);
    - ``k`` 2: the turning radius rho/k of path C is half the circle of path A (section 3
      only says k shrinks it);
    - ``d`` 0.165 m: half the ~0.33 m wheel track of the Pioneer base a PeopleBot is built on;
    - ``stop_m``/``full_m``: the seed gives no following distance. Ours scales v linearly
      from 0 at 1.5 m to full at 2.5 m, so the robot neither runs the person over nor
      falls behind;
    - ``v_max`` 0.9 m/s, the PeopleBot's maximum (section 4): faster wheel commands are
      scaled down together, keeping the curvature.
    """

    v: float = 0.6
    k: float = 2.0
    d: float = 0.165
    stop_m: float = 1.5
    full_m: float = 2.5
    v_max: float = 0.9
    #: The followed track is taken on within this distance of the person (the 1 m metric
    #: gate of the evaluation) and judged "on the target" while it stays within it.
    lock_m: float = 1.0

    def __post_init__(self) -> None:
        for name in ("v", "k", "d", "v_max", "lock_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}={getattr(self, name)} must be > 0")
        if not 0 <= self.stop_m < self.full_m:
            raise ValueError(f"stop_m={self.stop_m} must be >= 0 and below full_m={self.full_m}")


def path_c_wheel_speeds(X: float, Y: float, v: float, k: float, d: float) -> tuple[float, float]:
    """``(v_L, v_R)`` of path C (section 3) toward a target at robot-frame ``(X, Y)``."""
    r2 = X * X + Y * Y
    turn = k * 2.0 * d * Y / r2 if r2 > 0 else 0.0
    return v * (1.0 - turn), v * (1.0 + turn)


def wheel_command(X: float, Y: float, c: FollowControl) -> tuple[float, float]:
    """Path C at the distance-scaled speed, both wheels scaled into ``[-v_max, v_max]``."""
    r = exact.hypot(X, Y)
    v = c.v * min(1.0, max(0.0, (r - c.stop_m) / (c.full_m - c.stop_m)))
    v_L, v_R = path_c_wheel_speeds(X, Y, v, c.k, c.d)
    top = max(abs(v_L), abs(v_R))
    if top > c.v_max:
        v_L, v_R = v_L * c.v_max / top, v_R * c.v_max / top
    return v_L, v_R


def drive(
    pose: tuple[float, float, float], v_L: float, v_R: float, d: float, dt: float
) -> tuple[float, float, float]:
    """The planar pose after ``dt`` at wheel speeds ``(v_L, v_R)`` (the arc of 2.3.1).

    The arithmetic of :func:`rgbd_eval.methods.satake2009.ekf.robot_motion`, in
    :mod:`rgbd_eval.exact`: the simulated robot's path is part of the recording, the same on
    every CPU.
    """
    if not d > 0:
        raise ValueError(f"half wheel separation d={d} must be > 0")
    v = 0.5 * (v_R + v_L)
    d_theta = (v_R - v_L) / (2.0 * d) * dt
    half = d_theta / 2.0
    s_half, c_half = exact.sincos(half)
    d_L = v * dt * (s_half / half if half != 0.0 else 1.0)  # 2 rho sin(d_theta/2)
    d_X, d_Y = d_L * c_half, d_L * s_half
    x, y, yaw = pose
    s, c = exact.sincos(yaw)
    return (x + c * d_X - s * d_Y, y + s * d_X + c * d_Y, yaw + d_theta)


def in_robot_frame(
    pose: tuple[float, float, float], point: tuple[float, float]
) -> tuple[float, float]:
    """A world ground point as ``(X forward, Y left)`` of planar robot pose ``pose``."""
    x, y, yaw = pose
    s, c = exact.sincos(yaw)
    dx, dy = point[0] - x, point[1] - y
    return c * dx + s * dy, -s * dx + c * dy


@dataclass(frozen=True)
class FollowStep:
    """One frame of the closed loop (true quantities from the simulator)."""

    frame: int
    stamp_ns: int
    t: float
    robot_x: float
    robot_y: float
    robot_yaw_deg: float
    target_x: float | None  # None: the person is not in the scene
    target_y: float | None
    distance_m: float | None  # true robot (base_link) to target
    bearing_deg: float | None  # true, left positive
    track_id: int | None  # the followed track (None before the lock)
    track_x: float | None  # its world position (odometry frame)
    track_y: float | None
    track_error_m: float | None  # followed track to the target's true position
    status: Status
    v_left: float
    v_right: float


@dataclass(frozen=True)
class FollowSummary:
    """Whether the target was kept, and the following error over the frames after the lock."""

    scenario: str
    seed: int
    target: int
    frames: int
    locked_track: int | None
    lock_frame: int | None
    kept: bool
    frames_following: int
    frames_wrong: int
    frames_lost: int
    first_lost_frame: int | None
    distance_mean_m: float | None
    distance_min_m: float | None
    distance_max_m: float | None
    distance_final_m: float | None
    bearing_mean_abs_deg: float | None
    bearing_max_abs_deg: float | None
    track_error_mean_m: float | None
    control: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class FollowResult:
    steps: tuple[FollowStep, ...]
    summary: FollowSummary
    #: The tracks output at every frame (for scoring the run like a recording).
    tracks: tuple[tuple[TrackOutput, ...], ...]
    ground_truth: tuple[tuple[GroundTruthObject, ...], ...]
    #: CPU seconds (``time.process_time``: the process, with OpenCV on one thread during the
    #: loop, so one core's work) per part of the loop: ``render`` (the simulator),
    #: ``detect`` and ``track`` (the method alone), summed over frames.
    cpu_s: dict[str, float] = field(default_factory=dict)


def stereo_pair_of(scenario: Scenario) -> tuple[int, StereoPairConfig]:
    """The scenario's stereo pair and its place in the rig (ConfigError when it has none)."""
    for k, sensor in enumerate(scenario.rig):
        if isinstance(sensor, StereoPairConfig):
            return k, sensor
    raise ConfigError(
        f"scenario {scenario.name!r} has no stereo_pair rig sensor: following needs one "
        "(add --rig stereo)"
    )


def _frame(
    index: int,
    stamp_ns: int,
    images: tuple[NDArray[np.uint8], NDArray[np.uint8]],
    pair: StereoPair,
    base_odom: Pose,
) -> Frame:
    """The frame a recording of this instant would give the method (odometry poses)."""
    left_pose = base_odom.compose(pair.base_to_left)
    right_pose = base_odom.compose(pair.base_to_right)
    streams = {
        "left": Stream(images[0], "rgb8", pair.left, stamp_ns, left_pose),
        "right": Stream(images[1], "rgb8", pair.right, stamp_ns, right_pose),
    }
    return Frame(
        index,
        stamp_ns,
        streams,
        camera_pose=left_pose,
        world_frame=rig.WORLD_FRAME,
        has_odometry=True,
    )


def _summary(
    scenario: Scenario,
    seed: int,
    target: int,
    steps: Sequence[FollowStep],
    control: FollowControl,
) -> FollowSummary:
    locked = [s for s in steps if s.status != "searching"]
    lock = locked[0] if locked else None
    dist = [s.distance_m for s in locked if s.distance_m is not None]
    bear = [abs(s.bearing_deg) for s in locked if s.bearing_deg is not None]
    err = [s.track_error_m for s in locked if s.track_error_m is not None]
    count = {st: sum(1 for s in locked if s.status == st) for st in ("following", "wrong", "lost")}
    first_lost = next((s.frame for s in locked if s.status != "following"), None)

    def mean(v: list[float]) -> float | None:
        return sum(v) / len(v) if v else None

    return FollowSummary(
        scenario=scenario.name,
        seed=seed,
        target=target,
        frames=len(steps),
        locked_track=lock.track_id if lock else None,
        lock_frame=lock.frame if lock else None,
        kept=lock is not None and count["following"] == len(locked),
        frames_following=count["following"],
        frames_wrong=count["wrong"],
        frames_lost=count["lost"],
        first_lost_frame=first_lost,
        distance_mean_m=mean(dist),
        distance_min_m=min(dist) if dist else None,
        distance_max_m=max(dist) if dist else None,
        distance_final_m=steps[-1].distance_m if steps else None,
        bearing_mean_abs_deg=mean(bear),
        bearing_max_abs_deg=max(bear) if bear else None,
        track_error_mean_m=mean(err),
        control={k: float(v) for k, v in asdict(control).items()},
    )


def follow(
    scenario: Scenario,
    target: int,
    seed: int | None = None,
    control: FollowControl | None = None,
    config: RunConfig | None = None,
    out_path: Path | None = None,
    container: SynthContainer = "mcap",
    max_frames: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> FollowResult:
    """Drive the robot of ``scenario`` after person ``target`` with the satake2009 tracker online.

    The scenario's robot path is ignored: the robot starts at its start pose and moves
    only as the controller commands. ``config`` is the run config of the tracker
    (default: the satake2009 method's). With ``out_path`` the frames are also written
    as a recording (robot motion as driven) plus its ground-truth sidecar.
    """
    c = control or FollowControl()
    if target not in {p.id for p in scenario.people}:
        known = ", ".join(str(p.id) for p in scenario.people) or "none"
        raise ConfigError(
            f"--follow {target}: scenario {scenario.name!r} has no such person ({known})"
        )
    k_pair, pair_cfg = stereo_pair_of(scenario)
    cfg = config or load_config(method="satake2009")
    detector, tracker = create_detector(cfg), create_tracker(cfg)
    sim = Simulator(scenario, seed)
    pair = StereoPair(pair_cfg, rig.WORLD_FRAME)
    n = sim.n_frames if max_frames is None else min(sim.n_frames, max_frames)
    if n < 1:
        raise ValueError(f"max_frames={max_frames} must be at least 1")
    dt = 1.0 / scenario.sensor.rate_hz
    r = scenario.robot
    pose = (r.x, r.y, math.radians(r.yaw_deg))
    sim.set_robot_pose(0, pose)

    steps: list[FollowStep] = []
    all_tracks: list[tuple[TrackOutput, ...]] = []
    truth: list[tuple[GroundTruthObject, ...]] = []
    annotated: list[tuple[int, int]] = []  # (frame, stamp) of every frame written
    locked: int | None = None
    lost = False
    cpu = {"render": 0.0, "detect": 0.0, "track": 0.0}
    with ExitStack() as stack:
        # OpenCV on one thread: the method's CPU time (time.process_time around its calls)
        # is then one core's work, as the seed's figure is, not that of a thread pool
        stack.callback(cv2.setNumThreads, cv2.getNumThreads())
        cv2.setNumThreads(1)
        writer = None
        sensors = [make_rig_sensor(s, rig.WORLD_FRAME) for s in scenario.rig]
        if out_path is not None:
            options = stream_options(scenario)
            writer = stack.enter_context(RecordingWriter(out_path, container, options, owner=OWNER))
            loop = json.dumps({"target": target, "config": config_to_dict(cfg)}, sort_keys=True)
            digest = hashlib.sha256(loop.encode("utf-8")).hexdigest()
            writer.write_provenance(scenario.stamp_ns(0), provenance(sim, n, container, digest))
            write_static(writer, sim, sensors)
        for i in range(n):
            c0 = time.process_time()
            f = sim.frame(i)
            images = pair.render_pair(sim.scene_view(i, k_pair))
            c1 = time.process_time()
            if writer is not None:
                write_frame(writer, sim, f)
                for k, sensor in enumerate(sensors):  # each sensor on its own noise stream
                    if k == k_pair:
                        pair.write_pair(writer, f.stamp_ns, images)
                    else:
                        sensor.write(writer, sim.scene_view(i, k))
            ox, oy, oyaw = (float(v) for v in sim.odom_poses[i])
            frame = _frame(i, f.stamp_ns, images, pair, rig.base_pose(ox, oy, oyaw))
            c2 = time.process_time()
            detections = detector.detect(frame)
            c3 = time.process_time()
            tracks = tuple(tracker.update(f.stamp_ns, detections, frame))
            c4 = time.process_time()
            cpu["render"] += c1 - c0
            cpu["detect"] += c3 - c2
            cpu["track"] += c4 - c3
            all_tracks.append(tracks)
            truth.append(tuple(f.ground_truth))
            annotated.append((i, f.stamp_ns))
            where = next(
                (
                    (o.world_xyz[0], o.world_xyz[1])
                    for o in f.ground_truth
                    if o.object_id == target and o.world_xyz is not None
                ),
                None,
            )
            step, locked, lost = _step(
                i, f.stamp_ns, f.t, pose, (ox, oy, oyaw), where, tracks, locked, lost, c
            )
            steps.append(step)
            if i + 1 < n:
                pose = drive(pose, step.v_left, step.v_right, c.d, dt)
                sim.set_robot_pose(i + 1, pose)
            if progress is not None:
                progress(i + 1, n)
    if out_path is not None:
        write_csv(
            ground_truth_path(out_path), [o for frame in truth for o in frame], annotated, OWNER
        )
    summary = _summary(scenario, sim.seed, target, steps, c)
    return FollowResult(tuple(steps), summary, tuple(all_tracks), tuple(truth), cpu)


def _step(
    index: int,
    stamp_ns: int,
    t: float,
    pose: tuple[float, float, float],
    odom: tuple[float, float, float],
    where: tuple[float, float] | None,
    tracks: Sequence[TrackOutput],
    locked: int | None,
    lost: bool,
    c: FollowControl,
) -> tuple[FollowStep, int | None, bool]:
    """Judge one frame and choose the wheel speeds; returns the step, the lock and lost."""
    if locked is None and where is not None:
        near = [(exact.hypot(o.x - where[0], o.y - where[1]), o.track_id) for o in tracks]
        near = [(dist, tid) for dist, tid in near if dist <= c.lock_m]
        locked = min(near)[1] if near else None
    followed = next((o for o in tracks if o.track_id == locked), None)
    error = None
    status: Status = "searching"
    if locked is not None:
        lost = lost or followed is None
        if followed is not None and where is not None:
            error = exact.hypot(followed.x - where[0], followed.y - where[1])
        status = (
            "lost"
            if lost
            else ("following" if error is not None and error <= c.lock_m else "wrong")
        )
    v_L = v_R = 0.0
    if followed is not None and not lost:
        # what the robot believes, to the millimetre: the tracker's last bits (BLAS, libm)
        # differ between CPUs, the robot's path (part of the recording) must not
        seen = (round(followed.x * 1000.0) / 1000.0, round(followed.y * 1000.0) / 1000.0)
        X, Y = in_robot_frame(odom, seen)
        v_L, v_R = wheel_command(X, Y, c)
    dist = bearing = None
    if where is not None:
        X, Y = in_robot_frame(pose, where)
        dist, bearing = exact.hypot(X, Y), math.degrees(exact.atan2(Y, X))
    step = FollowStep(
        frame=index,
        stamp_ns=stamp_ns,
        t=t,
        robot_x=pose[0],
        robot_y=pose[1],
        robot_yaw_deg=math.degrees(pose[2]),
        target_x=where[0] if where else None,
        target_y=where[1] if where else None,
        distance_m=dist,
        bearing_deg=bearing,
        track_id=locked,
        track_x=followed.x if followed else None,
        track_y=followed.y if followed else None,
        track_error_m=error,
        status=status,
        v_left=v_L,
        v_right=v_R,
    )
    return step, locked, lost


def steps_csv(steps: Sequence[FollowStep]) -> str:
    """The per-frame following record as CSV (empty cells for missing values)."""
    buf = io.StringIO()
    names = list(FollowStep.__dataclass_fields__)
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(names)
    for s in steps:
        row = asdict(s)
        w.writerow(
            [
                "" if row[k] is None else (f"{row[k]:.6g}" if isinstance(row[k], float) else row[k])
                for k in names
            ]
        )
    return buf.getvalue()


def follow_paths(out_path: Path) -> tuple[Path, Path]:
    """``<stem>.follow.csv`` and ``<stem>.follow.json`` beside a recording."""
    p = Path(out_path)
    return p.with_name(f"{p.stem}.follow.csv"), p.with_name(f"{p.stem}.follow.json")


def write_follow(result: FollowResult, out_path: Path) -> tuple[Path, Path]:
    """Write the per-frame CSV and the summary JSON beside ``out_path`` (atomically; each
    replaces only a file ``synth`` wrote)."""
    csv_path, json_path = follow_paths(out_path)
    write_text(csv_path, steps_csv(result.steps), OWNER)
    write_json(json_path, {"schema_version": 1, **asdict(result.summary)}, OWNER)
    return csv_path, json_path
