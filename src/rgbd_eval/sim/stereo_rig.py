"""A robot-mounted rectified stereo pair for the satake2009 method (seed 002, section 4).

Defaults are the paper's Bumblebee2: XGA (1024x768) at 20 fps, 100 degrees horizontal
field of view; the baseline of 12 cm is Point Grey's BB2 specification (the seed gives
none). Both cameras look along the same axis (rectified), the right one ``baseline_m``
to the right of the left one, so the right CameraInfo carries ``Tx = -fx * B``.

Stereo needs texture: every surface is lit as the Kinect's RGB is (albedo, Lambert) and
modulated by a solid (3D) value-noise texture of the world position, deterministic for
``texture_seed``. Being a function of the surface point, both cameras see the same
texture where they see the same point, as real surfaces do. Only the two images are
written: the rendered depth never reaches a method.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from rgbd_eval.sim import rig
from rgbd_eval.sim.meshes import rotation_y
from rgbd_eval.sim.rig_sensors import (
    RigSensorConfig,
    RigSensorSpec,
    SceneView,
    register_rig_sensor,
)
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

if TYPE_CHECKING:
    from rgbd_eval.io.writer import RecordingWriter

_LATTICE = 64  # period of the noise lattice (cells)


class StereoPairConfig(RigSensorConfig):
    """A stereo camera on the robot, looking ahead (Bumblebee2-like defaults)."""

    kind: Literal["stereo_pair"] = "stereo_pair"
    x: float = Field(0.1, ge=-2.0, le=2.0, description="ahead of base_link (m)")
    z: float = Field(1.2, gt=0.0, le=3.0, description="height of the left camera (m)")
    tilt_deg: float = Field(0.0, ge=-45.0, le=45.0, description="pitched down (positive)")
    baseline_m: float = Field(0.12, gt=0.0, le=1.0)
    width: int = Field(1024, ge=16, le=4096)
    height: int = Field(768, ge=16, le=4096)
    hfov_deg: float = Field(100.0, gt=10.0, lt=170.0)
    texture_seed: int = Field(0, ge=0)
    texture_scale_m: float = Field(0.05, gt=0.0, le=1.0, description="finest texture feature (m)")
    texture_contrast: float = Field(0.45, ge=0.0, le=0.9)
    noise_std: float = Field(2.0, ge=0.0, le=50.0, description="image noise (grey levels)")


@lru_cache(maxsize=4)
def _lattice(seed: int) -> NDArray[np.float32]:
    rng = np.random.default_rng(np.random.SeedSequence([seed, 0x57E2E0]))
    out = rng.random((_LATTICE, _LATTICE, _LATTICE), dtype=np.float32)
    out.setflags(write=False)
    return out


def value_noise(points: NDArray[np.floating], scale: float, seed: int) -> NDArray[np.float32]:
    """Smooth 3D value noise in [0, 1] at world points ``(N, 3)``, feature size ``scale`` (m)."""
    lat = _lattice(seed)
    q = np.asarray(points, dtype=np.float64) / scale
    i0 = np.floor(q)
    f = (q - i0).astype(np.float32)
    f = f * f * (3.0 - 2.0 * f)  # smoothstep: no creases at the cell borders
    i = i0.astype(np.int64) % _LATTICE
    j = (i + 1) % _LATTICE
    out = np.zeros(len(q), dtype=np.float32)
    for cx in (0, 1):
        wx = f[:, 0] if cx else 1.0 - f[:, 0]
        ix = j[:, 0] if cx else i[:, 0]
        for cy in (0, 1):
            wy = f[:, 1] if cy else 1.0 - f[:, 1]
            iy = j[:, 1] if cy else i[:, 1]
            for cz in (0, 1):
                wz = f[:, 2] if cz else 1.0 - f[:, 2]
                iz = j[:, 2] if cz else i[:, 2]
                out += wx * wy * wz * lat[ix, iy, iz]
    return out


def surface_texture(points: NDArray[np.floating], scale: float, seed: int) -> NDArray[np.float32]:
    """Two octaves of value noise (``scale`` and ``4 scale``), in [0, 1]."""
    fine = value_noise(points, scale, seed)
    coarse = value_noise(points, 4.0 * scale, seed + 1)
    return (0.6 * fine + 0.4 * coarse).astype(np.float32)


class StereoPair:
    """Writes ``/<name>/left|right/image_raw`` (rgb8) and their CameraInfo."""

    def __init__(self, config: StereoPairConfig, world_frame: str) -> None:
        self.cfg = c = config
        fx = (c.width / 2.0) / math.tan(math.radians(c.hfov_deg) / 2.0)
        cx, cy = (c.width - 1) / 2.0, (c.height - 1) / 2.0
        dist = (0.0,) * 5
        self.left = CameraModel(c.width, c.height, fx, fx, cx, cy, dist, f"{c.name}_left_optical")
        self.right = CameraModel(
            c.width, c.height, fx, fx, cx, cy, dist, f"{c.name}_right_optical", -fx * c.baseline_m
        )
        link = np.eye(4)
        link[:3, :3] = rotation_y(math.radians(c.tilt_deg))
        link[:3, 3] = (c.x, 0.0, c.z)
        #: base_link_T_left_optical and base_link_T_right_optical (B along optical +x)
        self.base_to_left = Pose.from_matrix(link).compose(OPTICAL_TO_BODY)
        shift = np.eye(4)
        shift[0, 3] = c.baseline_m
        self.base_to_right = self.base_to_left.compose(Pose.from_matrix(shift))

    def static_transforms(self) -> list[tuple[str, str, Pose]]:
        return [
            (rig.BASE_FRAME, self.left.frame_id, self.base_to_left),
            (rig.BASE_FRAME, self.right.frame_id, self.base_to_right),
        ]

    def render(self, view: SceneView, camera: CameraModel, base_to_cam: Pose) -> NDArray[np.uint8]:
        """One textured, lit, noisy rgb8 image of the scene from ``camera``."""
        if view.shade is None:
            raise ValueError("the stereo pair needs a scene view that shades")
        hits = view.render(camera, view.base_pose.compose(base_to_cam))
        img = view.shade(hits)
        hit = hits.triangle >= 0
        pts = hits.points()[hit]
        c = self.cfg
        tex = surface_texture(pts, c.texture_scale_m, c.texture_seed)
        img[hit] *= (1.0 - c.texture_contrast + 2.0 * c.texture_contrast * tex)[:, None]
        if c.noise_std > 0:
            img += view.rng.normal(0.0, c.noise_std, img.shape).astype(np.float32)
        out: NDArray[np.uint8] = np.clip(img + 0.5, 0, 255).astype(np.uint8)
        return out

    def write(self, writer: RecordingWriter, view: SceneView) -> None:
        ns = f"/{self.cfg.name}"
        for side, cam, pose in (
            ("left", self.left, self.base_to_left),
            ("right", self.right, self.base_to_right),
        ):
            img = self.render(view, cam, pose)
            writer.write_image(
                f"{ns}/{side}/image_raw",
                f"{ns}/{side}/camera_info",
                view.stamp_ns,
                img,
                cam,
                "rgb8",
            )


register_rig_sensor(RigSensorSpec("stereo_pair", StereoPairConfig, StereoPair))
