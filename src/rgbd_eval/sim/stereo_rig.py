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
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim import rig
from rgbd_eval.sim.meshes import rotation_y
from rgbd_eval.sim.rig import SceneView
from rgbd_eval.sim.rig_config import StereoPairConfig
from rgbd_eval.sim.scenario import Scenario, parse_scenario
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

if TYPE_CHECKING:
    from rgbd_eval.io.writer import RecordingWriter

_LATTICE = 64  # period of the noise lattice (cells)


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
        fx = (c.width / 2.0) / exact.tan(math.radians(c.hfov_deg) / 2.0)
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
            img += (exact.standard_normal(view.rng, img.shape) * c.noise_std).astype(np.float32)
        out: NDArray[np.uint8] = np.clip(img + 0.5, 0, 255).astype(np.uint8)
        return out

    def render_pair(self, view: SceneView) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
        """The left and right images of one frame."""
        return (
            self.render(view, self.left, self.base_to_left),
            self.render(view, self.right, self.base_to_right),
        )

    def write_pair(
        self,
        writer: RecordingWriter,
        stamp_ns: int,
        images: tuple[NDArray[np.uint8], NDArray[np.uint8]],
    ) -> None:
        """Write rendered left and right images with their CameraInfo."""
        ns = f"/{self.cfg.name}"
        for side, cam, img in (("left", self.left, images[0]), ("right", self.right, images[1])):
            writer.write_image(
                f"{ns}/{side}/image_raw", f"{ns}/{side}/camera_info", stamp_ns, img, cam, "rgb8"
            )

    def write(self, writer: RecordingWriter, view: SceneView) -> None:
        self.write_pair(writer, view.stamp_ns, self.render_pair(view))


#: The name of the pair :func:`with_stereo_rig` adds (topics ``/stereo/left/...``).
STEREO_NAME = "stereo"


def with_stereo_rig(scenario: Scenario, width: int = 512, height: int = 384) -> Scenario:
    """``scenario`` seen through the Bumblebee2-like pair (``synth --rig stereo``).

    The pair (:class:`StereoPairConfig` defaults, at ``width`` x ``height``: the seed's
    processed 512x384, section 4) is added as ``stereo``, replacing any stereo pair, and the
    frame rate becomes the camera's 20 fps (section 4). The Kinect, whose colour camera's
    id buffer decides ground-truth visibility, takes the left camera's place, size and
    field of view, so that the ground truth counts whom the pair can see. People, robot
    path and room are unchanged; the name gains ``_stereo``.
    """
    pair = StereoPairConfig(name=STEREO_NAME, width=width, height=height)
    half_h = exact.atan(exact.tan(math.radians(pair.hfov_deg) / 2.0) * height / width)
    data = scenario.model_dump(mode="json")
    data["name"] = f"{scenario.name}_stereo"
    data["sensor"].update(
        rate_hz=20.0,
        width=width,
        height=height,
        hfov_deg=pair.hfov_deg,
        vfov_deg=math.degrees(2.0 * half_h),
        depth_decimation=4 if width % 4 == 0 and height % 4 == 0 else 1,
    )
    data["robot"].update(camera_x=pair.x, camera_height=pair.z, camera_tilt_deg=pair.tilt_deg)
    rig = [r for r in data["rig"] if r["kind"] != "stereo_pair" and r["name"] != STEREO_NAME]
    data["rig"] = [*rig, pair.model_dump(mode="json")]
    return parse_scenario(data, f"{scenario.name} with the stereo rig")
