"""The ``thermal`` rig sensor: a long-wave infrared camera beside the colour camera.

The scene's temperatures come from the renderer's per-pixel object ids and materials:
people's skin (``MAT_SKIN``) and clothing (everything else of a person), the cool room
(walls, floor, and empty space at ambient temperature), and warm distractors (obstacles
listed by index in ``warm_obstacles``: a radiator, a monitor, a lamp). Surfaces seen at
a grazing angle lose part of their contrast to the ambient (emissivity falls off towards
grazing, ``limb_contrast``), which gives people the soft rims of real thermal images.
The camera then blurs (optics, Gaussian ``blur_px``), adds temporal noise (``netd_k``,
noise-equivalent temperature difference) and writes ``mono16`` raw counts in
centikelvin (``counts = 100 * kelvin``, the "TLinear" output of radiometric
microbolometers), so :func:`counts_to_celsius` recovers temperatures.

It is mounted on the colour camera: ``baseline_m`` to its right and ``offset_y_m`` below,
with parallel optical axes (seed 004, section 2: "the colour and thermal camera are
mounted close to each other"). Topics ``/<name>/image_raw`` and ``/<name>/camera_info``,
tf ``<colour optical frame> -> <name>_optical_frame`` in ``/tf_static``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.meshes import MAT_FLOOR, MAT_SKIN
from rgbd_eval.sim.rig import SceneView, pinhole_from_fov
from rgbd_eval.sim.rig_config import ThermalCameraConfig
from rgbd_eval.types import Pose

if TYPE_CHECKING:
    from rgbd_eval.io.writer import RecordingWriter
    from rgbd_eval.sim.render import Hits

#: Raw counts per kelvin of the ``mono16`` image (centikelvin).
COUNTS_PER_KELVIN = 100.0
_ZERO_C_K = 273.15
#: Object ids (see :mod:`rgbd_eval.sim.world`): people are 1 .. OBSTACLE_ID_BASE - 1.
_OBSTACLE_ID_BASE = 1_000_000


def celsius_to_counts(t_c: NDArray[np.float64]) -> NDArray[np.uint16]:
    """Temperatures (deg C) to ``mono16`` counts (centikelvin, rounded, clipped)."""
    counts = np.rint((t_c + _ZERO_C_K) * COUNTS_PER_KELVIN)
    return np.clip(counts, 0, 65535).astype(np.uint16)


def counts_to_celsius(counts: NDArray[np.integer]) -> NDArray[np.float64]:
    """``mono16`` counts back to deg C."""
    out: NDArray[np.float64] = counts.astype(np.float64) / COUNTS_PER_KELVIN - _ZERO_C_K
    return out


class ThermalCamera:
    """Renders and writes the thermal image of each frame."""

    def __init__(self, config: ThermalCameraConfig, world_frame: str) -> None:
        self.cfg = config
        self.world_frame = world_frame
        c = config
        self.camera = pinhole_from_fov(
            c.width, c.height, c.hfov_deg, c.vfov_deg, f"{c.name}_optical_frame"
        )
        #: colour_optical_T_thermal_optical (parallel axes)
        self.offset = Pose((c.baseline_m, c.offset_y_m, 0.0))

    def static_transforms(self) -> list[tuple[str, str, Pose]]:
        from rgbd_eval.sim.rig import RGB_FRAME  # the colour frame of the simulated rig

        return [(RGB_FRAME, self.camera.frame_id, self.offset)]

    def pose(self, view: SceneView) -> Pose:
        """world_T_thermal_optical at this instant."""
        return view.rgb_pose.compose(self.offset)

    def write(self, writer: RecordingWriter, view: SceneView) -> None:
        ns = f"/{self.cfg.name}"
        counts = self.render_counts(view)
        writer.write_image(
            f"{ns}/image_raw", f"{ns}/camera_info", view.stamp_ns, counts, self.camera, "mono16"
        )

    def temperatures(self, view: SceneView) -> NDArray[np.float64]:
        """The ideal (sharp, noiseless) apparent temperature image (deg C)."""
        if view.surface is None:
            raise ValueError("the thermal camera needs the scene's per-pixel object ids")
        hits = view.render(self.camera, self.pose(view))
        ids, mats = view.surface(hits)
        return self.surface_temperatures(hits, ids, mats)

    def surface_temperatures(
        self, hits: Hits, ids: NDArray[np.int32], mats: NDArray[np.int32]
    ) -> NDArray[np.float64]:
        """Apparent temperature per pixel from object ids, materials and view angles."""
        c = self.cfg
        t = np.full(ids.shape, c.ambient_c, dtype=np.float64)
        t[mats == MAT_FLOOR] = c.floor_c
        person = (ids >= 1) & (ids < _OBSTACLE_ID_BASE)
        t[person] = c.clothing_c
        t[person & (mats == MAT_SKIN)] = c.skin_c
        for index, temp in c.warm_obstacles.items():
            t[ids == _OBSTACLE_ID_BASE + index] = temp
        if c.limb_contrast > 0.0:
            n = hits.face_normals.astype(np.float64)
            d = hits.directions.astype(np.float64)
            cos = np.abs(exact.dot(n, d)) / np.maximum(exact.norm(n) * exact.norm(d), 1e-9)
            keep = 1.0 - c.limb_contrast * (1.0 - cos)
            t = np.where(ids >= 0, c.ambient_c + (t - c.ambient_c) * keep, t)
        return t

    def render_counts(self, view: SceneView) -> NDArray[np.uint16]:
        """The published image: blurred, noisy, in centikelvin counts."""
        t = self.temperatures(view)
        c = self.cfg
        if c.blur_px > 0.0:
            t = exact.gaussian_filter(t, c.blur_px)
        # always draw the noise so the stream stays aligned whatever netd_k is
        t = t + exact.standard_normal(view.rng, t.shape) * c.netd_k
        return celsius_to_counts(t)
