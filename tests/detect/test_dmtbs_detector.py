"""The DMT-BS detector on hand-made depth images, and its configuration file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from pydantic import ValidationError

from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.dmtbs.detector import (
    DepthView,
    DmtbsDetector,
    DmtbsDetectorConfig,
    FloorSource,
)
from rgbd_eval.methods.dmtbs.tracker import DmtbsTrackerConfig
from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.rig_sensors import StaticDepthCamera

METHOD_FILE = Path(__file__).parents[2] / "src" / "rgbd_eval" / "methods" / "dmtbs" / "method.yaml"
STEP = 33_333_333


def _overhead(name: str, x: float, y: float) -> tuple[StaticDepthCamera, np.ndarray]:
    """A 64x48 camera 3 m above (x, y) looking straight down, and its empty-floor depth."""
    cfg = StaticDepthConfig(name=name, x=x, y=y, z=3.0, pitch_deg=90.0, width=64, height=48)
    return StaticDepthCamera(cfg, "world"), np.full((48, 64), 3.0, dtype=np.float32)


def _views(cams: list[StaticDepthCamera], depths: list[np.ndarray]) -> list[DepthView]:
    return [DepthView(c.cfg.name, d, c.camera, c.pose) for c, d in zip(cams, depths, strict=True)]


def _with_box(floor: np.ndarray) -> np.ndarray:
    """A 1.8 m tall box top (depth 1.2 m) on pixels u 30..35, v 22..27."""
    d = floor.copy()
    d[22:28, 30:36] = 1.2
    return d


#: The box top is 6x6 pixels at 1.2 m from a 64x48 camera: about 0.026 m^2 of surface, below
#: the default smallest blob (a head, 0.04 m^2); these tests keep every blob.
KEEP_ALL = 0.0


def _box_xy(cam: StaticDepthCamera) -> np.ndarray:
    """World (x, y) of the box-top pixels' mean, by back-projection."""
    pts = cam.camera.backproject(_with_box(np.full((48, 64), np.nan, dtype=np.float32)))
    p = pts[22:28, 30:36].reshape(-1, 3)
    return cam.pose.transform_points(p)[:, :2].mean(axis=0)


def test_one_camera_one_box() -> None:
    spec, floor = _overhead("a", 0.0, 0.0)
    det = DmtbsDetector(
        DmtbsDetectorConfig(min_blob_area_m2=KEEP_ALL, init_frames=2, roi=(-2, -2, 2, 2))
    )
    for k in range(2):  # initialisation: nothing detected
        assert det.detect_views(k * STEP, _views([spec], [floor])).detections == []
    result = det.detect_views(2 * STEP, _views([spec], [_with_box(floor)]))
    assert len(result.detections) == 1
    d = result.detections[0]
    # The box top seen from above: its blob's centroid is the box's centre (within a cell,
    # the closing and the blur are symmetric); its height is 3 - 1.2 = 1.8 m.
    np.testing.assert_allclose(d.ground_xy, _box_xy(spec), atol=0.02)
    assert d.height == pytest.approx(1.8, abs=1e-5)
    # A horizontal surface seen from above has density ~1 on average (module docstring of
    # density.py); pixels 2.7 cm apart binned on 2 cm cells alias (1 or 2 points per cell),
    # which the 2 cm blur only partly smooths: the peak lies between 1 and 2.
    assert 1.0 < d.confidence < 2.0
    assert d.footprint is not None and d.footprint.shape[1] == 2
    np.testing.assert_allclose(d.footprint.mean(axis=0), d.ground_xy, atol=1e-9)


def test_two_cameras_merge_by_maximum() -> None:
    a, floor_a = _overhead("a", -1.0, 0.0)
    b, floor_b = _overhead("b", 1.0, 0.0)
    det = DmtbsDetector(
        DmtbsDetectorConfig(min_blob_area_m2=KEEP_ALL, init_frames=1, roi=(-2.5, -2, 2.5, 2))
    )
    det.detect_views(0, _views([a, b], [floor_a, floor_b]))
    result = det.detect_views(STEP, _views([a, b], [_with_box(floor_a), _with_box(floor_b)]))
    xs = sorted(d.ground_xy[0] for d in result.detections)
    np.testing.assert_allclose(xs, sorted([_box_xy(a)[0], _box_xy(b)[0]]), atol=0.02)
    # The merged map is the pixel-wise maximum of each camera's own map.
    singles = []
    for spec, floor in ((a, floor_a), (b, floor_b)):
        alone = DmtbsDetector(
            DmtbsDetectorConfig(min_blob_area_m2=KEEP_ALL, init_frames=1, roi=(-2.5, -2, 2.5, 2))
        )
        alone.detect_views(0, _views([spec], [floor]))
        singles.append(alone.detect_views(STEP, _views([spec], [_with_box(floor)])).density)
    np.testing.assert_array_equal(result.density, np.maximum(singles[0], singles[1]))


def test_floor_from_the_first_frame_matches_the_world_floor() -> None:
    spec, floor = _overhead("a", 0.5, -0.5)
    results = []
    cases = [(FloorSource.WORLD, True), (FloorSource.FIRST_FRAME, True), (FloorSource.AUTO, False)]
    for source, world_is_floor in cases:
        det = DmtbsDetector(
            DmtbsDetectorConfig(
                min_blob_area_m2=KEEP_ALL, init_frames=1, floor=source, roi=(-2, -2, 2, 2)
            )
        )
        det.detect_views(0, _views([spec], [floor]), world_is_floor)
        results.append(
            det.detect_views(STEP, _views([spec], [_with_box(floor)]), world_is_floor).detections
        )
    (world,), (found,), (auto,) = results
    np.testing.assert_allclose(found.ground_xy, world.ground_xy, atol=1e-6)
    assert found.height == pytest.approx(world.height, abs=1e-6)
    assert auto.ground_xy == found.ground_xy and auto.height == found.height


def test_no_floor_in_the_first_frame_is_a_config_error() -> None:
    spec, floor = _overhead("a", 0.0, 0.0)
    det = DmtbsDetector(DmtbsDetectorConfig(floor=FloorSource.FIRST_FRAME))
    with pytest.raises(ConfigError, match=r"detector\.floor=first_frame: no floor plane"):
        det.detect_views(0, _views([spec], [np.full_like(floor, np.nan)]))


def test_points_below_the_height_cut_are_not_detected() -> None:
    # A box 0.9 m tall (depth 2.1 m from 3 m): below the 1 m cut, no blob.
    spec, floor = _overhead("a", 0.0, 0.0)
    det = DmtbsDetector(
        DmtbsDetectorConfig(min_blob_area_m2=KEEP_ALL, init_frames=1, roi=(-2, -2, 2, 2))
    )
    det.detect_views(0, _views([spec], [floor]))
    low = floor.copy()
    low[22:28, 30:36] = 2.1
    assert det.detect_views(STEP, _views([spec], [low])).detections == []


def test_method_file_restates_the_defaults() -> None:
    data = yaml.safe_load(METHOD_FILE.read_text())
    assert data["method"] == "dmtbs"
    assert DmtbsDetectorConfig.model_validate(data["detector"]) == DmtbsDetectorConfig()
    assert DmtbsTrackerConfig.model_validate(data["tracker"]) == DmtbsTrackerConfig()


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("roi", (1, 0, 0, 1), "x_max > x_min"),
        ("roi", (-100, -100, 100, 100), "cells"),
        ("mog2_sigma_min_m", 0.5, "MOG2 stds"),
        ("cell_m", 0.0, "greater than 0"),
        ("nonsense", 1, "Extra inputs"),
    ],
)
def test_bad_detector_config_is_refused(field: str, value: object, message: str) -> None:
    with pytest.raises(ValidationError, match=message):
        DmtbsDetectorConfig.model_validate({field: value})
