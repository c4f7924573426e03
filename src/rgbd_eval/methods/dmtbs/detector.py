"""The DMT-BS detector (seed 003, section 3): static depth cameras -> density map -> blobs.

Per camera: background subtraction on the Z image (:mod:`.background`), foreground points to
floor coordinates with the one-time calibration (:mod:`.calibration`), a density map
(:mod:`.density`). The cameras' maps merge by pixel-wise maximum; blur, threshold, closing and
connected components give the blobs (:mod:`.blobs`), one detection each, carrying its cells
(``footprint``) for the tracker's blob splitting.

The seed's parameter table did not survive; the values chosen, with their reasons, are in
``methods/dmtbs/method.yaml`` and in the field descriptions below.
"""

from __future__ import annotations

import enum
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig
from rgbd_eval.detect.background import (
    BackgroundSubtractor,
    Mog2Background,
    RunningAverageBackground,
)
from rgbd_eval.detect.blobs import Blob, blob_mask, find_blobs
from rgbd_eval.detect.calibration import (
    CalibrationFile,
    CameraCalibration,
    floor_from_depth,
    load_calibration,
    plane_in_world,
    world_floor_frame,
)
from rgbd_eval.detect.density import CameraMap, FloorGrid, camera_density, merge_maps
from rgbd_eval.errors import ConfigError
from rgbd_eval.plugins import (
    DetectionContract,
    DetectorSpec,
    StreamSpec,
    register_detector,
    role_kind,
)
from rgbd_eval.types import Box2D, CameraModel, Detection, Frame, Pose

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]


class BackgroundMethod(enum.Enum):
    """Which background subtractor (seed 003, 3.1 and Fig. 10)."""

    RUNNING_AVERAGE = "running_average"
    MOG2 = "mog2"


class FloorSource(enum.Enum):
    """Where the floor plane comes from (seed 003, section 3)."""

    #: ``world`` when the recording places its cameras in a world frame (tf, odometry) or a
    #: calibration file is given, else ``first_frame`` (a lone camera in its own frame)
    AUTO = "auto"
    #: the world frame's z = 0 plane (tf from the recording), or the calibration file's floor
    WORLD = "world"
    #: found in the first depth image of the first camera (RANSAC)
    FIRST_FRAME = "first_frame"


class DmtbsDetectorConfig(ComponentConfig):
    """The DMT-BS detector's parameters (values and reasons: methods/dmtbs/method.yaml)."""

    name: Literal["dmtbs"] = "dmtbs"
    background: BackgroundMethod = Field(
        BackgroundMethod.RUNNING_AVERAGE, description="background subtractor (Fig. 10: mog2)"
    )
    init_frames: int = Field(30, ge=1, description="frames that initialise the background")
    background_time_constant_s: float = Field(
        10.0, gt=0.0, description="time constant of the background's running average (s)"
    )
    foreground_margin_m: float = Field(
        0.1, gt=0.0, description="nearer than the background by more than this is foreground (m)"
    )
    mog2_var_threshold: float = Field(
        16.0, gt=0.0, description="MOG2 squared Mahalanobis distance to a mode (OpenCV default)"
    )
    mog2_sigma_init_m: float = Field(0.05, gt=0.0, description="MOG2 initial mode std (m)")
    mog2_sigma_min_m: float = Field(0.01, gt=0.0, description="MOG2 smallest mode std (m)")
    mog2_sigma_max_m: float = Field(0.2, gt=0.0, description="MOG2 largest mode std (m)")
    min_height_m: float = Field(
        1.0, ge=0.0, description="only points higher above the floor count (seed 003, 3.2: 1 m)"
    )
    roi: tuple[float, float, float, float] = Field(
        (-5.0, -5.0, 5.0, 5.0), description="floor region x_min, y_min, x_max, y_max (m)"
    )
    cell_m: float = Field(0.02, gt=0.0, le=0.2, description="density map cell side (m)")
    blur_sigma_m: float = Field(
        0.02, ge=0.0, le=1.0, description="Gaussian blur std (seed 003, 3.3: 2 cm)"
    )
    density_threshold: float = Field(
        0.5,
        gt=0.0,
        le=1000.0,
        description="blob threshold on the blurred map (m^2 surface per m^2 floor)",
    )
    closing_radius_m: float = Field(  # its kernel is (2 r / cell_m + 1)^2 cells
        0.1, ge=0.0, le=1.0, description="disk radius of the closing (seed 003, 3.3: 10 cm)"
    )
    min_blob_area_m2: float = Field(
        0.041, ge=0.0, description="smallest blob surface kept (m^2; seed 003, 3.4: small objects)"
    )
    floor: FloorSource = Field(FloorSource.AUTO, description="where the floor plane comes from")
    floor_band_m: float = Field(0.03, gt=0.0, description="RANSAC inlier band of the floor (m)")
    floor_max_tilt_deg: float = Field(
        30.0, gt=0.0, lt=90.0, description="largest floor tilt from the world's up (deg)"
    )
    calibration: Path | None = Field(
        None, description="calibration YAML with world_T_optical per camera (overrides tf)"
    )

    @model_validator(mode="after")
    def _check(self) -> DmtbsDetectorConfig:
        x0, y0, x1, y1 = self.roi
        if not (x1 > x0 and y1 > y0):
            raise ValueError(f"roi={self.roi} must have x_max > x_min and y_max > y_min")
        cells = ((x1 - x0) / self.cell_m) * ((y1 - y0) / self.cell_m)
        if cells > 4e6:
            raise ValueError(
                f"roi={self.roi} at cell_m={self.cell_m} has {cells:.0f} cells (max 4e6)"
            )
        if not self.mog2_sigma_min_m <= self.mog2_sigma_init_m <= self.mog2_sigma_max_m:
            raise ValueError(
                f"MOG2 stds must satisfy min ({self.mog2_sigma_min_m}) <= init "
                f"({self.mog2_sigma_init_m}) <= max ({self.mog2_sigma_max_m})"
            )
        return self

    def grid(self) -> FloorGrid:
        x0, y0, x1, y1 = self.roi
        return FloorGrid(x0, y0, x1, y1, self.cell_m)


@dataclass(frozen=True)
class DepthView:
    """One static depth camera's image at one instant, with its intrinsics and world pose."""

    name: str
    depth: F32
    camera: CameraModel
    world_from_optical: Pose


@dataclass(frozen=True)
class DensityResult:
    """What one step produced: the detections and the maps behind them (for plots and tests)."""

    detections: list[Detection]
    density: F32
    blobs: NDArray[np.int32]


#: The detector's stages, in order (for bench).
STAGES = ("background", "density", "blobs")


class _Camera:
    """A camera's one-time calibration, cached rays and background model."""

    def __init__(self, calibration: CameraCalibration, background: BackgroundSubtractor) -> None:
        self.calibration = calibration
        self.rays = calibration.camera.rays()
        self.background = background


class DmtbsDetector:
    """Density-map detection over one or more static depth cameras; one instance per sequence."""

    def __init__(self, config: DmtbsDetectorConfig) -> None:
        self._cfg = config
        self._grid = config.grid()
        self._file: CalibrationFile | None = (
            load_calibration(config.calibration) if config.calibration is not None else None
        )
        self._floor_T_world: Pose | None = None
        self._cameras: dict[str, _Camera] = {}
        self._last_ns: int | None = None
        #: Seconds per stage, summed over the sequence (tests, in-memory runs).
        self.stage_seconds = dict.fromkeys(STAGES, 0.0)
        self._last_timings: dict[str, float] = dict.fromkeys(STAGES, 0.0)

    @property
    def last_timings(self) -> Mapping[str, float]:
        """Seconds of each stage of the last call."""
        return self._last_timings

    def detect(self, frame: Frame) -> list[Detection]:
        """Detections from every depth stream of the frame (``depth``, ``depth_2``, ...)."""
        roles = sorted((r for r in frame.streams if role_kind(r) == "depth"), key=_role_order)
        views = []
        for role in roles:
            stream = frame.streams[role]
            image = np.asarray(stream.image, dtype=np.float32)
            views.append(DepthView(role, image, stream.camera, stream.pose))
        return self.detect_views(frame.stamp_ns, views, frame.has_odometry).detections

    def detect_views(
        self, stamp_ns: int, views: list[DepthView], world_is_floor: bool = True
    ) -> DensityResult:
        """Detections in the world frame from the synchronised depth images of all cameras.

        ``world_is_floor``: the views' poses place them in a z-up world whose z = 0 is the
        floor (what ``floor: auto`` then uses); False for a camera in its own frame.
        """
        if not views:
            raise ValueError("DMT-BS needs at least one depth camera")
        dt = 0.0 if self._last_ns is None else (stamp_ns - self._last_ns) * 1e-9
        self._last_ns = stamp_ns
        cfg = self._cfg
        timings = dict.fromkeys(STAGES, 0.0)
        maps: list[CameraMap] = []
        for view in views:
            cam = self._camera(view, world_is_floor)
            t0 = time.perf_counter()
            foreground = cam.background.apply(view.depth, dt)
            t1 = time.perf_counter()
            maps.append(
                camera_density(
                    view.depth, foreground, cam.calibration, self._grid, cfg.min_height_m, cam.rays
                )
            )
            t2 = time.perf_counter()
            timings["background"] += t1 - t0
            timings["density"] += t2 - t1
        t0 = time.perf_counter()
        density = merge_maps([m.density for m in maps])
        binary, blurred = blob_mask(
            density, self._grid, cfg.blur_sigma_m, cfg.density_threshold, cfg.closing_radius_m
        )
        blobs, labels = find_blobs(binary, blurred, self._grid, cfg.min_blob_area_m2)
        detections = self._detections(blobs, labels, maps)
        timings["blobs"] = time.perf_counter() - t0
        self._last_timings = timings
        for stage, seconds in timings.items():
            self.stage_seconds[stage] += seconds
        return DensityResult(detections, density, labels)

    # ------------------------------------------------------------------ helpers

    def _camera(self, view: DepthView, world_is_floor: bool) -> _Camera:
        cam = self._cameras.get(view.name)
        if cam is not None:
            return cam
        world_T_optical = (
            self._file.pose(view.camera.frame_id or view.name)
            if self._file is not None
            else view.world_from_optical
        )
        if self._floor_T_world is None:
            self._floor_T_world = self._floor(view, world_T_optical, world_is_floor)
        calibration = CameraCalibration(
            view.name, view.camera, self._floor_T_world.compose(world_T_optical)
        )
        cam = _Camera(calibration, self._background())
        self._cameras[view.name] = cam
        return cam

    def _floor(self, view: DepthView, world_T_optical: Pose, world_is_floor: bool) -> Pose:
        cfg = self._cfg
        source = cfg.floor
        if source is FloorSource.AUTO:
            world = world_is_floor or self._file is not None
            source = FloorSource.WORLD if world else FloorSource.FIRST_FRAME
        if source is FloorSource.WORLD:
            plane = self._file.floor_plane() if self._file is not None else np.array([0, 0, 1.0, 0])
            return world_floor_frame(plane)
        up = world_T_optical.rotation_matrix().T @ np.array([0.0, 0.0, 1.0])
        try:
            plane_optical = floor_from_depth(
                view.depth, view.camera, up, cfg.floor_band_m, cfg.floor_max_tilt_deg
            )
        except ValueError as err:
            raise ConfigError(f"detector.floor={source.value}: {err}") from err
        return world_floor_frame(plane_in_world(plane_optical, world_T_optical))

    def _background(self) -> BackgroundSubtractor:
        cfg = self._cfg
        if cfg.background is BackgroundMethod.MOG2:
            return Mog2Background(
                cfg.init_frames,
                cfg.background_time_constant_s,
                cfg.mog2_var_threshold,
                cfg.mog2_sigma_init_m**2,
                cfg.mog2_sigma_min_m**2,
                cfg.mog2_sigma_max_m**2,
            )
        return RunningAverageBackground(
            cfg.init_frames, cfg.background_time_constant_s, cfg.foreground_margin_m
        )

    def _detections(
        self, blobs: list[Blob], labels: NDArray[np.int32], maps: list[CameraMap]
    ) -> list[Detection]:
        if not blobs:
            return []
        heights = np.full(len(blobs) + 1, -np.inf)
        for m in maps:
            np.maximum.at(heights, labels.ravel()[m.cells], m.heights.astype(np.float64))
        floor_T_world = self._floor_T_world
        if floor_T_world is None:
            raise RuntimeError("detections asked for before any camera was calibrated")
        world_T_floor = floor_T_world.inverse()
        out = []
        for k, blob in enumerate(blobs, start=1):
            cells3 = np.column_stack([blob.cells, np.zeros(blob.cells.shape[0])])
            footprint = world_T_floor.transform_points(cells3)[:, :2]
            centre = world_T_floor.transform_points(np.array([[*blob.centroid, 0.0]]))[0]
            height = float(heights[k]) if math.isfinite(heights[k]) else 0.0
            out.append(
                Detection(
                    position=(float(centre[0]), float(centre[1]), float(centre[2])),
                    height=height,
                    confidence=blob.peak_density,
                    box2d=Box2D(0.0, 0.0, 0.0, 0.0),
                    footprint=footprint,
                )
            )
        return out


def _role_order(role: str) -> int:
    """``depth`` first, then ``depth_2``, ``depth_3``, ..."""
    _, _, number = role.rpartition("_")
    return int(number) if number.isdigit() else 1


def _contract(config: DmtbsDetectorConfig) -> DetectionContract:
    """Floor positions on the density map's grid, no image boxes, each blob's cells."""
    return DetectionContract(world_position=True, box2d=False, position_resolution_m=config.cell_m)


SPEC = register_detector(
    DetectorSpec(
        name="dmtbs",
        config_model=DmtbsDetectorConfig,
        factory=DmtbsDetector,
        streams=(StreamSpec("depth", multiple=True),),
        contract=_contract,
        stages=STAGES,
        summary="background subtraction, density map, blobs; 1..N static depth cameras "
        "(seed 003, section 3)",
        warmup=lambda c: (
            c.init_frames,
            f"its background initialisation (detector.init_frames={c.init_frames})",
        ),
    )
)
