"""Seed 003's experiments (4.3) for ``rgbd-eval reproduce dmtbs``: DMT-BS on simulated static
ToF rigs, in memory (render, detect, track, score).

No recording is written: the sensitivity analyses vary one thing at a time (the camera's angle,
the cameras used, added noise and background model, a camera's extrinsic error) on the same
scene, which is cheapest in memory. Runs are scored from the end of the background
initialisation on (the seed's sequences start with a learnt background).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rgbd_eval.config import EvaluationConfig, Gating
from rgbd_eval.detect.dmtbs import BackgroundMethod, DepthView, DmtbsDetector, DmtbsDetectorConfig
from rgbd_eval.metrics import SequenceScores, evaluate_sequence, summarize
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.scenario import Obstacle, Scenario
from rgbd_eval.sim.tof import TofFrame, TofRig
from rgbd_eval.track.dmtbs import DmtbsTracker, DmtbsTrackerConfig
from rgbd_eval.types import GroundTruthObject, Pose, TrackOutput

#: Metric gating distance (m). The seed matches within a threshold distance whose value did
#: not survive in its text; 0.5 m (configs/methods/dmtbs.yaml states why).
MATCH_THRESHOLD_M = 0.5


@dataclass(frozen=True)
class RigRun:
    """What one run produced: per-frame tracks, the scores, and the detector's stage times."""

    tracks: list[list[TrackOutput]]
    scores: SequenceScores
    stage_seconds: dict[str, float]
    splits: int

    def row(self) -> dict[str, Any]:
        """The run's headline numbers (MOTA, MOTP in m, FP, FN, ID switches)."""
        s = summarize(self.scores.counts)
        c = self.scores.counts
        return {
            "mota": s["mota"],
            "motp_m": s["motp"],
            "fp": c.fp,
            "fn": c.fn,
            "id_switches": c.id_switches,
            "num_gt": c.num_gt,
            "splits": self.splits,
        }


def yaw_error(pose: Pose, degrees: float) -> Pose:
    """``pose`` rotated about the world's vertical through the camera (Fig. 11's error)."""
    a = math.radians(degrees)
    Rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0, 0, 1]])
    T = pose.matrix()
    T[:3, :3] = Rz @ T[:3, :3]
    return Pose.from_matrix(T)


def with_noise(frames: Iterable[TofFrame], sigma_m: float, seed: int) -> Iterator[TofFrame]:
    """The frames with independent Gaussian depth noise of std ``sigma_m`` added (Fig. 10).

    The rig's ``extra_noise_m`` does the same at render time; adding it here reuses one
    rendering for every level. Depths pushed to or below zero become invalid.
    """
    for frame in frames:
        if sigma_m <= 0.0:
            yield frame
            continue
        rng = np.random.default_rng([seed, frame.index])
        images = []
        for im in frame.images:
            noise = rng.standard_normal(im.depth.shape, dtype=np.float32) * np.float32(sigma_m)
            depth = im.depth + noise
            depth[~(depth > 0)] = np.nan
            images.append(replace(im, depth=depth))
        yield replace(frame, images=images)


def run_frames(
    frames: Iterable[TofFrame],
    cameras: list[str],
    detector: DmtbsDetectorConfig,
    tracker: DmtbsTrackerConfig,
    threshold_m: float = MATCH_THRESHOLD_M,
    pose_errors_deg: dict[str, float] | None = None,
) -> RigRun:
    """Run DMT-BS on the named cameras of rendered frames and score with metric gating.

    Every present person is ground truth (:class:`~rgbd_eval.sim.tof.TofRig`); the first
    ``detector.init_frames`` frames, where the background is being learnt, are not scored.
    ``pose_errors_deg`` gives a camera the extrinsic yaw error of Fig. 11: the detector
    believes the camera is rotated by that angle about the vertical.
    """
    errors = pose_errors_deg or {}
    det = DmtbsDetector(detector)
    trk = DmtbsTracker(tracker)
    tracks: list[list[TrackOutput]] = []
    gt: list[list[GroundTruthObject]] = []
    for k, frame in enumerate(frames):
        images = {im.name: im for im in frame.images}
        missing = [c for c in cameras if c not in images]
        if missing:
            raise ValueError(f"frame {frame.index} has no camera {missing} (has {sorted(images)})")
        views = []
        for name in cameras:
            im = images[name]
            pose = yaw_error(im.pose, errors[name]) if name in errors else im.pose
            views.append(DepthView(name, im.depth, im.camera, pose))
        result = det.detect_views(frame.stamp_ns, views)
        out = trk.update(frame.stamp_ns, result.detections)
        if k >= detector.init_frames:
            tracks.append(out)
            gt.append(list(frame.ground_truth))
    evaluation = EvaluationConfig(gating=Gating.METRIC, threshold=threshold_m)
    scores = evaluate_sequence(gt, tracks, evaluation)
    return RigRun(tracks, scores, dict(det.stage_seconds), trk.splits)


# ----------------------------------------------------------------------------- experiments


def camera_count(
    frames: list[TofFrame], cameras: list[str], det: DmtbsDetectorConfig, trk: DmtbsTrackerConfig
) -> list[dict[str, Any]]:
    """Fig. 9: the same sequence with the first 1, 2, ... cameras."""
    return [
        {"cameras": n, **run_frames(frames, cameras[:n], det, trk).row()}
        for n in range(1, len(cameras) + 1)
    ]


def depth_noise(
    frames: list[TofFrame],
    cameras: list[str],
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    levels_m: list[float],
    seed: int,
    mog2: bool = True,
) -> list[dict[str, Any]]:
    """Fig. 10: added Gaussian noise, with the running average and (``mog2``) with MOG2."""
    rows = []
    methods = [BackgroundMethod.RUNNING_AVERAGE] + ([BackgroundMethod.MOG2] if mog2 else [])
    for method in methods:
        config = det.model_copy(update={"background": method})
        for sigma in levels_m:
            run = run_frames(with_noise(frames, sigma, seed), cameras, config, trk)
            rows.append({"background": method.value, "noise_m": sigma, **run.row()})
    return rows


def calibration_error(
    frames: list[TofFrame],
    cameras: list[str],
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    errors_deg: list[float],
) -> list[dict[str, Any]]:
    """Fig. 11: a yaw error of the second camera's extrinsic calibration."""
    return [
        {
            "yaw_error_deg": e,
            **run_frames(frames, cameras, det, trk, pose_errors_deg={cameras[1]: e}).row(),
        }
        for e in errors_deg
    ]


def arc_camera(
    cfg: StaticDepthConfig, angle_deg: float, target: tuple[float, float, float], distance_m: float
) -> StaticDepthConfig:
    """``cfg`` moved onto Fig. 8's arc: ``distance_m`` from ``target``, tilted ``angle_deg`` down.

    The camera looks along +x at 0 degrees (level with the target) and straight down at 90;
    it always looks at ``target``, so the scene stays in view as the angle changes.
    """
    if not 0.0 <= angle_deg <= 90.0:
        raise ValueError(f"angle_deg={angle_deg} must be in [0, 90]")
    if not distance_m > 0:
        raise ValueError(f"distance_m={distance_m} must be > 0")
    a = math.radians(angle_deg)
    tx, ty, tz = target
    return cfg.model_copy(
        update={
            "x": tx - distance_m * math.cos(a),
            "y": ty,
            "z": tz + distance_m * math.sin(a),
            "yaw_deg": 0.0,
            "pitch_deg": angle_deg,
        }
    )


def camera_angle(
    scenario: Scenario,
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    angles_deg: list[float],
    target: tuple[float, float, float],
    distance_m: float,
    seeds: list[int],
    progress: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """Fig. 8: the same sequence seen by the scenario's one camera at each angle of the arc.

    Each angle is run once per seed (the sensor's noise and dropout; the people's paths are
    the scenario's): the row's counts and MOTA are pooled over the runs (the seed reports
    "all frames of the set"), ``mota_min`` and ``mota_max`` give the spread between runs.
    """
    cams = [c for c in scenario.rig if isinstance(c, StaticDepthConfig)]
    if len(cams) != 1:
        raise ValueError(
            f"scenario {scenario.name!r} must have one static_depth camera, has {len(cams)}"
        )
    if not seeds:
        raise ValueError("camera_angle needs at least one seed")
    rows = []
    for angle in angles_deg:
        if progress is not None:
            progress(f"Fig. 8: camera at {angle:g} deg, {len(seeds)} runs")
        cam = arc_camera(cams[0], angle, target, distance_m)
        runs = [
            run_frames(
                TofRig(scenario.model_copy(update={"rig": [cam], "seed": seed})).frames(),
                [cam.name],
                det,
                trk,
            )
            for seed in seeds
        ]
        pooled = sum((r.scores.counts for r in runs[1:]), runs[0].scores.counts)
        summary = summarize(pooled)
        motas = [_run_mota(r) for r in runs]
        rows.append(
            {
                "angle_deg": angle,
                "camera_height_m": round(cam.z, 3),
                "runs": len(runs),
                "mota": summary["mota"],
                "mota_min": min(motas),
                "mota_max": max(motas),
                "motp_m": summary["motp"],
                "fp": pooled.fp,
                "fn": pooled.fn,
                "id_switches": pooled.id_switches,
                "num_gt": pooled.num_gt,
                "splits": sum(r.splits for r in runs),
            }
        )
    return rows


def _run_mota(run: RigRun) -> float:
    """A run's MOTA (NaN when nothing was scored)."""
    value = summarize(run.scores.counts)["mota"]
    return float(value) if value is not None else float("nan")


def left_object_frames(scenario: Scenario, left_at_s: float) -> Iterator[TofFrame]:
    """The scenario's frames with its obstacles present only from ``left_at_s`` on.

    The simulator's obstacles are static, so the object appears between two frames, as if
    set down: the frames before are rendered from the scenario without its obstacles. The
    sensor noise depends only on the seed, the frame and the camera, so the two renderings
    join without a seam.
    """
    if not scenario.obstacles:
        raise ValueError(f"scenario {scenario.name!r} has no obstacle to leave behind")
    before = TofRig(scenario.model_copy(update={"obstacles": []}))
    after = TofRig(scenario)
    k = round(left_at_s * scenario.sensor.rate_hz)
    for i in range(scenario.n_frames):
        yield (before if i < k else after).frame(i)


def left_object(
    scenario: Scenario,
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    left_at_s: float,
    settle_s: float = 1.0,
    threshold_m: float = MATCH_THRESHOLD_M,
) -> dict[str, Any]:
    """The known limitation (seed 003, section 6): a large object left behind is tracked.

    Runs DMT-BS on every camera of ``scenario``, whose first obstacle is the object, and
    counts the frames from ``settle_s`` after it is left on in which a reported track (as
    scored: confirmed, not lost) lies within ``threshold_m`` of it (none of them matches a
    person: the object is not ground truth).
    """
    obj: Obstacle = scenario.obstacles[0]
    names = [c.name for c in scenario.rig if isinstance(c, StaticDepthConfig)]
    run = run_frames(left_object_frames(scenario, left_at_s), names, det, trk, threshold_m)
    rate = scenario.sensor.rate_hz
    first = round((left_at_s + settle_s) * rate) - det.init_frames
    after = run.tracks[max(first, 0) :]
    on = [
        any(
            is_scored_track(t) and math.hypot(t.x - obj.x, t.y - obj.y) <= threshold_m
            for t in frame
        )
        for frame in after
    ]
    return {
        **run.row(),
        "object_frames": len(on),
        "object_tracked_frames": int(sum(on)),
        "object_tracked_share": (sum(on) / len(on)) if on else None,
    }
