"""Which of two overlapping persons is in front: AdaBoost over pairwise features (seed 004, section 5).

Seed 004, section 5: "an approach that sorts the order of all persons in the image
according to pairwise comparisons. The proposed occlusion classifier specifies which one
of two overlapping persons is in front of the other. The order of the persons from
front-to-back is then determined by a sort procedure requiring M_O log(M_O) comparisons";
the classifier is built with AdaBoost from "thermal and colour features provided by the
tracker" (introduction). The snippet does not list the features; ours, for persons ``a``
and ``b`` with boxes on the thermal image (the tracker's state) and their overlap ``O``:

thermal group (the thermal image and the thermal tracker's boxes)
  ``bottom``, ``top``: box bottom and top ``v`` of ``a`` minus ``b``, in mean box heights
  (on a level floor the nearer person's feet are lower in the image);
  ``log_height``: ``ln(h_a / h_b)`` (the nearer person is larger);
  ``visible``: the share of ``a``'s box outside ``O`` minus ``b``'s;
  ``overlap_temp_mean``, ``overlap_temp_std``: how much more the overlap's temperature
  mean (deviation) differs from ``b``'s unoccluded part than from ``a``'s (the overlap
  shows the person in front);
  ``edge_thermal``: mean horizontal temperature gradient along ``a``'s box sides that lie
  inside ``b``'s box, minus the same for ``b`` (the front person's outline is visible,
  the occluded one's is not).
colour group (the colour image, aligned by the thermal-to-colour affine map, section 4.1)
  ``overlap_colour_mean``, ``overlap_colour_std``, ``overlap_colour_skew``: as the
  temperature ones, with the colour moments of section 4 (mean, deviation, skewness per
  channel, summed over the channels);
  ``edge_colour``: as ``edge_thermal`` on the colour image's luminance.

Every feature is antisymmetric, ``f(b, a) = -f(a, b)``, and the decision is
``H(f(a, b)) - H(f(b, a)) > 0`` with ``H`` the boosted score, so ``in_front(a, b)`` and
``in_front(b, a)`` never both hold (a tie falls back to the lower box bottom). A feature that
cannot be measured (no colour image, ``a`` wholly inside ``b``) is 0, which adds the same
vote to both scores and so drops out.

The tracker's interface (``tracker.py``): ``order(a, b, thermal, colour,
affine) -> 0 | 1`` (0: ``a`` is in front), ``sort_front_to_back(boxes, thermal, colour,
affine)`` and ``overlap(a, b)``; they build the :class:`OcclusionScene` once per frame.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.errors import ConfigError
from rgbd_eval.track.adaboost import BoostedStumps
from rgbd_eval.track.colour_moments import IntegralMoments

F64 = NDArray[np.float64]
#: A person's box on the thermal image: (u0, v0, u1, v1), pixels, half-open.
Box = tuple[float, float, float, float]

THERMAL = "thermal"
COLOUR = "colour"
#: (name, group) of every feature, in the order of the feature vector.
FEATURES: tuple[tuple[str, str], ...] = (
    ("bottom", THERMAL),
    ("top", THERMAL),
    ("log_height", THERMAL),
    ("visible", THERMAL),
    ("overlap_temp_mean", THERMAL),
    ("overlap_temp_std", THERMAL),
    ("edge_thermal", THERMAL),
    ("overlap_colour_mean", COLOUR),
    ("overlap_colour_std", COLOUR),
    ("overlap_colour_skew", COLOUR),
    ("edge_colour", COLOUR),
)
FEATURE_NAMES: tuple[str, ...] = tuple(n for n, _ in FEATURES)
#: Feature groups as the paper reports them (section 5): thermal, colour, both.
GROUPS: dict[str, tuple[int, ...]] = {
    THERMAL: tuple(i for i, (_, g) in enumerate(FEATURES) if g == THERMAL),
    COLOUR: tuple(i for i, (_, g) in enumerate(FEATURES) if g == COLOUR),
    "both": tuple(range(len(FEATURES))),
}
#: The shipped classifiers (``tools/train_occlusion.py`` writes it).
MODEL_PATH = Path(__file__).resolve().parent / "occlusion.json"
#: Half-width of the band along a box side, as a share of the box width (at least 1 px).
_EDGE_BAND = 0.06
_LUMA = np.array([0.299, 0.587, 0.114])


class AffineLike(Protocol):
    """``colour = scale * thermal + offset`` per axis (``track.cielniak2010.Affine``)."""

    @property
    def scale(self) -> tuple[float, float]: ...

    @property
    def offset(self) -> tuple[float, float]: ...


def _integral(a: F64) -> F64:
    out = np.zeros((a.shape[0] + 1, a.shape[1] + 1))
    out[1:, 1:] = a.cumsum(axis=0).cumsum(axis=1)
    return out


def _box_mean(integral: F64, box: tuple[int, int, int, int]) -> float:
    """Mean over an integer box of the image behind ``integral``; NaN when empty."""
    h, w = integral.shape[0] - 1, integral.shape[1] - 1
    u0, v0, u1, v1 = box
    u0, u1 = min(max(u0, 0), w), min(max(u1, 0), w)
    v0, v1 = min(max(v0, 0), h), min(max(v1, 0), h)
    n = (u1 - u0) * (v1 - v0)
    if n <= 0:
        return math.nan
    s = integral[v1, u1] - integral[v0, u1] - integral[v1, u0] + integral[v0, u0]
    mean: float = float(s) / float(n)
    return mean


def _gradient_integral(image: F64) -> F64:
    """Integral image of ``|dI/du|`` (central differences, one-sided at the borders)."""
    g = np.abs(np.gradient(image, axis=1))
    return _integral(g)


@dataclass(frozen=True, eq=False)
class OcclusionScene:
    """What the features read from one frame; build it once per frame with :meth:`of`."""

    thermal: IntegralMoments
    thermal_grad: F64
    colour: IntegralMoments | None = None
    colour_grad: F64 | None = None
    #: thermal -> colour pixel map (identity when None)
    scale: tuple[float, float] = (1.0, 1.0)
    offset: tuple[float, float] = (0.0, 0.0)

    @staticmethod
    def of(
        temperature: NDArray[np.floating[Any]],
        colour: NDArray[np.uint8] | None = None,
        affine: AffineLike | None = None,
        colour_moments: IntegralMoments | None = None,
    ) -> OcclusionScene:
        """From the temperature image (any unit, ``HxW``) and the colour image (``HxWx3``).

        ``affine`` maps thermal pixels to colour pixels; ``colour_moments`` reuses integral
        images of the colour image the tracker already computed.
        """
        t = np.asarray(temperature, dtype=np.float64)
        if t.ndim != 2:
            raise ValueError(f"temperature image shape {t.shape} must be HxW")
        cm, cg = None, None
        if colour is not None:
            c = np.asarray(colour)
            if c.ndim != 3 or c.shape[2] != 3:
                raise ValueError(f"colour image shape {c.shape} must be HxWx3")
            cm = colour_moments if colour_moments is not None else IntegralMoments.of(c)
            cf = c.astype(np.float64)
            cg = _gradient_integral(
                cf[..., 0] * _LUMA[0] + cf[..., 1] * _LUMA[1] + cf[..., 2] * _LUMA[2]
            )
        scale, offset = (
            ((1.0, 1.0), (0.0, 0.0)) if affine is None else (affine.scale, affine.offset)
        )
        return OcclusionScene(
            IntegralMoments.of(t),
            _gradient_integral(t),
            cm,
            cg,
            (float(scale[0]), float(scale[1])),
            (float(offset[0]), float(offset[1])),
        )

    def to_colour(self, box: tuple[float, float, float, float]) -> tuple[int, int, int, int]:
        (sx, sy), (ox, oy) = self.scale, self.offset
        u0, v0, u1, v1 = box
        return (round(sx * u0 + ox), round(sy * v0 + oy), round(sx * u1 + ox), round(sy * v1 + oy))


def _check_box(box: Box) -> None:
    u0, v0, u1, v1 = box
    if not (all(math.isfinite(x) for x in box) and u1 > u0 and v1 > v0):
        raise ValueError(f"box {box} must be finite (u0, v0, u1, v1) with u1 > u0 and v1 > v0")


def intersection(a: Box, b: Box) -> Box | None:
    """The overlap of two boxes; None when they do not overlap."""
    u0, v0 = max(a[0], b[0]), max(a[1], b[1])
    u1, v1 = min(a[2], b[2]), min(a[3], b[3])
    return (u0, v0, u1, v1) if u1 > u0 and v1 > v0 else None


def _own_strip(a: Box, b: Box, rows: tuple[float, float]) -> Box | None:
    """The wider vertical strip of ``a`` beside ``b``'s columns, over ``rows``; None if < 1 px."""
    left = (a[0], rows[0], min(a[2], b[0]), rows[1])
    right = (max(a[0], b[2]), rows[0], a[2], rows[1])
    best = left if left[2] - left[0] >= right[2] - right[0] else right
    return best if best[2] - best[0] >= 1.0 else None


def _ibox(box: Box) -> tuple[int, int, int, int]:
    return (round(box[0]), round(box[1]), round(box[2]), round(box[3]))


def _edge_strength(a: Box, b: Box, rows: tuple[float, float], grad: F64, to_image: Any) -> float:
    """Mean ``|dI/du|`` in bands along ``a``'s sides that lie inside ``b``'s columns (0: none)."""
    half = max(1.0, _EDGE_BAND * (a[2] - a[0]))
    values = []
    for u in (a[0], a[2]):
        if b[0] < u < b[2]:
            m = _box_mean(grad, to_image((u - half, rows[0], u + half, rows[1])))
            if math.isfinite(m):
                values.append(m)
    return float(np.mean(values)) if values else 0.0


def _moment_gap(
    integral: IntegralMoments, overlap: tuple[int, int, int, int], own: tuple[int, int, int, int]
) -> F64:
    """``|moments(overlap) - moments(own)|`` summed over channels: (mean, std, skew); NaN if empty."""
    d: F64 = np.abs(integral.moments(overlap) - integral.moments(own)).sum(axis=1)
    return d


def pair_features(a: Box, b: Box, scene: OcclusionScene) -> F64:
    """The feature vector ``f(a, b)`` (see the module docstring); ``f(b, a) = -f(a, b)``."""
    _check_box(a)
    _check_box(b)
    f = np.zeros(len(FEATURES))
    ha, hb = a[3] - a[1], b[3] - b[1]
    hm = (ha + hb) / 2.0
    f[0] = (a[3] - b[3]) / hm
    f[1] = (a[1] - b[1]) / hm
    f[2] = exact.log(ha / hb)
    o = intersection(a, b)
    if o is None:
        return f
    area_o = (o[2] - o[0]) * (o[3] - o[1])
    f[3] = area_o / ((b[2] - b[0]) * hb) - area_o / ((a[2] - a[0]) * ha)
    rows = (o[1], o[3])
    own_a, own_b = _own_strip(a, b, rows), _own_strip(b, a, rows)
    ident = _ibox
    f[6] = _edge_strength(a, b, rows, scene.thermal_grad, ident) - _edge_strength(
        b, a, rows, scene.thermal_grad, ident
    )
    if scene.colour_grad is not None:
        f[10] = _edge_strength(a, b, rows, scene.colour_grad, scene.to_colour) - _edge_strength(
            b, a, rows, scene.colour_grad, scene.to_colour
        )
    if own_a is None or own_b is None:
        return f
    gap_t = _moment_gap(scene.thermal, _ibox(o), _ibox(own_b)) - _moment_gap(
        scene.thermal, _ibox(o), _ibox(own_a)
    )
    if np.all(np.isfinite(gap_t[:2])):
        f[4:6] = gap_t[:2]
    if scene.colour is not None:
        co = scene.to_colour(o)
        gap_c = _moment_gap(scene.colour, co, scene.to_colour(own_b)) - _moment_gap(
            scene.colour, co, scene.to_colour(own_a)
        )
        if np.all(np.isfinite(gap_c)):
            f[7:10] = gap_c
    return f


@dataclass(frozen=True)
class OcclusionClassifier:
    """A boosted pairwise classifier over :data:`FEATURES` (one feature group or all)."""

    model: BoostedStumps
    group: str = "both"

    def __post_init__(self) -> None:
        if self.model.feature_names != FEATURE_NAMES:
            raise ValueError(
                f"classifier features {list(self.model.feature_names)} are not {list(FEATURE_NAMES)}"
            )

    def margin(self, features: F64) -> float:
        """``H(f) - H(-f)``: positive when ``a`` is in front (antisymmetric in ``f``)."""
        s = self.model.score(np.stack([features, -features]))
        return float(s[0] - s[1])


def load_classifiers(path: Path | None = None) -> dict[str, OcclusionClassifier]:
    """The classifiers per feature group from a model file (default: the shipped one)."""
    source = path or MODEL_PATH
    try:
        data = json.loads(source.read_text(encoding="utf-8"))
        return {
            group: OcclusionClassifier(BoostedStumps.from_dict(m), group)
            for group, m in data["models"].items()
        }
    except OSError as err:
        raise ConfigError(f"{source}: cannot read the occlusion classifier: {err}") from err
    except (ValueError, KeyError, TypeError) as err:
        raise ConfigError(f"{source}: not an occlusion classifier file: {err}") from err


@functools.cache
def shipped_classifier(group: str = "both") -> OcclusionClassifier:
    """The shipped classifier of a feature group (``thermal``, ``colour`` or ``both``)."""
    models = load_classifiers()
    if group not in models:
        raise ConfigError(f"occlusion classifier group {group!r} is not one of {sorted(models)}")
    return models[group]


def in_front(
    a: Box, b: Box, scene: OcclusionScene, classifier: OcclusionClassifier | None = None
) -> bool:
    """True when person ``a`` is in front of person ``b`` (boxes on the thermal image).

    ``classifier`` defaults to the shipped one over both feature groups. A tie (margin 0)
    is decided by the lower box bottom, then the wider box, then the one further right
    (identical boxes: False both ways).
    """
    clf = classifier if classifier is not None else shipped_classifier()
    m = clf.margin(pair_features(a, b, scene))
    if m != 0.0:
        return m > 0.0
    return (a[3], a[2] - a[0], a[0]) > (b[3], b[2] - b[0], b[0])


def merge_sort_by(count: int, a_in_front: Callable[[int, int], bool]) -> list[int]:
    """Indices ``0 .. count-1`` sorted front to back by a pairwise test (merge sort).

    At most ``count * ceil(log2 count)`` calls of ``a_in_front`` (seed 004, section 5:
    "M_O log(M_O) comparisons"); stable: when ``a_in_front(j, i)`` is False for a later
    ``j``, the earlier ``i`` goes first. The test need not be transitive; any answer is a
    permutation.
    """
    if count < 0:
        raise ValueError(f"count={count} must be non-negative")

    def merge_sort(items: list[int]) -> list[int]:
        if len(items) <= 1:
            return items
        mid = len(items) // 2
        left, right = merge_sort(items[:mid]), merge_sort(items[mid:])
        out: list[int] = []
        i = j = 0
        while i < len(left) and j < len(right):
            if a_in_front(right[j], left[i]):
                out.append(right[j])
                j += 1
            else:
                out.append(left[i])
                i += 1
        return out + left[i:] + right[j:]

    return merge_sort(list(range(count)))


def _as_box(box: Sequence[float] | NDArray[np.floating[Any]]) -> Box:
    values = [float(x) for x in box]
    if len(values) != 4:
        raise ValueError(f"box {values} must have 4 coordinates (u0, v0, u1, v1)")
    return (values[0], values[1], values[2], values[3])


def depth_order(
    persons: Sequence[Sequence[float] | NDArray[np.floating[Any]]],
    scene: OcclusionScene,
    classifier: OcclusionClassifier | None = None,
) -> list[int]:
    """Indices of ``persons`` (thermal boxes) from front to back, by :func:`in_front`."""
    boxes = [_as_box(p) for p in persons]
    clf = classifier if classifier is not None else shipped_classifier()
    return merge_sort_by(len(boxes), lambda i, j: in_front(boxes[i], boxes[j], scene, clf))


# ----------------------------------------------------------------------------- tracker interface
# The interface agreed with the tracker (tracker.py): images in, the scene built
# once per frame (the last one is kept while the tracker passes the same image objects).

_last: list[tuple[object, object, object, OcclusionScene]] = []


def scene_for(
    thermal: NDArray[np.floating[Any]],
    colour: NDArray[np.uint8] | None = None,
    affine: AffineLike | None = None,
) -> OcclusionScene:
    """:meth:`OcclusionScene.of`, reused while the same image objects are passed.

    Without ``affine`` the colour image is mapped by the ratio of the image sizes (parallel
    cameras with equal fields of view and no parallax); pass the tracker's affine map.
    """
    if _last and _last[0][0] is thermal and _last[0][1] is colour and _last[0][2] is affine:
        return _last[0][3]
    mapping = affine
    if mapping is None and colour is not None:
        t, c = np.shape(thermal), np.shape(colour)
        mapping = _SizeRatio((c[1] / t[1], c[0] / t[0]), (0.0, 0.0))
    scene = OcclusionScene.of(thermal, colour, mapping)
    _last[:] = [(thermal, colour, affine, scene)]  # holds the images: their ids stay unique
    return scene


@dataclass(frozen=True)
class _SizeRatio:
    scale: tuple[float, float]
    offset: tuple[float, float]


def order(
    a: Sequence[float] | NDArray[np.floating[Any]],
    b: Sequence[float] | NDArray[np.floating[Any]],
    thermal: NDArray[np.floating[Any]],
    colour: NDArray[np.uint8] | None = None,
    affine: AffineLike | None = None,
    classifier: OcclusionClassifier | None = None,
) -> int:
    """Which of two persons is in front: 0 for ``a``, 1 for ``b``.

    ``a``, ``b``: boxes ``(u0, v0, u1, v1)`` on the thermal image; ``thermal``: its
    temperatures; ``colour``: the colour image, mapped to the thermal one by ``affine``
    (``colour = scale * thermal + offset``).
    """
    scene = scene_for(thermal, colour, affine)
    return 0 if in_front(_as_box(a), _as_box(b), scene, classifier) else 1


def sort_front_to_back(
    boxes: Sequence[Sequence[float] | NDArray[np.floating[Any]]],
    thermal: NDArray[np.floating[Any]],
    colour: NDArray[np.uint8] | None = None,
    affine: AffineLike | None = None,
    classifier: OcclusionClassifier | None = None,
) -> list[int]:
    """Indices of ``boxes`` from front to back (seed 004, section 5: M log M comparisons)."""
    return depth_order(boxes, scene_for(thermal, colour, affine), classifier)


def overlap(
    a: Sequence[float] | NDArray[np.floating[Any]], b: Sequence[float] | NDArray[np.floating[Any]]
) -> float:
    """Intersection over the smaller box (0 when they do not overlap)."""
    ba, bb = _as_box(a), _as_box(b)
    o = intersection(ba, bb)
    if o is None:
        return 0.0
    smaller = min((ba[2] - ba[0]) * (ba[3] - ba[1]), (bb[2] - bb[0]) * (bb[3] - bb[1]))
    return (o[2] - o[0]) * (o[3] - o[1]) / max(smaller, 1e-9)


def classifier_summary(models: Mapping[str, OcclusionClassifier]) -> dict[str, list[str]]:
    """Per group, the features its stumps use, most votes first (for reports)."""
    out: dict[str, list[str]] = {}
    for group, clf in models.items():
        votes: dict[str, float] = {}
        for s in clf.model.stumps:
            name = FEATURE_NAMES[s.feature]
            votes[name] = votes.get(name, 0.0) + s.alpha
        out[group] = sorted(votes, key=lambda n: -votes[n])
    return out
