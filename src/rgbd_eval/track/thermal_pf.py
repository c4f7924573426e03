"""Particle filter of one person in the thermal image, track-before-detect (seed 004, section 3).

The state is ``(u, v, h, du, dv, a)``: the silhouette's centre and height (pixels), its
image velocity (px/s) and its width factor ``a`` (a person is about 0.65 times as wide
in profile as from the front: with a fixed width, walkers seen from the side were fitted
25-40% too small). Prediction is constant velocity with Gaussian diffusion (position
and velocity noise proportional to ``h``, so a near person moves more pixels), and a
log-normal random walk of the size. The weight of a particle is ``exp(L)`` with ``L`` the
log-likelihood the caller supplies (the thermal silhouette score over its scale, plus
the colour and height terms of :mod:`rgbd_eval.methods.cielniak2010.tracker`), times the
interaction factor: several filters run side by side, and a particle overlapping another
filter's estimate loses ``rho * overlap`` of log-likelihood (overlap: intersection over
the smaller box, so that a small silhouette on a part of a tracked person, such as its
legs, is penalised as fully as one on the whole person; seed 004, sections 3 and 6: the
interaction factor rho prevents "target fetching", two filters converging on one person,
and section 6 changes it per pair when one person occludes the other). The penalty is in
log-likelihood units because the likelihood is sharp: a bounded factor such as
``1 - rho * IoU`` is outweighed by the likelihood of a hotter person.
Resampling is systematic (Kitagawa 1996). All randomness comes from one
:class:`numpy.random.Generator`: a run is bit-identical for a seed.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.track.silhouette import Silhouette, state_boxes

F64 = NDArray[np.float64]
#: States (N, 6) -> log-likelihood (N,).
LogLikelihood = Callable[[F64], F64]
#: Another filter's box ``(u0, v0, u1, v1)`` and the interaction ``rho`` towards it.
Neighbour = tuple[F64, float]
#: (u, v, h, du, dv, a)
STATE_SIZE = 6


@dataclass(frozen=True)
class FilterParams:
    """Particle filter settings (values and sources in ``methods/cielniak2010/method.yaml``)."""

    n_particles: int = 300
    pos_noise: float = 0.1  # position diffusion, silhouette heights per sqrt(s)
    vel_noise: float = 0.5  # velocity random walk, heights/s per sqrt(s)
    size_noise: float = 0.1  # log-size random walk per sqrt(s)
    min_height: float = 20.0  # px
    max_height: float = 1000.0  # px
    aspect_noise: float = 0.2  # log width-factor random walk per sqrt(s)
    min_aspect: float = 0.55  # width factor range: profile .. front
    max_aspect: float = 1.1

    def __post_init__(self) -> None:
        if self.n_particles < 2:
            raise ValueError(f"n_particles={self.n_particles} must be at least 2")
        if not 0.0 < self.min_height < self.max_height:
            raise ValueError(f"heights [{self.min_height}, {self.max_height}] must be increasing")
        if not 0.0 < self.min_aspect <= self.max_aspect:
            raise ValueError(f"aspects [{self.min_aspect}, {self.max_aspect}] must be increasing")


def box_iou(boxes: F64, box: F64, *, of_smaller: bool = False) -> F64:
    """IoU of boxes (N, 4) with one box (4,), all ``(u0, v0, u1, v1)``; with ``of_smaller``
    the intersection over the smaller area (1 when one box lies inside the other)."""
    iw = np.clip(np.minimum(boxes[:, 2], box[2]) - np.maximum(boxes[:, 0], box[0]), 0.0, None)
    ih = np.clip(np.minimum(boxes[:, 3], box[3]) - np.maximum(boxes[:, 1], box[1]), 0.0, None)
    inter = iw * ih
    a = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    b = (box[2] - box[0]) * (box[3] - box[1])
    union = np.minimum(a, b) if of_smaller else a + b - inter
    out: F64 = inter / np.maximum(union, 1e-9)
    return out


def systematic_resample(weights: F64, rng: np.random.Generator) -> NDArray[np.intp]:
    """Indices drawn by systematic resampling (one uniform offset, N evenly spaced points)."""
    n = len(weights)
    positions = (rng.random() + np.arange(n)) / n
    cumulative = np.cumsum(weights)
    cumulative[-1] = 1.0  # guard against rounding
    idx: NDArray[np.intp] = np.searchsorted(cumulative, positions, side="right")
    return np.minimum(idx, n - 1)


class ThermalParticleFilter:
    """One person's filter: predict, weigh against the thermal gradient, resample."""

    def __init__(
        self,
        params: FilterParams,
        silhouette: Silhouette,
        particles: F64,
        rng: np.random.Generator,
    ) -> None:
        if particles.shape != (params.n_particles, STATE_SIZE):
            raise ValueError(
                f"particles shape {particles.shape} must be ({params.n_particles}, {STATE_SIZE})"
            )
        self.params = params
        self.silhouette = silhouette
        self.particles = particles.astype(np.float64, copy=True)
        self.rng = rng
        self.estimate: F64 = self.particles.mean(axis=0)

    @staticmethod
    def uniform(
        params: FilterParams,
        silhouette: Silhouette,
        image_shape: tuple[int, int],
        height_range: tuple[float, float],
        rng: np.random.Generator,
    ) -> ThermalParticleFilter:
        """Particles spread over the whole image and a size range, at rest (detection)."""
        H, W = image_shape
        lo, hi = height_range
        n = params.n_particles
        p = np.zeros((n, STATE_SIZE))
        p[:, 2] = np.exp(rng.uniform(math.log(lo), math.log(hi), n))
        p[:, 5] = rng.uniform(params.min_aspect, params.max_aspect, n)
        p[:, 0] = rng.uniform(0.0, W - 1.0, n)
        p[:, 1] = rng.uniform(0.0, H - 1.0, n)
        return ThermalParticleFilter(params, silhouette, p, rng)

    @staticmethod
    def around(
        params: FilterParams,
        silhouette: Silhouette,
        state: F64,
        spread: float,
        rng: np.random.Generator,
    ) -> ThermalParticleFilter:
        """Particles around ``state`` (u, v, h, du, dv, a): Gaussian, sigma ``spread * h``."""
        n = params.n_particles
        h = float(state[2])
        p = np.tile(np.asarray(state, dtype=np.float64), (n, 1))
        p[:, 0:2] += rng.standard_normal((n, 2)) * spread * h
        p[:, 2] *= np.exp(rng.standard_normal(n) * spread)
        return ThermalParticleFilter(params, silhouette, p, rng)

    def box(self) -> F64:
        """The estimate's box ``(u0, v0, u1, v1)``."""
        box: F64 = state_boxes(self.estimate[None, :], self.silhouette.width_ratio)[0]
        return box

    def predict(self, dt: float) -> None:
        """Constant velocity plus diffusion over ``dt`` seconds."""
        if dt < 0.0:
            raise ValueError(f"dt={dt} must not be negative")
        q = self.params
        p = self.particles
        n = len(p)
        s = math.sqrt(dt)
        noise = self.rng.standard_normal((n, STATE_SIZE))
        h = p[:, 2].copy()
        p[:, 0] += p[:, 3] * dt + noise[:, 0] * q.pos_noise * h * s
        p[:, 1] += p[:, 4] * dt + noise[:, 1] * q.pos_noise * h * s
        p[:, 3] += noise[:, 3] * q.vel_noise * h * s
        p[:, 4] += noise[:, 4] * q.vel_noise * h * s
        p[:, 2] = np.clip(h * np.exp(noise[:, 2] * q.size_noise * s), q.min_height, q.max_height)
        a = p[:, 5] * np.exp(noise[:, 5] * q.aspect_noise * s)
        p[:, 5] = np.clip(a, q.min_aspect, q.max_aspect)

    def update(self, loglik: LogLikelihood, others: Sequence[Neighbour] = ()) -> None:
        """Weigh by ``loglik`` and the interaction with ``others``, estimate, resample."""
        ll = np.asarray(loglik(self.particles), dtype=np.float64)
        if others:
            boxes = state_boxes(self.particles, self.silhouette.width_ratio)
            for box, rho in others:
                if rho > 0.0:
                    ll = ll - rho * box_iou(boxes, np.asarray(box), of_smaller=True)
        w = np.exp(ll - ll.max())
        w /= w.sum()
        self.estimate = w @ self.particles
        self.particles = self.particles[systematic_resample(w, self.rng)]

    def step(self, loglik: LogLikelihood, dt: float, others: Sequence[Neighbour] = ()) -> None:
        self.predict(dt)
        self.update(loglik, others)
