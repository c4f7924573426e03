"""cielniak2010 tracker: independent thermal particle filters and a sequential detector.

Seed 004, section 3 and the introduction: "A sequential detector initialises an
independent tracking filter for each new person appearing in the image, using thermal
information. A single filter is automatically deleted when it stops tracking a person."
Track-before-detect: the tracker reads the thermal image of every frame
(``needs_frame``) and ignores the detections (the method's detector passes none).

The sequential detector is one more particle filter spread uniformly over the image and
the size range, penalised by every tracking filter's estimate (the interaction factor,
so it searches where no one is tracked yet). When its estimate scores at least
``start_score`` and its particles have gathered (position spread below
``start_spread`` heights) it starts a tracking filter there and spreads out again; it
also spreads out again after ``restart_frames`` frames without a start. A tracking
filter is deleted after ``lost_frames`` consecutive frames scoring below ``stop_score``.

Boxes are mapped from the thermal to the colour image, where the ground truth lives, by
the affine transform of parallel cameras at a nominal depth (seed 004, section 4.1: the
baseline is small compared to the distance to persons, so an affine transform aligns the
images), computed once from the two CameraInfos and the tf between the cameras.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from rgbd_eval.config import ComponentConfig
from rgbd_eval.plugins import DetectionContract, StreamSpec, TrackerSpec, register_tracker
from rgbd_eval.track.silhouette import GradientImage, Silhouette, silhouette_scores
from rgbd_eval.track.thermal_pf import FilterParams, ThermalParticleFilter, step_filters
from rgbd_eval.types import Box2D, Detection, Frame, Stream, TrackOutput, Visibility

_ZERO_C_K = 273.15


class Cielniak2010TrackerConfig(ComponentConfig):
    """Tracker settings; every value and its source is in ``configs/methods/cielniak2010.yaml``."""

    name: Literal["cielniak2010"] = "cielniak2010"
    n_particles: int = Field(300, ge=10, le=100_000)
    detector_particles: int = Field(1000, ge=10, le=100_000)
    pos_noise: float = Field(0.1, ge=0.0, description="heights per sqrt(s)")
    vel_noise: float = Field(0.5, ge=0.0, description="heights/s per sqrt(s)")
    size_noise: float = Field(0.1, ge=0.0, description="log-size per sqrt(s)")
    score_scale: float = Field(0.2, gt=0.0, description="K/px")
    rho: float = Field(2.0, ge=0.0, description="interaction: K/px lost at full overlap")
    min_height_px: float = Field(50.0, gt=0.0)
    max_height_px: float = Field(400.0, gt=0.0)
    start_score: float = Field(0.6, ge=0.0, description="K/px to start a filter")
    start_spread: float = Field(0.1, gt=0.0, description="particle spread to start, heights")
    restart_frames: int = Field(15, ge=1)
    stop_score: float = Field(0.3, ge=0.0, description="K/px below which a filter is losing")
    lost_frames: int = Field(10, ge=1)
    alignment_depth_m: float = Field(3.0, gt=0.0, description="nominal depth of the affine map")
    seed: int = Field(0, ge=0)


@dataclass(frozen=True)
class Affine:
    """``colour = scale * thermal + offset`` per axis."""

    scale: tuple[float, float]
    offset: tuple[float, float]

    @staticmethod
    def between(thermal: Stream, colour: Stream, depth_m: float) -> Affine:
        """Parallel cameras: the intrinsics ratio, and the baseline's parallax at ``depth_m``."""
        t, c = thermal.camera, colour.camera
        colour_T_thermal = colour.pose.inverse().compose(thermal.pose)
        bx, by, _ = colour_T_thermal.translation
        sx, sy = c.fx / t.fx, c.fy / t.fy
        return Affine(
            (sx, sy),
            (c.cx - sx * t.cx + c.fx * bx / depth_m, c.cy - sy * t.cy + c.fy * by / depth_m),
        )

    def box(self, u0: float, v0: float, u1: float, v1: float) -> Box2D:
        (sx, sy), (ox, oy) = self.scale, self.offset
        return Box2D(sx * u0 + ox, sy * v0 + oy, sx * (u1 - u0), sy * (v1 - v0))


@dataclass
class _Track:
    track_id: int
    filter: ThermalParticleFilter
    weak_frames: int = 0


def temperature_image(stream: Stream) -> np.ndarray:
    """Thermal counts as temperature: mono16 centikelvin to deg C; mono8 kept as counts."""
    img = stream.image.astype(np.float32)
    if stream.encoding == "mono16":
        return img / np.float32(100.0) - np.float32(_ZERO_C_K)
    return img


class Cielniak2010Tracker:
    """Multi-person thermal tracking with one particle filter per person."""

    def __init__(self, config: Cielniak2010TrackerConfig, contract: DetectionContract) -> None:
        self.cfg = config
        self.rng = np.random.default_rng(config.seed)
        self.silhouette = Silhouette.head_and_body()
        common = {
            "pos_noise": config.pos_noise,
            "vel_noise": config.vel_noise,
            "size_noise": config.size_noise,
            "score_scale": config.score_scale,
            "rho": config.rho,
            "min_height": config.min_height_px,
            "max_height": config.max_height_px,
        }
        self.params = FilterParams(n_particles=config.n_particles, **common)
        self.detector_params = FilterParams(n_particles=config.detector_particles, **common)
        self.tracks: list[_Track] = []
        self.next_id = 1
        self.detector: ThermalParticleFilter | None = None
        self.detector_age = 0
        self.last_stamp: int | None = None
        self.affine: Affine | None = None
        self.last_timings: Mapping[str, float] = {}

    def _new_detector(self, shape: tuple[int, int]) -> ThermalParticleFilter:
        self.detector_age = 0
        return ThermalParticleFilter.uniform(
            self.detector_params,
            self.silhouette,
            shape,
            (self.cfg.min_height_px, self.cfg.max_height_px),
            self.rng,
        )

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        if frame is None:
            raise ValueError("the cielniak2010 tracker reads the thermal image of every frame")
        t0 = time.perf_counter()
        thermal = frame.stream("thermal")
        grad = GradientImage.of(temperature_image(thermal))
        dt = 1.0 / 30.0 if self.last_stamp is None else max(stamp_ns - self.last_stamp, 0) / 1e9
        self.last_stamp = stamp_ns
        t1 = time.perf_counter()
        step_filters([t.filter for t in self.tracks], grad, dt)
        kept = []
        for t in self.tracks:
            t.weak_frames = t.weak_frames + 1 if t.filter.score < self.cfg.stop_score else 0
            if t.weak_frames < self.cfg.lost_frames:
                kept.append(t)
        self.tracks = kept
        t2 = time.perf_counter()
        self._detect(grad, dt)
        t3 = time.perf_counter()
        out = self._outputs(frame, thermal)
        self.last_timings = {
            "gradient": t1 - t0,
            "filters": t2 - t1,
            "detector": t3 - t2,
            "output": time.perf_counter() - t3,
        }
        return out

    def _detect(self, grad: GradientImage, dt: float) -> None:
        c = self.cfg
        if self.detector is None or self.detector_age >= c.restart_frames:
            self.detector = self._new_detector(grad.shape)
        det = self.detector
        det.step(grad, dt, [t.filter.box() for t in self.tracks])
        self.detector_age += 1
        est = det.estimate
        spread = float(np.hypot(*det.particles[:, :2].std(axis=0))) / max(float(est[2]), 1e-9)
        if det.score >= c.start_score and spread <= c.start_spread:
            state = est.copy()
            state[3:5] = 0.0  # at rest
            f = ThermalParticleFilter.around(self.params, self.silhouette, state, 0.05, self.rng)
            f.estimate = state
            f.score = float(silhouette_scores(grad, self.silhouette, state[None, :])[0])
            self.tracks.append(_Track(self.next_id, f))
            self.next_id += 1
            self.detector = self._new_detector(grad.shape)

    def _outputs(self, frame: Frame, thermal: Stream) -> list[TrackOutput]:
        colour = frame.streams.get("colour")
        if colour is not None and self.affine is None:
            self.affine = Affine.between(thermal, colour, self.cfg.alignment_depth_m)
        affine = self.affine or Affine((1.0, 1.0), (0.0, 0.0))
        out = []
        for t in self.tracks:
            u0, v0, u1, v1 = (float(x) for x in t.filter.box())
            x, y = _ground_point(thermal, (u0 + u1) / 2.0, v1)
            out.append(
                TrackOutput(t.track_id, x, y, 0.0, affine.box(u0, v0, u1, v1), Visibility.VISIBLE)
            )
        return out


def _ground_point(stream: Stream, u: float, v: float) -> tuple[float, float]:
    """Where the ray through pixel (u, v) meets the floor (world z = 0); the camera's own
    ground position when the ray does not go down."""
    cam = stream.camera
    ray = np.array([(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0])
    R = stream.pose.rotation_matrix()
    d = R @ ray
    o = np.asarray(stream.pose.translation, dtype=np.float64)
    if d[2] >= -1e-6 or o[2] <= 0.0:
        return float(o[0]), float(o[1])
    p = o + d * (-o[2] / d[2])
    return float(p[0]), float(p[1])


register_tracker(
    TrackerSpec(
        "cielniak2010",
        Cielniak2010TrackerConfig,
        Cielniak2010Tracker,
        needs_frame=True,
        streams=(StreamSpec("thermal"), StreamSpec("colour", required=False)),
        stages=("gradient", "filters", "detector", "output"),
        summary="thermal particle filters with a sequential detector (seed 004, section 3)",
    )
)
