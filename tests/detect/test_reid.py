"""Re-ID embedders: the ONNX path through a tiny model, the colour+texture descriptor, the built-in."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.detect.reid import (
    ColourTextureEmbedder,
    OnnxEmbedder,
    OnnxEmbedderParams,
    builtin_mobilenet,
    crop,
)
from rgbd_eval.types import Box2D
from tests.detect.onnx_models import channel_mean_model


def _two_colour_image() -> np.ndarray:
    rgb = np.zeros((60, 80, 3), dtype=np.uint8)
    rgb[:, :40] = (255, 0, 0)
    rgb[:, 40:] = (51, 102, 204)
    return rgb


def test_crop_clips_to_the_image() -> None:
    rgb = _two_colour_image()
    assert crop(rgb, Box2D(-5, -5, 10, 10)).shape == (5, 5, 3)
    assert crop(rgb, Box2D(78.5, 10, 10, 10)).shape == (10, 2, 3)
    assert crop(rgb, Box2D(200, 200, 5, 5)).shape == (1, 1, 3)  # outside: one edge pixel


def test_onnx_embedder_crops_resizes_and_normalises(tmp_path: Path) -> None:
    path = channel_mean_model(tmp_path / "mean.onnx", 8, 4)
    params = OnnxEmbedderParams(
        input_width=4, input_height=8, mean=(0.5, 0.5, 0.5), std=(0.5, 0.25, 0.5)
    )
    emb = OnnxEmbedder(path, params)
    assert emb.dimension == 3
    out = emb.embed(_two_colour_image(), [Box2D(0, 0, 40, 60), Box2D(40, 0, 40, 60)])
    # (v / 255 - 0.5) / std per channel: red (255, 0, 0) -> (1, -2, -1);
    # (51, 102, 204) -> (0.2 - 0.5) / 0.5 = -0.6, (0.4 - 0.5) / 0.25 = -0.4, (0.8 - 0.5) / 0.5 = 0.6
    np.testing.assert_allclose(out, [[1.0, -2.0, -1.0], [-0.6, -0.4, 0.6]], atol=1e-5)
    single = OnnxEmbedder(path, OnnxEmbedderParams(4, 8, (0.5,) * 3, (0.5, 0.25, 0.5), batch=False))
    np.testing.assert_allclose(
        single.embed(_two_colour_image(), [Box2D(0, 0, 40, 60)]), out[:1], atol=1e-6
    )
    normed = OnnxEmbedder(
        path, OnnxEmbedderParams(4, 8, (0.5,) * 3, (0.5, 0.25, 0.5), l2_normalise=True)
    )
    np.testing.assert_allclose(
        np.linalg.norm(normed.embed(_two_colour_image(), [Box2D(0, 0, 40, 60)])), 1.0
    )
    assert emb.embed(_two_colour_image(), []).shape == (0, 3)


def test_colour_texture_separates_colours_and_is_unit_norm() -> None:
    rgb = _two_colour_image()
    emb = ColourTextureEmbedder()
    out = emb.embed(rgb, [Box2D(0, 0, 20, 60), Box2D(20, 0, 20, 60), Box2D(40, 0, 40, 60)])
    assert out.shape == (3, emb.dimension) == (3, 6 * (8 * 4 + 8))
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0, rtol=1e-6)
    same = np.linalg.norm(out[0] - out[1])
    different = np.linalg.norm(out[0] - out[2])
    assert same < 1e-6  # two crops of the same flat red
    # flat colours: no gradients, so the texture halves are zero and the colour halves are
    # one-hot per stripe in different bins: distance sqrt(2)
    assert different == pytest.approx(np.sqrt(2.0))


def test_builtin_mobilenet_runs_and_is_deterministic() -> None:
    emb = builtin_mobilenet()
    assert emb.dimension == 1280
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, size=(120, 160, 3), dtype=np.uint8)
    boxes = [Box2D(10, 10, 40, 100), Box2D(80, 5, 50, 110)]
    a = emb.embed(rgb, boxes)
    b = emb.embed(rgb, boxes[:1])
    np.testing.assert_allclose(np.linalg.norm(a, axis=1), 1.0, rtol=1e-5)
    np.testing.assert_allclose(a[:1], b, atol=1e-5)  # batch and single agree


def test_colour_texture_uses_no_cpu_dependent_maths(monkeypatch: pytest.MonkeyPatch) -> None:
    # numpy's arctan2 and hypot (SIMD/SVML by CPU) and BLAS norms can differ in the last bit
    # between CPUs, and a last bit can move a gradient orientation across a bin edge: the
    # descriptor (and so pinto2022's calibrated thresholds) must not call them.
    rng = np.random.default_rng(5)
    rgb = rng.integers(0, 256, (120, 80, 3), dtype=np.uint8)
    boxes = [Box2D(4.0, 2.0, 60.0, 110.0)]
    expected = ColourTextureEmbedder().embed(rgb, boxes)

    def refuse(*_a: object, **_k: object) -> None:
        raise AssertionError("CPU-dependent maths called")

    monkeypatch.setattr(np, "arctan2", refuse)
    monkeypatch.setattr(np, "hypot", refuse)
    monkeypatch.setattr(np.linalg, "norm", refuse)
    got = ColourTextureEmbedder().embed(rgb, boxes)
    assert got.tobytes() == expected.tobytes()
    assert float(np.sqrt(np.sum(got.astype(np.float64) ** 2))) == pytest.approx(1.0, abs=1e-6)
