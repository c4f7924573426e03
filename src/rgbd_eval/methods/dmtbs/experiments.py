"""Seed 003's experiments (4.3 and 6) for ``rgbd-eval reproduce dmtbs``: DMT-BS on simulated
static ToF rigs, in memory (render, detect, track, score), over several scenario seeds.

No recording is written: the sensitivity analyses vary one thing at a time (the camera's angle,
the cameras used, added noise and background model, a camera's extrinsic error) on the same
scene, which is cheapest in memory: each scene is rendered once per seed and every variant
runs on the same frames as they stream by (:func:`run_setups`).

Each claim of ``methods/dmtbs/paper.yaml`` is judged on every scenario seed of its ``seeds``
and the verdict is taken over them (:func:`rgbd_eval.verdicts.over_runs`): held when held on
every seed, failed when failed on every seed, else inconclusive; the measured values' spread
is shown beside it. Each seed draws other bodies and clothes for the scenes' people, other
paths and other sensor noise, and looks at its own part of scenes 1 and 2 (:func:`window_start`): the seed
ran seven sequences of 100 s per setting, ours are a few seconds per seed. Each of those
short runs starts like a sequence: its background is learnt without the people
(:func:`window`), and the first :data:`WARMUP_S` after that is not scored (see there why);
a sequence of 100 s pays for its start once, five runs of 5 s five times.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from rgbd_eval.config import EvaluationConfig, Gating, config_dir, load_config, load_paper
from rgbd_eval.machine import machine_info
from rgbd_eval.methods.dmtbs.detector import (
    BackgroundMethod,
    DepthView,
    DmtbsDetector,
    DmtbsDetectorConfig,
)
from rgbd_eval.methods.dmtbs.tracker import DmtbsTracker, DmtbsTrackerConfig
from rgbd_eval.metrics import SequenceScores, evaluate_sequence, summarize
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.plugins import ReproduceOptions, ReproduceResult
from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.scenario import Obstacle, Scenario, load_scenario
from rgbd_eval.sim.tof import TofFrame, TofRig
from rgbd_eval.types import GroundTruthObject, Pose, TrackOutput
from rgbd_eval.verdicts import (
    ClaimOverSeeds,
    Spread,
    Verdict,
    claims_over_seeds,
    spreads_json,
    tally,
)

#: Metric gating distance (m). The seed matches within a threshold distance whose value did
#: not survive in its text; 0.5 m (methods/dmtbs/method.yaml states why).
MATCH_THRESHOLD_M = 0.5

#: Scene 1 (seed 003 4.3.1): one camera moved along an arc (Fig. 8).
SCENE1 = "dmtbs/scene1.yaml"
#: Scene 2 (seed 003 4.3.2), rendered in memory for the sensitivity analyses.
SCENE2 = "dmtbs/scene2.yaml"
#: The left-behind object (seed 003 section 6); the box appears at LEFT_OBJECT_AT_S.
LEFT_OBJECT = "dmtbs/left_object.yaml"
LEFT_OBJECT_AT_S = 5.0
#: The largest depth gap between the left object and the background behind it, over the
#: pixels above the 1 m cut whose background is finite (m): 3.59 m measured in
#: left_object.yaml's camera (the box against the floor behind it; pixels that see nothing
#: behind it take the box as background after ``init_frames``). With the running average's
#: time constant tau and margin, the last of the box has faded tau ln(gap / margin) after it
#: is left (10 ln(36) = 35.8 s): the sequence runs past that (tests check both).
LEFT_OBJECT_GAP_M = 3.6
#: Seconds of scene 2 per seed: the seed ran seven sequences of 100 s (4.3.2); five seeds of
#: 7 s, each from its own part of scene 2's 100 s (:func:`window_start`; 150 frames scored
#: each after the background's second and the warm-up's, 750 in all; 4 x 512x424 depth,
#: streamed), keep `reproduce` within its budget (configs/scenarios/dmtbs/README.md).
SCENE2_S = 7.0
#: Seconds after the background's initialisation that are not scored in scenes 1 and 2: the
#: tracks of the people in view when a run starts are confirmed in them, and people whose
#: blobs are merged when first seen are one track until they part (seed 3.3). A sequence of
#: 100 s pays that once, a run of 5 s a fifth of its frames: on the first 5 s of scene 2
#: (seed 2, two cameras) all 31 misses fell in the first 25 scored frames (all four people in
#: the first two, then one person, merged with another when the run began, for 23 frames):
#: MOTA 93.5%, where the single-seed reproduce's 15 s of scene 2 read 98.1% (32 misses among
#: 1680). Not scoring that second lets the short runs stand for the long ones.
WARMUP_S = 1.0
#: Fig. 8: "10 different camera angles" from horizontal to looking down (4.3.1; the range's
#: end did not survive in the text): 0 to 90 degrees in steps of 10.
ANGLES_DEG = [float(a) for a in range(0, 91, 10)]
#: Fig. 8's arc: around the point 1 m above the floor's centre (the height threshold, 3.2),
#: at 5 m, so that a level camera sees the whole 5 m x 5 m floor and a camera looking
#: straight down (6 m high) sees it from 1 m above the floor.
ARC_TARGET = (0.0, 0.0, 1.0)
ARC_DISTANCE_M = 5.0
#: Seconds of scene 1 per angle and seed (one 512x424 camera): the seed averaged seven runs
#: of 100 s per setting; 6 s on each of the five seeds, each from its own part of scene 1's
#: 20 s (120 frames scored after the background's second and the warm-up's, 600 per angle in
#: all). The scored 4 s hold at least one pass of the people on the camera's line of sight
#: (every 3.6 s): with 4 s per seed (2 s scored) the passes fell outside the scored frames
#: and every angle read 100%.
SCENE1_S = 6.0
#: Fig. 10: added noise from 0 to beyond 50 mm (the seed went to 125 mm and beyond).
NOISE_LEVELS_M = [0.0, 0.025, 0.05, 0.075, 0.1, 0.125, 0.15]
#: Fig. 11: yaw error of the second camera, 0 to 3 degrees.
YAW_ERRORS_DEG = [0.0, 0.5, 1.0, 1.5, 2.0, 3.0]


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


@dataclass(frozen=True)
class Setup:
    """One variant run on a stream of frames: which cameras, which method configs, how much
    added depth noise (Fig. 10) and which extrinsic yaw errors (Fig. 11)."""

    cameras: tuple[str, ...]
    detector: DmtbsDetectorConfig
    tracker: DmtbsTrackerConfig
    noise_m: float = 0.0
    noise_seed: int = 0
    pose_errors_deg: tuple[tuple[str, float], ...] = ()


@dataclass
class Clock:
    """CPU seconds spent rendering and running the method (detector, tracker, scoring)."""

    render_s: float = 0.0
    method_s: float = 0.0

    def add(self, other: Clock) -> None:
        self.render_s += other.render_s
        self.method_s += other.method_s


def yaw_error(pose: Pose, degrees: float) -> Pose:
    """``pose`` rotated about the world's vertical through the camera (Fig. 11's error)."""
    a = math.radians(degrees)
    Rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0, 0, 1]])
    T = pose.matrix()
    T[:3, :3] = Rz @ T[:3, :3]
    return Pose.from_matrix(T)


def noisy(
    frame: TofFrame, sigma_m: float, seed: int, names: Iterable[str] | None = None
) -> TofFrame:
    """``frame`` with independent Gaussian depth noise of std ``sigma_m`` added to the images
    named in ``names`` (all: None), in the frame's order; the others are left out (Fig. 10).

    The rig's ``extra_noise_m`` does the same at render time; adding it here reuses one
    rendering for every level. Depths pushed to or below zero become invalid. The noise of an
    image depends only on ``seed``, the frame's index and the images before it.
    """
    if sigma_m <= 0.0:
        return frame
    wanted = None if names is None else set(names)
    rng = np.random.default_rng([seed, frame.index])
    images = []
    for im in frame.images:
        if wanted is not None and im.name not in wanted:
            continue
        noise = rng.standard_normal(im.depth.shape, dtype=np.float32) * np.float32(sigma_m)
        depth = im.depth + noise
        depth[~(depth > 0)] = np.nan
        images.append(replace(im, depth=depth))
    return replace(frame, images=images)


def with_noise(frames: Iterable[TofFrame], sigma_m: float, seed: int) -> Iterator[TofFrame]:
    """The frames with independent Gaussian depth noise of std ``sigma_m`` added (Fig. 10)."""
    for frame in frames:
        yield noisy(frame, sigma_m, seed)


class _Runner:
    """One setup's detector and tracker, fed frame by frame."""

    def __init__(self, setup: Setup, warmup_frames: int) -> None:
        self.setup = setup
        self.score_from = setup.detector.init_frames + warmup_frames
        self.errors = dict(setup.pose_errors_deg)
        self.det = DmtbsDetector(setup.detector)
        self.trk = DmtbsTracker(setup.tracker)
        self.tracks: list[list[TrackOutput]] = []
        self.gt: list[list[GroundTruthObject]] = []
        self.k = 0

    def feed(self, frame: TofFrame) -> None:
        images = {im.name: im for im in frame.images}
        missing = [c for c in self.setup.cameras if c not in images]
        if missing:
            raise ValueError(f"frame {frame.index} has no camera {missing} (has {sorted(images)})")
        views = []
        for name in self.setup.cameras:
            im = images[name]
            pose = yaw_error(im.pose, self.errors[name]) if name in self.errors else im.pose
            views.append(DepthView(name, im.depth, im.camera, pose))
        result = self.det.detect_views(frame.stamp_ns, views)
        out = self.trk.update(frame.stamp_ns, result.detections)
        if self.k >= self.score_from:
            self.tracks.append(out)
            self.gt.append(list(frame.ground_truth))
        self.k += 1

    def result(self, threshold_m: float) -> RigRun:
        evaluation = EvaluationConfig(gating=Gating.METRIC, threshold=threshold_m)
        scores = evaluate_sequence(self.gt, self.tracks, evaluation)
        return RigRun(self.tracks, scores, dict(self.det.stage_seconds), self.trk.splits)


def run_setups(
    frames: Iterable[TofFrame],
    setups: Sequence[Setup],
    threshold_m: float = MATCH_THRESHOLD_M,
    clock: Clock | None = None,
    warmup_frames: int = 0,
) -> list[RigRun]:
    """Run DMT-BS once per setup on the same frames as they stream by; score each with metric
    gating (every present person is ground truth, :class:`~rgbd_eval.sim.tof.TofRig`).

    The first ``detector.init_frames`` frames of a setup, where its background is being
    learnt, are not scored, nor the ``warmup_frames`` after them (:data:`WARMUP_S`). A
    setup's ``pose_errors_deg`` gives a camera the extrinsic yaw error of Fig. 11: the
    detector believes the camera is rotated by that angle about the vertical. Setups with the
    same noise share the noisy images. ``clock`` (if given) gets the CPU seconds spent
    producing the frames (rendering) and running the setups.
    """
    if warmup_frames < 0:
        raise ValueError(f"warmup_frames={warmup_frames} must be >= 0")
    runners = [_Runner(s, warmup_frames) for s in setups]
    clock = clock if clock is not None else Clock()
    needed: dict[tuple[float, int], set[str]] = {}
    for s in setups:
        needed.setdefault((s.noise_m, s.noise_seed), set()).update(s.cameras)
    it = iter(frames)
    while True:
        t0 = time.process_time()
        frame = next(it, None)
        t1 = time.process_time()
        clock.render_s += t1 - t0
        if frame is None:
            break
        versions = {key: noisy(frame, key[0], key[1], names) for key, names in needed.items()}
        for r in runners:
            r.feed(versions[(r.setup.noise_m, r.setup.noise_seed)])
        clock.method_s += time.process_time() - t1
    t0 = time.process_time()
    runs = [r.result(threshold_m) for r in runners]
    clock.method_s += time.process_time() - t0
    return runs


def run_frames(
    frames: Iterable[TofFrame],
    cameras: list[str],
    detector: DmtbsDetectorConfig,
    tracker: DmtbsTrackerConfig,
    threshold_m: float = MATCH_THRESHOLD_M,
    pose_errors_deg: dict[str, float] | None = None,
) -> RigRun:
    """Run DMT-BS on the named cameras of rendered frames and score with metric gating
    (:func:`run_setups` with one setup)."""
    errors = tuple((pose_errors_deg or {}).items())
    setup = Setup(tuple(cameras), detector, tracker, pose_errors_deg=errors)
    return run_setups(frames, [setup], threshold_m)[0]


# ----------------------------------------------------------------------------- experiments


def window_start(index: int, seeds: int, duration_s: float, seconds: float) -> float:
    """Where the ``seconds`` of seed number ``index`` of ``seeds`` start in a scene of
    ``duration_s``: spread evenly over it, the first at its start, the last at its end, so
    that the seeds see other moments of the people's paths, not only other bodies and noise."""
    if not 0 <= index < seeds:
        raise ValueError(f"index={index} must be in [0, {seeds})")
    if not 0 < seconds <= duration_s:
        raise ValueError(f"seconds={seconds} must be in (0, {duration_s}]")
    return 0.0 if seeds == 1 else index * (duration_s - seconds) / (seeds - 1)


def window(
    scenario: Scenario, start_s: float, seconds: float, empty_frames: int = 0
) -> Iterator[TofFrame]:
    """``seconds`` of the scenario's frames from ``start_s`` on, rendered in memory, the first
    ``empty_frames`` of them without the people.

    A run of a few seconds starts where a sequence would, and five of them start five times
    where a 100 s sequence starts once. The frames that learn the background
    (``init_frames``) show the scene without its people, who step in at their places on the
    next frame. With the people in those frames, MOG2 missed one of them for 20 frames after
    the warm-up (5 s of scene 2 from 20 s, seed 2, two cameras; none without them), and the
    level camera of Fig. 8 missed far more (scene 1 from 3.5 s, seed 2, 0 deg: 115 misses
    after the warm-up against 36; probably the background learnt from people in front of
    nothing at that height, docs/dmtbs-reproduce.md). Stepping in all at once is a start of
    its own: at 0 deg it can merge people for longer than the warm-up (scene 1's first 8 s,
    seed 1: 33 misses at 0 deg against 1 with the people in the initialisation; 0 at 90 deg
    either way). A frame depends only on the seed, its index and the camera, so the two
    renderings join without a seam.
    """
    rate = scenario.sensor.rate_hz
    first = round(start_s * rate)
    count = round(seconds * rate)
    if first < 0 or count < 1 or first + count > scenario.n_frames:
        raise ValueError(
            f"{seconds:g} s from {start_s:g} s is not within scenario {scenario.name!r} "
            f"({scenario.duration_s:g} s)"
        )
    full = TofRig(scenario)
    empty = TofRig(scenario.model_copy(update={"people": []})) if empty_frames > 0 else full
    for i in range(first, first + count):
        yield (empty if i < first + empty_frames else full).frame(i)


def scene2_setups(
    cameras: list[str], det: DmtbsDetectorConfig, trk: DmtbsTrackerConfig, seed: int
) -> dict[str, list[tuple[dict[str, Any], Setup]]]:
    """Figs. 9-11 on scene 2, as (row key, setup) per figure: the first 1, 2, ... cameras
    (Fig. 9); two cameras with added noise, running average and MOG2 (Fig. 10); two cameras
    with a yaw error of the second (Fig. 11). Equal setups run once."""
    if len(cameras) < 2:
        raise ValueError(f"scene 2 needs at least two cameras, has {cameras}")
    two = tuple(cameras[:2])
    out: dict[str, list[tuple[dict[str, Any], Setup]]] = {
        "cameras": [
            ({"cameras": n}, Setup(tuple(cameras[:n]), det, trk))
            for n in range(1, len(cameras) + 1)
        ],
        "noise": [],
        "yaw": [],
    }
    for method in (BackgroundMethod.RUNNING_AVERAGE, BackgroundMethod.MOG2):
        config = det.model_copy(update={"background": method})
        for sigma in NOISE_LEVELS_M:
            setup = Setup(two, config, trk, sigma, seed if sigma > 0 else 0)
            out["noise"].append(({"background": method.value, "noise_m": sigma}, setup))
    for e in YAW_ERRORS_DEG:
        errors = ((two[1], e),) if e != 0.0 else ()
        out["yaw"].append(({"yaw_error_deg": e}, Setup(two, det, trk, pose_errors_deg=errors)))
    return out


def scene2_rows(
    frames: Iterable[TofFrame],
    cameras: list[str],
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    seed: int,
    clock: Clock | None = None,
    warmup_frames: int = 0,
) -> dict[str, list[dict[str, Any]]]:
    """Figs. 9, 10 and 11 on one rendering of scene 2 (:func:`scene2_setups`)."""
    plan = scene2_setups(cameras, det, trk, seed)
    unique: list[Setup] = []
    for rows in plan.values():
        for _, s in rows:
            if s not in unique:
                unique.append(s)
    runs = run_setups(frames, unique, clock=clock, warmup_frames=warmup_frames)
    return {
        fig: [{**key, **runs[unique.index(s)].row()} for key, s in rows]
        for fig, rows in plan.items()
    }


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
    clock: Clock | None = None,
    start_s: float = 0.0,
    seconds: float | None = None,
    warmup_s: float = 0.0,
) -> list[dict[str, Any]]:
    """Fig. 8: the same sequence seen by the scenario's one camera at each angle of the arc.

    One rendering carries a camera per angle (each with its own sensor noise); each angle's
    camera is run on its own, on ``seconds`` (None: all) from ``start_s``, the background
    learnt without the people (:func:`window`), the first ``warmup_s`` after the background's
    initialisation not scored.
    """
    cams = [c for c in scenario.rig if isinstance(c, StaticDepthConfig)]
    if len(cams) != 1:
        raise ValueError(
            f"scenario {scenario.name!r} must have one static_depth camera, has {len(cams)}"
        )
    if not angles_deg:
        raise ValueError("camera_angle needs at least one angle")
    arc = [
        arc_camera(cams[0], a, target, distance_m).model_copy(
            update={"name": f"{cams[0].name}_{a:g}deg"}
        )
        for a in angles_deg
    ]
    moved = scenario.model_copy(update={"rig": arc})
    length = scenario.duration_s - start_s if seconds is None else seconds
    setups = [Setup((c.name,), det, trk) for c in arc]
    warmup = round(warmup_s * scenario.sensor.rate_hz)
    frames = window(moved, start_s, length, det.init_frames)
    runs = run_setups(frames, setups, clock=clock, warmup_frames=warmup)
    return [
        {"angle_deg": a, "camera_height_m": round(c.z, 3), **run.row()}
        for a, c, run in zip(angles_deg, arc, runs, strict=True)
    ]


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


def absorb_s(det: DmtbsDetectorConfig, gap_m: float) -> float:
    """Seconds after which the running average has absorbed a static surface ``gap_m`` nearer
    than the background: ``tau ln(gap / margin)`` (``B`` closes on it as ``exp(-t / tau)``;
    foreground while the rest exceeds the margin)."""
    if not gap_m > det.foreground_margin_m:
        return 0.0
    return det.background_time_constant_s * math.log(gap_m / det.foreground_margin_m)


def left_object(
    scenario: Scenario,
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    left_at_s: float,
    settle_s: float = 1.0,
    gap_m: float = LEFT_OBJECT_GAP_M,
    threshold_m: float = MATCH_THRESHOLD_M,
    clock: Clock | None = None,
) -> dict[str, Any]:
    """The known limitation (seed 003, section 6) against the note of section 3: is a large
    object left behind tracked, and for how long?

    Runs DMT-BS on every camera of ``scenario``, whose first obstacle is the object, and
    counts the frames in which a reported track (as scored: confirmed, not lost) lies within
    ``threshold_m`` of it (none of them matches a person: the object is not ground truth) in
    two windows: *before*, from ``settle_s`` after it is left to the last frame in which it
    can still be foreground (:func:`absorb_s` of ``gap_m`` after it is left), and *after*,
    from the first frame after that plus the tracker's ``max_missed_s`` (a lost track's last
    reports) to the end. ValueError when the sequence does not reach the second window.
    """
    obj: Obstacle = scenario.obstacles[0]
    names = [c.name for c in scenario.rig if isinstance(c, StaticDepthConfig)]
    setup = Setup(tuple(names), det, trk)
    frames = left_object_frames(scenario, left_at_s)
    (run,) = run_setups(frames, [setup], threshold_m, clock)
    rate = scenario.sensor.rate_hz
    absorbed = absorb_s(det, gap_m)
    start = round((left_at_s + settle_s) * rate)
    # the last frame it can be foreground in, and the last its track can coast to
    middle = math.floor((left_at_s + absorbed) * rate) + 1
    end_start = middle + round(trk.max_missed_s * rate)
    if end_start >= scenario.n_frames:
        raise ValueError(
            f"scenario {scenario.name!r} ends at {scenario.duration_s:g} s, before the running "
            f"average can have absorbed the object ({left_at_s:g} + {absorbed:.1f} + "
            f"{trk.max_missed_s:g} s)"
        )
    on = {
        det.init_frames + k: any(
            is_scored_track(t) and math.hypot(t.x - obj.x, t.y - obj.y) <= threshold_m
            for t in frame
        )
        for k, frame in enumerate(run.tracks)
    }

    def share(first: int, last: int) -> float | None:
        window = [on[i] for i in range(max(first, det.init_frames), last) if i in on]
        return sum(window) / len(window) if window else None

    tracked = [i for i, v in on.items() if v and i >= round(left_at_s * rate)]
    return {
        **run.row(),
        "duration_s": scenario.duration_s,
        "time_constant_s": det.background_time_constant_s,
        "margin_m": det.foreground_margin_m,
        "absorb_s": absorbed,
        "object_frames": scenario.n_frames - start,
        "object_tracked_frames": sum(on[i] for i in range(start, scenario.n_frames) if i in on),
        "object_tracked_share": share(start, scenario.n_frames),
        "share_before_absorbed": share(start, middle),
        "share_after_absorbed": share(end_start, scenario.n_frames),
        "tracked_for_s": ((max(tracked) + 1) / rate - left_at_s) if tracked else 0.0,
    }


# ----------------------------------------------------------------------------- claims


@dataclass(frozen=True)
class Judgement:
    """One claim judged on one seed's rows: held or not, and what it compared (by name, in
    percent, percentage points or seconds)."""

    key: str
    sentence: str
    held: bool
    measured: dict[str, float]


def _value(row: Mapping[str, Any]) -> float:
    """A row's MOTA (NaN when nothing was scored, which fails every comparison)."""
    value = row["mota"]
    return float(value) if value is not None else float("nan")


def _mota(rows: Sequence[Mapping[str, Any]], **match: Any) -> float:
    for row in rows:
        if all(row[k] == v for k, v in match.items()):
            return _value(row)
    raise KeyError(f"no row with {match}")


def _share(value: Any) -> float:
    return float(value) if value is not None else float("nan")


def _pts(x: float) -> float:
    """A share as percent (or a difference of shares as points)."""
    return 100.0 * x


def _worst(values: Iterable[float], key: Callable[[float], float]) -> float:
    """The value ``key`` ranks highest; NaN if any is NaN (nothing scored fails)."""
    vals = list(values)
    if not vals or any(math.isnan(v) for v in vals):
        return float("nan")
    return max(vals, key=key)


def check_claims(
    cams: Sequence[Mapping[str, Any]],
    noise: Sequence[Mapping[str, Any]],
    yaw: Sequence[Mapping[str, Any]],
    angles: Sequence[Mapping[str, Any]],
    left: Mapping[str, Any],
    paper: Mapping[str, Any] | None = None,
) -> list[Judgement]:
    """The seed's claims (sections 3, 5.2 and 6), each judged on one seed's measured rows
    with the thresholds of ``paper`` (by default ``paper.yaml``: :func:`paper_values`)."""
    claims = (paper if paper is not None else paper_values())["claims"]
    out: list[Judgement] = []

    def add(key: str, held: bool, measured: dict[str, float], **fmt: str) -> None:
        sentence = str(claims[key]["sentence"]).format(**fmt) if fmt else claims[key]["sentence"]
        out.append(Judgement(key, sentence, bool(held), measured))

    by_angle = {float(r["angle_deg"]): _value(r) for r in angles}
    c = claims["every_angle"]
    low = _worst(by_angle.values(), key=lambda v: -v)
    add("every_angle", low >= c["min_mota"], {"lowest MOTA over the angles (%)": _pts(low)})

    shallow_max = float(claims["lower_at_shallow_angles"]["shallow_max_deg"])
    shallow = [v for a, v in by_angle.items() if a <= shallow_max]
    steep = [v for a, v in by_angle.items() if a > shallow_max]
    gap = (sum(steep) / len(steep) - sum(shallow) / len(shallow)) if shallow and steep else math.nan
    add("lower_at_shallow_angles", gap > 0, {"steep minus shallow mean MOTA (points)": _pts(gap)})

    c = claims["cameras"]
    m = {int(r["cameras"]): _value(r) for r in cams}
    gain = m[2] - m[1] if 1 in m and 2 in m else math.nan
    beyond = _worst((m[n] - m[2] for n in m if n > 2), key=abs) if 2 in m else math.nan
    add(
        "cameras",
        gain >= c["min_gain_one_to_two"] and abs(beyond) <= c["max_change_beyond_two"],
        {
            "gain from 1 to 2 cameras (points)": _pts(gain),
            "largest change beyond 2 cameras (points)": _pts(beyond),
        },
    )

    ra = "running_average"
    c = claims["stable_noise"]
    base = _mota(noise, background=ra, noise_m=0.0)
    drop = _worst(
        (
            base - _value(r)
            for r in noise
            if r["background"] == ra and 0 < r["noise_m"] <= c["noise_m"]
        ),
        key=lambda v: v,
    )
    add("stable_noise", drop <= c["max_drop"], {"largest drop up to 50 mm (points)": _pts(drop)})

    c = claims["mog2_beyond"]
    top = max(float(r["noise_m"]) for r in noise)
    lead = _mota(noise, background="mog2", noise_m=top) - _mota(noise, background=ra, noise_m=top)
    add(
        "mog2_beyond",
        lead >= c["min_lead"],
        {f"MOG2 minus running average at {top * 1000:.0f} mm (points)": _pts(lead)},
        top_mm=f"{top * 1000:.0f}",
    )

    c = claims["mog2_up_to_125mm"]
    lowest = _worst(
        (
            _value(r)
            for r in noise
            if r["background"] == "mog2" and r["noise_m"] <= c["max_noise_m"]
        ),
        key=lambda v: -v,
    )
    add(
        "mog2_up_to_125mm",
        lowest >= c["min_mota"],
        {"lowest MOG2 MOTA up to 125 mm (%)": _pts(lowest)},
    )

    zero = _mota(yaw, yaw_error_deg=0.0)
    c = claims["yaw_error"]
    within = _worst(
        (zero - _value(r) for r in yaw if 0 < r["yaw_error_deg"] <= c["yaw_error_deg"]),
        key=lambda v: v,
    )
    add("yaw_error", within <= c["max_drop"], {"largest drop up to 1 deg (points)": _pts(within)})
    c = claims["yaw_beyond"]
    past = _worst(
        (zero - _value(r) for r in yaw if r["yaw_error_deg"] > c["beyond_deg"]),
        key=lambda v: -v,
    )
    add("yaw_beyond", past > c["min_drop"], {"smallest drop beyond 1 deg (points)": _pts(past)})

    before = _share(left.get("share_before_absorbed"))
    after = _share(left.get("share_after_absorbed"))
    c = claims["left_object"]
    add(
        "left_object",
        before >= c["min_share"] and after >= c["min_share"],
        {
            "frames with a track on it before it can fade (%)": _pts(before),
            "frames with a track on it after (%)": _pts(after),
            "tracked for (s after it is left)": float(left.get("tracked_for_s", math.nan)),
        },
    )
    c = claims["stationary_fades"]
    add(
        "stationary_fades",
        after <= c["max_share"],
        {"frames with a track on it after it can fade (%)": _pts(after)},
    )
    return out


def paper_values() -> dict[str, Any]:
    """The claims, their thresholds and the seeds (``methods/dmtbs/paper.yaml``)."""
    return load_paper("dmtbs", mappings=("claims",), present=("seeds",))


# ----------------------------------------------------------------------------- one seed


@dataclass
class SeedRun:
    """Everything one scenario seed produced: each figure's rows, the left object, the CPU."""

    seed: int
    angles: list[dict[str, Any]]
    cameras: list[dict[str, Any]]
    noise: list[dict[str, Any]]
    yaw: list[dict[str, Any]]
    left: dict[str, Any]
    frames: dict[str, int]
    clock: Clock = field(default_factory=Clock)
    #: where this seed's part of scenes 1 and 2 starts (s)
    starts: dict[str, float] = field(default_factory=dict)

    def judge(self, paper: Mapping[str, Any]) -> list[Judgement]:
        return check_claims(self.cameras, self.noise, self.yaw, self.angles, self.left, paper)


def run_seed(
    seed: int,
    det: DmtbsDetectorConfig,
    trk: DmtbsTrackerConfig,
    index: int = 0,
    seeds: int = 1,
    progress: Callable[[str], None] = lambda _m: None,
) -> SeedRun:
    """Figs. 8-11 and the object left behind on one scenario seed (people and noise), seed
    number ``index`` of ``seeds``: scenes 1 and 2 from its own part (:func:`window_start`)."""
    scenes = config_dir() / "scenarios"
    clock = Clock()
    scene1 = load_scenario(scenes / SCENE1, [("seed", seed)])
    start1 = window_start(index, seeds, scene1.duration_s, SCENE1_S)
    progress(
        f"seed {seed}: Fig. 8, scene 1 from {start1:g} s for {SCENE1_S:g} s at "
        f"{len(ANGLES_DEG)} camera angles"
    )
    angles = camera_angle(
        scene1, det, trk, ANGLES_DEG, ARC_TARGET, ARC_DISTANCE_M, clock, start1, SCENE1_S, WARMUP_S
    )
    scene2 = load_scenario(scenes / SCENE2, [("seed", seed)])
    start2 = window_start(index, seeds, scene2.duration_s, SCENE2_S)
    names = [c.name for c in scene2.rig if isinstance(c, StaticDepthConfig)]
    progress(
        f"seed {seed}: Figs. 9-11, scene 2 from {start2:g} s for {SCENE2_S:g} s "
        f"({len(names)} cameras)"
    )
    warmup = round(WARMUP_S * scene2.sensor.rate_hz)
    frames = window(scene2, start2, SCENE2_S, det.init_frames)
    rows = scene2_rows(frames, names, det, trk, seed, clock, warmup)
    left_scene = load_scenario(scenes / LEFT_OBJECT, [("seed", seed)])
    progress(f"seed {seed}: section 6, an object left behind ({left_scene.n_frames} frames)")
    left = left_object(left_scene, det, trk, LEFT_OBJECT_AT_S, clock=clock)
    rate1, rate2 = scene1.sensor.rate_hz, scene2.sensor.rate_hz
    return SeedRun(
        seed,
        angles,
        rows["cameras"],
        rows["noise"],
        rows["yaw"],
        left,
        {
            "scene1": round(SCENE1_S * rate1) * len(ANGLES_DEG),
            "scene2": round(SCENE2_S * rate2) * len(names),
            "left_object": left_scene.n_frames * len(left_scene.rig),
        },
        clock,
        {"scene1": start1, "scene2": start2},
    )


def method_configs() -> tuple[DmtbsDetectorConfig, DmtbsTrackerConfig]:
    """The method's configs (methods/dmtbs/method.yaml) with scene 2's 5 m x 5 m floor."""
    config = load_config(method="dmtbs", overrides=["detector.roi=[-2.5,-2.5,2.5,2.5]"])
    det, trk = config.detector, config.tracker
    if not isinstance(det, DmtbsDetectorConfig) or not isinstance(trk, DmtbsTrackerConfig):
        raise TypeError("the dmtbs method config must select the dmtbs detector and tracker")
    return det, trk


def reproduce(_recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    """``rgbd-eval reproduce dmtbs``: Figs. 8-11 and the left-behind object on every seed of
    the paper file, rendered in memory; each claim judged over the seeds."""
    paper = paper_values()
    det, trk = method_configs()
    seeds = [int(s) for s in paper["seeds"]]
    runs = {}
    for k, seed in enumerate(seeds):
        options.progress(f"scenario seed {seed} ({k + 1} of {len(seeds)})")
        runs[seed] = run_seed(seed, det, trk, k, len(seeds), options.progress)
    return summarise(paper, runs)


# ----------------------------------------------------------------------------- over seeds


def _mean(values: Iterable[float]) -> float:
    return Spread.of(list(values)).mean


def aggregate(
    per_seed: Sequence[Sequence[Mapping[str, Any]]], keys: Sequence[str]
) -> list[dict[str, Any]]:
    """Rows of the same settings over the seeds: MOTA's mean, least and greatest, MOTP's
    mean, and the counts summed (``keys`` name the setting; every seed has the same rows)."""
    if not per_seed:
        return []
    out = []
    for i, first in enumerate(per_seed[0]):
        rows = [rows[i] for rows in per_seed]
        for r in rows:
            if any(r[k] != first[k] for k in keys):
                raise ValueError(f"row {i} differs between seeds: {[r[k] for k in keys]}")
        motas = Spread.of([_value(r) for r in rows])
        motp = [float(r["motp_m"]) if r["motp_m"] is not None else math.nan for r in rows]
        out.append(
            {
                **{k: first[k] for k in keys},
                "seeds": len(rows),
                "mota": motas.mean,
                "mota_min": motas.low,
                "mota_max": motas.high,
                "motp_m": _mean(motp),
                **{
                    c: sum(int(r[c]) for r in rows)
                    for c in ("fp", "fn", "id_switches", "num_gt", "splits")
                },
            }
        )
    return out


#: One claim of the paper over the seeds.
ClaimVerdict = ClaimOverSeeds[Judgement]


def verdicts(per_seed: Mapping[int, Sequence[Judgement]]) -> list[ClaimVerdict]:
    """Each claim over the seeds: held on every seed, failed on every seed, else
    inconclusive (:func:`rgbd_eval.verdicts.claims_over_seeds`), with each measured value's
    spread."""
    return claims_over_seeds(per_seed, lambda j: j.key)


def summarise(paper: Mapping[str, Any], runs: Mapping[int, SeedRun]) -> ReproduceResult:
    """The claims judged over the seeds' runs; Markdown and JSON."""
    if not runs:
        raise ValueError("summarise needs at least one seed's run")
    seeds = list(runs)
    judged = verdicts({s: runs[s].judge(paper) for s in seeds})
    clock = Clock()
    for r in runs.values():
        clock.add(r.clock)
    tables = {
        "angles": aggregate([runs[s].angles for s in seeds], ["angle_deg", "camera_height_m"]),
        "cameras": aggregate([runs[s].cameras for s in seeds], ["cameras"]),
        "noise": aggregate([runs[s].noise for s in seeds], ["background", "noise_m"]),
        "yaw": aggregate([runs[s].yaw for s in seeds], ["yaw_error_deg"]),
    }
    data: dict[str, Any] = {
        "seeds": seeds,
        "seconds_per_seed": {"scene1_per_angle": SCENE1_S, "scene2": SCENE2_S},
        "warmup_s": WARMUP_S,
        "starts_s": {str(s): r.starts for s, r in runs.items()},
        "tables": tables,
        "per_seed": {
            str(s): {
                "angles": r.angles,
                "cameras": r.cameras,
                "noise": r.noise,
                "yaw": r.yaw,
                "left_object": r.left,
                "frames_rendered": r.frames,
                "cpu_s": {"render": r.clock.render_s, "method": r.clock.method_s},
            }
            for s, r in runs.items()
        },
        "cpu_s": {"render": clock.render_s, "method": clock.method_s},
        "machine": machine_info()["cpu"] or "unknown CPU",
        "claims": [
            {
                "key": c.key,
                "text": c.judged.sentence,
                "verdict": c.verdict.value,
                "held": c.verdict is Verdict.HELD,
                "per_seed": {str(s): j.held for s, j in c.per_seed.items()},
                "measured": spreads_json(c.spreads, {s: j.measured for s, j in c.per_seed.items()}),
            }
            for c in judged
        ],
    }
    return ReproduceResult(
        render_markdown(data, runs, judged),
        data,
        tuple((c.judged.sentence, c.verdict) for c in judged),
    )


# ----------------------------------------------------------------------------- Markdown


def _pct(v: Any) -> str:
    return (
        "-" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{100 * float(v):.1f}%"
    )


def _table(rows: Sequence[Mapping[str, Any]], first: list[str]) -> list[str]:
    cols = [*first, "MOTA mean [min, max]", "MOTP m", "FP", "FN", "ID sw.", "GT", "splits"]
    out = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        cells = [f"{r[c]:g}" if isinstance(r[c], float) else str(r[c]) for c in first]
        cells += [
            f"{_pct(r['mota'])} [{_pct(r['mota_min'])}, {_pct(r['mota_max'])}]",
            "-" if math.isnan(r["motp_m"]) else f"{r['motp_m']:.3f}",
            *(str(r[c]) for c in ("fp", "fn", "id_switches", "num_gt", "splits")),
        ]
        out.append("| " + " | ".join(cells) + " |")
    return out


def render_markdown(
    data: Mapping[str, Any], runs: Mapping[int, SeedRun], judged: Sequence[ClaimVerdict]
) -> str:
    seeds = list(runs)
    n = len(seeds)
    tables = data["tables"]
    first = runs[seeds[0]]
    cpu = data["cpu_s"]
    left_absorb = first.left["absorb_s"]
    lines = [
        f"# Reproduction of dmtbs (seed 003, 4.3 and 6) over {n} scenario seeds, in memory",
        "",
        f"Scenario seeds {', '.join(map(str, seeds))}: each draws other bodies and clothes for "
        "the scenes' people, other paths and other sensor noise, and looks at its own part of scenes 1 and "
        "2, spread evenly over each ("
        + ", ".join(
            f"seed {s}: scene 1 from {r.starts.get('scene1', 0.0):g} s, scene 2 from "
            f"{r.starts.get('scene2', 0.0):g} s"
            for s, r in runs.items()
        )
        + f"). Per seed: scene 1 for {SCENE1_S:g} s at each of the {len(ANGLES_DEG)} camera "
        f"angles, scene 2 (configs/scenarios/dmtbs/scene2.yaml, four static ToF cameras) for "
        f"{SCENE2_S:g} s, the object left behind for {first.left['duration_s']:g} s; the seed "
        "used seven sequences of 100 s per setting. Metric gating at 0.5 m. Not scored: the "
        "first second (the background's initialisation) and, in scenes 1 and 2, the "
        f"{WARMUP_S:g} s after it (tracks of the people in view when a run starts are "
        "confirmed, people merged when first seen part: once per 100 s sequence, once per "
        "run here). The seed's figures lost their numbers: only its claims are checked. A "
        "claim is held when it holds on every seed, failed when it fails on every seed, else "
        "inconclusive; beside it, what it compared: mean [least, greatest] over the seeds. "
        "MOTA per setting below is the seeds' mean [least, greatest]; the counts are summed "
        "over the seeds.",
        "",
        f"**{tally([c.verdict for c in judged])}.**",
        "",
        "## Claims (over the seeds)",
        "",
        "| claim | verdict | measured: mean [min, max] over the seeds | held on seeds |",
        "|---|---|---|---|",
    ]
    for c in judged:
        measured = "; ".join(f"{name}: {sp.text('.1f')}" for name, sp in c.spreads.items())
        held = ", ".join(str(s) for s, j in c.per_seed.items() if j.held) or "none"
        lines.append(f"| {c.judged.sentence} | **{c.verdict.value}** | {measured} | {held} |")
    lines += [
        "",
        "## Fig. 8: camera angle (scene 1, one camera)",
        "",
        f"Scene 1 (configs/scenarios/dmtbs/scene1.yaml): three people crossing on the camera's "
        f"line of sight; the camera {ARC_DISTANCE_M:g} m from the point {ARC_TARGET[2]:g} m "
        "above the floor's centre, from level (0 deg) to straight down.",
        "",
        *_table(tables["angles"], ["angle_deg", "camera_height_m"]),
        "",
        "## Fig. 9: number of cameras (scene 2)",
        "",
        *_table(tables["cameras"], ["cameras"]),
        "",
        "## Fig. 10: added depth noise (scene 2, two cameras)",
        "",
        *_table(tables["noise"], ["background", "noise_m"]),
        "",
        "## Fig. 11: yaw error of the second camera (scene 2, two cameras)",
        "",
        *_table(tables["yaw"], ["yaw_error_deg"]),
        "",
        "## Sections 6 and 3: an object left behind",
        "",
        f"configs/scenarios/dmtbs/left_object.yaml ({first.left['duration_s']:g} s): a 1.5 m "
        f"box is set down at {LEFT_OBJECT_AT_S:g} s and stays; it is not ground truth. The "
        f"running average (time constant {first.left['time_constant_s']:g} s, margin "
        f"{first.left['margin_m']:g} m) can have absorbed a surface up to {LEFT_OBJECT_GAP_M:g} m "
        "in front of the background tau ln(gap / margin) = "
        f"{left_absorb:.1f} s after it appears. Share of the frames with a track within 0.5 m "
        "of the box: *before*, from 1 s after it is left until then; *after*, from then plus "
        "the tracker's 1 s of coasting to the end; and the time from its setting down to the "
        "last frame with a track on it.",
        "",
        "| seed | before | after | from 1 s to the end | tracked for (s) | FP | FN | MOTA |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for s, r in runs.items():
        lf = r.left
        lines.append(
            f"| {s} | {_pct(lf['share_before_absorbed'])} | {_pct(lf['share_after_absorbed'])} | "
            f"{_pct(lf['object_tracked_share'])} | {lf['tracked_for_s']:.1f} | {lf['fp']} | "
            f"{lf['fn']} | {_pct(lf['mota'])} |"
        )
    lines += [
        "",
        "## Cost",
        "",
        f"CPU time, all seeds: rendering {cpu['render']:.0f} s, method (detectors, trackers, "
        f"scoring) {cpu['method']:.0f} s, on {data['machine']} (one process).",
        "",
    ]
    return "\n".join(lines)
