"""Colour moments by integral images (seed 004, section 4; Stricker and Orengo 1995)."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.track.colour_moments import (
    ColourModel,
    IntegralMoments,
    MomentWeights,
    channel_means,
    moment_distance,
    moment_distances,
    noise_sigma,
    person_moments,
    person_moments_many,
    region_boxes,
    reliability,
)


def _direct(image: np.ndarray, box: tuple[int, int, int, int]) -> np.ndarray:
    u0, v0, u1, v1 = box
    p = image[v0:v1, u0:u1].reshape(-1, image.shape[2]).astype(np.float64)
    mean = p.mean(axis=0)
    std = np.sqrt(((p - mean) ** 2).mean(axis=0))
    skew = np.cbrt(((p - mean) ** 3).mean(axis=0))
    return np.stack([mean, std, skew])


def test_integral_moments_equal_direct_computation() -> None:
    rng = np.random.default_rng(0)
    # skewed channels (exponential) so that the third moment is far from zero
    image = np.clip(rng.exponential(40.0, (60, 80, 3)), 0, 255).astype(np.uint8)
    integral = IntegralMoments.of(image)
    for _ in range(50):
        u0, u1 = sorted(rng.integers(0, 81, 2))
        v0, v1 = sorted(rng.integers(0, 61, 2))
        if u1 == u0 or v1 == v0:
            continue
        box = (int(u0), int(v0), int(u1), int(v1))
        np.testing.assert_allclose(integral.moments(box), _direct(image, box), atol=1e-6)


def test_hand_computed_moments_of_a_small_patch() -> None:
    # one channel, values 0, 0, 0, 4: mean 1, variance (1+1+1+9)/4 = 3,
    # third central moment (-1-1-1+27)/4 = 6 -> skewness 6^(1/3)
    image = np.array([[0, 0], [0, 4]], dtype=np.uint8)
    m = IntegralMoments.of(image).moments((0, 0, 2, 2))
    np.testing.assert_allclose(m[:, 0], [1.0, np.sqrt(3.0), 6.0 ** (1 / 3)])


def test_empty_and_clipped_boxes() -> None:
    integral = IntegralMoments.of(np.ones((4, 4, 3)))
    assert np.isnan(integral.moments((2, 2, 2, 3))).all()
    # a box beyond the image is clipped to it: all ones -> mean 1, std 0, skew 0
    np.testing.assert_allclose(integral.moments((-5, -5, 10, 10))[:, 0], [1.0, 0.0, 0.0])


def test_regions_split_the_box_head_torso_legs() -> None:
    # box 100 wide, 200 tall at (0, 0): head 0..26 (0.13 * 200) 33 wide around u=50
    assert region_boxes(np.array([0.0, 0.0, 100.0, 200.0])) == [
        (34, 0, 66, 26),  # 50 -+ 16.5, rounded half to even
        (6, 26, 94, 104),  # 50 -+ 43.5; 0.52 * 200 = 104
        (20, 104, 80, 200),
    ]


def test_red_shirt_and_blue_shirt_are_told_apart() -> None:
    image = np.zeros((200, 200, 3), dtype=np.uint8)
    image[:, :100] = (200, 30, 30)
    image[:, 100:] = (30, 30, 200)
    integral = IntegralMoments.of(image)
    red = person_moments(integral, np.array([20.0, 20.0, 80.0, 180.0]))
    red2 = person_moments(integral, np.array([25.0, 15.0, 85.0, 175.0]))
    blue = person_moments(integral, np.array([120.0, 20.0, 180.0, 180.0]))
    # same colour: all moments equal; red vs blue: |200-30| on two channels per region,
    # std and skew 0 -> 340 per region
    assert moment_distance(red, red2) == pytest.approx(0.0)
    assert moment_distance(red, blue) == pytest.approx(340.0)
    assert moment_distance(red, blue, MomentWeights(mean=0.5)) == pytest.approx(170.0)


def test_adaptive_update_blends_and_keeps_unobserved_regions() -> None:
    old = ColourModel(np.array([[[10.0]], [[20.0]]]))
    obs = np.array([[[20.0]], [[np.nan]]])
    new = old.updated(obs, 0.25)
    # region 0: 0.75 * 10 + 0.25 * 20 = 12.5; region 1 not observed: kept
    np.testing.assert_allclose(new.moments[:, 0, 0], [12.5, 20.0])
    fresh = ColourModel(np.full((2, 1, 1), np.nan)).updated(obs, 0.25)
    assert fresh.moments[0, 0, 0] == 20.0 and np.isnan(fresh.moments[1, 0, 0])
    with pytest.raises(ValueError, match="alpha"):
        old.updated(obs, 1.5)


def test_moments_of_many_boxes_equal_one_at_a_time() -> None:
    rng = np.random.default_rng(1)
    image = rng.integers(0, 256, (50, 70, 3)).astype(np.uint8)
    integral = IntegralMoments.of(image)
    # inside, clipped at the border, and empty (u1 <= u0)
    boxes = np.array([[3, 4, 20, 30], [-5, 40, 10, 60], [30, 10, 30, 20]], dtype=np.intp)
    many = integral.moments_many(boxes)
    for k, box in enumerate(boxes):
        np.testing.assert_allclose(many[k], integral.moments(tuple(int(x) for x in box)))
    person = np.array([[10.0, 5.0, 40.0, 45.0], [0.0, 0.0, 20.0, 30.0]])
    regions = person_moments_many(integral, person)
    for k in range(2):
        np.testing.assert_allclose(regions[k], person_moments(integral, person[k]))
    # the distance of the first person's moments to both: 0 to itself, as moment_distance
    d = moment_distances(regions[0], regions)
    assert d[0] == 0.0 and d[1] == pytest.approx(moment_distance(regions[0], regions[1]))


def test_masked_moments_equal_direct_computation_over_the_mask() -> None:
    rng = np.random.default_rng(1)
    image = np.clip(rng.exponential(40.0, (40, 50, 3)), 0, 255).astype(np.uint8)
    mask = rng.random((40, 50)) < 0.4
    integral = IntegralMoments.of(image, mask, min_count=3)
    boxes = []
    for _ in range(40):
        u0, u1 = sorted(int(x) for x in rng.integers(0, 51, 2))
        v0, v1 = sorted(int(x) for x in rng.integers(0, 41, 2))
        boxes.append((u0, v0, u1, v1))
    many = integral.moments_many(np.array(boxes))
    for box, got in zip(boxes, many, strict=True):
        u0, v0, u1, v1 = box
        p = image[v0:v1, u0:u1][mask[v0:v1, u0:u1]].astype(np.float64)
        if len(p) < 3:  # too few masked pixels: not measured
            assert np.isnan(integral.moments(box)).all() and np.isnan(got).all()
            continue
        mean = p.mean(axis=0)
        want = np.stack(
            [mean, np.sqrt(((p - mean) ** 2).mean(axis=0)), np.cbrt(((p - mean) ** 3).mean(axis=0))]
        )
        np.testing.assert_allclose(integral.moments(box), want, atol=1e-6)
        np.testing.assert_allclose(got, want, atol=1e-6)


def test_masked_moments_ignore_the_background_around_a_person() -> None:
    # a red 2-px-wide "person" on a grey wall, box 6 wide: unmasked the mean is
    # (2 * 200 + 4 * 100) / 6 = 133.3; over the mask it is the shirt's 200, deviation 0
    image = np.full((4, 6, 3), 100, dtype=np.uint8)
    image[:, 2:4, 0] = 200
    mask = np.zeros((4, 6), dtype=bool)
    mask[:, 2:4] = True
    box = (0, 0, 6, 4)
    assert IntegralMoments.of(image).moments(box)[0, 0] == pytest.approx(400 / 3)
    np.testing.assert_allclose(IntegralMoments.of(image, mask).moments(box)[:, 0], [200, 0, 0])


def test_mask_of_another_shape_is_refused() -> None:
    with pytest.raises(ValueError, match="mask shape"):
        IntegralMoments.of(np.zeros((4, 4, 3)), np.zeros((4, 5), dtype=bool))


def test_noise_sigma_finds_gaussian_noise_and_ignores_ramps() -> None:
    rng = np.random.default_rng(2)
    flat = 100.0 + 6.0 * rng.standard_normal((240, 320, 3))
    assert noise_sigma(flat) == pytest.approx(6.0, rel=0.05)
    # a linear ramp has no noise: Immerkaer's mask is zero on planes
    ramp = np.tile(np.arange(320, dtype=np.float64), (240, 1))
    assert noise_sigma(ramp) == pytest.approx(0.0, abs=1e-6)
    assert noise_sigma(np.zeros((2, 2))) == 0.0


def test_reliability_of_contrast_against_noise() -> None:
    # c^2 / (c^2 + (f n)^2): lit, contrast 60 vs noise 2.5 x 3 -> 3600 / (3600 + 56.25) = 0.985;
    # dark, contrast 3 vs noise 6 x 3 -> 9 / (9 + 324) = 0.027; contrast = 3 noise: 0.5
    assert reliability(60.0, 2.5, 3.0) == pytest.approx(3600 / 3656.25)
    assert reliability(3.0, 6.0, 3.0) == pytest.approx(9 / 333)
    assert reliability(18.0, 6.0, 3.0) == pytest.approx(0.5)
    assert reliability(0.0, 0.0, 3.0) == 0.0


def test_model_contrast_to_the_background() -> None:
    # two regions, one channel: means 110 and 70 vs background 100 -> (10 + 30) / 2 = 20;
    # an unmeasured region (NaN) is left out
    moments = np.array([[[110.0], [5.0], [0.0]], [[70.0], [5.0], [0.0]], [[np.nan]] * 3])
    assert ColourModel(moments).contrast(np.array([100.0])) == pytest.approx(20.0)
    assert ColourModel(np.full((1, 3, 1), np.nan)).contrast(np.array([100.0])) == 0.0


def test_eight_bit_and_float_integrals_are_the_same_numbers() -> None:
    # the uint8 path (integral2 and a float32 cube) sums the same integers as float64
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (30, 40, 3)).astype(np.uint8)
    mask = rng.random((30, 40)) < 0.5
    for img in (image, image[..., 1]):
        for m in (None, mask):
            a, b = IntegralMoments.of(img, m), IntegralMoments.of(img.astype(np.float64), m)
            for x, y in ((a.s1, b.s1), (a.s2, b.s2), (a.s3, b.s3)):
                np.testing.assert_array_equal(x, y)


def test_reused_integrals_are_overwritten_with_the_same_numbers() -> None:
    # a tracker passes last frame's integrals to be written into: equal to fresh ones
    rng = np.random.default_rng(4)
    frames = [rng.integers(0, 256, (30, 40, 3)).astype(np.uint8) for _ in range(3)]
    masks = [rng.random((30, 40)) < 0.4 for _ in range(3)]
    last = None
    for image, mask in zip(frames, masks, strict=True):
        fresh = IntegralMoments.of(image, mask, 4)
        last = IntegralMoments.of(image, mask, 4, reuse=last)
        assert last.count is not None and fresh.count is not None
        for x, y in ((last.s1, fresh.s1), (last.s2, fresh.s2), (last.s3, fresh.s3)):
            np.testing.assert_array_equal(x, y)
        np.testing.assert_array_equal(last.count, fresh.count)
    # another shape: new arrays
    other = IntegralMoments.of(frames[0][:20], masks[0][:20], 4, reuse=last)
    assert other.s1.shape == (21, 41, 3)
    np.testing.assert_array_equal(other.s3, IntegralMoments.of(frames[0][:20], masks[0][:20]).s3)


def test_eight_bit_noise_and_means_are_the_float_numbers() -> None:
    # the 8-bit paths (int16 filter, OpenCV sums) give the float paths' numbers exactly
    rng = np.random.default_rng(5)
    for shape in ((48, 64, 3), (48, 64), (5, 7, 1)):
        image = rng.integers(0, 256, shape).astype(np.uint8)
        assert noise_sigma(image) == noise_sigma(image.astype(np.float32))
    image = rng.integers(0, 256, (48, 64, 3)).astype(np.uint8)
    np.testing.assert_array_equal(channel_means(image), image.reshape(-1, 3).mean(axis=0))
    np.testing.assert_array_equal(
        channel_means(image[::2, ::2]), image[::2, ::2].reshape(-1, 3).mean(axis=0)
    )
