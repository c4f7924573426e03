"""cielniak2010 tracker: independent thermal particle filters and a sequential detector.

Seed 004, section 3 and the introduction: "A sequential detector initialises an
independent tracking filter for each new person appearing in the image, using thermal
information. A single filter is automatically deleted when it stops tracking a person."
Track-before-detect: the tracker reads the thermal image of every frame
(``needs_frame``) and ignores the detections (the method's detector passes none).

Per frame:

1. Each tracking filter (:mod:`rgbd_eval.track.thermal_pf`) is predicted and weighed by
   the log-likelihood ``score / score_scale + log p(height)``: the silhouette's thermal
   contrast (:mod:`rgbd_eval.track.silhouette`, K) and the plausibility of the standing
   height the silhouette implies on the floor (:mod:`rgbd_eval.methods.cielniak2010.person_geometry`,
   our addition), minus the distance of the colour moments of its head, torso and legs
   to the person's adaptive colour model over ``colour_scale`` (section 4; the colour
   image is aligned by the affine map below), with the interaction ``rho`` towards the
   other filters' estimates. The moments are of the person's own pixels: the warm pixels
   of the thermal image mapped onto the colour image (``colour_mask``). The colour term is
   weighted by the person's colour reliability, its contrast to the image's mean colour
   against the image noise (:func:`rgbd_eval.track.colour_moments.reliability`): about 1
   in the light, about 0 in the dark, where colour would otherwise mislead. A filter
   behind another one (section 6: pairwise
   :func:`rgbd_eval.methods.cielniak2010.occlusion.order`, overlap of the boxes at least
   ``occlusion_overlap``) coasts on its motion model, and neither penalises nor is
   penalised by the others, for at most ``max_occluded_frames``.
2. A filter whose estimate scores below ``stop_score`` for ``lost_frames`` frames in a
   row, or whose centre leaves the image, is deleted; its colour model is remembered
   ``reid_memory_frames`` for re-identification (section 6). The colour model of a filter
   seen clearly (score at least ``start_score``, its box overlapping no other filter's)
   adapts at rate ``colour_alpha``.
3. The sequential detector proposes person-shaped warm regions
   (:mod:`rgbd_eval.methods.cielniak2010.warm_regions`) away from the tracked persons; a proposal that
   scores at least ``start_score`` and implies a standing height within the prior's
   range, and is seen again (IoU >= 0.3) in ``confirm_frames`` consecutive frames,
   starts a filter, with the id of the nearest remembered person whose colour moments lie
   within ``reid_distance``, when the new person's colour reliability is at least
   ``reid_min_reliability``; else a new one.

Boxes are mapped from the thermal to the colour image, where the ground truth lives, by
the affine transform of parallel cameras at a nominal depth (seed 004, section 4.1: the
baseline is small compared to the distance to persons, so an affine transform aligns the
images), computed once from the two CameraInfos and the tf between the cameras.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import cv2
import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig
from rgbd_eval.methods.cielniak2010.occlusion import order, overlap
from rgbd_eval.methods.cielniak2010.person_geometry import (
    HeightPrior,
    height_log_prior,
    implied_heights,
)
from rgbd_eval.methods.cielniak2010.warm_regions import (
    WarmRegionParams,
    WarmRegions,
    room_median,
    warm_regions,
)
from rgbd_eval.plugins import DetectionContract, StreamSpec, TrackerSpec, register_tracker
from rgbd_eval.track.colour_moments import (
    ColourModel,
    IntegralMoments,
    channel_means,
    moment_distances,
    noise_sigma,
    person_moments_many,
    reliability,
)
from rgbd_eval.track.silhouette import (
    ContrastParams,
    Silhouette,
    room_temperature,
    silhouette_scores,
    state_boxes,
)
from rgbd_eval.track.thermal_pf import (
    F64,
    FilterParams,
    Neighbour,
    ThermalParticleFilter,
    box_iou,
)
from rgbd_eval.types import Box2D, Detection, Frame, Stream, TrackOutput, Visibility

_ZERO_C_K = 273.15
#: A proposal is the same as the last frame's when their boxes overlap this much (IoU).
_SAME_PROPOSAL_IOU = 0.3
#: A proposal overlapping a tracked person's box this much (over the smaller box) is theirs.
_TRACKED_OVERLAP = 0.3
#: A warm component is a filter's own when this much of the smaller of the two overlaps.
_OWN_COMPONENT = 0.5


class Cielniak2010TrackerConfig(ComponentConfig):
    """Tracker settings; every value and its source is in ``methods/cielniak2010/method.yaml``."""

    name: Literal["cielniak2010"] = "cielniak2010"
    n_particles: int = Field(200, ge=10, le=100_000)
    pos_noise: float = Field(0.1, ge=0.0, description="heights per sqrt(s)")
    vel_noise: float = Field(0.5, ge=0.0, description="heights/s per sqrt(s)")
    size_noise: float = Field(0.1, ge=0.0, description="log-size per sqrt(s)")
    score_scale: float = Field(0.5, gt=0.0, description="K: likelihood exp(score / score_scale)")
    rho: float = Field(10.0, ge=0.0, description="interaction: log-likelihood lost at full overlap")
    contrast_offset: float = Field(0.05, gt=0.0, le=0.5, description="share of the height")
    contrast_saturation_k: float = Field(8.0, gt=0.0)
    surround: float = Field(0.15, gt=0.0, description="share of h outside the contour")
    surround_weight: float = Field(0.5, ge=0.0, description="K of score per K of warm surround")
    min_height_px: float = Field(20.0, gt=0.0)
    max_height_px: float = Field(400.0, gt=0.0)
    ground_prior: bool = Field(True, description="weigh by the implied standing height")
    person_min_m: float = Field(1.4, gt=0.0)
    person_max_m: float = Field(2.05, gt=0.0)
    person_sigma_m: float = Field(0.1, gt=0.0)
    warm_contrast_k: float = Field(3.0, gt=0.0, description="proposal: above the room median")
    warm_max_c: float = Field(40.0, description="proposal: below this (radiators, lamps)")
    warm_elongation: float = Field(1.5, gt=0.0, description="proposal: height / width")
    warm_fill: float = Field(0.3, ge=0.0, le=1.0, description="proposal: pixels / box")
    start_score: float = Field(2.5, ge=0.0, description="K: a proposal's score to start")
    confirm_frames: int = Field(3, ge=1)
    stop_score: float = Field(1.5, ge=0.0, description="K below which a filter is losing")
    lost_frames: int = Field(10, ge=1)
    occlusion_handling: bool = Field(True, description="section 6: order overlapping persons")
    occlusion_overlap: float = Field(0.3, gt=0.0, le=1.0, description="over the smaller box")
    max_occluded_frames: int = Field(60, ge=1, description="an occluded filter coasts this long")
    colour: bool = Field(True, description="section 4: colour moments in the likelihood")
    colour_scale: float = Field(10.0, gt=0.0, description="moment distance per log-likelihood")
    colour_alpha: float = Field(0.05, ge=0.0, le=1.0, description="adaptive update rate")
    colour_stride: int = Field(2, ge=1, le=16, description="colour image subsampling")
    colour_noise_factor: float = Field(
        3.0, gt=0.0, description="contrast this many noise sigmas gives colour half weight"
    )
    reid_min_reliability: float = Field(
        0.5, ge=0.0, le=1.0, description="colour trust to re-use an id"
    )
    colour_mask: bool = Field(True, description="moments of the warm (person) pixels only")
    colour_min_pixels: int = Field(4, ge=1, description="fewer masked pixels: region unmeasured")
    reid_distance: float = Field(
        40.0, ge=0.0, description="section 6: moment distance to re-use an id"
    )
    reid_memory_frames: int = Field(150, ge=0, description="how long a lost person is remembered")
    alignment_depth_m: float = Field(3.0, gt=0.0, description="nominal depth of the affine map")
    seed: int = Field(0, ge=0)

    @model_validator(mode="after")
    def _check(self) -> Cielniak2010TrackerConfig:
        for low, high in (("min_height_px", "max_height_px"), ("person_min_m", "person_max_m")):
            if not getattr(self, low) < getattr(self, high):
                raise ValueError(
                    f"{low}={getattr(self, low)} must be below {high}={getattr(self, high)}"
                )
        return self


@dataclass(frozen=True)
class Affine:
    """``colour = scale * thermal + offset`` per axis."""

    scale: tuple[float, float]
    offset: tuple[float, float]

    @staticmethod
    def between(thermal: Stream, colour: Stream, depth_m: float) -> Affine:
        """Parallel cameras: the intrinsics ratio, and the baseline's parallax at ``depth_m``.

        With lens distortion the map is not affine: the affine map (per axis) fitted by least
        squares to a grid of thermal pixels carried to the colour image at ``depth_m``.
        """
        t, c = thermal.camera, colour.camera
        colour_T_thermal = colour.pose.inverse().compose(thermal.pose)
        bx, by, _ = colour_T_thermal.translation
        if t.lens is not None or c.lens is not None:
            u, v = np.meshgrid(np.linspace(0, t.width - 1, 17), np.linspace(0, t.height - 1, 13))
            points = t.points_at(u.ravel(), v.ravel(), depth_m) + np.array([bx, by, 0.0])
            uv = c.project(points)
            (sx, ox), (sy, oy) = (
                np.polyfit(u.ravel(), uv[:, 0], 1),
                np.polyfit(v.ravel(), uv[:, 1], 1),
            )
            return Affine((float(sx), float(sy)), (float(ox), float(oy)))
        sx, sy = c.fx / t.fx, c.fy / t.fy
        return Affine(
            (sx, sy),
            (c.cx - sx * t.cx + c.fx * bx / depth_m, c.cy - sy * t.cy + c.fy * by / depth_m),
        )

    def warp(
        self, mask: NDArray[np.bool_], shape: tuple[int, int], stride: int
    ) -> NDArray[np.bool_]:
        """A thermal-image mask on the colour image subsampled by ``stride`` (``shape``)."""
        (sx, sy), (ox, oy) = self.scale, self.offset
        m = np.array([[sx / stride, 0.0, ox / stride], [0.0, sy / stride, oy / stride]])
        out = cv2.warpAffine(
            mask.astype(np.uint8), m, (shape[1], shape[0]), flags=cv2.INTER_NEAREST
        )
        return np.asarray(out, dtype=bool)

    def box(self, u0: float, v0: float, u1: float, v1: float) -> Box2D:
        (sx, sy), (ox, oy) = self.scale, self.offset
        return Box2D(sx * u0 + ox, sy * v0 + oy, sx * (u1 - u0), sy * (v1 - v0))


@dataclass
class _Track:
    track_id: int
    filter: ThermalParticleFilter
    colour: ColourModel | None = None
    score: float = 0.0
    weak_frames: int = 0
    occluded_frames: int = 0


@dataclass(frozen=True)
class _Lost:
    track_id: int
    colour: ColourModel
    frame: int


@dataclass(frozen=True)
class _Proposal:
    state: F64
    seen: int


def temperature_image(stream: Stream) -> np.ndarray:
    """Thermal counts as temperature: mono16 centikelvin to deg C; mono8 kept as counts."""
    return _temperatures(stream.image, stream.encoding)


def _temperatures(counts: np.ndarray, encoding: str) -> NDArray[np.float32]:
    img = counts.astype(np.float32)
    if encoding == "mono16":
        out: NDArray[np.float32] = img / np.float32(100.0) - np.float32(_ZERO_C_K)
        return out
    return img


def median_temperature(stream: Stream, temp: NDArray[np.float32]) -> float:
    """``float(np.median(temp))`` of ``temp = temperature_image(stream)``, the same number.

    Integer counts (mono8, mono16) by a histogram, several times faster than sorting: the
    map from counts to temperatures does not decrease, so the middle counts map to the
    middle temperatures, and ``np.median`` of those two takes their mean as it would.
    """
    counts = stream.image
    if counts.dtype not in (np.uint8, np.uint16) or counts.size == 0:
        return room_median(temp)
    flat = counts.ravel()
    low = int(flat.min())
    cumulative = np.cumsum(np.bincount(flat - np.asarray(low, dtype=flat.dtype)))
    n = flat.size
    ranks = np.array(sorted({(n - 1) // 2, n // 2}))
    middle = np.searchsorted(cumulative, ranks, side="right") + low
    return room_median(_temperatures(middle.astype(counts.dtype), stream.encoding))


def _every_kth_pixel(image: NDArray[np.uint8], k: int) -> NDArray[np.uint8]:
    """``image[::k, ::k]``, contiguous. By OpenCV's nearest-pixel resize where that picks the
    same pixels (``k`` a power of two dividing both sides: its source column ``floor(x *
    k)`` is then exact), three times faster than numpy's strided copy."""
    h, w = image.shape[:2]
    if k > 1 and k & (k - 1) == 0 and h % k == 0 and w % k == 0 and image.dtype == np.uint8:
        out = cv2.resize(image, (w // k, h // k), interpolation=cv2.INTER_NEAREST)
        return np.asarray(out, dtype=np.uint8).reshape(h // k, w // k, *image.shape[2:])
    return np.ascontiguousarray(image[::k, ::k])


def _state_of_box(box: F64, width_ratio: float, aspect: tuple[float, float]) -> F64:
    """A filter state (u, v, h, 0, 0, a) whose box is ``box``."""
    u0, v0, u1, v1 = (float(x) for x in box)
    h = v1 - v0
    a = min(max((u1 - u0) / (width_ratio * h), aspect[0]), aspect[1])
    return np.array([(u0 + u1) / 2.0, (v0 + v1) / 2.0, h, 0.0, 0.0, a])


class Cielniak2010Tracker:
    """Multi-person thermal tracking with one particle filter per person."""

    def __init__(self, config: Cielniak2010TrackerConfig, contract: DetectionContract) -> None:
        self.cfg = c = config
        self.rng = np.random.default_rng(c.seed)
        self.silhouette = Silhouette.head_and_body()
        self.params = FilterParams(
            n_particles=c.n_particles,
            pos_noise=c.pos_noise,
            vel_noise=c.vel_noise,
            size_noise=c.size_noise,
            min_height=c.min_height_px,
            max_height=c.max_height_px,
        )
        self.contrast = ContrastParams(
            c.contrast_offset,
            saturation=c.contrast_saturation_k,
            surround=c.surround,
            surround_weight=c.surround_weight,
        )
        self.height_prior = HeightPrior(c.person_min_m, c.person_max_m, c.person_sigma_m)
        self.warm = WarmRegionParams(
            c.warm_contrast_k, c.warm_max_c, c.min_height_px, c.warm_elongation, c.warm_fill
        )
        self.tracks: list[_Track] = []
        self.proposals: list[_Proposal] = []
        self.lost: list[_Lost] = []
        self.frame_index = 0
        self.integral: IntegralMoments | None = None
        self.noise = 0.0
        self.surround_room = 0.0
        self.background: F64 = np.zeros(3)
        self.next_id = 1
        self.last_stamp: int | None = None
        self.affine: Affine | None = None
        self.last_timings: Mapping[str, float] = {}

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        if frame is None:
            raise ValueError("the cielniak2010 tracker reads the thermal image of every frame")
        t0 = time.perf_counter()
        thermal = frame.stream("thermal")
        temp = temperature_image(thermal)
        room = median_temperature(thermal, temp)
        self.surround_room = room_temperature(temp)
        colour = frame.streams.get("colour")
        if colour is not None and self.affine is None:
            self.affine = Affine.between(thermal, colour, self.cfg.alignment_depth_m)
        previous, self.integral = self.integral, None
        if self.cfg.colour and colour is not None and colour.image.ndim == 3:
            k = self.cfg.colour_stride
            image = _every_kth_pixel(colour.image, k)
            mask = None
            if self.cfg.colour_mask and self.affine is not None:
                mask = self.affine.warp(self._warm_mask(temp, room), image.shape[:2], k)
            self.integral = IntegralMoments.of(
                image, mask, self.cfg.colour_min_pixels, reuse=previous
            )
            self.noise = noise_sigma(image)
            self.background = channel_means(image)
        self.frame_index += 1
        dt = 1.0 / 30.0 if self.last_stamp is None else max(stamp_ns - self.last_stamp, 0) / 1e9
        self.last_stamp = stamp_ns
        t1 = time.perf_counter()
        self._track(temp, thermal, frame.streams.get("colour"), dt)
        t2 = time.perf_counter()
        regions = warm_regions(temp, self.warm, room)
        self._detect(temp, thermal, regions)
        t3 = time.perf_counter()
        out = self._outputs(frame, thermal, regions)
        self.last_timings = {
            "thermal": t1 - t0,
            "filters": t2 - t1,
            "detector": t3 - t2,
            "output": time.perf_counter() - t3,
        }
        return out

    def _warm_mask(self, temp: NDArray[np.float32], room: float) -> NDArray[np.bool_]:
        """Pixels in the band of human surface temperature (as :func:`warm_regions`), the
        room being at ``room`` (:func:`room_median`)."""
        out: NDArray[np.bool_] = (temp > room + self.cfg.warm_contrast_k) & (
            temp < self.cfg.warm_max_c
        )
        return out

    def _observe(self, states: F64) -> F64:
        """``(N, R, 3, C)`` colour moments of the body regions of N states (section 4)."""
        if self.integral is None or self.affine is None:
            raise ValueError("no colour image to observe")
        (sx, sy), (ox, oy) = self.affine.scale, self.affine.offset
        k = float(self.cfg.colour_stride)
        b = state_boxes(states, self.silhouette.width_ratio)
        colour_boxes = np.stack(
            [(sx * b[:, 0] + ox) / k, (sy * b[:, 1] + oy) / k, (sx * b[:, 2] + ox) / k,
             (sy * b[:, 3] + oy) / k],
            axis=1,
        )  # fmt: skip
        return person_moments_many(self.integral, colour_boxes)

    def _reliability(self, model: ColourModel) -> float:
        """How far this person's colour can be trusted now: its contrast to the image's mean
        colour against the image noise (:func:`reliability`); ~1 in the light, ~0 in the dark."""
        return reliability(
            model.contrast(self.background), self.noise, self.cfg.colour_noise_factor
        )

    def _colour_distances(self, model: ColourModel, states: F64) -> F64:
        d = moment_distances(model.moments, self._observe(states))
        out: F64 = np.where(np.isfinite(d), d, 0.0)  # nothing measured: no evidence
        return out

    def _loglik(
        self,
        temp: NDArray[np.float32],
        thermal: Stream,
        states: F64,
        *,
        model: ColourModel | None,
    ) -> F64:
        """Thermal contrast over its scale, plus the standing-height log-prior, minus the colour
        moments' distance to the person's model over its scale (section 4)."""
        ll: F64 = (
            silhouette_scores(temp, self.silhouette, states, self.contrast, self.surround_room)
            / self.cfg.score_scale
        )
        if self.cfg.ground_prior:
            heights = implied_heights(thermal.camera, thermal.pose, states)
            ll = ll + height_log_prior(self.height_prior, heights)
        if model is not None and self.integral is not None:
            weight = self._reliability(model) / self.cfg.colour_scale
            ll = ll - weight * self._colour_distances(model, states)
        return ll

    def _occluded(self, temp: NDArray[np.float32], colour: Stream | None) -> set[int]:
        """Indices of the filters behind another one (section 6), by pairwise :func:`order`."""
        if not self.cfg.occlusion_handling:
            return set()
        boxes = [t.filter.box() for t in self.tracks]
        image = None if colour is None else colour.image
        behind = set()
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                if overlap(boxes[i], boxes[j]) >= self.cfg.occlusion_overlap:
                    front = order(boxes[i], boxes[j], temp, image, self.affine)
                    behind.add(j if front == 0 else i)
        return behind

    def _track(
        self, temp: NDArray[np.float32], thermal: Stream, colour: Stream | None, dt: float
    ) -> None:
        """Step every filter. An occluded filter (section 6) coasts on its motion model and
        neither penalises nor is penalised by the others; its occluder tracks as usual."""
        H, W = temp.shape
        behind = self._occluded(temp, colour)
        stepped = []
        for i, t in enumerate(self.tracks):
            if i in behind:
                t.filter.predict(dt)
                t.filter.estimate = t.filter.particles.mean(axis=0)
                t.occluded_frames += 1
                continue
            t.occluded_frames = 0
            others: list[Neighbour] = [
                (o.filter.box(), self.cfg.rho)
                for j, o in enumerate(self.tracks)
                if j != i and j not in behind
            ]
            t.filter.step(
                functools.partial(self._loglik, temp, thermal, model=t.colour), dt, others
            )
            stepped.append(t)
        if stepped:  # the estimates' scores in one call (each row is computed on its own)
            estimates = np.stack([t.filter.estimate for t in stepped])
            scores = silhouette_scores(
                temp, self.silhouette, estimates, self.contrast, self.surround_room
            )
            for t, score in zip(stepped, scores, strict=True):
                t.score = float(score)
        kept = []
        for i, t in enumerate(self.tracks):
            est = t.filter.estimate
            inside = 0.0 <= est[0] < W and 0.0 <= est[1] < H
            if i in behind:
                alive = inside and t.occluded_frames <= self.cfg.max_occluded_frames
            else:
                t.weak_frames = t.weak_frames + 1 if t.score < self.cfg.stop_score else 0
                alive = inside and t.weak_frames < self.cfg.lost_frames
            if alive:
                kept.append(t)
            else:
                self._forget(t)
        self.tracks = kept
        self._adapt_colour()

    def _forget(self, track: _Track) -> None:
        """Remember a deleted person's colour for re-identification (section 6)."""
        if track.colour is not None and self.cfg.reid_memory_frames > 0:
            self.lost.append(_Lost(track.track_id, track.colour, self.frame_index))

    def _adapt_colour(self) -> None:
        """Blend each clearly seen person's colour moments into its model (section 4): a
        filter scoring at least ``start_score`` and overlapping no other filter."""
        if self.integral is None:
            return
        boxes = [t.filter.box() for t in self.tracks]
        clear = [
            t
            for i, t in enumerate(self.tracks)
            if not t.occluded_frames
            and t.score >= self.cfg.start_score
            and not any(overlap(boxes[i], b) > 0.0 for j, b in enumerate(boxes) if j != i)
        ]
        if not clear:
            return
        # the moments of all their estimates in one call (each row is computed on its own)
        observed = self._observe(np.stack([t.filter.estimate for t in clear]))
        for t, seen in zip(clear, observed, strict=True):
            t.colour = (
                ColourModel(seen)
                if t.colour is None
                else t.colour.updated(seen, self.cfg.colour_alpha)
            )

    def _detect(self, temp: NDArray[np.float32], thermal: Stream, regions: WarmRegions) -> None:
        c = self.cfg
        boxes = regions.boxes[regions.person]
        tracked = [t.filter.box() for t in self.tracks]
        aspect = (self.params.min_aspect, self.params.max_aspect)
        fresh: list[F64] = []
        for box in boxes:
            if any(
                box_iou(box[None, :], tb, of_smaller=True)[0] > _TRACKED_OVERLAP for tb in tracked
            ):
                continue
            state = _state_of_box(box, self.silhouette.width_ratio, aspect)
            score = silhouette_scores(
                temp, self.silhouette, state[None, :], self.contrast, self.surround_room
            )[0]
            if score < c.start_score:
                continue
            if c.ground_prior:
                height = implied_heights(thermal.camera, thermal.pose, state[None, :])
                if height_log_prior(self.height_prior, height)[0] < -2.0:  # beyond 2 sigma
                    continue
            fresh.append(state)
        proposals = []
        for state in fresh:
            box = self._box(state)
            seen = 1 + max(
                (
                    p.seen
                    for p in self.proposals
                    if box_iou(box[None, :], self._box(p.state))[0] >= _SAME_PROPOSAL_IOU
                ),
                default=0,
            )
            if seen >= c.confirm_frames:
                self._start(state)
            else:
                proposals.append(_Proposal(state, seen))
        self.proposals = proposals

    def _box(self, state: F64) -> F64:
        a = float(state[5])
        w = self.silhouette.width_ratio * float(state[2]) * a
        h = float(state[2])
        return np.array([state[0] - w / 2, state[1] - h / 2, state[0] + w / 2, state[1] + h / 2])

    def _start(self, state: F64) -> None:
        """A filter on a confirmed proposal; it takes the id of a recently lost person whose
        colour moments are within ``reid_distance`` (section 6), else a new id."""
        f = ThermalParticleFilter.around(self.params, self.silhouette, state, 0.05, self.rng)
        f.estimate = state.copy()
        recent = self.frame_index - self.cfg.reid_memory_frames
        self.lost = [lost for lost in self.lost if lost.frame >= recent]
        model = None
        track_id = self.next_id
        if self.integral is not None:
            seen = self._observe(state[None, :])
            model = ColourModel(seen[0])
            if self.lost and self._reliability(model) >= self.cfg.reid_min_reliability:
                d = [float(moment_distances(lost.colour.moments, seen)[0]) for lost in self.lost]
                best = int(np.argmin(d))
                if d[best] <= self.cfg.reid_distance:
                    track_id = self.lost.pop(best).track_id
        if track_id == self.next_id:
            self.next_id += 1
        self.tracks.append(_Track(track_id, f, colour=model))

    def _reported_box(self, box: F64, h: float, regions: WarmRegions, boxes: list[F64]) -> F64:
        """The warm component that overlaps this filter's box and no other filter's, when
        its height is within 0.7-1.4 of the filter's; else the filter's box."""
        if len(regions.boxes) == 0:
            return box
        mine = box_iou(regions.boxes, box, of_smaller=True) >= _OWN_COMPONENT
        if np.count_nonzero(mine) != 1:
            return box
        k = int(np.argmax(mine))
        comp: F64 = regions.boxes[k]
        for other in boxes:
            if (
                other is not box
                and box_iou(comp[None, :], other, of_smaller=True)[0] >= _TRACKED_OVERLAP
            ):
                return box
        if not 0.7 * h <= comp[3] - comp[1] <= 1.4 * h:
            return box
        return comp

    def _outputs(self, frame: Frame, thermal: Stream, regions: WarmRegions) -> list[TrackOutput]:
        affine = self.affine or Affine((1.0, 1.0), (0.0, 0.0))
        out = []
        boxes = [t.filter.box() for t in self.tracks]
        for t, box in zip(self.tracks, boxes, strict=True):
            own = self._reported_box(box, float(t.filter.estimate[2]), regions, boxes)
            u0, v0, u1, v1 = (float(x) for x in own)
            x, y = _ground_point(thermal, (u0 + u1) / 2.0, v1)
            seen = Visibility.OCCLUDED if t.occluded_frames else Visibility.VISIBLE
            out.append(TrackOutput(t.track_id, x, y, 0.0, affine.box(u0, v0, u1, v1), seen))
        return out


def _ground_point(stream: Stream, u: float, v: float) -> tuple[float, float]:
    """Where the ray through pixel (u, v) meets the floor (world z = 0); the camera's own
    ground position when the ray does not go down."""
    cam = stream.camera
    ray = cam.rays_at(u, v)
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
        stages=("thermal", "filters", "detector", "output"),
        summary="thermal particle filters with a sequential detector (seed 004, section 3)",
    )
)
