"""A method defined outside the package: it registers through ``$RGBD_EVAL_PLUGINS``.

``toy``: a depth-only detector (world points in a height band, occupancy grid on the
ground, connected components) and a nearest-neighbour tracker that reads frames. It
exists to prove the plug-in seam: ``run``, ``sweep``, ``bench`` and ``reproduce`` use it
without any edit of the pipeline, CLI, bench, sweep or config core.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Literal

import cv2
import numpy as np
from pydantic import Field

from rgbd_eval.config import ComponentConfig
from rgbd_eval.plugins import (
    DetectionContract,
    DetectorSpec,
    MethodSpec,
    PaperSpec,
    ReproduceOptions,
    ReproduceResult,
    StreamSpec,
    TrackerSpec,
    register_detector,
    register_method,
    register_paper,
    register_tracker,
)
from rgbd_eval.types import Box2D, Detection, Frame, TrackOutput, Visibility

HERE = Path(__file__).resolve().parent


class ToyDetectorConfig(ComponentConfig):
    name: Literal["toy"] = "toy"
    min_z: float = Field(0.5, description="lowest world height kept (m)")
    max_z: float = Field(2.2, description="highest world height kept (m)")
    cell: float = Field(0.2, gt=0.0, description="ground grid cell (m)")
    min_points: int = Field(20, ge=1)
    max_extent: float = Field(1.0, gt=0.0, description="wider blobs (walls) are not people (m)")


class ToyDetector:
    def __init__(self, config: ToyDetectorConfig) -> None:
        self.cfg = config
        self.last_timings: Mapping[str, float] = {}

    def detect(self, frame: Frame) -> list[Detection]:
        t0 = time.perf_counter()
        depth = frame.stream("depth")
        pts = depth.camera.backproject(depth.image).reshape(-1, 3)
        rows = np.flatnonzero(np.isfinite(pts[:, 2]))
        world = depth.pose.transform_points(pts[rows])
        band = (world[:, 2] > self.cfg.min_z) & (world[:, 2] < self.cfg.max_z)
        world, rows = world[band], rows[band]
        t1 = time.perf_counter()
        out: list[Detection] = []
        if len(world):
            lo = world[:, :2].min(axis=0)
            ij = np.floor((world[:, :2] - lo) / self.cfg.cell).astype(np.int64)
            grid = np.zeros(ij.max(axis=0) + 1, dtype=np.uint8)
            grid[ij[:, 0], ij[:, 1]] = 1
            n, labels = cv2.connectedComponents(grid, connectivity=8)
            blob = labels[ij[:, 0], ij[:, 1]]
            for k in range(1, n):
                sel = blob == k
                extent = np.ptp(world[sel, :2], axis=0).max()
                if sel.sum() < self.cfg.min_points or extent > self.cfg.max_extent:
                    continue
                c = world[sel].mean(axis=0)
                v, u = np.divmod(rows[sel], depth.camera.width)
                box = Box2D(
                    float(u.min()), float(v.min()), float(np.ptp(u) + 1), float(np.ptp(v) + 1)
                )
                dist = float(np.linalg.norm(c - np.asarray(depth.pose.translation)))
                out.append(
                    Detection(
                        (float(c[0]), float(c[1]), float(c[2])),
                        float(world[sel, 2].max()),
                        1.0,
                        box,
                        distance=dist,
                    )
                )
        self.last_timings = {"segment": t1 - t0, "blobs": time.perf_counter() - t1}
        return out


class ToyTrackerConfig(ComponentConfig):
    name: Literal["toy"] = "toy"
    gate_m: float = Field(1.0, gt=0.0, description="largest step of a track between frames (m)")


class ToyTracker:
    """Greedy nearest neighbour; it reads frames (and refuses to run without them)."""

    last_timings: Mapping[str, float] = {}

    def __init__(self, config: ToyTrackerConfig, contract: DetectionContract) -> None:
        self.cfg = config
        self.tracks: dict[int, tuple[float, float]] = {}
        self.next_id = 1

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        if frame is None or frame.stamp_ns != stamp_ns:
            raise ValueError("the toy tracker reads the frame of every update")
        free = dict(self.tracks)
        out = []
        for d in detections:
            x, y = d.ground_xy
            best = min(free, key=lambda t: np.hypot(free[t][0] - x, free[t][1] - y), default=None)
            if best is None or np.hypot(free[best][0] - x, free[best][1] - y) > self.cfg.gate_m:
                best, self.next_id = self.next_id, self.next_id + 1
            else:
                del free[best]
            self.tracks[best] = (x, y)
            out.append(TrackOutput(best, x, y, d.height, d.box2d, Visibility.VISIBLE))
        for t in free:
            del self.tracks[t]
        return out


register_detector(
    DetectorSpec(
        "toy",
        ToyDetectorConfig,
        ToyDetector,
        streams=(StreamSpec("depth"),),
        contract=lambda _c: DetectionContract(box2d=False),
        stages=("segment", "blobs"),
    )
)
register_tracker(TrackerSpec("toy", ToyTrackerConfig, ToyTracker, needs_frame=True))
register_method(
    MethodSpec("toy", "toy", "toy", title="a test method from outside the package", gating="metric")
)


def _reproduce(recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    from rgbd_eval.metrics import summarize
    from rgbd_eval.sweep import SweepParam, expand_grid, point_configs, run_sweep

    grid = expand_grid([SweepParam("tracker.gate_m", (0.25, 1.0))])
    configs = point_configs({"method": "toy", "evaluation": {"gating": "metric"}}, [], grid)
    result = run_sweep(
        list(recordings.values()), grid, configs, options.client, cache_root=options.cache
    )
    mota = {p["tracker.gate_m"]: summarize(c)["mota"] for p, c in result.overall()}
    held = mota[1.0] is not None and mota[0.25] is not None and mota[1.0] >= mota[0.25]
    return ReproduceResult(
        markdown="| gate (m) | MOTA |\n|---|---|\n"
        + "".join(f"| {g} | {m} |\n" for g, m in mota.items()),
        data={"mota": {str(g): m for g, m in mota.items()}},
        claims=(("a wider gate keeps identities: MOTA does not drop", held),),
    )


register_paper(PaperSpec("toy", "the toy experiment", (str(HERE / "toy_scene.yaml"),), _reproduce))
