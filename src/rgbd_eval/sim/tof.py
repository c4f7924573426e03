"""Static time-of-flight depth cameras modelled on the Kinect for Xbox One (seed 003, 4.3).

The seed's simulated sensor has the Kinect v2's properties: 512x424 depth at 30 Hz, noise
that depends on the depth and on the pixel's distance from the image centre, "at 5 m a
standard deviation of 5 mm for most of the pixels" (4.3.3). The model (the rig's
``static_depth`` sensor, :mod:`rgbd_eval.sim.rig_sensors`; its noise functions,
:func:`~rgbd_eval.sim.sensor.tof_depth`, are in :mod:`rgbd_eval.sim.sensor`):

``sigma(z, rho) = noise_k * z^2 * (1 + off_centre_gain * rho^2)`` with ``rho`` the pixel's
distance from the principal point over the half-diagonal (0 at the centre, ~1 in a corner):
a ToF camera's return signal falls with the square of the distance and towards the image
border (its illumination's vignetting), and its noise rises as the signal falls. 5 mm at 5 m
is ``noise_k = 0.0002``. ``extra_noise_m`` adds the seed's Fig. 10 Gaussian noise on top.
Pixels are invalid outside the working range, with probability ``edge_dropout`` on depth
edges (the mixed "flying" pixels the Kinect SDK discards) and ``random_dropout`` anywhere.

:class:`TofRig` renders a scenario's static depth cameras in memory (no recording), with
the same bytes as ``rgbd-eval synth`` writes before the 16UC1 millimetre quantisation: the
sensitivity analyses re-run the detector on the same rendered frames.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.rig_sensors import StaticDepthCamera
from rgbd_eval.sim.scenario import Scenario
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.types import CameraModel, GroundTruthObject, Pose

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class TofImage:
    """One camera's depth image at one instant."""

    name: str
    depth: F32
    camera: CameraModel
    pose: Pose


@dataclass(frozen=True, eq=False)
class TofFrame:
    """All static cameras' images at one instant, and every present person's position."""

    index: int
    stamp_ns: int
    images: list[TofImage]
    ground_truth: list[GroundTruthObject]


class TofRig:
    """Renders a scenario's ``static_depth`` rig sensors in memory, frame by frame.

    Ground truth counts every person present (as ``truth_visibility: present``).
    """

    def __init__(self, scenario: Scenario, seed: int | None = None) -> None:
        self.scenario = scenario
        self._sim = Simulator(scenario, seed)
        #: (stream number as in synth, camera)
        self._cameras = [
            (k, StaticDepthCamera(c, "world"))
            for k, c in enumerate(scenario.rig)
            if isinstance(c, StaticDepthConfig)
        ]
        if not self._cameras:
            raise ValueError(f"scenario {scenario.name!r} has no static_depth camera in its rig")

    @property
    def names(self) -> list[str]:
        return [cam.cfg.name for _, cam in self._cameras]

    @property
    def n_frames(self) -> int:
        return self.scenario.n_frames

    def frame(self, index: int) -> TofFrame:
        """Render frame ``index`` (depends only on the seed and the index)."""
        if not 0 <= index < self.n_frames:
            raise ValueError(f"index={index} must be in [0, {self.n_frames})")
        images = []
        for k, cam in self._cameras:
            view = self._sim.scene_view(index, k)
            images.append(TofImage(cam.cfg.name, cam.render_depth(view), cam.camera, cam.pose))
        stamp = self.scenario.stamp_ns(index)
        gt = [
            GroundTruthObject(index, stamp, pid, None, (xy[0], xy[1], top / 2.0))
            for pid, _, top, xy in self._sim.people_meshes(self._sim.time(index))
        ]
        return TofFrame(index, stamp, images, gt)

    def frames(self) -> Iterator[TofFrame]:
        for i in range(self.n_frames):
            yield self.frame(i)
