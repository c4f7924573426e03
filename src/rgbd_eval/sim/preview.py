"""A contact sheet of a few synthetic frames with their ground-truth boxes (``synth --preview``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.atomic import write_bytes
from rgbd_eval.errors import OutputError
from rgbd_eval.outdir import check_output_file
from rgbd_eval.sim.scenario import Scenario
from rgbd_eval.sim.simulate import SimFrame, Simulator
from rgbd_eval.sim.synth import OWNER

#: Box colours per id (RGB), cycled.
_PALETTE = [
    (255, 60, 60),
    (60, 220, 60),
    (80, 140, 255),
    (255, 200, 40),
    (220, 80, 255),
    (0, 220, 220),
]


def default_frames(n_frames: int, count: int = 6) -> list[int]:
    """``count`` frame indices spread evenly over the sequence."""
    if count < 1:
        raise ValueError(f"count={count} must be at least 1")
    return sorted({round(i * (n_frames - 1) / max(count - 1, 1)) for i in range(count)})


def depth_colour(depth: NDArray[np.float32], max_m: float = 8.0) -> NDArray[np.uint8]:
    """Depth as an RGB false-colour image; invalid pixels black."""
    scaled = np.nan_to_num(np.clip(depth / max_m, 0.0, 1.0), nan=0.0)
    grey = (255 - scaled * 255).astype(np.uint8)
    bgr = cv2.applyColorMap(grey, cv2.COLORMAP_JET)
    bgr[~np.isfinite(depth)] = 0
    return np.asarray(bgr[..., ::-1], dtype=np.uint8)


def annotate(frame: SimFrame) -> NDArray[np.uint8]:
    """The frame's RGB with ground-truth boxes, ids, visible fractions and a depth inset."""
    img = np.ascontiguousarray(frame.rgb.copy())
    for gt in frame.ground_truth:
        if gt.box2d is None:
            continue
        colour = _PALETTE[(gt.object_id - 1) % len(_PALETTE)]
        if gt.ignore:
            colour = (128, 128, 128)
        b = gt.box2d
        p0 = (round(b.left), round(b.top))
        p1 = (round(b.right) - 1, round(b.bottom) - 1)
        cv2.rectangle(img, p0, p1, colour, 2)
        label = f"{gt.object_id} v={gt.visibility:.2f}"
        cv2.putText(
            img, label, (p0[0] + 2, max(12, p0[1] - 4)), cv2.FONT_HERSHEY_SIMPLEX, 0.45, colour, 1
        )
    inset = depth_colour(frame.depth)
    h = img.shape[0] // 4
    w = round(inset.shape[1] * h / inset.shape[0])
    img[-h:, -w:] = cv2.resize(inset, (w, h), interpolation=cv2.INTER_NEAREST)
    cv2.putText(
        img,
        f"#{frame.index} t={frame.t:.1f}s",
        (6, 18),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.55,
        (255, 255, 255),
        1,
    )
    return img


def contact_sheet(images: Sequence[NDArray[np.uint8]], columns: int = 3) -> NDArray[np.uint8]:
    """Tile equally sized images row by row (missing tiles black)."""
    if not images:
        raise ValueError("images must not be empty")
    if columns < 1:
        raise ValueError(f"columns={columns} must be at least 1")
    h, w = images[0].shape[:2]
    rows = -(-len(images) // columns)
    sheet = np.zeros((rows * h, columns * w, 3), dtype=np.uint8)
    for k, im in enumerate(images):
        r, c = divmod(k, columns)
        sheet[r * h : (r + 1) * h, c * w : (c + 1) * w] = im
    return sheet


def write_preview(
    scenario: Scenario,
    png_path: Path | str,
    seed: int | None = None,
    frames: Sequence[int] | None = None,
    columns: int = 3,
) -> Path:
    """Render ``frames`` (default: six spread over the sequence) and write a PNG contact sheet.

    It replaces only a preview ``synth`` wrote (OutputError otherwise, or when it cannot
    be written).
    """
    out = Path(png_path)
    check_output_file(out, OWNER)
    sim = Simulator(scenario, seed)
    indices = list(frames) if frames is not None else default_frames(sim.n_frames)
    images = [annotate(sim.frame(i)) for i in indices]
    sheet = contact_sheet(images, columns)
    ok, png = cv2.imencode(".png", sheet[..., ::-1])
    if not ok:
        raise OutputError(out, "cannot encode the contact sheet as PNG")
    write_bytes(out, png.tobytes(), OWNER)
    return out
