"""Rendered pairs of overlapping persons with known depth order (training data, seed 004 section 5).

Each pair is a one-frame scene rendered by the simulator: a static robot with the default
Kinect colour camera and a thermal camera beside it (:mod:`rgbd_eval.sim.thermal_camera`),
and two walking people, the far one placed so that its image box overlaps the near one's.
Everything random (distances, bearings, headings, heights, clothes, the room's and the
clothes' temperatures, the light, the gait phase) is drawn from one generator, so a pair
is a pure function of the seed and its index. The boxes are the people's full projected
extents on the thermal image cut to the image, as the tracker's silhouette state describes
them (occluded parts included), optionally jittered to mimic a tracker's estimate.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.annotate import projected_extent
from rgbd_eval.sim.rig_config import ThermalCameraConfig
from rgbd_eval.sim.scenario import Scenario, parse_scenario
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.sim.thermal_camera import ThermalCamera, counts_to_celsius
from rgbd_eval.sim.world import NO_HIT

Box = tuple[float, float, float, float]
#: The nominal depth of the thermal-to-colour affine map (methods/cielniak2010/method.yaml,
#: ``tracker.alignment_depth_m``), so the training pairs are aligned as the tracker aligns.
ALIGNMENT_DEPTH_M = 3.0
#: A pair counts as overlapping when the boxes share this share of the smaller box.
MIN_OVERLAP = 0.1
#: Draws allowed per accepted pair before giving up (a configuration error, not bad luck).
_MAX_TRIES = 200


@dataclass(frozen=True, eq=False)
class RenderedPair:
    """Two overlapping people: images, thermal boxes, and which one is in front."""

    temperature: NDArray[np.float64]  # thermal image, deg C (blurred, noisy)
    colour: NDArray[np.uint8]  # the colour camera's image
    boxes: tuple[Box, Box]  # full extents on the thermal image (jittered when asked)
    distances: tuple[float, float]  # along the optical axis, m
    visible: tuple[float, float]  # share of each person's thermal pixels that is visible
    scale: tuple[float, float]  # thermal -> colour affine map
    offset: tuple[float, float]

    @property
    def front(self) -> int:
        """0 or 1: the nearer person."""
        return 0 if self.distances[0] < self.distances[1] else 1


def _colour(rng: np.random.Generator) -> list[int]:
    return [int(c) for c in rng.integers(15, 241, size=3)]


def _overlap(a: Box, b: Box) -> float:
    """Intersection area over the smaller box's area."""
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    if w <= 0 or h <= 0:
        return 0.0
    small = min((a[2] - a[0]) * (a[3] - a[1]), (b[2] - b[0]) * (b[3] - b[1]))
    return w * h / small


def pair_scenario(rng: np.random.Generator, illumination: float = 1.0) -> Scenario:
    """A one-frame scenario with two people, the second behind the first on a nearby bearing."""
    near = float(rng.uniform(1.8, 6.0))
    far = min(near + float(rng.uniform(0.4, 3.0)), 9.0)
    bearing = float(rng.uniform(-0.35, 0.35))
    bearings = (bearing, bearing + float(rng.uniform(-0.12, 0.12)))
    people = []
    for pid, (dist, b) in enumerate(zip((near, far), bearings, strict=True), start=1):
        x, y = dist, dist * exact.tan(b)
        heading = float(rng.uniform(0.0, 2.0 * math.pi))
        step = float(rng.uniform(0.3, 0.6))
        people.append(
            {
                "id": pid,
                "height": float(rng.uniform(1.55, 1.92)),
                "shirt": _colour(rng),
                "trousers": _colour(rng),
                "path": [
                    {"x": x - step * exact.cos(heading), "y": y - step * exact.sin(heading)},
                    {"x": x, "y": y, "speed": 1.2},
                ],
            }
        )
    ambient = float(rng.uniform(18.0, 24.0))
    thermal = {
        "kind": "thermal",
        "name": "thermal",
        "ambient_c": ambient,
        "floor_c": ambient - float(rng.uniform(0.0, 2.0)),
        "clothing_c": float(rng.uniform(26.0, 31.0)),
        "skin_c": float(rng.uniform(32.0, 35.5)),
    }
    return parse_scenario(
        {
            "name": "occlusion_pair",
            "duration_s": 0.5,
            "seed": int(rng.integers(0, 2**31)),
            "room": {"x_min": -1.0, "x_max": 11.0, "y_min": -5.0, "y_max": 5.0},
            "people": people,
            "robot": {"x": 0.0, "y": 0.0, "yaw_deg": 0.0},
            "sensor": {
                "depth_decimation": 4,
                "light_azimuth_deg": float(rng.uniform(-180.0, 180.0)),
                "light_elevation_deg": float(rng.uniform(30.0, 80.0)),
                "illumination": illumination,
            },
            "rig": [thermal],
        },
        "occlusion pair",
    )


def _visible_share(ids: NDArray[np.int32], box: Box, pid: int, hidden: NDArray[np.int32]) -> float:
    seen = int(np.count_nonzero(ids == pid))
    total = seen + int(np.count_nonzero(hidden == pid))
    return seen / total if total else 0.0


def render_pair(
    rng: np.random.Generator, jitter: float = 0.0, illumination: float = 1.0
) -> RenderedPair:
    """Draw scenes until the two people's thermal boxes (cut to the image) overlap by
    :data:`MIN_OVERLAP`, and render that one.

    ``jitter`` adds Gaussian noise of ``jitter`` box heights to every box coordinate.
    """
    if jitter < 0.0:
        raise ValueError(f"jitter={jitter} must be non-negative")
    for _ in range(_MAX_TRIES):
        scenario = pair_scenario(rng, illumination)
        index = int(rng.integers(0, 12))
        sim = Simulator(scenario)
        pairs = _frame_pairs(sim, index, rng, jitter)
        if pairs:
            return pairs[0]
    raise ValueError(f"no overlapping pair in {_MAX_TRIES} draws")


def _thermal_camera(scenario: Scenario) -> tuple[int, ThermalCamera]:
    """The rig index and camera of the scenario's first thermal camera (ValueError: none)."""
    for k, cfg in enumerate(scenario.rig):
        if isinstance(cfg, ThermalCameraConfig):
            return k, ThermalCamera(cfg, "world")
    raise ValueError(f"scenario {scenario.name!r} has no thermal camera")


def _frame_pairs(
    sim: Simulator, index: int, rng: np.random.Generator, jitter: float
) -> list[RenderedPair]:
    """Every pair of people in frame ``index`` whose thermal boxes (cut to the image)
    overlap by :data:`MIN_OVERLAP`, rendered (nothing is rendered when none does).

    The pairs are in the order of the people in the scenario (``(i, j)``, ``i < j``);
    the jitter of each pair's boxes is drawn from ``rng`` in that order.
    """
    stream, camera = _thermal_camera(sim.scenario)
    view = sim.scene_view(index, stream)
    pose = camera.pose(view)
    meshes = sim.people_meshes(sim.time(index))
    size = (float(camera.camera.width), float(camera.camera.height))
    boxes: list[Box | None] = []
    for _, mesh, _, _ in meshes:
        extent = projected_extent(mesh.vertices, camera.camera, pose)
        boxes.append(None if extent is None else _clipped(extent, size))
    found = [
        (i, j)
        for i in range(len(meshes))
        for j in range(i + 1, len(meshes))
        if (a := boxes[i]) is not None
        and (b := boxes[j]) is not None
        and _overlap(a, b) >= MIN_OVERLAP
    ]
    if not found:
        return []
    frame = sim.frame(index)
    view = sim.scene_view(index, stream)
    temperature = counts_to_celsius(camera.render_counts(view))
    # visibility on the thermal camera: people alone vs the full scene
    hits = view.render(camera.camera, pose)
    ids, _ = view.surface(hits) if view.surface is not None else (None, None)
    if ids is None:  # pragma: no cover - the simulator always gives surfaces
        raise TypeError("the simulator's scene view has no surface ids")
    hidden = _hidden_ids(sim, index, camera, pose, ids)
    t_pose = pose.inverse()
    dist = [
        float(t_pose.transform_points(np.array([[xy[0], xy[1], 1.0]]))[0, 2])
        for _, _, _, xy in meshes
    ]
    scale, offset = thermal_to_colour(sim, camera)
    out = []
    for i, j in found:
        a, b = boxes[i], boxes[j]
        if a is None or b is None:  # pragma: no cover - filtered above
            continue
        visible = (
            _visible_share(ids, a, meshes[i][0], hidden),
            _visible_share(ids, b, meshes[j][0], hidden),
        )
        if jitter > 0.0:
            a, b = _jittered(a, jitter, rng), _jittered(b, jitter, rng)
        out.append(
            RenderedPair(temperature, frame.rgb, (a, b), (dist[i], dist[j]), visible, scale, offset)
        )
    return out


#: The stream of the box jitter of :func:`scene_pairs` (apart from the simulator's streams).
SCENE_JITTER_STREAM = 91


def scene_pairs(
    scenario: Scenario, jitter: float = 0.0, stride: int = 1, limit: int | None = None
) -> Iterator[RenderedPair]:
    """Overlapping pairs of people in a scenario's own frames, with its seed.

    Frames ``0, stride, 2 stride, ...``: in each, every pair of people whose thermal boxes
    (cut to the image) overlap by :data:`MIN_OVERLAP` (:func:`_frame_pairs`), at most
    ``limit`` pairs in all. The boxes' jitter of frame ``k`` is drawn from numpy
    ``default_rng([seed, SCENE_JITTER_STREAM, k])``, so a pair is a pure function of the
    scenario, its seed and the frame. Person ``a`` of a pair is the one listed first in the
    scenario.
    """
    if jitter < 0.0:
        raise ValueError(f"jitter={jitter} must be non-negative")
    if stride < 1:
        raise ValueError(f"stride={stride} must be at least 1")
    if limit is not None and limit < 0:
        raise ValueError(f"limit={limit} must be non-negative")
    sim = Simulator(scenario)
    given = 0
    for index in range(0, sim.n_frames, stride):
        if limit is not None and given >= limit:
            return
        rng = np.random.default_rng([sim.seed, SCENE_JITTER_STREAM, index])
        for pair in _frame_pairs(sim, index, rng, jitter):
            if limit is not None and given >= limit:
                return
            given += 1
            yield pair


def _hidden_ids(
    sim: Simulator, index: int, camera: ThermalCamera, pose: object, ids: NDArray[np.int32]
) -> NDArray[np.int32]:
    """Ids of people hidden by another person: rendered alone, minus what the scene shows."""
    from rgbd_eval.sim.meshes import concatenate
    from rgbd_eval.sim.render import make_scene, object_ids, render_hits
    from rgbd_eval.types import Pose

    if not isinstance(pose, Pose):  # pragma: no cover - internal call
        raise TypeError("pose must be a Pose")
    hidden = np.full(ids.shape, NO_HIT, dtype=np.int32)
    for pid, mesh, _, _ in sim.people_meshes(sim.time(index)):
        alone = concatenate([mesh])
        own = object_ids(alone, render_hits(make_scene(alone), camera.camera, pose))
        hidden[(own == pid) & (ids != pid)] = pid
    return hidden


def _clipped(box: Box, size: tuple[float, float]) -> Box:
    """The box cut to the image (a person partly outside is tracked by its visible part)."""
    w, h = size
    return (max(box[0], 0.0), max(box[1], 0.0), min(box[2], w), min(box[3], h))


def _jittered(box: Box, jitter: float, rng: np.random.Generator) -> Box:
    h = box[3] - box[1]
    d = exact.standard_normal(rng, 4) * (jitter * h)
    u0, v0, u1, v1 = (float(box[k] + d[k]) for k in range(4))
    return (min(u0, u1 - 1.0), min(v0, v1 - 1.0), max(u1, u0 + 1.0), max(v1, v0 + 1.0))


def thermal_to_colour(
    sim: Simulator, camera: ThermalCamera
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The affine thermal -> colour pixel map of parallel cameras at :data:`ALIGNMENT_DEPTH_M`."""
    t, c = camera.camera, sim.rgb_camera
    bx, by, _ = camera.offset.translation
    sx, sy = c.fx / t.fx, c.fy / t.fy
    return (sx, sy), (
        c.cx - sx * t.cx + c.fx * bx / ALIGNMENT_DEPTH_M,
        c.cy - sy * t.cy + c.fy * by / ALIGNMENT_DEPTH_M,
    )


def overlapping_pairs(
    seed: int, count: int, jitter: float = 0.0, illumination: float = 1.0
) -> Iterator[RenderedPair]:
    """``count`` pairs; pair ``k`` depends only on ``(seed, k)``."""
    if count < 0:
        raise ValueError(f"count={count} must be non-negative")
    for k in range(count):
        yield render_pair(np.random.default_rng([seed, k]), jitter, illumination)
