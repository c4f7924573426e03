"""The cielniak2010 tracker: thermal-to-colour boxes, frame requirement, method config,
the warm-region proposals, the standing-height prior and the occlusion order the tracker calls."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy import ndimage

from rgbd_eval.config import build_config
from rgbd_eval.methods.cielniak2010.occlusion import order, overlap, sort_front_to_back
from rgbd_eval.methods.cielniak2010.person_geometry import (
    HeightPrior,
    height_log_prior,
    implied_heights,
)
from rgbd_eval.methods.cielniak2010.tracker import (
    Affine,
    Cielniak2010Tracker,
    Cielniak2010TrackerConfig,
    _every_kth_pixel,
    median_temperature,
    temperature_image,
)
from rgbd_eval.methods.cielniak2010.warm_regions import (
    WarmRegionParams,
    _dilated,
    warm_regions,
)
from rgbd_eval.plugins import DetectionContract
from rgbd_eval.types import CameraModel, Frame, Pose, Stream

THERMAL = CameraModel(320, 240, 300.0, 300.0, 159.5, 119.5, (0.0,) * 5, "thermal")
COLOUR = CameraModel(640, 480, 525.0, 525.0, 319.5, 239.5, (0.0,) * 5, "rgb")


def _frame(i: int, temp_c: np.ndarray) -> Frame:
    counts = np.rint((temp_c + 273.15) * 100).astype(np.uint16)
    stamp = i * 33_333_333
    return Frame(
        i,
        stamp,
        {
            "thermal": Stream(counts, "mono16", THERMAL, stamp, Pose((0.06, 0.0, 0.0))),
            "colour": Stream(np.zeros((480, 640, 3), np.uint8), "rgb8", COLOUR, stamp, Pose()),
        },
    )


def test_affine_of_parallel_cameras_hand_computed() -> None:
    # scale 525/300 = 1.75; offset 319.5 - 1.75 * 159.5 + 525 * 0.06 / 3 = 40.375 + 10.5
    a = Affine.between(
        _frame(0, np.zeros((240, 320))).streams["thermal"],
        _frame(0, np.zeros((240, 320))).streams["colour"],
        3.0,
    )
    assert a.scale == pytest.approx((1.75, 1.75))
    assert a.offset == pytest.approx((50.875, 239.5 - 1.75 * 119.5))


def test_affine_with_lens_distortion_is_fitted_to_the_exact_map() -> None:
    # A barely distorted thermal camera gives the hand-computed map above; a distorted one
    # the least-squares affine map of its pixels carried to the colour image at 3 m.
    frame = _frame(0, np.zeros((240, 320)))
    colour = frame.streams["colour"]

    def thermal(distortion: tuple[float, ...]) -> Stream:
        t = frame.streams["thermal"]
        return replace(t, camera=replace(t.camera, distortion=distortion))

    near = Affine.between(thermal((1e-12, 0.0, 0.0, 0.0, 0.0)), colour, 3.0)
    assert near.scale == pytest.approx((1.75, 1.75)) and near.offset == pytest.approx(
        (50.875, 239.5 - 1.75 * 119.5)
    )
    cam = replace(THERMAL, distortion=(-0.3, 0.1, 0.0, 0.0, 0.0))
    fitted = Affine.between(thermal(cam.distortion), colour, 3.0)
    # Barrel distortion packs the thermal image: the fitted scale is larger than 1.75.
    assert fitted.scale[0] > 1.8 and fitted.scale[1] > 1.8
    # The thermal image's centre is the lens' centre: mapped where the exact map puts it.
    centre = COLOUR.project(cam.points_at(159.5, 119.5, 3.0)[None, :] + [0.06, 0.0, 0.0])[0]
    (sx, sy), (ox, oy) = fitted.scale, fitted.offset
    assert (sx * 159.5 + ox, sy * 119.5 + oy) == pytest.approx(tuple(centre), abs=0.5)


def test_tracker_needs_the_frame_and_method_config_loads() -> None:
    trk = Cielniak2010Tracker(Cielniak2010TrackerConfig(), DetectionContract())
    with pytest.raises(ValueError, match="thermal image"):
        trk.update(0, [], None)
    cfg = build_config({"method": "cielniak2010"})
    assert (
        cfg.tracker.name == "cielniak2010"
        and cfg.tracker.rho == 10.0
        and cfg.evaluation.gating.value == "iou"
    )


def test_warm_regions_keep_person_shaped_components() -> None:
    # 20 C room; a 60x20 px person at 28 C (elongation 3, fill 1), a 20x40 px monitor at
    # 35 C (wider than tall), and a 30x10 px radiator at 45 C (above max_temp_c) with a
    # 28 C person of 30x10 px touching it: the radiator's margin (2 px) keeps them apart
    img = np.full((120, 160), 20.0)
    img[10:70, 10:30] = 28.0
    img[80:100, 40:80] = 35.0
    img[20:50, 100:110] = 45.0
    img[20:50, 110:120] = 28.0
    regions = warm_regions(img, WarmRegionParams(min_height_px=20.0))
    people = {tuple(int(x) for x in b) for b in regions.boxes[regions.person]}
    # the second person loses the 2 px next to the radiator: columns 112..119
    assert people == {(10, 10, 30, 70), (112, 20, 120, 50)}
    assert (40, 80, 80, 100) in {tuple(int(x) for x in b) for b in regions.boxes}


def test_fast_median_and_subsampling_are_numpys() -> None:
    # the histogram median of the counts and OpenCV's subsampling give numpy's numbers
    rng = np.random.default_rng(7)
    for shape, encoding, dtype in (
        ((24, 32), "mono16", np.uint16),
        ((25, 31), "mono16", np.uint16),
        ((24, 32), "mono8", np.uint8),
    ):
        counts = rng.integers(29000 if dtype == np.uint16 else 0, 31000, shape).astype(dtype)
        stream = Stream(counts, encoding, THERMAL, 0)
        temp = temperature_image(stream)
        assert median_temperature(stream, temp) == float(np.median(temp))
    image = rng.integers(0, 256, (48, 64, 3)).astype(np.uint8)
    for k in (1, 2, 3, 4, 16):
        np.testing.assert_array_equal(_every_kth_pixel(image, k), image[::k, ::k])
    np.testing.assert_array_equal(_every_kth_pixel(image[:47], 2), image[:47:2, ::2])


def test_hot_margin_is_scipys_binary_dilation() -> None:
    # OpenCV's dilation grows the hot pixels as ndimage's 8-connected one, up to the border
    rng = np.random.default_rng(6)
    for iterations in (1, 2, 3):
        hot = rng.random((40, 50)) < 0.02
        hot[0, 7] = hot[39, 49] = True
        expected = ndimage.binary_dilation(hot, np.ones((3, 3), bool), iterations=iterations)
        np.testing.assert_array_equal(_dilated(hot, iterations), expected)


def test_implied_height_of_a_person_on_the_floor_hand_computed() -> None:
    # level camera 1.1 m above the floor looking along world x (optical z = world x,
    # optical y = -world z); fy = 300, cy = 119.5. A 1.75 m person 5 m away: feet at
    # v = 119.5 + 300 * 1.1 / 5 = 185.5, top at v = 119.5 - 300 * 0.65 / 5 = 80.5,
    # so the box is h = 105 px centred at v = 133
    pose = Pose((0.0, 0.0, 1.1), (-0.5, 0.5, -0.5, 0.5))
    states = np.array([[159.5, 133.0, 105.0], [159.5, 90.0, 52.5], [159.5, 50.0, 40.0]])
    heights = implied_heights(THERMAL, pose, states)
    assert heights[0] == pytest.approx(1.75)
    # half the box on the upper body: feet at v = 116.25, above the horizon: no floor
    assert np.isnan(heights[1]) and np.isnan(heights[2])
    prior = height_log_prior(HeightPrior(), np.array([1.75, 2.25, np.nan]))
    # 2.25 m is 0.2 m = 2 sigma above 2.05 m: -(2^2)/2 = -2
    assert prior.tolist() == pytest.approx([0.0, -2.0, HeightPrior().no_floor])


def test_implied_height_follows_the_lens_distortion() -> None:
    # The same level camera with barrel distortion (k1 = -0.3); the 1.75 m person 2 m away:
    # its feet (0.55 below the axis) and top (0.325 above) are imaged 9 % and 3 % nearer
    # the centre, so the pinhole model would put the feet farther away, at 2.2 m, and make
    # the person 1.79 m tall.
    cam = replace(THERMAL, distortion=(-0.3, 0.0, 0.0, 0.0, 0.0))
    pose = Pose((0.0, 0.0, 1.1), (-0.5, 0.5, -0.5, 0.5))
    feet_top = cam.project(np.array([[0.0, 1.1, 2.0], [0.0, -0.65, 2.0]]))
    v_feet, v_top = feet_top[:, 1]
    states = np.array([[159.5, (v_feet + v_top) / 2, v_feet - v_top]])
    assert implied_heights(cam, pose, states)[0] == pytest.approx(1.75, abs=1e-9)
    assert implied_heights(replace(cam, distortion=()), pose, states)[0] > 1.78


def test_order_on_a_blank_image_puts_the_lower_feet_in_front() -> None:
    # The shipped AdaBoost classifier with nothing to measure but the boxes: on a level
    # floor the nearer person's feet are lower in the image.
    near = np.array([100.0, 40.0, 140.0, 200.0])  # feet at v = 200
    far = np.array([120.0, 60.0, 150.0, 150.0])  # feet at v = 150
    thermal = np.zeros((240, 320))
    assert order(near, far, thermal, None) == 0 and order(far, near, thermal, None) == 1
    assert sort_front_to_back([far, near, far + 1.0], thermal, None) == [1, 2, 0]
    # overlap over the smaller box: intersection 20 x 90 = 1800, smaller 30 x 90 = 2700
    assert overlap(near, far) == pytest.approx(1800 / 2700)


#: A level camera 1.1 m above the floor (optical z = world x, optical y = -world z).
LEVEL = Pose((0.0, 0.0, 1.1), (-0.5, 0.5, -0.5, 0.5))


def _people_image(us: list[float]) -> np.ndarray:
    """20 C room, 28 C people 1.75 m tall 5 m away (h = 105 px, centre v = 133, see
    test_implied_height...) at columns ``us``: head, torso and legs ellipses."""
    H, W = 240, 320
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float64)
    img = np.full((H, W), 20.0)
    h, v = 105.0, 133.0
    for u in us:
        inside = np.zeros((H, W), dtype=bool)
        for cy, a, b in ((-0.435, 0.05, 0.065), (-0.175, 0.13, 0.195), (0.26, 0.09, 0.24)):
            inside |= ((xx - u) / (a * h)) ** 2 + ((yy - (v + cy * h)) / (b * h)) ** 2 <= 1
        img[inside] = 28.0
    return img


def _level_frame(i: int, temp_c: np.ndarray) -> Frame:
    counts = np.rint((temp_c + 273.15) * 100).astype(np.uint16)
    stamp = i * 33_333_333
    return Frame(i, stamp, {"thermal": Stream(counts, "mono16", THERMAL, stamp, LEVEL)})


def test_sequential_detector_starts_one_filter_per_person_and_deletes_lost_ones() -> None:
    trk = Cielniak2010Tracker(Cielniak2010TrackerConfig(), DetectionContract())
    two = _people_image([100.0, 220.0])
    # confirm_frames = 3: the proposals of frames 0 and 1 are pending, frame 2 starts both
    counts = [len(trk.update(i * 33_333_333, [], _level_frame(i, two))) for i in range(3)]
    assert counts == [0, 0, 2]
    for i in range(3, 20):
        out = trk.update(i * 33_333_333, [], _level_frame(i, two))
    assert sorted(t.track_id for t in out) == [1, 2]
    by_id = {t.track_id: t.box2d for t in out}
    # without a colour stream the boxes stay in thermal pixels: the warm components' boxes
    # (the blobs' extents: 105 px tall, the torso 2 * 0.13 * 105 = 27 px wide)
    for box, u in zip((by_id[1], by_id[2]), (100.0, 220.0), strict=True):
        assert abs(box.left + box.width / 2 - u) <= 1.0 and abs(box.height - 105.0) <= 2.0
    # the person at u = 220 leaves: its filter scores below stop_score and goes after
    # lost_frames = 10 frames; the other keeps its id
    one = _people_image([100.0])
    alive = []
    for i in range(20, 32):
        alive.append(
            sorted(t.track_id for t in trk.update(i * 33_333_333, [], _level_frame(i, one)))
        )
    assert alive[0] == [1, 2] and alive[-1] == [1]


def _dressed_frame(
    i: int, u: float | None, rgb: tuple[int, int, int], light: float = 1.0, noise: float = 0.0
) -> Frame:
    """A thermal frame with a person at column ``u`` (none when None) and a colour frame, same
    pose (affine: scale 525 / 300 = 1.75, offset 319.5 - 1.75 * 159.5 = 40.375 and
    239.5 - 1.75 * 119.5 = 30.375), where the person's thermal box is painted ``rgb``; the
    colour image scaled by ``light`` with Gaussian ``noise`` (levels) added."""
    temp = _people_image([] if u is None else [u])
    colour = np.full((480, 640, 3), 128, np.uint8)
    if u is not None:
        u0, u1 = 1.75 * (u - 20.0) + 40.375, 1.75 * (u + 20.0) + 40.375
        v0, v1 = 1.75 * 80.0 + 30.375, 1.75 * 186.0 + 30.375
        colour[round(v0) : round(v1), round(u0) : round(u1)] = rgb
    if light != 1.0 or noise > 0.0:
        dim = light * colour + noise * np.random.default_rng(i).standard_normal(colour.shape)
        colour = np.clip(np.rint(dim), 0, 255).astype(np.uint8)
    counts = np.rint((temp + 273.15) * 100).astype(np.uint16)
    stamp = i * 33_333_333
    return Frame(
        i,
        stamp,
        {
            "thermal": Stream(counts, "mono16", THERMAL, stamp, LEVEL),
            "colour": Stream(colour, "rgb8", COLOUR, stamp, LEVEL),
        },
    )


@pytest.mark.parametrize(("again", "same_id"), [((200, 30, 30), True), ((30, 30, 200), False)])
def test_a_lost_person_is_reidentified_by_colour(
    again: tuple[int, int, int], same_id: bool
) -> None:
    trk = Cielniak2010Tracker(Cielniak2010TrackerConfig(), DetectionContract())
    for i in range(15):  # a red-clad person at u = 100
        out = trk.update(i * 33_333_333, [], _dressed_frame(i, 100.0, (200, 30, 30)))
    assert [t.track_id for t in out] == [1]
    for i in range(15, 30):  # gone: deleted after lost_frames = 10
        out = trk.update(i * 33_333_333, [], _dressed_frame(i, None, (0, 0, 0)))
    assert out == []
    for i in range(30, 40):  # someone appears elsewhere: red again, or blue
        out = trk.update(i * 33_333_333, [], _dressed_frame(i, 180.0, again))
    # red: the same paint in the same body regions, the moments match (below reid_distance): id 1;
    # blue: the means differ by 170 in two channels, far beyond reid_distance: a new id
    assert [t.track_id for t in out] == ([1] if same_id else [2])


def test_in_the_dark_colour_is_not_trusted() -> None:
    """thermal_darkness.yaml's colour camera: light 0.04, noise 6 levels. The red paint is
    0.04 * 200 = 8 levels on a 0.04 * 128 = 5 background, a contrast of ~3 levels against
    6 of noise: reliability ~ 9 / (9 + (3 * 6)^2) = 0.03, so colour neither weighs the
    particles nor re-uses the lost id of a person in other clothes (blue: 0.04 * 170 = 7
    levels away in two channels, which the raw moment distance would call the same)."""
    trk = Cielniak2010Tracker(Cielniak2010TrackerConfig(), DetectionContract())
    lit = Cielniak2010Tracker(Cielniak2010TrackerConfig(), DetectionContract())
    for i in range(15):
        out = trk.update(i * 33_333_333, [], _dressed_frame(i, 100.0, (200, 30, 30), 0.04, 6.0))
        lit.update(i * 33_333_333, [], _dressed_frame(i, 100.0, (200, 30, 30), 1.0, 2.5))
    assert [t.track_id for t in out] == [1]
    dark_model, lit_model = trk.tracks[0].colour, lit.tracks[0].colour
    assert dark_model is not None and lit_model is not None
    # 6 levels of noise, less what clipping at 0 removes around a mean of 5 levels
    assert 4.0 < trk.noise < 6.5
    assert trk._reliability(dark_model) < 0.1 < 0.9 < lit._reliability(lit_model)
    for i in range(15, 30):
        out = trk.update(i * 33_333_333, [], _dressed_frame(i, None, (0, 0, 0), 0.04, 6.0))
    for i in range(30, 40):
        out = trk.update(i * 33_333_333, [], _dressed_frame(i, 180.0, (30, 30, 200), 0.04, 6.0))
    assert [t.track_id for t in out] == [2]


def test_same_seed_same_filters_bit_for_bit() -> None:
    """Particle filters are random: the tracker's own generator, seeded by ``seed``, makes
    two runs on the same frames equal to the last bit (colour on, noisy image); another
    seed moves the particles (the reported box may still be the warm component's)."""

    def run(seed: int) -> list[bytes]:
        trk = Cielniak2010Tracker(Cielniak2010TrackerConfig(seed=seed), DetectionContract())
        out = []
        for i in range(12):
            frame = _dressed_frame(i, 100.0 + 2.0 * i, (200, 30, 30), 1.0, 2.5)
            trk.update(i * 33_333_333, [], frame)
            out.append(b"".join(t.filter.particles.tobytes() for t in trk.tracks))
        return out

    first = run(0)
    assert first[-1] and first == run(0) and first[-1] != run(1)[-1]
