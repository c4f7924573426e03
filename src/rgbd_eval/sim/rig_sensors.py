"""Extra sensors of a synthetic rig, beside the robot's Kinect: a registry of kinds.

A scenario's ``rig`` lists extra sensors, each a mapping whose ``kind`` selects its
config model (registered here, like detectors and trackers in :mod:`rgbd_eval.plugins`)
and whose ``name`` becomes its topic namespace (``/<name>/...``) and tf frame
(``<name>_optical_frame``). The writer puts each sensor on its own topics, with its
tf: a static sensor as ``/tf_static`` from the world frame, a robot-mounted one from
``base_link`` (or the colour camera's frame). Method issues add kinds (stereo pair, thermal camera, wheel encoders);
``static_depth`` (a fixed time-of-flight depth camera) is built in.

A sensor renders from the same scene as the Kinect, frame by frame, through
:class:`SceneView`, so its images agree with the ground truth.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from rgbd_eval import exact
from rgbd_eval.sim.meshes import rotation_y, rotation_z
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

if TYPE_CHECKING:  # the scenario model imports this module: keep it free of rendering
    from rgbd_eval.io.writer import RecordingWriter
    from rgbd_eval.sim.render import Hits


class RigSensorConfig(BaseModel):
    """Base of every rig sensor's config: its kind and its name (topics, tf frame)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: str
    name: str = Field(min_length=1, max_length=40, pattern=r"^[A-Za-z][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class SceneView:
    """One instant of the scene, for a rig sensor to render and write."""

    index: int
    stamp_ns: int
    world_frame: str
    #: Ray-cast static scene + people from ``pose`` (world_T_optical) through ``camera``.
    render: Callable[[CameraModel, Pose], Hits]
    rng: np.random.Generator
    #: world_T_base_link of the robot at this instant (robot-mounted sensors render from it).
    base_pose: Pose = field(default_factory=Pose.identity)
    #: Lit colour ((H, W, 3) float32, 0..255) of rendered hits, as the Kinect's RGB is shaded.
    shade: Callable[[Hits], NDArray[np.float32]] | None = None
    #: Per-pixel (object id, material) of a :meth:`render` result (``NO_HIT``, -1: nothing).
    surface: Callable[[Hits], tuple[NDArray[np.int32], NDArray[np.int32]]] | None = None
    #: The colour camera's true world_T_optical (the thermal camera sits beside it).
    rgb_pose: Pose = field(default_factory=Pose.identity)


class RigSensor(Protocol):
    """A sensor of the rig: its static tf, and what it writes each frame."""

    def static_transforms(self) -> list[tuple[str, str, Pose]]:
        """``(parent, child, parent_T_child)`` written once to ``/tf_static``."""
        ...

    def write(self, writer: RecordingWriter, view: SceneView) -> None:
        """Render and write this sensor's messages of one frame."""
        ...


@dataclass(frozen=True)
class RigSensorSpec:
    kind: str
    config_model: type[RigSensorConfig]
    factory: Callable[[Any, str], RigSensor]  # (config, world frame) -> sensor


_KINDS: dict[str, RigSensorSpec] = {}


def register_rig_sensor(spec: RigSensorSpec) -> RigSensorSpec:
    """Register a sensor kind (its config model's ``kind`` must default to it)."""
    if spec.config_model.model_fields["kind"].default != spec.kind:
        raise ValueError(f"rig sensor {spec.kind!r}: its config model must default kind to it")
    if spec.kind in _KINDS and _KINDS[spec.kind] != spec:
        raise ValueError(f"rig sensor kind {spec.kind!r} is already registered")
    _KINDS[spec.kind] = spec
    return spec


def rig_sensor_config(data: Mapping[str, Any]) -> RigSensorConfig:
    """Validate one ``rig`` entry by its ``kind`` (ValueError naming the known kinds)."""
    kind = data.get("kind")
    spec = _KINDS.get(kind) if isinstance(kind, str) else None
    if spec is None:
        raise ValueError(f"unknown rig sensor kind {kind!r} (known: {', '.join(sorted(_KINDS))})")
    return spec.config_model.model_validate(data)


def make_rig_sensor(config: RigSensorConfig, world_frame: str) -> RigSensor:
    return _KINDS[config.kind].factory(config, world_frame)


# ----------------------------------------------------------------------------- static_depth


class StaticDepthConfig(RigSensorConfig):
    """A fixed depth camera (time of flight), placed in the world.

    Defaults are the Kinect for Xbox One's depth camera: 512x424, 70.6 x 60 degrees.
    The noise is Gaussian with sigma ``noise_k * z^2 * (1 + off_centre_gain * rho^2)`` (0:
    ideal; ``rho`` the pixel's distance from the image centre over the half-diagonal) plus
    independent ``extra_noise_m``; pixels are invalid beyond ``max_range_m`` and below
    ``min_range_m``, with probability ``edge_dropout`` on depth edges and ``random_dropout``
    anywhere (see :mod:`rgbd_eval.sim.tof`, seed 003 4.3).
    """

    kind: Literal["static_depth"] = "static_depth"
    x: float
    y: float
    z: float = Field(gt=0.0, le=20.0)
    yaw_deg: float = Field(0.0, ge=-360.0, le=360.0, description="heading in the world")
    pitch_deg: float = Field(0.0, ge=-90.0, le=90.0, description="tilt down (positive)")
    width: int = Field(512, ge=8, le=4096)
    height: int = Field(424, ge=8, le=4096)
    hfov_deg: float = Field(70.6, gt=10.0, lt=170.0)
    vfov_deg: float = Field(60.0, gt=10.0, lt=170.0)
    noise_k: float = Field(0.0, ge=0.0, le=0.1, description="depth sigma = k z^2 (m)")
    min_range_m: float = Field(0.5, ge=0.0)
    max_range_m: float = Field(8.0, gt=0.5, le=50.0)
    off_centre_gain: float = Field(
        0.0, ge=0.0, le=10.0, description="noise growth from the image centre to a corner"
    )
    extra_noise_m: float = Field(
        0.0, ge=0.0, le=1.0, description="added Gaussian depth noise std (m), seed 003 Fig. 10"
    )
    edge_jump: float = Field(0.05, gt=0.0, le=1.0, description="relative jump marking an edge")
    edge_dropout: float = Field(0.0, ge=0.0, le=1.0, description="P(invalid) on a depth edge")
    random_dropout: float = Field(0.0, ge=0.0, le=1.0, description="P(invalid) anywhere")


def pinhole_from_fov(
    width: int, height: int, hfov_deg: float, vfov_deg: float, frame_id: str
) -> CameraModel:
    """An undistorted camera with the given fields of view, principal point at the centre."""
    fx = (width / 2.0) / exact.tan(math.radians(hfov_deg) / 2.0)
    fy = (height / 2.0) / exact.tan(math.radians(vfov_deg) / 2.0)
    return CameraModel(
        width, height, fx, fy, (width - 1) / 2.0, (height - 1) / 2.0, (0.0,) * 5, frame_id
    )


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
        from rgbd_eval.sim.tof import tof_depth  # rendering helpers: imported on use

        return tof_depth(view.render(self.camera, self.pose).depth, self.cfg, view.rng)


register_rig_sensor(RigSensorSpec("static_depth", StaticDepthConfig, StaticDepthCamera))


# the kinds that live in their own modules register on import (at the end: they import this one)
from rgbd_eval.sim import thermal_camera as _thermal_camera  # noqa: E402, F401
