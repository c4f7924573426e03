"""The pinto2022 detector composes person boxes, the localiser and the embedder."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.detect.person2d import ColourImage, PersonBox
from rgbd_eval.detect.reid import ColourTextureEmbedder
from rgbd_eval.methods.pinto2022.detector import STAGES, Pinto2022Detector
from rgbd_eval.types import OPTICAL_TO_BODY, Box2D, CameraModel, Frame

CAM = CameraModel(8, 6, fx=4.0, fy=4.0, cx=3.5, cy=2.5)


class _FixedBoxes:
    """A 2D detector returning given boxes (the real backends are tested in test_person2d)."""

    def __init__(self, boxes: list[PersonBox]) -> None:
        self.boxes = boxes
        self.seen: list[int] = []

    def detect(self, image: ColourImage) -> list[PersonBox]:
        self.seen.append(image.index)
        return self.boxes


def _frame() -> Frame:
    rgb = np.zeros((6, 8, 3), dtype=np.uint8)
    rgb[:, :4] = (200, 30, 30)
    depth = np.full((6, 8), np.nan, dtype=np.float32)
    depth[:, :4] = 2.0  # only the left half has depth
    return Frame.rgbd(
        index=7,
        stamp_ns=123,
        rgb=rgb,
        depth=depth,
        rgb_camera=CAM,
        depth_camera=CAM,
        camera_pose=OPTICAL_TO_BODY,
    )


def test_detections_carry_position_box_score_and_embedding() -> None:
    boxes = [PersonBox(Box2D(0, 0, 4, 6), 0.9), PersonBox(Box2D(4, 0, 4, 6), 0.8)]
    person = _FixedBoxes(boxes)
    detector = Pinto2022Detector(person, ColourTextureEmbedder())
    (det,) = detector.detect(_frame())
    assert person.seen == [7]
    # box centre (2, 3): optical ((2 - 3.5)/4 * 2, (3 - 2.5)/4 * 2, 2) = (-0.75, 0.25, 2)
    # -> body (z, -x, -y) = (2, 0.75, -0.25)
    np.testing.assert_allclose(det.position, (2.0, 0.75, -0.25))
    assert det.confidence == pytest.approx(0.9)
    assert det.box2d == boxes[0].box
    assert det.appearance is not None and det.appearance.shape == (
        ColourTextureEmbedder().dimension,
    )
    assert detector.dropped_without_depth == 1  # the right box has no valid depth
    assert set(detector.last_timings) == set(STAGES)
