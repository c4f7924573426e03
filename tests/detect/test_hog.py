"""Tests of the HOG people-detector confidence (seed 000, 5.3)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from rgbd_eval.detect.hog import (
    CONTEXT_PX,
    hog_confidence,
    hog_confidences,
    window_region,
    window_tile,
)
from rgbd_eval.types import Box2D


def _textured(seed: int = 0) -> NDArray[np.uint8]:
    rng = np.random.default_rng(seed)
    img = (rng.random((480, 640, 3)) * 255).astype(np.uint8)
    return np.asarray(cv2.GaussianBlur(img, (7, 7), 2.0), dtype=np.uint8)


def _bias() -> float:
    return float(cv2.HOGDescriptor_getDefaultPeopleDetector()[-1])


def test_window_region_places_person_as_in_inria_training() -> None:
    # A 96 px tall box fills 96 of 128 window pixels: the window is 128 px tall,
    # 64 px wide, with 16 px above and below and centred horizontally.
    # Box centre x = 100 + 40/2 = 120 -> window left = 120 - 32 = 88.
    left, top, width, height = window_region(Box2D(100.0, 50.0, 40.0, 96.0))
    assert (left, top, width, height) == pytest.approx((88.0, 34.0, 64.0, 128.0))
    # A 192 px box: scale 2, window 128x256, top = 50 - 32 = 18.
    left, top, width, height = window_region(Box2D(100.0, 50.0, 40.0, 192.0))
    assert (left, top, width, height) == pytest.approx((56.0, 18.0, 128.0, 256.0))


def test_blank_image_scores_the_bias_only() -> None:
    # No gradients -> all-zero descriptor -> score = b, which is strongly negative.
    blank = np.full((480, 640, 3), 128, dtype=np.uint8)
    score = hog_confidence(blank, Box2D(300.0, 100.0, 60.0, 200.0))
    assert score == pytest.approx(_bias(), abs=1e-6)
    assert score < -3.0


@pytest.mark.parametrize(
    "box",
    [
        Box2D(300.0, 100.0, 80.0, 250.0),  # inside, shrinking
        Box2D(10.0, 10.0, 20.0, 60.0),  # enlarging, partly outside (replicated border)
        Box2D(560.0, 300.0, 100.0, 300.0),  # leaves the image bottom-right
    ],
)
def test_score_equals_opencv_detect_weight(box: Box2D) -> None:
    img = _textured()
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())
    tile = window_tile(img, box)
    assert tile.shape == (130, 66, 3)
    locations, weights = hog.detect(
        tile,
        hitThreshold=-1e9,
        winStride=(8, 8),
        padding=(0, 0),
        searchLocations=[(CONTEXT_PX, CONTEXT_PX)],
    )
    assert [tuple(p) for p in locations] == [(CONTEXT_PX, CONTEXT_PX)]
    assert hog_confidence(img, box) == pytest.approx(float(weights.ravel()[0]), abs=1e-4)


def test_batched_equals_single() -> None:
    img = _textured(1)
    boxes = [Box2D(50.0 * i, 40.0 + 10 * i, 30.0 + 5 * i, 100.0 + 20 * i) for i in range(8)]
    batch = hog_confidences(img, boxes)
    single = np.array([hog_confidence(img, b) for b in boxes])
    np.testing.assert_allclose(batch, single, atol=1e-9)
    assert hog_confidences(img, []).shape == (0,)


def test_box_entirely_outside_image_is_scored_from_replicated_border() -> None:
    img = np.full((480, 640, 3), 50, dtype=np.uint8)
    # Border replication of a flat image is flat: the bias again.
    assert hog_confidence(img, Box2D(-500.0, -500.0, 40.0, 120.0)) == pytest.approx(
        _bias(), abs=1e-6
    )


def test_person_silhouette_scores_above_clutter_free_background() -> None:
    # A dark upright figure (head, torso, legs) on a light background: the
    # detector's score rises well above the flat-image bias.
    img = np.full((480, 640, 3), 200, dtype=np.uint8)
    cv2.circle(img, (320, 130), 18, (40, 40, 40), -1)  # head
    cv2.rectangle(img, (295, 150), (345, 270), (40, 40, 40), -1)  # torso
    cv2.rectangle(img, (300, 270), (318, 380), (40, 40, 40), -1)  # left leg
    cv2.rectangle(img, (322, 270), (340, 380), (40, 40, 40), -1)  # right leg
    score = hog_confidence(img, Box2D(290.0, 112.0, 60.0, 268.0))
    assert score > _bias() + 2.0


@pytest.mark.parametrize("height", [0.0, -5.0, float("nan")])
def test_bad_box_height_raises(height: float) -> None:
    with pytest.raises(ValueError, match="box height"):
        hog_confidence(_textured(), Box2D(10.0, 10.0, 10.0, height))


def test_bad_image_raises() -> None:
    with pytest.raises(ValueError, match="uint8"):
        hog_confidence(np.zeros((48, 64, 3), dtype=np.float32), Box2D(1.0, 1.0, 10.0, 20.0))
