"""The frame loop: scenario + seed -> rendered, noisy frames with exact ground truth.

:class:`Simulator` holds what is built once (static mesh, camera models, the
timelines, the odometry track) and renders frame ``i`` on demand. Random
streams are derived from ``(seed, stream)`` so that each frame's noise depends
only on the seed and the frame index: same scenario and seed, same bytes.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim import rig
from rgbd_eval.sim.annotate import person_ground_truth
from rgbd_eval.sim.meshes import MAT_SHINY, MAT_SKIN, Mesh, concatenate
from rgbd_eval.sim.motion import (
    clothes_at,
    follower_state,
    gait_amplitude,
    person_state,
    person_timeline,
    robot_pose,
    robot_timeline,
)
from rgbd_eval.sim.odometry import integrate_odometry
from rgbd_eval.sim.people import dress, look_of
from rgbd_eval.sim.render import (
    CameraCast,
    Hits,
    Scene,
    light_direction,
    make_scene,
    object_ids,
    occluded_towards,
    shade,
)
from rgbd_eval.sim.rig import SceneView
from rgbd_eval.sim.scenario import Scenario
from rgbd_eval.sim.sensor import (
    depth_edges,
    dropout_probability,
    exposure_gain,
    frame_noise,
    noise_bank,
    noisy_depth,
    noisy_rgb,
)
from rgbd_eval.sim.variation import vary_paths
from rgbd_eval.sim.world import NO_HIT, static_mesh
from rgbd_eval.types import CameraModel, GroundTruthObject, Pose

# Random stream numbers (never reorder: they fix the bytes of every recording).
_STREAM_ODOMETRY = 1
_STREAM_DEPTH = 2
_STREAM_RGB = 3
_STREAM_RGB_BANK = 4
#: First noise stream of the rig's extra sensors (one stream each, in rig order).
_STREAM_RIG = 100
#: Noise images drawn once per recording; each frame shifts one of them at random.
_NOISE_BANK = 4


def _rng(seed: int, stream: int, index: int = 0) -> np.random.Generator:
    return np.random.default_rng([seed, stream, index])


@dataclass(frozen=True, eq=False)
class SimFrame:
    """One synthetic instant: sensor images, poses and ground truth."""

    index: int
    stamp_ns: int
    t: float
    rgb: NDArray[np.uint8]
    depth: NDArray[np.float32]  # decimated, metres, NaN invalid
    ids: NDArray[np.int32]  # RGB-camera id buffer (full resolution)
    base_true: Pose  # world_T_base_link
    base_odom: Pose  # odom_T_base_link (drifting)
    rgb_pose: Pose  # true world_T_rgb_optical
    ground_truth: list[GroundTruthObject]


class Simulator:
    """Renders the frames of one scenario for one seed."""

    def __init__(self, scenario: Scenario, seed: int | None = None) -> None:
        self.seed = scenario.seed if seed is None else int(seed)
        if self.seed < 0:
            raise ValueError(f"seed={self.seed} must be non-negative")
        #: The scenario as given (its digest and the seed name what is rendered).
        self.source_scenario = scenario
        #: The scenario as this seed renders it: its paths varied (rgbd_eval.sim.variation).
        self.scenario = scenario = vary_paths(scenario, self.seed)
        s = scenario.sensor
        self.rgb_camera: CameraModel = rig.rgb_camera(s)
        self.depth_camera_full: CameraModel = rig.depth_camera_full(s)
        self.depth_camera: CameraModel = rig.depth_camera(s)
        self.base_to_link = rig.base_to_camera_link(scenario.robot)
        self.link_to_rgb = rig.camera_link_to_rgb()
        self.link_to_depth = rig.camera_link_to_depth(s)
        static = static_mesh(scenario.room, scenario.obstacles)
        self.static = replace(static, smooth=static.smooth_triangles())  # once, not per frame
        self._static_scene = make_scene(self.static)
        #: Static-scene casts per camera model (size, intrinsics and frame id), with the pose
        #: they were cast from.
        self._static_casts: dict[CameraModel, CameraCast] = {}
        #: The people of the last rendered frame (index, mesh, scene), reused by scene_view.
        self._people: tuple[int, Mesh, Scene] | None = None
        self.light = light_direction(s.light_azimuth_deg, s.light_elevation_deg)
        leaders = {p.id: p for p in scenario.people if p.follow is None}
        timelines = {pid: person_timeline(p) for pid, p in leaders.items()}
        #: per person: whose path drives it, and that path's timeline
        self._drivers = [
            (leaders[p.follow.id] if p.follow else p, timelines[p.follow.id if p.follow else p.id])
            for p in scenario.people
        ]
        self._robot_segments = robot_timeline(scenario.robot)
        times = [self.time(i) for i in range(scenario.n_frames)]
        true = np.array([robot_pose(scenario.robot, self._robot_segments, t) for t in times])
        self.true_poses = true
        shape = (s.height, s.width, 3)
        self._noise = noise_bank(shape, _NOISE_BANK, _rng(self.seed, _STREAM_RGB_BANK))
        self.odom_poses = integrate_odometry(
            true, scenario.odometry, _rng(self.seed, _STREAM_ODOMETRY)
        )

    def set_robot_pose(self, index: int, pose: tuple[float, float, float]) -> None:
        """Closed loop: the robot's true ``(x, y, yaw)`` from frame ``index`` on.

        The odometry is integrated again from the new true path, with the same noise
        stream, so frames before ``index`` keep their poses and the result depends only
        on the seed and the poses set.
        """
        if not 0 <= index < self.n_frames:
            raise ValueError(f"index={index} must be in [0, {self.n_frames})")
        self.true_poses[index:] = pose
        self.odom_poses = integrate_odometry(
            self.true_poses, self.scenario.odometry, _rng(self.seed, _STREAM_ODOMETRY)
        )

    @property
    def n_frames(self) -> int:
        return self.scenario.n_frames

    def time(self, index: int) -> float:
        """Seconds since the start of frame ``index``."""
        return index / self.scenario.sensor.rate_hz

    def people_meshes(self, t: float) -> list[tuple[int, Mesh, float, tuple[float, float]]]:
        """(id, mesh, top height, ground xy) of every person present at time t."""
        out = []
        for person, (driver, segs) in zip(self.scenario.people, self._drivers, strict=True):
            st = person_state(driver, segs, t)
            if person.follow is not None:
                st = follower_state(st, person.follow)
            if not st.present:
                continue
            shirt, trousers = clothes_at(person, t)
            dressed = dress(*look_of(person, self.seed, shirt, trousers))
            mesh, top = dressed.mesh(
                st.x,
                st.y,
                st.heading,
                st.distance / dressed.stride(st.speed),
                st.speed,
                gait_amplitude(driver, segs, t),
                st.sit,
                person.id,
                person.bag_colour if person.bag else None,
            )
            out.append((person.id, mesh, top, (st.x, st.y)))
        return out

    def frame(self, index: int) -> SimFrame:
        """Render frame ``index`` (any order; the result depends only on seed and index)."""
        if not 0 <= index < self.n_frames:
            raise ValueError(f"index={index} must be in [0, {self.n_frames})")
        sc = self.scenario
        s = sc.sensor
        t = self.time(index)
        x, y, yaw = self.true_poses[index]
        base_true = rig.base_pose(float(x), float(y), float(yaw))
        ox, oy, oyaw = self.odom_poses[index]
        base_odom = rig.base_pose(float(ox), float(oy), float(oyaw))
        link = base_true.compose(self.base_to_link)
        rgb_pose = link.compose(self.link_to_rgb)
        depth_pose = link.compose(self.link_to_depth)

        people = self.people_meshes(t)
        people_mesh = concatenate([m for _, m, _, _ in people])
        people_scene = make_scene(people_mesh)
        self._people = (index, people_mesh, people_scene)
        stamp = sc.stamp_ns(index)
        if not sc.robot_camera:  # no Kinect: empty images, everyone present is ground truth
            gt = [
                GroundTruthObject(index, stamp, pid, None, (xy[0], xy[1], top / 2.0))
                for pid, _, top, xy in people
            ]
            empty = np.zeros((0, 0), dtype=np.float32)
            return SimFrame(
                index,
                stamp,
                t,
                np.zeros((0, 0, 3), dtype=np.uint8),
                empty,
                np.zeros((0, 0), dtype=np.int32),
                base_true,
                base_odom,
                rgb_pose,
                gt,
            )

        # RGB: shaded colour and the id buffer used for visibility
        mesh = concatenate([self.static, people_mesh])
        hits = self._render(people_scene, self.rgb_camera, rgb_pose)
        casters = [(xy[0], xy[1], 0.3) for _, _, _, xy in people]
        clean = shade(mesh, hits, self.light, sc.room.floor_tile, casters)
        if s.rgb_blur_px > 0.0:  # the lens and the Bayer demosaic soften the image
            clean = np.stack(
                [
                    exact.gaussian_filter(clean[..., k].astype(np.float64), s.rgb_blur_px)
                    for k in range(3)
                ],
                axis=-1,
            ).astype(np.float32)
        ids = object_ids(mesh, hits)
        gain = exposure_gain(t, s.exposure_amplitude, s.exposure_period_s) * s.illumination
        noise = frame_noise(self._noise, _rng(self.seed, _STREAM_RGB, index))
        rgb = noisy_rgb(clean, gain, s.rgb_noise_std, noise)

        # depth: ideal z from the depth camera, then the sensor model
        # Rays go through the published (decimated) camera's pixel centres, so the
        # image agrees with its CameraInfo; edges are found on the published grid.
        dh = self._render(people_scene, self.depth_camera, depth_pose)
        edges = depth_edges(dh.depth, s.edge_jump)
        tri = dh.triangle
        hit = tri >= 0
        safe = np.where(hit, tri, 0)
        albedo = mesh.colours[safe]
        luminance = albedo[..., 0] * 0.299 + albedo[..., 1] * 0.587 + albedo[..., 2] * 0.114
        material = mesh.materials[safe]
        dark = hit & (luminance < s.dark_level) & (material != MAT_SKIN)
        shiny = hit & (material == MAT_SHINY)
        dropout = dropout_probability(edges, dark, shiny, s)
        if s.projector_shadows:
            # structured light: what the projector cannot see returns no depth
            projector = depth_pose.transform_points(np.array([[s.baseline_m, 0.0, 0.0]]))[0]
            seen = np.flatnonzero(hit)
            points = dh.points().reshape(-1, 3)[seen]
            shadow = occluded_towards(
                [self._static_scene, people_scene],
                points,
                projector,
                depth_pose.rotation_matrix(),
            )
            dropout.flat[seen[shadow]] = 1.0
        depth = noisy_depth(
            dh.depth,
            dropout,
            s,
            self.depth_camera_full.fx,
            _rng(self.seed, _STREAM_DEPTH, index),
        )

        gt = [
            person_ground_truth(index, stamp, pid, m, top, xy, ids, self.rgb_camera, rgb_pose)
            for pid, m, top, xy in people
        ]
        if sc.truth_visibility == "present":
            gt = [replace(o, visibility=1.0, ignore=False) for o in gt]
        return SimFrame(index, stamp, t, rgb, depth, ids, base_true, base_odom, rgb_pose, gt)

    def _render(self, people: Scene, camera: CameraModel, pose: Pose) -> Hits:
        """Hits of static scene + people: the static part is cached while the camera stands.

        The cache is keyed by the whole camera model, so two cameras that share a frame id
        but differ in size or intrinsics never get each other's hits.
        """
        base = self._static_casts.get(camera)
        if base is None or base.pose != pose:
            base = CameraCast(camera, pose)
            base.cast(self._static_scene)
            self._static_casts[camera] = base
        cast = base.copy()
        cast.cast(people, self._static_scene.n_triangles)
        normals = np.concatenate([self._static_scene.face_normals, people.face_normals])
        return cast.hits(normals)

    def scene_view(self, index: int, stream: int) -> SceneView:
        """Frame ``index`` for a rig sensor: its stamp and a renderer of the same scene.

        ``stream`` seeds the sensor's own noise (one stream per sensor), so every
        sensor's output depends only on the seed, the frame and the sensor.
        """
        if self._people is None or self._people[0] != index:
            people_mesh = concatenate([m for _, m, _, _ in self.people_meshes(self.time(index))])
            self._people = (index, people_mesh, make_scene(people_mesh))
        _, people_mesh, people_scene = self._people

        def render(camera: CameraModel, pose: Pose) -> Hits:
            return self._render(people_scene, camera, pose)

        ids_all = np.concatenate([self.static.object_ids, people_mesh.object_ids])
        mats_all = np.concatenate([self.static.materials, people_mesh.materials])

        def surface(hits: Hits) -> tuple[NDArray[np.int32], NDArray[np.int32]]:
            tri = hits.triangle
            safe = np.maximum(tri, 0)
            ids = np.where(tri >= 0, ids_all[safe], NO_HIT).astype(np.int32)
            mats = np.where(tri >= 0, mats_all[safe], -1).astype(np.int32)
            return ids, mats

        def lit(hits: Hits) -> NDArray[np.float32]:
            mesh = concatenate([self.static, people_mesh])
            return shade(mesh, hits, self.light, self.scenario.room.floor_tile)

        x, y, yaw = self.true_poses[index]
        base = rig.base_pose(float(x), float(y), float(yaw))
        return SceneView(
            index,
            self.scenario.stamp_ns(index),
            rig.WORLD_FRAME,
            render,
            _rng(self.seed, _STREAM_RIG + stream, index),
            base,
            lit,
            surface,
            base.compose(self.base_to_link).compose(self.link_to_rgb),
        )

    def frames(self, indices: list[int] | None = None) -> Iterator[SimFrame]:
        """Frames in order (all, or the given indices)."""
        for i in range(self.n_frames) if indices is None else indices:
            yield self.frame(i)
