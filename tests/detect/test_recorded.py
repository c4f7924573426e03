"""Recorded 2D detections: topics in bags written here with the package's writer, and det.txt."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rgbd_eval.detect.person2d import ColourImage
from rgbd_eval.detect.recorded import RecordedDetector, RecordedParams
from rgbd_eval.errors import InputError
from rgbd_eval.io.messages import BOUNDING_BOXES_TYPE, DETECTION2D_ARRAY_TYPE
from rgbd_eval.io.writer import RecordingWriter

RGB = np.zeros((4, 4, 3), dtype=np.uint8)
T0 = 1_600_000_000_000_000_000
DT = 33_333_333


def _image(index: int, stamp_ns: int) -> ColourImage:
    return ColourImage(index, stamp_ns, RGB)


def _darknet(
    w: RecordingWriter, stamp: int, boxes: list[tuple[str, float, int, int, int, int]]
) -> Any:
    t = w.store.types
    items = [
        t["darknet_ros_msgs/msg/BoundingBox"](
            probability=p, xmin=x0, ymin=y0, xmax=x1, ymax=y1, id=0, Class=c
        )
        for c, p, x0, y0, x1, y1 in boxes
    ]
    return t[BOUNDING_BOXES_TYPE](
        header=w.header(stamp + 20_000_000, "det", "d"),  # published 20 ms after the image
        image_header=w.header(stamp, "camera", "i"),
        bounding_boxes=items,
    )


def test_darknet_boxes_in_a_ros1_bag(tmp_path: Path) -> None:
    path = tmp_path / "det.bag"
    with RecordingWriter(path) as w:
        w.write_message(
            "/darknet_ros/bounding_boxes",
            BOUNDING_BOXES_TYPE,
            T0 + 20_000_000,
            _darknet(w, T0, [("person", 0.9, 10, 20, 60, 140), ("chair", 0.8, 0, 0, 5, 5)]),
        )
        w.write_message(
            "/darknet_ros/bounding_boxes",
            BOUNDING_BOXES_TYPE,
            T0 + 2 * DT + 20_000_000,
            _darknet(w, T0 + 2 * DT, [("person", 0.4, 1, 2, 3, 4), ("person", 0.7, 5, 6, 9, 10)]),
        )
    det = RecordedDetector.from_topic(path, "/darknet_ros/bounding_boxes")
    # Matched by the image stamp (image_header), not the publication stamp: person only.
    (only,) = det.detect(_image(0, T0))
    assert only.box.as_tuple() == (10, 20, 50, 120) and only.score == pytest.approx(0.9)
    assert det.detect(_image(1, T0 + DT)) == []  # no message for this image
    assert [b.score for b in det.detect(_image(2, T0 + 2 * DT + 1_000_000))] == [0.7, 0.4]
    assert det.detect(_image(2, T0 + 2 * DT + 6_000_000)) == []  # beyond the 5 ms gap


def test_vision_msgs_detection2d_array_in_mcap(tmp_path: Path) -> None:
    path = tmp_path / "det.mcap"
    with RecordingWriter(path) as w:
        t = w.store.types
        hyp = t["vision_msgs/msg/ObjectHypothesisWithPose"]
        pose = t["geometry_msgs/msg/PoseWithCovariance"](
            pose=t["geometry_msgs/msg/Pose"](
                position=t["geometry_msgs/msg/Point"](x=0.0, y=0.0, z=0.0),
                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
            covariance=np.zeros(36),
        )

        def detection(cx: float, cy: float, sx: float, sy: float, label: str, score: float) -> Any:
            return t["vision_msgs/msg/Detection2D"](
                header=w.header(T0, "camera"),
                results=[
                    hyp(
                        hypothesis=t["vision_msgs/msg/ObjectHypothesis"](
                            class_id=label, score=score
                        ),
                        pose=pose,
                    )
                ],
                bbox=t["vision_msgs/msg/BoundingBox2D"](
                    center=t["vision_msgs/msg/Pose2D"](
                        position=t["vision_msgs/msg/Point2D"](x=cx, y=cy), theta=0.0
                    ),
                    size_x=sx,
                    size_y=sy,
                ),
                id="",
            )

        msg = t[DETECTION2D_ARRAY_TYPE](
            header=w.header(T0, "camera"),
            detections=[
                detection(100, 200, 40, 160, "person", 0.8),
                detection(5, 5, 2, 2, "dog", 0.9),
            ],
        )
        w.write_message("/detections", DETECTION2D_ARRAY_TYPE, T0, msg)
    (box,) = RecordedDetector.from_topic(path, "/detections").detect(_image(0, T0))
    # centre (100, 200), size 40 x 160 -> left 80, top 120
    assert box.box.as_tuple() == (80, 120, 40, 160) and box.score == pytest.approx(0.8)
    every = RecordedDetector.from_topic(path, "/detections", RecordedParams(classes=()))
    assert len(every.detect(_image(0, T0))) == 2


def test_wrong_topic_or_type_is_an_input_error(tmp_path: Path) -> None:
    path = tmp_path / "det.bag"
    with RecordingWriter(path) as w:
        w.write_message("/boxes", BOUNDING_BOXES_TYPE, T0, _darknet(w, T0, []))
        w.write_ground_truth(T0, "world", [])
    with pytest.raises(InputError, match="no such topic"):
        RecordedDetector.from_topic(path, "/missing")
    with pytest.raises(InputError, match="expected one of"):
        RecordedDetector.from_topic(path, "/ground_truth")


def test_mot_det_txt(tmp_path: Path) -> None:
    path = tmp_path / "det.txt"
    path.write_text(
        "1,-1,10,20,30,60,0.9,-1,-1,-1\n1,-1,0,0,5,5,0.2,-1,-1,-1\n\n3,-1,1,2,3,4,0.5\n"
    )
    det = RecordedDetector.from_det_txt(path, RecordedParams(min_score=0.3))
    (first,) = det.detect(_image(0, 0))  # frame 1 is the first image
    assert first.box.as_tuple() == (10, 20, 30, 60)
    assert det.detect(_image(1, 0)) == []
    assert [b.score for b in det.detect(_image(2, 0))] == [0.5]
    bad = tmp_path / "bad.txt"
    bad.write_text("1,-1,10,20\n")
    with pytest.raises(InputError, match="line 1"):
        RecordedDetector.from_det_txt(bad)
    with pytest.raises(InputError, match="cannot read"):
        RecordedDetector.from_det_txt(tmp_path / "none.txt")
