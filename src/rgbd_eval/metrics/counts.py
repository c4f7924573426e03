"""Summable CLEAR MOT counts and the one place where ratios are derived from them.

:class:`Counts` holds integer counts and one float sum, so that the counts of
several sequences add up; the overall score is ``summarize(total(...))``, never an
average of per-sequence ratios.

Derived measures (:func:`summarize`), with ``GT`` the number of scored
ground-truth instances:

- ``mota = 1 - (FN + FP + IDSW) / GT`` (seed 000, eq. 7.1).
- ``motp``: IoU gating, the mean IoU of the matches (seed 000, 7.3; higher is
  better); metric gating, the mean ground-plane distance of the matches in metres
  (seed 001, V-B; lower is better).
- ``fp_rate``, ``fn_rate``, ``id_switch_rate``: FP, FN, IDSW as a share of GT
  (seed 000, Tables 7.2-7.6; seed 001, Table II).
- ``main_tr``: matches of every ground-truth track by its single most frequent
  track id, summed over tracks, over GT; ``all_tr``: matches by any id over GT,
  i.e. ``1 - fn_rate`` (seed 000, 7.3 and Tables 7.2, 7.3, 7.6).
- ``mt``/``pt``/``ml``: ground-truth tracks matched in most of their scored
  frames (> 80 % under the ``motchallenge`` convention, >= 80 % under
  ``motmetrics``), in at least 20 % otherwise, or in fewer; ``mt_rate`` and
  ``ml_rate`` as shares of the ground-truth tracks.
- ``idf1 = 2 IDTP / (2 IDTP + IDFP + IDFN)``, with ``idp`` and ``idr``.
- ``recall_errors`` (seed 001, V-C): id switches where a track id that had been
  given up is handed back, on a different person (see :mod:`rgbd_eval.metrics.clear`).
- ``precision``: matches over scored track instances.
- ``hota``, ``deta``, ``assa``, ``loca``: TrackEval's HOTA family, averaged over
  its 19 localisation thresholds (:mod:`rgbd_eval.metrics.hota`); ``None`` for
  counts that carry no HOTA sums.

Empty cases: a ratio whose denominator is zero is ``None`` (no ground truth:
``mota``, ``fp_rate``, ``fn_rate``, ``main_tr``, ``all_tr`` ... are ``None``; no
match: ``motp`` is ``None``), never a crash and never a made-up 0 or 1.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field, fields

from rgbd_eval.config import Convention, Gating
from rgbd_eval.metrics.gating import check_threshold
from rgbd_eval.metrics.hota import HotaCounts

#: The version of the :meth:`Counts.to_dict` layout (2: convention and HOTA sums).
COUNTS_SCHEMA = 2

_FLOAT_TOLERANCE = 1e-6

Summary = dict[str, float | int | None]


@dataclass(frozen=True)
class Counts:
    """Summable counts of one or more scored sequences.

    ``num_gt`` and ``num_tracks`` count scored instances (one per object per
    frame) after ignored ground truth and the tracks sitting on it were removed;
    ``num_matches`` includes the matches that are id switches. ``similarity_sum``
    adds IoU (IoU gating) or metres (metric gating) over all matches.
    ``main_tr_matches`` adds, per ground-truth track, the matches of its most
    frequent track id. ``idtp``/``idfp``/``idfn`` are the identity counts of
    Ristani et al. ``ignored_gt`` counts ignored ground-truth instances and
    ``ignored_tracks`` the track instances dropped because they sat on one.
    ``convention`` names the matching rules; ``hota`` holds the HOTA sums (all
    zero when not computed).
    """

    gating: Gating
    threshold: float
    convention: Convention = Convention.MOTCHALLENGE
    num_frames: int = 0
    num_gt: int = 0
    num_tracks: int = 0
    num_matches: int = 0
    fp: int = 0
    fn: int = 0
    id_switches: int = 0
    fragmentations: int = 0
    similarity_sum: float = 0.0
    num_gt_tracks: int = 0
    mostly_tracked: int = 0
    partly_tracked: int = 0
    mostly_lost: int = 0
    main_tr_matches: int = 0
    idtp: int = 0
    idfp: int = 0
    idfn: int = 0
    recall_errors: int = 0
    ignored_gt: int = 0
    ignored_tracks: int = 0
    hota: HotaCounts = field(default_factory=HotaCounts)

    def __post_init__(self) -> None:
        if not isinstance(self.gating, Gating):
            raise ValueError(f"gating={self.gating!r} must be one of {[g.value for g in Gating]}")
        if not isinstance(self.convention, Convention):
            raise ValueError(
                f"convention={self.convention!r} must be one of {[c.value for c in Convention]}"
            )
        if not isinstance(self.hota, HotaCounts):
            raise ValueError(f"hota={self.hota!r} must be HotaCounts")
        check_threshold(self.gating, self.threshold)
        for name in _INT_FIELDS:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise ValueError(f"{name}={value!r} must be a non-negative integer")
        if not (math.isfinite(self.similarity_sum) and self.similarity_sum >= 0.0):
            raise ValueError(f"similarity_sum={self.similarity_sum!r} must be finite and >= 0")
        self._check_consistency()

    def _check_consistency(self) -> None:
        similarity_bound = self.num_matches * self._similarity_bound() + _FLOAT_TOLERANCE
        rules = (
            ("num_matches + fn == num_gt", self.num_matches + self.fn == self.num_gt),
            ("num_matches + fp == num_tracks", self.num_matches + self.fp == self.num_tracks),
            ("idtp + idfn == num_gt", self.idtp + self.idfn == self.num_gt),
            ("idtp + idfp == num_tracks", self.idtp + self.idfp == self.num_tracks),
            (
                "mostly_tracked + partly_tracked + mostly_lost == num_gt_tracks",
                self.mostly_tracked + self.partly_tracked + self.mostly_lost == self.num_gt_tracks,
            ),
            ("main_tr_matches <= num_matches", self.main_tr_matches <= self.num_matches),
            ("id_switches <= num_matches", self.id_switches <= self.num_matches),
            ("recall_errors <= id_switches", self.recall_errors <= self.id_switches),
            ("num_gt_tracks <= num_gt", self.num_gt_tracks <= self.num_gt),
            (
                "hota tp + fn == num_gt and tp + fp == num_tracks (or no HOTA sums)",
                self.hota == HotaCounts()
                or all(
                    tp + fn == self.num_gt and tp + fp == self.num_tracks
                    for tp, fn, fp in zip(self.hota.tp, self.hota.fn, self.hota.fp, strict=True)
                ),
            ),
            ("fragmentations <= num_gt", self.fragmentations <= self.num_gt),
            (
                "similarity_sum <= num_matches * bound",
                self.similarity_sum <= similarity_bound,
            ),
        )
        broken = [rule for rule, holds in rules if not holds]
        if broken:
            raise ValueError(f"inconsistent counts ({'; '.join(broken)}): {self.to_dict()}")

    def _similarity_bound(self) -> float:
        return 1.0 if self.gating is Gating.IOU else self.threshold

    @staticmethod
    def empty(
        gating: Gating, threshold: float, convention: Convention = Convention.MOTCHALLENGE
    ) -> Counts:
        """Counts of nothing (the neutral element of ``+``)."""
        return Counts(gating=gating, threshold=threshold, convention=convention)

    def __add__(self, other: Counts) -> Counts:
        if not isinstance(other, Counts):
            return NotImplemented
        if (
            other.gating is not self.gating
            or other.threshold != self.threshold
            or other.convention is not self.convention
        ):
            raise ValueError(
                f"cannot add counts scored with gating={other.gating.value} "
                f"threshold={other.threshold} convention={other.convention.value} to counts "
                f"scored with gating={self.gating.value} threshold={self.threshold} "
                f"convention={self.convention.value}"
            )
        summed: dict[str, int | float] = {
            name: getattr(self, name) + getattr(other, name) for name in _SUMMED_FIELDS
        }
        return Counts(
            gating=self.gating,
            threshold=self.threshold,
            convention=self.convention,
            hota=self.hota + other.hota,
            **summed,  # type: ignore[arg-type]
        )

    def __radd__(self, other: object) -> Counts:
        """Lets the built-in ``sum(counts)`` start from its initial 0."""
        if isinstance(other, int) and not isinstance(other, bool) and other == 0:
            return self
        return NotImplemented

    def to_dict(self) -> dict[str, object]:
        """A JSON-ready dict; :meth:`from_dict` reads it back exactly."""
        data: dict[str, object] = {"schema": COUNTS_SCHEMA}
        data.update(asdict(self))
        data["gating"] = self.gating.value
        data["convention"] = self.convention.value
        data["hota"] = self.hota.to_dict()
        return data

    @staticmethod
    def from_dict(data: Mapping[str, object]) -> Counts:
        """Rebuild counts written by :meth:`to_dict`; ``ValueError`` naming the bad key."""
        expected = {"schema", *(f.name for f in fields(Counts))}
        unknown = sorted(set(data) - expected)
        missing = sorted(expected - set(data))
        if unknown or missing:
            raise ValueError(f"counts: unknown keys {unknown}, missing keys {missing}")
        if data["schema"] != COUNTS_SCHEMA:
            raise ValueError(f"counts: schema={data['schema']!r}, expected {COUNTS_SCHEMA}")
        gating_value = data["gating"]
        try:
            gating = Gating(gating_value)
        except ValueError as err:
            raise ValueError(
                f"counts: gating={gating_value!r} must be one of {[g.value for g in Gating]}"
            ) from err
        try:
            convention = Convention(data["convention"])
        except ValueError as err:
            raise ValueError(
                f"counts: convention={data['convention']!r} must be one of "
                f"{[c.value for c in Convention]}"
            ) from err
        ints = {name: data[name] for name in _INT_FIELDS}
        return Counts(
            gating=gating,
            convention=convention,
            hota=HotaCounts.from_dict(data["hota"]),
            threshold=_number(data, "threshold"),
            similarity_sum=_number(data, "similarity_sum"),
            **ints,  # type: ignore[arg-type]
        )


def _number(data: Mapping[str, object], name: str) -> float:
    value = data[name]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"counts: {name}={value!r} must be a number")
    return float(value)


_INT_FIELDS = tuple(
    f.name
    for f in fields(Counts)
    if f.name not in ("gating", "threshold", "convention", "similarity_sum", "hota")
)
_SUMMED_FIELDS = (*_INT_FIELDS, "similarity_sum")


def total(counts: Iterable[Counts]) -> Counts:
    """The sum of the counts of several sequences (all scored with the same gate)."""
    items = list(counts)
    if not items:
        raise ValueError("total: counts must not be empty (the gating is unknown)")
    result = items[0]
    for item in items[1:]:
        result = result + item
    return result


def _ratio(numerator: float, denominator: float) -> float | None:
    return numerator / denominator if denominator > 0 else None


def summarize(counts: Counts) -> Summary:
    """Every derived measure, with stable JSON key names (see the module docstring)."""
    c = counts
    mota = _ratio(c.fn + c.fp + c.id_switches, c.num_gt)
    return {
        "mota": None if mota is None else 1.0 - mota,
        "motp": _ratio(c.similarity_sum, c.num_matches),
        "fp_rate": _ratio(c.fp, c.num_gt),
        "fn_rate": _ratio(c.fn, c.num_gt),
        "id_switch_rate": _ratio(c.id_switches, c.num_gt),
        "main_tr": _ratio(c.main_tr_matches, c.num_gt),
        "all_tr": _ratio(c.num_matches, c.num_gt),
        "precision": _ratio(c.num_matches, c.num_tracks),
        **(
            dict.fromkeys(("hota", "deta", "assa", "loca"))
            if c.hota == HotaCounts()
            else c.hota.summary()
        ),
        "idf1": _ratio(2 * c.idtp, 2 * c.idtp + c.idfp + c.idfn),
        "idp": _ratio(c.idtp, c.idtp + c.idfp),
        "idr": _ratio(c.idtp, c.idtp + c.idfn),
        "mt_rate": _ratio(c.mostly_tracked, c.num_gt_tracks),
        "ml_rate": _ratio(c.mostly_lost, c.num_gt_tracks),
        "id_switches": c.id_switches,
        "recall_errors": c.recall_errors,
        "fragmentations": c.fragmentations,
        "mt": c.mostly_tracked,
        "pt": c.partly_tracked,
        "ml": c.mostly_lost,
        "num_frames": c.num_frames,
        "num_gt": c.num_gt,
        "num_gt_tracks": c.num_gt_tracks,
        "num_tracks": c.num_tracks,
        "num_matches": c.num_matches,
        "fp": c.fp,
        "fn": c.fn,
        "ignored_gt": c.ignored_gt,
        "ignored_tracks": c.ignored_tracks,
        "threshold": c.threshold,
    }
