"""Static time-of-flight depth cameras modelled on the Kinect for Xbox One (seed 003, 4.3).

The seed's simulated sensor has the Kinect v2's properties: 512x424 depth at 30 Hz, noise
that depends on the depth and on the pixel's distance from the image centre, "at 5 m a
standard deviation of 5 mm for most of the pixels" (4.3.3). The model here:

``sigma(z, rho) = sigma_5m * (z / 5 m)^2 * (1 + off_centre_gain * rho^2)``, with ``rho`` the
pixel's distance from the principal point over the half-diagonal (0 at the centre, 1 in a
corner); a ToF camera's signal falls with the square of the distance and towards the image
border (vignetting of its illumination), and its noise with the signal. ``extra_noise_m``
adds the seed's Fig. 10 Gaussian noise on top (independent per pixel). Pixels are invalid
outside the working range, with probability ``edge_dropout`` on depth edges (the mixed
"flying" pixels the Kinect SDK discards) and ``random_dropout`` anywhere.

The field of view (70.6 x 60 degrees) is Microsoft's specification of the Kinect v2 depth
camera; its working range is given as 0.5-4.5 m, but it returns depth to 8 m, used here so
that a 5 m x 5 m scene is seen from its corners.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from rgbd_eval.errors import ConfigError
from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.writer import RecordingWriter, StreamOptions
from rgbd_eval.sim.meshes import concatenate, rotation_y, rotation_z
from rgbd_eval.sim.render import Hits, make_scene, overlay_hits, render_hits
from rgbd_eval.sim.scenario import Scenario
from rgbd_eval.sim.sensor import depth_edges
from rgbd_eval.sim.simulate import Simulator, people_window
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, GroundTruthObject, Pose

F32 = NDArray[np.float32]

#: Random stream of the ToF cameras' noise (apart from the Kinect v1 simulator's streams).
_STREAM_TOF = 11
#: The frame the cameras are placed in by /tf_static (the scenario's world, z up).
WORLD_FRAME = "world"


class TofCamera(BaseModel):
    """One static ToF depth camera: where it stands and its sensor properties."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(
        min_length=1, description="camera name; its optical frame is <name>_depth_optical_frame"
    )
    x: float
    y: float
    z: float = Field(gt=0.0, le=10.0, description="height of the optical centre (m)")
    yaw_deg: float = Field(0.0, ge=-360.0, le=360.0, description="viewing direction, from +x")
    pitch_deg: float = Field(0.0, ge=-10.0, le=90.0, description="downward tilt (0: horizontal)")
    width: int = Field(512, ge=16, le=2048, description="Kinect v2 depth: 512x424")
    height: int = Field(424, ge=16, le=2048)
    hfov_deg: float = Field(70.6, gt=10.0, lt=170.0, description="Kinect v2 depth: 70.6 deg")
    vfov_deg: float = Field(60.0, gt=10.0, lt=170.0, description="Kinect v2 depth: 60 deg")
    sigma_5m: float = Field(0.005, ge=0.0, le=0.5, description="noise std at 5 m (seed 003, 4.3.3)")
    off_centre_gain: float = Field(
        1.0, ge=0.0, le=10.0, description="relative noise growth from the centre to a corner"
    )
    extra_noise_m: float = Field(0.0, ge=0.0, le=1.0, description="added Gaussian noise (Fig. 10)")
    min_range_m: float = Field(0.5, ge=0.0, le=5.0)
    max_range_m: float = Field(8.0, gt=0.5, le=20.0)
    edge_jump: float = Field(0.05, gt=0.0, le=1.0, description="relative jump marking an edge")
    edge_dropout: float = Field(0.5, ge=0.0, le=1.0, description="P(invalid) on a depth edge")
    random_dropout: float = Field(0.002, ge=0.0, le=1.0, description="P(invalid) anywhere")

    @property
    def frame_id(self) -> str:
        return f"{self.name}_depth_optical_frame"

    def camera(self) -> CameraModel:
        """The pinhole model (focal lengths from the field of view, centred principal point)."""
        fx = (self.width / 2.0) / math.tan(math.radians(self.hfov_deg) / 2.0)
        fy = (self.height / 2.0) / math.tan(math.radians(self.vfov_deg) / 2.0)
        return CameraModel(
            self.width,
            self.height,
            fx,
            fy,
            (self.width - 1) / 2.0,
            (self.height - 1) / 2.0,
            (0.0, 0.0, 0.0, 0.0, 0.0),
            self.frame_id,
        )

    def pose(self) -> Pose:
        """``world_T_optical``: yaw about world z, then pitch down about the camera's y."""
        T = np.eye(4)
        T[:3, :3] = rotation_z(math.radians(self.yaw_deg)) @ rotation_y(
            math.radians(self.pitch_deg)
        )
        T[:3, 3] = (self.x, self.y, self.z)
        return Pose.from_matrix(T).compose(OPTICAL_TO_BODY)


class TofCameraList(BaseModel):
    """A file of static ToF cameras (``cameras: [...]``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    cameras: list[TofCamera] = Field(min_length=1)


def load_tof_cameras(path: Path | str) -> list[TofCamera]:
    """Read a camera list YAML; :class:`ConfigError` naming the file and the bad field."""
    p = Path(path)
    try:
        raw = yaml.safe_load(p.read_text())
    except (OSError, yaml.YAMLError) as err:
        raise ConfigError(f"{p}: cannot read the camera list: {err}") from err
    try:
        cameras = TofCameraList.model_validate(raw).cameras
    except ValidationError as err:
        first = err.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "(top level)"
        raise ConfigError(f"{p}: {where}: {first['msg']}") from err
    names = [c.name for c in cameras]
    if len(set(names)) != len(names):
        raise ConfigError(f"{p}: camera names must be unique, got {names}")
    return cameras


def radial_position(camera: CameraModel) -> F32:
    """Per pixel, the distance from the principal point over the half-diagonal, squared."""
    u = (np.arange(camera.width, dtype=np.float32) - np.float32(camera.cx)) / np.float32(
        camera.width / 2.0
    )
    v = (np.arange(camera.height, dtype=np.float32) - np.float32(camera.cy)) / np.float32(
        camera.height / 2.0
    )
    rho2: F32 = ((u[None, :] ** 2 + v[:, None] ** 2) / np.float32(2.0)).astype(np.float32)
    return rho2


def tof_sigma(z: F32, rho2: F32, spec: TofCamera) -> F32:
    """Noise std per pixel: the sensor's own (depth and off-centre) and the added noise."""
    own = spec.sigma_5m * (z / 5.0) ** 2 * (1.0 + spec.off_centre_gain * rho2)
    sigma: F32 = np.sqrt(own * own + spec.extra_noise_m**2).astype(np.float32)
    return sigma


def noisy_tof_depth(z: F32, rho2: F32, spec: TofCamera, rng: np.random.Generator) -> F32:
    """Sensor depth from the ideal depth ``z`` (NaN: nothing hit).

    Always draws two full arrays from ``rng`` so each frame's noise depends only on its seed.
    """
    gauss = rng.standard_normal(z.shape, dtype=np.float32)
    uniform = rng.random(z.shape, dtype=np.float32)
    valid = np.isfinite(z)
    zz = np.where(valid, z, np.float32(1.0))
    out = zz + gauss * tof_sigma(zz, rho2, spec)
    p_drop = np.where(depth_edges(z, spec.edge_jump), spec.edge_dropout, spec.random_dropout)
    keep = valid & (zz >= spec.min_range_m) & (zz <= spec.max_range_m) & (uniform >= p_drop)
    keep &= out > 0
    result: F32 = np.where(keep, out, np.nan).astype(np.float32)
    return result


@dataclass(frozen=True, eq=False)
class TofImage:
    """One camera's depth image at one instant."""

    name: str
    depth: F32
    camera: CameraModel
    pose: Pose


@dataclass(frozen=True, eq=False)
class TofFrame:
    """All cameras' images at one instant, and the people's exact floor positions."""

    index: int
    stamp_ns: int
    images: list[TofImage]
    ground_truth: list[GroundTruthObject]


class TofRig:
    """Renders a scenario's people and static world through static ToF cameras."""

    def __init__(
        self, scenario: Scenario, cameras: list[TofCamera], seed: int | None = None
    ) -> None:
        if not cameras:
            raise ValueError("a ToF rig needs at least one camera")
        names = [c.name for c in cameras]
        if len(set(names)) != len(names):
            raise ValueError(f"camera names must be unique, got {names}")
        self.scenario = scenario
        self.cameras = cameras
        self._sim = Simulator(scenario, seed)
        self.seed = self._sim.seed
        self._models = [c.camera() for c in cameras]
        self._poses = [c.pose() for c in cameras]
        self._rho2 = [radial_position(m) for m in self._models]
        scene = make_scene(self._sim.static)
        self._static: list[Hits] = [
            render_hits(scene, m, p) for m, p in zip(self._models, self._poses, strict=True)
        ]

    @property
    def n_frames(self) -> int:
        return self.scenario.n_frames

    def frame(self, index: int) -> TofFrame:
        """Render frame ``index`` (depends only on the seed and the index)."""
        if not 0 <= index < self.n_frames:
            raise ValueError(f"index={index} must be in [0, {self.n_frames})")
        t = self._sim.time(index)
        stamp = self.scenario.stamp_ns(index)
        people = self._sim.people_meshes(t)
        mesh = concatenate([m for _, m, _, _ in people])
        scene = make_scene(mesh)
        images = []
        for k, spec in enumerate(self.cameras):
            window = people_window(mesh, self._models[k], self._poses[k])
            hits = overlay_hits(self._static[k], scene, window, self._sim.static.n_triangles)
            rng = np.random.default_rng([self.seed, _STREAM_TOF, k, index])
            depth = noisy_tof_depth(hits.depth, self._rho2[k], spec, rng)
            images.append(TofImage(spec.name, depth, self._models[k], self._poses[k]))
        gt = [
            GroundTruthObject(index, stamp, pid, None, (xy[0], xy[1], top / 2.0))
            for pid, _, top, xy in people
        ]
        return TofFrame(index, stamp, images, gt)

    def frames(self) -> Iterator[TofFrame]:
        for i in range(self.n_frames):
            yield self.frame(i)


def tof_topics(name: str) -> tuple[str, str]:
    """A camera's depth image and CameraInfo topics."""
    return f"/{name}/depth/image_raw", f"/{name}/depth/camera_info"


@dataclass(frozen=True)
class TofRecording:
    """What :func:`write_tof_recording` wrote."""

    path: Path
    ground_truth: Path
    frames: int


def write_tof_recording(
    rig: TofRig,
    out_path: Path | str,
    max_frames: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> TofRecording:
    """Render the rig's frames into a recording (see :func:`write_tof_frames`)."""
    total = rig.n_frames if max_frames is None else min(rig.n_frames, max_frames)
    if total < 1:
        raise ValueError(f"max_frames={max_frames} must be at least 1")
    frames = (rig.frame(i) for i in range(total))
    return write_tof_frames(rig.cameras, frames, total, out_path, progress)


def write_tof_frames(
    cameras: list[TofCamera],
    frames: Iterable[TofFrame],
    total: int,
    out_path: Path | str,
    progress: Callable[[int, int], None] | None = None,
) -> TofRecording:
    """Write rendered frames as a depth-only multi-camera recording, plus ``<stem>.gt.csv``.

    One depth topic per camera (16UC1 millimetres, like the Kinect v2), each with its
    CameraInfo; the cameras placed in the ``world`` frame by /tf_static; ground truth on
    ``/ground_truth`` and in the sidecar. The container follows the suffix (.bag, .mcap);
    both files appear atomically.
    """
    out = Path(out_path)
    truth: list[GroundTruthObject] = []
    written = 0
    with RecordingWriter(out, options=StreamOptions(depth_encoding="16UC1"), overwrite=True) as w:
        for frame in frames:
            if written == 0:
                for spec in cameras:
                    w.write_static_transform(
                        frame.stamp_ns, WORLD_FRAME, spec.frame_id, spec.pose()
                    )
            for im in frame.images:
                topic, info = tof_topics(im.name)
                w.write_depth(frame.stamp_ns, im.depth, im.camera, topic=topic, info_topic=info)
            w.write_ground_truth(frame.stamp_ns, WORLD_FRAME, frame.ground_truth)
            truth.extend(frame.ground_truth)
            written += 1
            if progress is not None:
                progress(written, total)
    csv_path = out.with_name(out.stem + ".gt.csv")
    write_csv(csv_path, truth)
    return TofRecording(out, csv_path, written)
