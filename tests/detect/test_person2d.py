"""2D person detector backends: box helpers, YOLO and SSD decoding through tiny ONNX models, HOG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from onnx import TensorProto

from rgbd_eval.detect.hog_people import HogPeopleDetector
from rgbd_eval.detect.person2d import ColourImage, letterbox, nms
from rgbd_eval.detect.ssdlite import SsdLiteDetector, SsdParams
from rgbd_eval.detect.yolo_onnx import OnnxYoloDetector, YoloLayout, YoloParams, decode
from rgbd_eval.errors import ConfigError
from tests.detect.onnx_models import constant_output_model

IMAGE = ColourImage(0, 0, np.full((480, 640, 3), 90, dtype=np.uint8))


def test_letterbox_scales_and_centres() -> None:
    tile, lb = letterbox(IMAGE.rgb, 64, 64)
    # scale = min(64/640, 64/480) = 0.1 -> 64x48, padded by (64 - 48)/2 = 8 rows top and bottom
    assert tile.shape == (64, 64, 3)
    assert (lb.scale, lb.pad_x, lb.pad_y) == (0.1, 0.0, 8.0)
    assert (tile[:8] == 114).all() and (tile[8:56] == 90).all() and (tile[56:] == 114).all()
    # input (27, 22, 37, 42) -> image ((27 - 0)/0.1, (22 - 8)/0.1, ...) = (270, 140, 370, 340)
    np.testing.assert_allclose(lb.to_image(np.array([[27.0, 22, 37, 42]])), [[270, 140, 370, 340]])


def test_nms_keeps_best_of_overlapping_boxes() -> None:
    boxes = np.array([[0, 0, 10, 10], [1, 0, 11, 10], [20, 20, 30, 30]], dtype=float)
    # IoU(0, 1) = 90 / 110 = 0.82 > 0.45: box 0 (score 0.6) suppresses box 1 (0.5)
    assert nms(boxes, np.array([0.6, 0.5, 0.9]), 0.45) == [2, 0]
    assert nms(boxes, np.array([0.6, 0.5, 0.9]), 0.9) == [2, 0, 1]


def _v5_rows() -> np.ndarray:
    rows = np.zeros((8, 7))  # 8 candidates, cx cy w h obj + 2 classes
    rows[0] = [32, 32, 10, 20, 0.9, 0.8, 0.1]  # person, score 0.72
    rows[1] = [33, 32, 10, 20, 0.9, 0.7, 0.1]  # duplicate, score 0.63: suppressed by NMS
    rows[2] = [10, 30, 6, 12, 0.9, 0.1, 0.9]  # the other class: dropped
    rows[3] = [50, 30, 6, 12, 0.2, 0.9, 0.0]  # score 0.18 < 0.25: dropped
    return rows


def test_decode_v5_layout() -> None:
    boxes, scores = decode(_v5_rows()[None], YoloParams())
    np.testing.assert_allclose(scores, [0.72, 0.63])
    np.testing.assert_allclose(boxes[0], [27, 22, 37, 42])


def test_decode_v8_layout_is_transposed_without_objectness() -> None:
    cols = np.zeros((6, 8))  # cx cy w h + 2 classes, 8 candidates
    cols[:, 0] = [32, 32, 10, 20, 0.8, 0.1]
    cols[:, 1] = [10, 30, 6, 12, 0.3, 0.6]  # best class is not person
    boxes, scores = decode(cols[None], YoloParams())  # auto: 6 < 8 -> v8
    np.testing.assert_allclose(scores, [0.8])
    np.testing.assert_allclose(boxes, [[27, 22, 37, 42]])
    with pytest.raises(ConfigError, match="person_class"):
        decode(cols[None], YoloParams(person_class=5, layout=YoloLayout.V8))


def test_onnx_yolo_end_to_end(tmp_path: Path) -> None:
    path = constant_output_model(
        tmp_path / "yolo.onnx",
        "images",
        [1, 3, 64, 64],
        TensorProto.FLOAT,
        {"out": _v5_rows()[None]},
    )
    det = OnnxYoloDetector(path)
    boxes = det.detect(IMAGE)
    # one person after NMS, mapped back through the letterbox (see test_letterbox_scales_and_centres)
    assert len(boxes) == 1
    assert boxes[0].score == pytest.approx(0.72)
    np.testing.assert_allclose(boxes[0].box.as_tuple(), (270, 140, 100, 200), atol=1e-4)


def test_onnx_model_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="does not exist"):
        OnnxYoloDetector(tmp_path / "missing.onnx")
    bad = tmp_path / "bad.onnx"
    bad.write_bytes(b"not a model")
    with pytest.raises(ConfigError, match="cannot be loaded"):
        OnnxYoloDetector(bad)


def _ssd_model(tmp_path: Path) -> Path:
    boxes = np.zeros((1, 4, 4))
    boxes[0, 0] = [0.25, 0.5, 0.75, 0.625]  # ymin xmin ymax xmax
    boxes[0, 1] = [0.25, 0.51, 0.75, 0.635]  # near-duplicate, suppressed by the extra NMS
    boxes[0, 2] = [0.0, 0.0, 0.5, 0.1]  # another label
    boxes[0, 3] = [0.1, 0.1, 0.2, 0.2]  # beyond num_detections
    outputs = {
        "detection_boxes": boxes,
        "detection_scores": np.array([[0.9, 0.8, 0.95, 0.99]]),
        "detection_classes": np.array([[1.0, 1.0, 2.0, 1.0]]),
        "num_detections": np.array([3.0]),
    }
    return constant_output_model(
        tmp_path / "ssd.onnx", "image_tensor", [1, "h", "w", 3], TensorProto.UINT8, outputs
    )


def test_ssdlite_decodes_tf_od_outputs(tmp_path: Path) -> None:
    det = SsdLiteDetector(_ssd_model(tmp_path))
    boxes = det.detect(IMAGE)
    # (ymin, xmin, ymax, xmax) = (0.25, 0.5, 0.75, 0.625) of 640x480 -> left 320, top 120,
    # width 0.125 * 640 = 80, height 0.5 * 480 = 240
    assert [round(b.score, 2) for b in boxes] == [0.9]
    np.testing.assert_allclose(boxes[0].box.as_tuple(), (320, 120, 80, 240), atol=1e-4)
    assert (
        SsdLiteDetector(_ssd_model(tmp_path), SsdParams(score_threshold=0.95)).detect(IMAGE) == []
    )


def test_ssdlite_refuses_a_model_without_tf_od_outputs(tmp_path: Path) -> None:
    path = constant_output_model(
        tmp_path / "m.onnx", "image_tensor", [1, 8, 8, 3], TensorProto.UINT8, {"y": np.zeros(2)}
    )
    with pytest.raises(ConfigError, match="detection_boxes"):
        SsdLiteDetector(path)


def test_hog_finds_nothing_on_a_flat_image() -> None:
    assert HogPeopleDetector().detect(IMAGE) == []
