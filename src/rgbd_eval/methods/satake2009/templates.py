"""Distance templates of satake2009 (seed 002, 2.2): upper-body depth templates and matching.

Three templates (body turned 0, 45 and 90 degrees from the camera; the seed says three
directions, not which) are depth images of people standing 2 m from a camera at 1.2 m
height (the seed: "the target person was at 2m away from the camera"), cut from the top of
the head to the hips. The people are tuning bodies no scenario scores
(:func:`tuning_bodies`), merged into one template per direction. Each keeps
a mask and its depth relative to the person's distance ``D`` (median depth of the mask),
at the focal length :data:`F_REF`. For a searched distance ``D`` a template is scaled in
size by ``(fx / F_REF) * (2 / D)`` and in depth by adding ``D`` (:func:`scale_template`).

Evaluation value (the seed gives no formula; this is ours): over the template's box,
the share of pixels that agree -- a mask pixel agrees when its depth is within
``band_m`` of ``D``, a pixel around the body when it is farther than ``D + gap_m`` or
has no depth. A person-shaped region standing free of its background scores near 1;
a wall (no free outline) or an empty floor scores low.

Regenerate the shipped data with ``python -m rgbd_eval.methods.satake2009.templates``.
"""

from __future__ import annotations

import math
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import CameraModel, Pose

if TYPE_CHECKING:
    from rgbd_eval.sim.body import BodyShape
    from rgbd_eval.sim.people import Appearance

DATA = Path(__file__).resolve().parent / "templates.npz"
#: Focal length (px) the templates are stored at: a 100-degree camera 512 px wide.
F_REF = 256.0 / math.tan(math.radians(50.0))
D_REF = 2.0
#: :meth:`Agreement.score_all` correlates maps this large (pixels) through a shared DFT;
#: on smaller ones :func:`cv2.matchTemplate` is as fast (about 64x64, measured).
DFT_MIN_PIXELS = 4096
#: Body orientations of the three templates (degrees from facing the camera).
ORIENTATIONS = (0.0, 45.0, 90.0)
_CAMERA_HEIGHT = 1.2
#: The random stream of the bodies the templates merge (see :func:`tuning_bodies`).
TUNING_SEED = 2009
TUNING_STREAM = 20
#: Image row the bodies' head tops are aligned on before merging.
TOP_ROW = 100


@dataclass(frozen=True)
class DistanceTemplate:
    """A template at one distance: mask, depth (m, NaN off the body), its head-top anchor."""

    orientation_deg: float
    mask: NDArray[np.bool_]
    depth: NDArray[np.float32]
    #: (column, row) of the top of the head inside the template.
    anchor: tuple[float, float]
    distance: float

    @cached_property
    def kernel(self) -> NDArray[np.float32]:
        """The mask as 1.0 / 0.0, the correlation kernel of :meth:`Agreement.score`."""
        return self.mask.astype(np.float32)

    @cached_property
    def _spectra(self) -> dict[tuple[int, int], NDArray[np.float32]]:
        return {}

    def spectrum(self, shape: tuple[int, int]) -> NDArray[np.float32]:
        """DFT (OpenCV's packed CCS) of :attr:`kernel` zero-padded to ``shape``, kept per shape."""
        got = self._spectra.get(shape)
        if got is None:
            padded = np.zeros(shape, np.float32)
            h, w = self.mask.shape
            padded[:h, :w] = self.kernel
            got = np.asarray(cv2.dft(padded, nonzeroRows=h), np.float32)
            self._spectra[shape] = got
        return got


def tuning_bodies() -> list[tuple[BodyShape, Appearance]]:
    """The people the templates are made from (none of them is scored).

    Six bodies spanning sex and height: a woman and a man at each of -1, 0 and +1 standard
    deviations of the renderer's adult heights (:data:`rgbd_eval.sim.people.HEIGHT_MEAN`,
    ``HEIGHT_SD``: 1.565, 1.63, 1.695 m and 1.69, 1.76, 1.83 m). Their age, build, hair and
    clothes are drawn by the renderer's own catalogues from ``default_rng([TUNING_SEED,
    TUNING_STREAM, k])``: scored people come from stream :data:`rgbd_eval.sim.people.STREAM`
    (7), never :data:`TUNING_STREAM`, so no scenario of any seed holds one of them. Nothing
    here is chosen by a detection score.
    """
    from rgbd_eval.sim.people import HEIGHT_MEAN, HEIGHT_SD, draw_appearance, draw_shape

    out = []
    for k, (sex, z) in enumerate((s, z) for s in (0, 1) for z in (-1.0, 0.0, 1.0)):
        rng = np.random.default_rng([TUNING_SEED, TUNING_STREAM, k])
        height = round(HEIGHT_MEAN[sex] + z * HEIGHT_SD[sex], 3)
        shape = draw_shape(rng, float(sex), height)
        out.append((shape, draw_appearance(rng, shape)))
    return out


def _render_body(
    shape: BodyShape, look: Appearance, angle: float, cam: CameraModel, pose: Pose
) -> tuple[NDArray[np.float64], float, float]:
    """Depth (NaN: no body) of one standing person at :data:`D_REF`, turned ``angle`` deg,
    with its head-top and hip heights (m)."""
    from rgbd_eval.sim.people import dress
    from rgbd_eval.sim.render import make_scene, render_hits

    person = dress(shape, look)
    heading = math.pi - math.radians(angle)  # facing the camera at angle 0
    mesh, top = person.mesh(D_REF, 0.0, heading, 0.0, 0.0, 0.0, 0.0, 1)
    hip = 0.5 * float(
        person.body.bone_head("upperleg01.L")[2] + person.body.bone_head("upperleg01.R")[2]
    )
    z = np.asarray(render_hits(make_scene(mesh), cam, pose).depth, np.float64)
    return z, top, hip


def build_templates() -> list[DistanceTemplate]:
    """The three templates: :func:`tuning_bodies` at :data:`D_REF`, standing, merged.

    Each body's depth image is shifted so that its head top falls on one row (the
    template's anchor), then a pixel is in the mask when at least half the bodies cover
    it, and its relative depth is the median over the bodies that do (each body's depth
    less its own median). Cut from the head top to the bodies' median hip row.
    """
    from rgbd_eval.types import OPTICAL_TO_BODY

    w, h = 512, 384
    cam = CameraModel(w, h, F_REF, F_REF, (w - 1) / 2, (h - 1) / 2)
    body = np.eye(4)
    body[2, 3] = _CAMERA_HEIGHT
    pose = Pose.from_matrix(body).compose(OPTICAL_TO_BODY)
    bodies = tuning_bodies()
    out = []
    for angle in ORIENTATIONS:
        covered = np.zeros((len(bodies), h, w), bool)
        rel = np.full((len(bodies), h, w), np.nan)
        hips = []
        for i, (shape, look) in enumerate(bodies):
            z, top, hip = _render_body(shape, look, angle, cam, pose)
            # head top of this body to row TOP_ROW: shift the image by whole pixels
            top_row = cam.cy + F_REF * (_CAMERA_HEIGHT - top) / D_REF
            shift = TOP_ROW - round(top_row)
            z = np.roll(z, shift, axis=0)
            if shift > 0:
                z[:shift] = np.nan
            elif shift < 0:
                z[shift:] = np.nan
            body_px = np.isfinite(z)
            covered[i] = body_px
            rel[i] = np.where(body_px, z - np.median(z[body_px]), np.nan)
            hips.append(cam.cy + F_REF * (_CAMERA_HEIGHT - hip) / D_REF + shift)
        hip_row = float(np.median(hips))
        rows = np.arange(h)[:, None]
        mask = (2 * covered.sum(axis=0) >= len(bodies)) & (rows <= hip_row)
        r, c = np.nonzero(mask)
        r0, r1, c0, c1 = r.min(), r.max() + 1, c.min(), c.max() + 1
        pad = max(2, (c1 - c0) // 4)  # a margin around the body to see it stand free
        c0, c1, r0 = c0 - pad, c1 + pad, r0 - pad
        m = mask[r0:r1, c0:c1]
        with warnings.catch_warnings():  # all-NaN columns lie outside the mask
            warnings.simplefilter("ignore", RuntimeWarning)
            med = np.nanmedian(rel[:, r0:r1, c0:c1], axis=0)
        d = np.where(m, med, np.nan)
        d = (d - np.nanmedian(d)).astype(np.float32)  # relative to the template's median
        anchor = (float(cam.cx - c0), float(TOP_ROW - r0))
        out.append(DistanceTemplate(angle, m, d, anchor, 0.0))
    return out


def save_templates(templates: list[DistanceTemplate], path: Path) -> None:
    """Write templates (relative depth, distance 0) to one ``.npz``, atomically."""
    arrays: dict[str, NDArray[np.generic]] = {}
    for i, t in enumerate(templates):
        arrays[f"mask_{i}"] = t.mask
        arrays[f"depth_{i}"] = t.depth
        arrays[f"meta_{i}"] = np.array([t.orientation_deg, *t.anchor])
    tmp = path.with_name(f".{path.name}.tmp")
    with tmp.open("wb") as fh:
        np.savez_compressed(fh, **arrays)  # type: ignore[arg-type]
    tmp.replace(path)


def load_templates(path: Path = DATA) -> list[DistanceTemplate]:
    """The shipped templates (depth relative to the person's distance)."""
    with np.load(path) as z:
        n = sum(1 for k in z.files if k.startswith("mask_"))
        out = []
        for i in range(n):
            meta = z[f"meta_{i}"]
            out.append(
                DistanceTemplate(
                    float(meta[0]),
                    z[f"mask_{i}"].astype(bool),
                    z[f"depth_{i}"].astype(np.float32),
                    (float(meta[1]), float(meta[2])),
                    0.0,
                )
            )
    return out


def scale_template(t: DistanceTemplate, distance: float, fx: float) -> DistanceTemplate:
    """``t`` (relative depth) as seen at ``distance`` by a camera of focal length ``fx``."""
    if not distance > 0:
        raise ValueError(f"distance={distance} must be > 0")
    s = (fx / F_REF) * (D_REF / distance)
    h, w = t.mask.shape
    size = (max(1, round(w * s)), max(1, round(h * s)))
    mask = cv2.resize(t.mask.astype(np.uint8), size, interpolation=cv2.INTER_NEAREST) > 0
    rel = cv2.resize(np.nan_to_num(t.depth), size, interpolation=cv2.INTER_NEAREST)
    depth = np.where(mask, rel + np.float32(distance), np.nan).astype(np.float32)
    sx, sy = size[0] / w, size[1] / h
    return DistanceTemplate(
        t.orientation_deg, mask, depth, (t.anchor[0] * sx, t.anchor[1] * sy), distance
    )


@dataclass(frozen=True)
class Match:
    """A template match: head-top pixel, distance D, evaluation value, template used."""

    u: float
    v: float
    distance: float
    score: float
    orientation_deg: float
    box: tuple[int, int, int, int]  # left, top, width, height of the template


def agreement_u8(
    depth: NDArray[np.float32], distance: float, band_m: float, gap_m: float
) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
    """Per pixel (255 yes, 0 no): within ``band_m`` of ``distance`` (body); free behind it.

    Free is farther than ``distance + gap_m`` or without depth (NaN).
    """
    near = np.asarray(cv2.inRange(depth, distance - band_m, distance + band_m), np.uint8)
    behind = np.asarray(cv2.inRange(depth, -np.inf, distance + gap_m), np.uint8)  # NaN: 0
    return near, 255 - behind


def no_depth_far(depth: NDArray[np.float32]) -> NDArray[np.float32]:
    """``depth`` with NaN (no depth) as +inf: what :func:`agreement_u8_far` takes."""
    return np.where(np.isnan(depth), np.float32(np.inf), depth).astype(np.float32, copy=False)


def agreement_u8_far(
    depth: NDArray[np.float32], distance: float, band_m: float, gap_m: float
) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
    """:func:`agreement_u8` of a depth image without NaN (:func:`no_depth_far`), in two passes.

    No depth is +inf there, so "free" is one comparison: farther than ``distance + gap_m``.
    """
    near = np.asarray(cv2.inRange(depth, distance - band_m, distance + band_m), np.uint8)
    # (OpenCV's stubs lack compare's scalar form, which it documents and accepts)
    free = np.asarray(cv2.compare(depth, distance + gap_m, cv2.CMP_GT), np.uint8)  # type: ignore[call-overload]
    return near, free


def agreement(
    depth: NDArray[np.float32], distance: float, band_m: float, gap_m: float
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """:func:`agreement_u8` as 1.0 / 0.0."""
    near, free = agreement_u8(depth, distance, band_m, gap_m)
    return near.astype(np.float32) / 255.0, free.astype(np.float32) / 255.0


@dataclass(frozen=True)
class Agreement:
    """What scoring a template at one distance needs: the maps ``near - free`` and ``free``.

    ``sum(near m) + sum(free (1 - m)) = sum((near - free) m) + sum(free)`` over a box
    (``m`` the mask): one correlation and one box filter per template.
    """

    diff: NDArray[np.float32]
    free: NDArray[np.float32]

    @staticmethod
    def of(near: NDArray[np.generic], free: NDArray[np.generic], unit: float = 1.0) -> Agreement:
        """From maps in which ``unit`` means yes (1.0 for float maps, 255 for 8-bit ones)."""
        scale = np.float32(1.0 / unit)
        f = free.astype(np.float32) * scale
        return Agreement(near.astype(np.float32) * scale - f, f)

    def score(self, t: DistanceTemplate) -> NDArray[np.float32]:
        """Evaluation value of ``t`` with its top-left corner at every pixel (see the module)."""
        inner = t.kernel
        h, w = inner.shape
        out = np.asarray(cv2.matchTemplate(self.diff, inner, cv2.TM_CCORR), np.float32)
        box = cv2.boxFilter(
            self.free, -1, (w, h), anchor=(0, 0), normalize=False, borderType=cv2.BORDER_CONSTANT
        )
        out += box[: out.shape[0], : out.shape[1]]
        out *= np.float32(1.0 / inner.size)
        return out

    def score_all(self, templates: Sequence[DistanceTemplate]) -> list[NDArray[np.float32] | None]:
        """:meth:`score` of each template (None: larger than the maps), in one pass.

        On maps of :data:`DFT_MIN_PIXELS` or more the correlations share one spectrum of
        ``diff`` (correlation theorem; placements inside the map never wrap around, so
        the circular correlation is the linear one there): one forward DFT and one
        inverse per template instead of :func:`cv2.matchTemplate`'s own transforms of
        the map for each. Equal to :meth:`score` up to float rounding (~1e-7).
        """
        H, W = self.diff.shape
        fits = [t.mask.shape[0] <= H and t.mask.shape[1] <= W for t in templates]
        if H * W < DFT_MIN_PIXELS:
            return [self.score(t) if ok else None for t, ok in zip(templates, fits, strict=True)]
        shape = (cv2.getOptimalDFTSize(H), cv2.getOptimalDFTSize(W))
        padded = self.diff
        if shape != (H, W):
            padded = np.zeros(shape, np.float32)
            padded[:H, :W] = self.diff
        spec = cv2.dft(padded, nonzeroRows=H)
        out: list[NDArray[np.float32] | None] = []
        for t, ok in zip(templates, fits, strict=True):
            if not ok:
                out.append(None)
                continue
            h, w = t.mask.shape
            rows, cols = H - h + 1, W - w + 1
            product = cv2.mulSpectrums(spec, t.spectrum(shape), 0, conjB=True)
            flags = cv2.DFT_INVERSE | cv2.DFT_SCALE | cv2.DFT_REAL_OUTPUT
            corr = np.asarray(cv2.dft(product, flags=flags, nonzeroRows=rows), np.float32)
            scores = corr[:rows, :cols] + self._free_box(h, w)[:rows, :cols]
            scores *= np.float32(1.0 / t.mask.size)
            out.append(scores)
        return out

    def _free_box(self, h: int, w: int) -> NDArray[np.float32]:
        box = cv2.boxFilter(
            self.free, -1, (w, h), anchor=(0, 0), normalize=False, borderType=cv2.BORDER_CONSTANT
        )
        return np.asarray(box, np.float32)


def score_agreement(
    near: NDArray[np.float32], free: NDArray[np.float32], t: DistanceTemplate
) -> NDArray[np.float32]:
    """Evaluation value of ``t`` with its top-left corner at every pixel (see the module)."""
    return Agreement.of(near, free).score(t)


def score_map(
    depth: NDArray[np.float32], t: DistanceTemplate, band_m: float, gap_m: float
) -> NDArray[np.float32]:
    """Evaluation value of scaled template ``t`` with its top-left corner at every pixel."""
    near, free = agreement(depth, t.distance, band_m, gap_m)
    return score_agreement(near, free, t)


def best_match(
    depth: NDArray[np.float32],
    templates: list[DistanceTemplate],
    distance: float,
    fx: float,
    band_m: float,
    gap_m: float,
) -> Match | None:
    """The best of the templates scaled to ``distance`` anywhere in ``depth`` (None: too small)."""
    best: Match | None = None
    for t0 in templates:
        t = scale_template(t0, distance, fx)
        th, tw = t.mask.shape
        if th > depth.shape[0] or tw > depth.shape[1]:
            continue
        s = score_map(depth, t, band_m, gap_m)
        _, val, _, (x, y) = cv2.minMaxLoc(s)
        if best is None or val > best.score:
            best = Match(
                x + t.anchor[0], y + t.anchor[1], distance, float(val), t.orientation_deg,
                (int(x), int(y), tw, th),
            )  # fmt: skip
    return best


def main(argv: list[str]) -> int:
    """Regenerate the shipped templates (``python -m rgbd_eval.methods.satake2009.templates``)."""
    path = Path(argv[0]) if argv else DATA
    path.parent.mkdir(parents=True, exist_ok=True)
    templates = build_templates()
    save_templates(templates, path)
    for t in templates:
        print(
            f"{t.orientation_deg:4.0f} deg: {t.mask.shape[1]}x{t.mask.shape[0]} px, {t.mask.sum()} body px"
        )
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
