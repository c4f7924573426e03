"""satake2009 detector (seed 002, 2.2 and 2.4 steps 1 and 3): SGBM depth, distance templates.

Per frame: depth of the left view from the rectified pair (:mod:`.stereo`, at the
processed size; the seed's is 512x384), then the three distance templates are matched
over the whole image at each searched distance (a geometric grid from ``min_distance_m``
to ``max_distance_m``); matches above ``min_score`` are kept after non-maximum
suppression, their distance refined to the median depth of the body pixels. A match's
head top, back-projected at that distance (eq. 1), is the detection's position.

Not done here: the search restricted around each track's prediction (2.4 step 2.2; this
detector searches the whole image every frame) and the colour/texture rejection of
false detections (2.2).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig
from rgbd_eval.detect import satake2009_templates as st
from rgbd_eval.detect import stereo
from rgbd_eval.plugins import DetectionContract, DetectorSpec, StreamSpec, register_detector
from rgbd_eval.types import Box2D, Detection, Frame


class Satake2009DetectorConfig(ComponentConfig):
    """The satake2009 detector (seed 002; values without a seed source are ours, see the YAML)."""

    name: Literal["satake2009"] = "satake2009"
    width: int = Field(512, ge=32, le=4096, description="processed width (seed 4: 512)")
    height: int = Field(384, ge=32, le=4096, description="processed height (seed 4: 384)")
    num_disparities: int = Field(64, ge=16, le=512, description="SGBM disparity range (px)")
    block_size: int = Field(5, ge=1, le=21, description="SGBM block size (odd)")
    template_rows: int = Field(
        24, ge=8, le=512, description="search at the image step where a template is this tall"
    )
    min_distance_m: float = Field(1.0, gt=0.2, description="nearest searched distance")
    max_distance_m: float = Field(6.0, gt=0.5, le=20.0, description="farthest searched distance")
    distance_ratio: float = Field(1.15, gt=1.0, le=2.0, description="step of the distance grid")
    band_m: float = Field(0.3, gt=0.0, le=2.0, description="body pixels within D +- band")
    gap_m: float = Field(0.5, gt=0.0, le=5.0, description="surroundings beyond D + gap")
    min_score: float = Field(0.8, ge=0.0, le=1.0, description="least evaluation value kept")
    nms_iou: float = Field(0.3, ge=0.0, le=1.0, description="overlap that suppresses a match")

    @model_validator(mode="after")
    def _check(self) -> Satake2009DetectorConfig:
        if self.max_distance_m <= self.min_distance_m:
            raise ValueError("max_distance_m must exceed min_distance_m")
        stereo.SgbmParams(self.num_disparities, self.block_size)  # ValueError if invalid
        return self


def distance_grid(config: Satake2009DetectorConfig) -> list[float]:
    """``min, min r, min r^2, ...`` up to ``max`` (inclusive of the last step below it)."""
    steps = math.log(config.max_distance_m / config.min_distance_m) / math.log(
        config.distance_ratio
    )
    n = math.floor(steps + 1e-9) + 1
    return [config.min_distance_m * config.distance_ratio**k for k in range(n)]


def _iou(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> float:
    w = min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0])
    h = min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1])
    inter = max(0, w) * max(0, h)
    return inter / float(a[2] * a[3] + b[2] * b[3] - inter)


class Satake2009Detector:
    """Stereo depth, then whole-image distance-template search."""

    def __init__(self, config: Satake2009DetectorConfig) -> None:
        self.cfg = config
        self.matcher = stereo.make_matcher(
            stereo.SgbmParams(config.num_disparities, config.block_size)
        )
        self.templates = st.load_templates()
        self.distances = distance_grid(config)
        self.last_timings: Mapping[str, float] = {}

    def candidates(self, depth: np.ndarray, fx: float) -> list[st.Match]:
        """Matches above ``min_score`` at every searched distance, best first, suppressed."""
        c = self.cfg
        found: list[st.Match] = []
        tallest = max(t.mask.shape[0] for t in self.templates)
        for D in self.distances:
            # every step-th pixel, so that the tallest template is about template_rows tall
            step = max(1, int(tallest * (fx / st.F_REF) * (st.D_REF / D)) // c.template_rows)
            small = np.ascontiguousarray(depth[::step, ::step])
            near, free = st.agreement(small, D, c.band_m, c.gap_m)
            for t0 in self.templates:
                t = st.scale_template(t0, D, fx / step)
                th, tw = t.mask.shape
                if th > small.shape[0] or tw > small.shape[1] or th < 8:
                    continue
                scores = st.score_agreement(near, free, t)
                ys, xs = np.nonzero(scores >= c.min_score)
                if not len(ys):
                    continue
                order = np.argsort(-scores[ys, xs])[:20]
                for y, x in zip(ys[order], xs[order], strict=True):
                    found.append(
                        st.Match(
                            (x + t.anchor[0]) * step, (y + t.anchor[1]) * step, D,
                            float(scores[y, x]), t.orientation_deg,
                            (int(x) * step, int(y) * step, tw * step, th * step),
                        )
                    )  # fmt: skip
        found.sort(key=lambda m: -m.score)
        kept: list[st.Match] = []
        for m in found:
            if all(_iou(m.box, k.box) <= c.nms_iou for k in kept):
                kept.append(m)
        return kept

    def detect(self, frame: Frame) -> list[Detection]:
        t0 = time.perf_counter()
        left, right = frame.stream("left"), frame.stream("right")
        size = (self.cfg.width, self.cfg.height)
        sd = stereo.stereo_depth(
            left.image,
            right.image,
            left.camera,
            stereo.baseline_of(right.camera),
            size,
            self.matcher,
        )
        t1 = time.perf_counter()
        cam, depth = sd.camera, sd.depth
        out: list[Detection] = []
        for m in self.candidates(depth, cam.fx):
            x, y, w, h = m.box
            patch = depth[max(0, y) : y + h, max(0, x) : x + w]
            with np.errstate(invalid="ignore"):
                body = patch[np.abs(patch - m.distance) < self.cfg.band_m]
            D = float(np.median(body)) if body.size else m.distance
            head = np.array([[(m.u - cam.cx) * D / cam.fx, (m.v - cam.cy) * D / cam.fy, D]])
            wx, wy, wz = (float(v) for v in left.pose.transform_points(head)[0])
            sx, sy = left.camera.width / cam.width, left.camera.height / cam.height
            box = Box2D(x * sx, y * sy, w * sx, h * sy)
            out.append(Detection((wx, wy, wz), wz, m.score, box, distance=D))
        self.last_timings = {"stereo": t1 - t0, "templates": time.perf_counter() - t1}
        return out


register_detector(
    DetectorSpec(
        "satake2009",
        Satake2009DetectorConfig,
        Satake2009Detector,
        streams=(StreamSpec("left"), StreamSpec("right")),
        contract=lambda _c: DetectionContract(),
        stages=("stereo", "templates"),
        summary="SGBM stereo depth, upper-body distance templates (3 orientations)",
    )
)
