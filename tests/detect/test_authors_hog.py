"""The thesis authors' classifier: Dollár's HOG + their SVM (seed 000, 5.4.2).

The oracle values in ``data/authors_hog/oracle.json`` were printed by the authors'
C++ (PCL 1.13 ``PersonClassifier::evaluate``, built from bench/peers/) with the
command stored in that file; these tests do not need PCL.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from rgbd_eval.detect.authors_hog import (
    DESCRIPTOR_SIZE,
    PersonWindow,
    _acos_table,
    hog_descriptors,
    load_svm,
    person_confidences,
    shipped_svm,
    sse_rcp,
    sse_rsqrt,
    window_bounds,
    window_sample,
)
from rgbd_eval.errors import ConfigError

from .scenes import ring_texture

DATA = Path(__file__).parent / "data" / "authors_hog"


def _image(name: str) -> NDArray[np.uint8]:
    if name == "rings":
        return ring_texture()
    bgr = cv2.imread(str(DATA / name), cv2.IMREAD_COLOR)
    assert bgr is not None
    return np.asarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), dtype=np.uint8)


def _oracle() -> list[dict[str, object]]:
    doc = json.loads((DATA / "oracle.json").read_text())
    assert "pcl_people_oracle classify" in doc["command"]
    cases: list[dict[str, object]] = doc["cases"]
    return cases


def _ours(approximate: bool) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    cases = _oracle()
    ours, theirs = [], []
    for name in sorted({str(c["image"]) for c in cases}):
        mine = [c for c in cases if c["image"] == name]
        windows = [PersonWindow(float(c["height"]), float(c["xc"]), float(c["yc"])) for c in mine]  # type: ignore[arg-type]
        ours.extend(person_confidences(_image(name), windows, approximate=approximate))
        theirs.extend(float(c["confidence"]) for c in mine)  # type: ignore[arg-type]
    return np.array(ours), np.array(theirs)


def test_confidences_match_the_authors_cpp() -> None:
    # 27 windows on a ray-cast room with five people (some cut by the border) and on
    # colour rings: enlarged, shrunk, cut on every side, 4x2 px. Target 1e-3; with
    # the SSE reciprocals emulated, the arithmetic is the C++'s and agrees to 1e-9.
    ours, theirs = _ours(approximate=True)
    assert ours.shape == (27,)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-6)
    # Rings first (11 windows), then the room: 11 fixed windows, the 5 people's last.
    # The best person window scores above every window on the empty parts of the room.
    assert theirs[22:].max() > -1.0 > theirs[11:22].max()


def test_exact_reciprocals_show_how_much_the_cpu_matters() -> None:
    # Exact 1/sqrt moves vertical edges' orientation across Dollár's arc-cosine table's
    # clipped ends: 1e-3 typical, up to ~0.07 on flat-coloured windows. This is the
    # spread of the C++ itself between CPUs with different 12-bit approximations.
    ours, theirs = _ours(approximate=False)
    diff = np.abs(ours - theirs)
    assert diff.max() < 0.1
    assert diff.max() > 1e-3


def test_window_bounds_arithmetic() -> None:
    # h = 96: height = round(96 / 0.75) = 128, width = round(96 * 64 / 96) = 64;
    # xmin = floor(200.5 - 64 // 2 + 0.5) = 169, ymin = floor(180.25 - 64 + 0.5) = 116.
    assert window_bounds(PersonWindow(96.0, 200.5, 180.25)) == (169, 116, 64, 128)
    # h = 150.3: height = round(200.4) = 200, width = round(100.2) = 100;
    # xmin = floor(100.7 - 50 + 0.5) = 51, ymin = floor(300.2 - 100 + 0.5) = 200.
    assert window_bounds(PersonWindow(150.3, 100.7, 300.2)) == (51, 200, 100, 200)


def test_sample_at_scale_one_is_the_crop_and_black_outside() -> None:
    img = ring_texture()
    # A 64x128 crop maps 1:1 (weights 0): the sample is the crop / 255.
    s = window_sample(img, PersonWindow(96.0, 200.5, 180.25))
    np.testing.assert_array_equal(s * 255, img[116:244, 169:233].astype(np.float32))
    # Cut by the left border: xmin = floor(10 - 32 + 0.5) = -22, so the first 22
    # sample columns are black and column 22 is image column 0.
    s = window_sample(img, PersonWindow(96.0, 10.0, 200.0))
    assert not s[:, :22].any()
    np.testing.assert_array_equal(s[:, 22:] * 255, img[136:264, 0:42].astype(np.float32))


def test_enlarged_sample_keeps_the_authors_black_last_row() -> None:
    # h = 48: a 64x32 crop; output row i reads crop row i / 2, and row 127's ceiling
    # (64) leaves the crop, so the authors' resize leaves it black; likewise column 63.
    img = np.full((480, 640, 3), 200, dtype=np.uint8)
    s = window_sample(img, PersonWindow(48.0, 320.0, 240.0))
    assert not s[127].any() and not s[:, 63].any()
    assert np.all(s[:127, :63] == np.float32(200) / np.float32(255))


def test_arc_cosine_table_ends() -> None:
    t = _acos_table()
    # Entry i holds acos(i * 2.02 / 25000 - 1.01), clipped to [-1, 1]; angles within
    # 1e-5 of pi are stored as 0 (the unsigned orientation wraps).
    assert t[12500] == pytest.approx(math.pi / 2, abs=1e-4)
    assert t[24999] == 0.0 and t[0] == 0.0
    assert t[100] == 0.0  # cos -1.0019, clipped to -1: pi -> 0


def test_blank_window_scores_minus_the_offset() -> None:
    # No gradient anywhere: each pixel's magnitude is the floor 1 / 1e10, so each
    # cell holds ~1e-10 and, over sqrt(eps) = sqrt(1e-4 / 4 / 8^4) = 7.8e-5, the
    # descriptor ~1e-6: the confidence is -b = -4.1021 to 1e-5.
    blank = np.full((480, 640, 3), 90, dtype=np.uint8)
    conf = person_confidences(blank, [PersonWindow(200.0, 320.0, 240.0)])
    assert conf[0] == pytest.approx(-4.1021, abs=1e-5)


def test_vertical_step_edge_descriptor() -> None:
    # Sample columns 0..31 black, 32..63 white (one channel suffices: the others tie).
    # Exact reciprocals: gx = (1 - 0) / 2 = 0.5 at columns 31 and 32, gy = 0, so
    # m = 0.5 and the cosine index is trunc(1 * 25000 / 2.02) = 12376:
    # angle = acos(24876 * 2.02 / 25000 - 1.01) = acos(0.99998) = 0.0062 rad,
    # o = 0.0062 * 9 / pi = 0.0178 -> 98.2% to bin 0, 1.8% to bin 1.
    # Column 31 (xb = 31.5 / 8 - 0.5 = 3.4375) votes 0.5625 to cell 3, 0.4375 to cell 4;
    # column 32 the reverse. No other cell gets a vote.
    sample = np.zeros((1, 128, 64, 3), dtype=np.float32)
    sample[0, :, 32:, :] = 1.0
    d = hog_descriptors(sample, approximate=False)[0].reshape(4, 9, 6, 14)
    angle = float(_acos_table()[24876])
    assert angle == pytest.approx(0.0062, abs=1e-4)
    o = angle * 9 / math.pi
    # Cells 3 and 4 are inner columns 2 and 3. Every block holding them has equal
    # energy per edge cell, so cell / block norm >= 1/2 x 0.98 -> clipped at 0.2.
    assert np.all(d[:, 0, 2:4, :] == np.float32(0.2))
    # Bin 1: 0.0178 of the magnitude. A block with four edge cells (both columns):
    # 0.0178 / (2 sqrt(0.982^2 + 0.0178^2)) = 0.0089; with two (columns 2, 3 or 4, 5): x sqrt 2.
    two_cols = o / (2 * math.hypot(1 - o, o))
    # Cell rows 1..13 (the last inner row's blocks reach the partly filled row 15).
    np.testing.assert_allclose(d[0, 1, 2, :13], two_cols, rtol=1e-5)  # block (3, r): 4 edge cells
    np.testing.assert_allclose(d[2, 1, 2, :13], two_cols * math.sqrt(2), rtol=1e-5)  # block (2, r)
    # Elsewhere only the flat regions' 1e-10 floor (see the blank window): < 1e-5.
    assert np.abs(d[:, 2:]).max() < 1e-5  # no other orientation
    assert np.abs(d[:, :, [0, 1, 4, 5], :]).max() < 1e-5  # no other cell column


def test_sse_reciprocal_tables() -> None:
    x = np.array([0.25, 1.0, 2.0, 3.7, 1e-6, 12345.0], dtype=np.float32)
    # 12-bit approximations: within 1.5 * 2^-12 of the exact values.
    np.testing.assert_allclose(sse_rsqrt(x), 1 / np.sqrt(x.astype(np.float64)), rtol=1.5 / 4096)
    np.testing.assert_allclose(sse_rcp(x), 1 / x.astype(np.float64), rtol=1.5 / 4096)
    # Scaling by 4 halves rsqrt exactly; 0 gives inf (as rsqrtps).
    np.testing.assert_array_equal(sse_rsqrt(4 * x), sse_rsqrt(x) / 2)
    assert np.isinf(sse_rsqrt(np.zeros(1, dtype=np.float32)))[0]


def test_batch_equals_single_and_empty() -> None:
    img = ring_texture()
    ws = [PersonWindow(60.0 + 40 * k, 100.0 + 90 * k, 240.0) for k in range(5)]
    batch = person_confidences(img, ws)
    single = [person_confidences(img, [w])[0] for w in ws]
    np.testing.assert_array_equal(batch, single)
    assert person_confidences(img, []).shape == (0,)


def test_shipped_model_and_bad_models(tmp_path: Path) -> None:
    svm = shipped_svm()
    assert svm.weights.shape == (DESCRIPTOR_SIZE,) and svm.offset == pytest.approx(4.1021)
    with pytest.raises(ConfigError, match="cannot read"):
        load_svm(tmp_path / "missing.yaml")
    short = tmp_path / "short.yaml"
    short.write_text("window_height: 128\nwindow_width: 64\nb: 1.0\nweights: [1.0, 2.0]\n")
    with pytest.raises(ConfigError, match="3024 weights, got 64x128 and 2"):
        load_svm(short)
    broken = tmp_path / "broken.yaml"
    broken.write_text("weights: [1.0,\n")
    with pytest.raises(ConfigError, match="not a YAML SVM model"):
        load_svm(broken)


def test_bad_image_raises() -> None:
    with pytest.raises(ValueError, match="HxWx3 uint8"):
        person_confidences(np.zeros((10, 10), dtype=np.uint8), [PersonWindow(5.0, 5.0, 5.0)])
