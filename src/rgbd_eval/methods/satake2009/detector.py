"""satake2009 detector (seed 002, 2.2 and 2.4 steps 1 and 3): SGBM depth, distance templates.

Per frame: depth of the left view from the rectified pair (:mod:`.stereo`, at the
processed size; the seed's is 512x384), then the three distance templates are matched
over the whole image at each searched distance (a geometric grid from ``min_distance_m``
to ``max_distance_m``, :func:`.satake2009_search.search_whole`); matches above
``min_score`` are kept after non-maximum suppression and the colour test
(:mod:`.satake2009_colour`), their distance refined to the median depth of the body
pixels. A match's head top, back-projected at that distance (eq. 1), is the
detection's position. These are the new-people detections of 2.4 step 3, a pure
function of the frame (cacheable).

The search around each track's prediction (2.4 steps 2.1-2.2) is the tracker's
(:mod:`rgbd_eval.methods.satake2009.tracker`): it needs the tracks, and reads this detector's
settings from its :class:`Satake2009Contract`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig
from rgbd_eval.detect import stereo
from rgbd_eval.methods.satake2009 import colour as colour
from rgbd_eval.methods.satake2009 import search as search
from rgbd_eval.methods.satake2009 import templates as st
from rgbd_eval.plugins import DetectionContract, DetectorSpec, register_detector
from rgbd_eval.types import Box2D, CameraModel, Detection, Frame


class Satake2009DetectorConfig(ComponentConfig):
    """The satake2009 detector (seed 002; values without a seed source are ours, see the YAML)."""

    name: Literal["satake2009"] = "satake2009"
    width: int = Field(512, ge=32, le=4096, description="processed width (seed 4: 512)")
    height: int = Field(384, ge=32, le=4096, description="processed height (seed 4: 384)")
    num_disparities: int = Field(32, ge=16, le=512, description="SGBM disparity range (px)")
    block_size: int = Field(5, ge=1, le=21, description="SGBM block size (odd)")
    uniqueness_ratio: int = Field(
        10, ge=0, le=100, description="SGBM: best cost beats the second by this % (0: no test)"
    )
    speckle_window: int = Field(
        100,
        ge=0,
        le=10000,
        description="SGBM: disparity blobs smaller than this are dropped (0: off)",
    )
    template_rows: int = Field(
        16, ge=8, le=512, description="search at the image step where a template is this tall"
    )
    min_distance_m: float = Field(1.0, gt=0.2, description="nearest searched distance")
    max_distance_m: float = Field(6.0, gt=0.5, le=20.0, description="farthest searched distance")
    distance_ratio: float = Field(1.2, gt=1.0, le=2.0, description="step of the distance grid")
    band_m: float = Field(0.3, gt=0.0, le=2.0, description="body pixels within D +- band")
    gap_m: float = Field(0.5, gt=0.0, le=5.0, description="surroundings beyond D + gap")
    min_score: float = Field(0.8, ge=0.0, le=1.0, description="least evaluation value kept")
    nms_iou: float = Field(0.3, ge=0.0, le=1.0, description="overlap that suppresses a match")
    min_head_torso_chroma: float = Field(
        2.7, ge=0.0, le=100.0, description="colour test: head vs torso (a*, b*) distance (0: off)"
    )

    @property
    def sgbm(self) -> stereo.SgbmParams:
        """The SGBM settings."""
        return stereo.SgbmParams(
            self.num_disparities,
            self.block_size,
            uniqueness_ratio=self.uniqueness_ratio,
            speckle_window=self.speckle_window,
        )

    @property
    def size(self) -> tuple[int, int]:
        """The processed ``(width, height)``."""
        return (self.width, self.height)

    @property
    def match(self) -> search.MatchParams:
        """How templates agree with depth."""
        return search.MatchParams(self.band_m, self.gap_m, self.min_score)

    @model_validator(mode="after")
    def _check(self) -> Satake2009DetectorConfig:
        if self.max_distance_m <= self.min_distance_m:
            raise ValueError("max_distance_m must exceed min_distance_m")
        _ = self.sgbm  # ValueError if invalid
        return self


def distance_grid(config: Satake2009DetectorConfig) -> list[float]:
    """``min, min r, min r^2, ...`` up to ``max`` (inclusive of the last step below it)."""
    steps = math.log(config.max_distance_m / config.min_distance_m) / math.log(
        config.distance_ratio
    )
    n = math.floor(steps + 1e-9) + 1
    return [config.min_distance_m * config.distance_ratio**k for k in range(n)]


@dataclass(frozen=True)
class Satake2009Contract(DetectionContract):
    """The satake2009 detector's contract: also its settings, for the tracker's own search."""

    detector: Satake2009DetectorConfig | None = None


def head_point(camera: CameraModel, m: st.Match, D: float) -> np.ndarray:
    """Eq. (1) inverted: the head top ``(x, y)`` at distance ``Z_c = D`` in camera coordinates."""
    return camera.points_at(m.u, m.v, D)


class Satake2009Detector:
    """Stereo depth, then whole-image distance-template search (new people, 2.4 step 3)."""

    def __init__(self, config: Satake2009DetectorConfig) -> None:
        self.cfg = config
        self.templates = st.load_templates()
        self.distances = distance_grid(config)
        self._scaled: dict[tuple[float, float], list[st.DistanceTemplate]] = {}
        self.last_timings: Mapping[str, float] = {}

    def candidates(
        self, depth: np.ndarray, fx: float, far: np.ndarray | None = None
    ) -> list[st.Match]:
        """Matches above ``min_score`` at every searched distance, best first, suppressed."""
        c = self.cfg
        found = search.search_whole(
            depth, fx, self.templates, self.distances, c.template_rows, c.match,
            cache=self._scaled, far=far,
        )  # fmt: skip
        return search.suppress(found, c.nms_iou)

    def detect(self, frame: Frame) -> list[Detection]:
        t0 = time.perf_counter()
        left = frame.stream("left")
        sd = search.frame_depth(frame, self.cfg.size, self.cfg.sgbm)
        t1 = time.perf_counter()
        cam, depth = sd.camera, sd.depth
        matches = self.candidates(depth, cam.fx, sd.far)
        t2 = time.perf_counter()
        c = self.cfg
        rgb = (
            stereo.resized(left.image, c.size) if matches and c.min_head_torso_chroma > 0 else None
        )
        out: list[Detection] = []
        sx, sy = left.camera.width / cam.width, left.camera.height / cam.height
        for m in matches:
            D = search.body_distance(depth, m, c.band_m)
            if rgb is not None and not colour.passes(
                rgb, depth, m, D, c.band_m, c.min_head_torso_chroma
            ):
                continue
            head = head_point(cam, m, D)[None, :]
            wx, wy, wz = (float(v) for v in left.pose.transform_points(head)[0])
            x, y, w, h = m.box
            box = Box2D(x * sx, y * sy, w * sx, h * sy)
            out.append(Detection((wx, wy, wz), wz, m.score, box, distance=D))
        self.last_timings = {
            "stereo": t1 - t0,
            "templates": t2 - t1,
            "colour": time.perf_counter() - t2,
        }
        return out


register_detector(
    DetectorSpec(
        "satake2009",
        Satake2009DetectorConfig,
        Satake2009Detector,
        streams=search.STREAMS,
        contract=lambda c: Satake2009Contract(detector=c),
        stages=("stereo", "templates", "colour"),
        summary="SGBM stereo depth, upper-body distance templates (3 orientations)",
    )
)
