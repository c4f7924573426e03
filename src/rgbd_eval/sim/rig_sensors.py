"""Extra sensors of a synthetic rig, beside the robot's Kinect: what each kind renders and writes.

A scenario's ``rig`` lists extra sensors (their config models: :mod:`rgbd_eval.sim.rig_config`).
The writer puts each sensor on its own topics, with its tf: a static sensor as ``/tf_static``
from the world frame, a robot-mounted one from ``base_link`` (or the colour camera's frame).
Method issues add kinds (stereo pair, thermal camera, wheel encoders); built in are
``static_depth`` (a fixed time-of-flight depth camera, here), ``stereo_pair``
(:mod:`rgbd_eval.sim.stereo_rig`) and ``thermal`` (:mod:`rgbd_eval.sim.thermal_camera`).

A sensor renders from the same scene as the Kinect, frame by frame, through
:class:`~rgbd_eval.sim.rig.SceneView`, so its images agree with the ground truth.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.meshes import rotation_y, rotation_z
from rgbd_eval.sim.rig import RigSensor, SceneView, pinhole_from_fov
from rgbd_eval.sim.rig_config import (
    RigSensorConfig,
    StaticDepthConfig,
    StereoPairConfig,
    ThermalCameraConfig,
    register_rig_config,
)
from rgbd_eval.sim.sensor import tof_depth
from rgbd_eval.sim.stereo_rig import StereoPair
from rgbd_eval.sim.thermal_camera import ThermalCamera
from rgbd_eval.types import OPTICAL_TO_BODY, Pose

if TYPE_CHECKING:
    from rgbd_eval.io.writer import RecordingWriter


@dataclass(frozen=True)
class RigSensorSpec:
    kind: str
    config_model: type[RigSensorConfig]
    factory: Callable[[Any, str], RigSensor]  # (config, world frame) -> sensor


_KINDS: dict[str, RigSensorSpec] = {}


def register_rig_sensor(spec: RigSensorSpec) -> RigSensorSpec:
    """Register a sensor kind: its config model (whose ``kind`` must default to it) and factory."""
    if spec.kind in _KINDS and _KINDS[spec.kind] != spec:
        raise ValueError(f"rig sensor kind {spec.kind!r} is already registered")
    register_rig_config(spec.kind, spec.config_model)
    _KINDS[spec.kind] = spec
    return spec


def make_rig_sensor(config: RigSensorConfig, world_frame: str) -> RigSensor:
    return _KINDS[config.kind].factory(config, world_frame)


# ----------------------------------------------------------------------------- static_depth


class StaticDepthCamera:
    """Writes ``/<name>/depth/image_raw`` (16UC1) and ``/<name>/depth/camera_info``."""

    def __init__(self, config: StaticDepthConfig, world_frame: str) -> None:
        self.cfg = config
        self.world_frame = world_frame
        c = config
        self.camera = pinhole_from_fov(
            c.width, c.height, c.hfov_deg, c.vfov_deg, f"{c.name}_optical_frame"
        )
        body = np.eye(4)
        body[:3, :3] = exact.matmul(
            rotation_z(math.radians(c.yaw_deg)), rotation_y(math.radians(c.pitch_deg))
        )
        body[:3, 3] = (c.x, c.y, c.z)
        #: world_T_optical
        self.pose = Pose.from_matrix(body).compose(OPTICAL_TO_BODY)

    def static_transforms(self) -> list[tuple[str, str, Pose]]:
        return [(self.world_frame, self.camera.frame_id, self.pose)]

    def write(self, writer: RecordingWriter, view: SceneView) -> None:
        depth = self.render_depth(view)
        ns = f"/{self.cfg.name}/depth"
        writer.write_image(
            f"{ns}/image_raw", f"{ns}/camera_info", view.stamp_ns, depth, self.camera, "16UC1"
        )

    def render_depth(self, view: SceneView) -> NDArray[np.float32]:
        return tof_depth(view.render(self.camera, self.pose).depth, self.cfg, view.rng)


register_rig_sensor(RigSensorSpec("static_depth", StaticDepthConfig, StaticDepthCamera))
register_rig_sensor(RigSensorSpec("stereo_pair", StereoPairConfig, StereoPair))
register_rig_sensor(RigSensorSpec("thermal", ThermalCameraConfig, ThermalCamera))
