"""The Kinect v1 sensor model: pure functions from ideal images to sensor output.

Depth (structured light): the ideal depth z becomes a disparity ``b f / z`` in
pixels; Gaussian noise of constant disparity sigma ``k b f`` gives a depth
sigma ``k z^2`` (seed 000, Figure 6.1: error proportional to the distance
squared); the disparity is quantised to ``1/subpixel`` pixel (the Kinect's
1/8 pixel), so the depth step grows as ``z^2 / (b f subpixel)``. Pixels are
invalid (NaN) outside [min_range, max_range] (seed 000, 2.1: poor beyond 8 m),
at random on depth edges, on dark and on shiny surfaces, and where the
projector's pattern is occluded (the shadow left of foreground objects, found
by ray casting in :mod:`rgbd_eval.sim.simulate` and passed in as a dropout of 1).
The disparity focal length is the full 640x480 one even when the image is
published decimated (QVGA/QQVGA, seed 000 3.2.2): the sensor measures at full
resolution.

RGB: a slow exposure gain and Gaussian pixel noise.

Time of flight (the rig's ``static_depth`` cameras, seed 003 4.3): depth noise growing with
the square of the distance and towards the image border, dropout on edges and at random
(:func:`tof_depth`; the model is described in :mod:`rgbd_eval.sim.tof`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from rgbd_eval import exact
from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.scenario import Sensor
from rgbd_eval.types import CameraModel

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]

#: Depth assigned to "nothing hit" when looking for edges (far beyond any range).
_FAR = 1.0e3


def depth_sigma(z: F64 | float, k: float) -> F64:
    """Standard deviation of the depth error at depth z: ``k z^2`` (seed 000, Figure 6.1)."""
    return np.asarray(k * np.square(z), dtype=np.float64)


def quantisation_step(z: F64 | float, baseline_m: float, focal_px: float, subpixel: int) -> F64:
    """Depth step between adjacent quantised disparities at depth z (first order)."""
    return np.asarray(np.square(z) / (baseline_m * focal_px * subpixel), dtype=np.float64)


def depth_edges(z: F32, jump: float) -> NDArray[np.bool_]:
    """Pixels whose 3x3 neighbourhood spans a relative depth jump above ``jump``."""
    if not 0.0 < jump <= 1.0:
        raise ValueError(f"jump={jump} must be in (0, 1]")
    zz = np.where(np.isfinite(z), z, _FAR).astype(np.float32)
    hi = ndimage.maximum_filter(zz, size=3, mode="nearest")
    lo = ndimage.minimum_filter(zz, size=3, mode="nearest")
    out: NDArray[np.bool_] = (hi - lo) > jump * lo
    return out


def noisy_depth(
    z: F32,
    dropout: F32,
    sensor: Sensor,
    focal_px: float,
    rng: np.random.Generator,
) -> F32:
    """Sensor depth from ideal depth ``z`` (NaN: nothing) and per-pixel dropout probability.

    Always draws two full arrays from ``rng`` so that the stream stays aligned
    frame after frame.
    """
    if z.shape != dropout.shape:
        raise ValueError(f"dropout shape {dropout.shape} differs from depth shape {z.shape}")
    bf = sensor.baseline_m * focal_px
    gauss = exact.standard_normal(rng, z.shape)
    uniform = rng.random(z.shape)
    valid = np.isfinite(z) & (z > 0)
    zz = np.where(valid, z, 1.0).astype(np.float64)
    disparity = bf / zz + gauss * (sensor.depth_noise_k * bf)
    if sensor.quantise:
        q = float(sensor.disparity_subpixel)
        disparity = np.round(disparity * q) / q
    with np.errstate(divide="ignore"):
        out = np.where(disparity > 0, bf / disparity, np.nan)
    keep = valid & (zz >= sensor.min_range_m) & (zz <= sensor.max_range_m) & (uniform >= dropout)
    return np.where(keep & np.isfinite(out), out, np.nan).astype(np.float32)


def dropout_probability(
    edges: NDArray[np.bool_],
    dark: NDArray[np.bool_],
    shiny: NDArray[np.bool_],
    sensor: Sensor,
) -> F32:
    """Per-pixel invalid probability: independent causes combine as 1 - prod(1 - p)."""
    keep = np.ones(edges.shape, dtype=np.float64)
    keep *= np.where(edges, 1.0 - sensor.edge_dropout, 1.0)
    keep *= np.where(dark, 1.0 - sensor.dark_dropout, 1.0)
    keep *= np.where(shiny, 1.0 - sensor.shiny_dropout, 1.0)
    return (1.0 - keep).astype(np.float32)


def exposure_gain(t: float, amplitude: float, period_s: float) -> float:
    """Slow auto-exposure drift: two incommensurate sines around 1."""
    if period_s <= 0:
        raise ValueError(f"period_s={period_s} must be positive")
    a = exact.sin(2.0 * math.pi * t / period_s)
    b = exact.sin(2.0 * math.pi * t / (0.37 * period_s) + 1.0)
    return 1.0 + amplitude * (0.7 * a + 0.3 * b)


def noise_bank(shape: tuple[int, ...], count: int, rng: np.random.Generator) -> F32:
    """``count`` standard-normal noise images (drawing fresh noise per frame is the slowest step)."""
    if count < 1:
        raise ValueError(f"count={count} must be at least 1")
    bank: F32 = exact.standard_normal(rng, (count, *shape), dtype=np.float32)
    return bank


def frame_noise(bank: F32, rng: np.random.Generator) -> F32:
    """A per-frame noise image: a random bank entry, circularly shifted by a random offset."""
    k = int(rng.integers(len(bank)))
    dy = int(rng.integers(bank.shape[1]))
    dx = int(rng.integers(bank.shape[2]))
    out: F32 = np.roll(bank[k], (dy, dx), axis=(0, 1))
    return out


def noisy_rgb(clean: F32, gain: float, noise_std: float, noise: F32) -> NDArray[np.uint8]:
    """8-bit RGB from a clean float image: exposure gain, Gaussian noise, rounding, clipping."""
    if noise.shape != clean.shape:
        raise ValueError(f"noise shape {noise.shape} differs from image shape {clean.shape}")
    img = clean.astype(np.float32) * np.float32(gain) + noise * np.float32(noise_std)
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


# ----------------------------------------------------------------------------- time of flight


def radial_position(camera: CameraModel) -> F32:
    """Per pixel, the distance from the principal point over the half-diagonal, squared."""
    u = (np.arange(camera.width, dtype=np.float32) - np.float32(camera.cx)) / np.float32(
        camera.width / 2.0
    )
    v = (np.arange(camera.height, dtype=np.float32) - np.float32(camera.cy)) / np.float32(
        camera.height / 2.0
    )
    rho2: F32 = ((u[None, :] * u[None, :] + v[:, None] * v[:, None]) / np.float32(2.0)).astype(
        np.float32
    )
    return rho2


def tof_sigma(z: F64, rho2: F32, cfg: StaticDepthConfig) -> F64:
    """Noise std per pixel: the sensor's own (depth and off-centre) and the added noise."""
    own = cfg.noise_k * z * z * (1.0 + cfg.off_centre_gain * rho2)
    sigma: F64 = np.sqrt(own * own + cfg.extra_noise_m * cfg.extra_noise_m)
    return sigma


def tof_depth(ideal: NDArray[np.floating], cfg: StaticDepthConfig, rng: np.random.Generator) -> F32:
    """Sensor depth (m, NaN invalid) from the ideal depth (NaN: nothing hit).

    Draws one normal image when there is noise and one uniform image when there is
    dropout, so that an ideal camera's output and its random stream stay as they were.
    """
    z = np.asarray(ideal, dtype=np.float64)
    valid = np.isfinite(z)
    if cfg.noise_k > 0.0 or cfg.extra_noise_m > 0.0:
        camera = _camera_shape(z.shape)
        rho2 = (
            radial_position(camera) if cfg.off_centre_gain > 0.0 else np.zeros(z.shape, np.float32)
        )
        z = z + exact.standard_normal(rng, z.shape) * tof_sigma(np.where(valid, z, 0.0), rho2, cfg)
    keep = valid & (z >= cfg.min_range_m) & (z <= cfg.max_range_m)
    if cfg.edge_dropout > 0.0 or cfg.random_dropout > 0.0:
        edges = depth_edges(np.asarray(ideal, dtype=np.float32), cfg.edge_jump)
        p_drop = np.where(edges, cfg.edge_dropout, cfg.random_dropout)
        keep &= rng.random(z.shape) >= p_drop
    out: F32 = np.where(keep, z, np.nan).astype(np.float32)
    return out


def _camera_shape(shape: tuple[int, ...]) -> CameraModel:
    """A camera of this image size with a centred principal point (for ``rho``)."""
    h, w = shape
    return CameraModel(w, h, 1.0, 1.0, (w - 1) / 2.0, (h - 1) / 2.0)
