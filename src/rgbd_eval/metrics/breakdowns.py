"""Where a tracker fails: counts by distance, visibility and robot motion, per person, per gap.

Everything here is counted from the scorer's own per-frame matches
(:class:`~rgbd_eval.metrics.frames.FrameTable`), never re-matched.

Bands. A scored ground-truth instance (one person in one frame) falls in one band of
each breakdown; its match, its miss (FN) and its id switch count in that band:

- ``distance``: the ground-plane distance from the camera to the person's annotated
  world position, bands ``[0, e1), [e1, e2), ..., [ek, inf)`` metres
  (``evaluation.distance_bands``, default 2, 4, 6). Needs the camera's position in every
  frame (``run``: the recording's odometry and tf; ``score`` of a recording: the tf of
  the frame the tracks were published in) and annotated world positions.
- ``visibility``: the ground truth's visible share, bands 0-25, 25-50, 50-75, 75-100 %
  (a share on an edge goes to the band above; 100 % to the last).
- ``motion``: the robot's motion in the frame (a band of frames): ``turning`` when the
  camera's heading changes faster than ``evaluation.turning_rate`` (rad/s, default 0.2,
  about 11.5 deg/s), else ``driving`` when it moves faster than
  ``evaluation.driving_speed`` (m/s, default 0.1), else ``standing``; speed and turn rate
  are measured between the frames 0.25 s before and after (:data:`MOTION_WINDOW_S`).
  Needs odometry (a recording without it is evaluated in the camera frame).

False positives (tracks matched to no one) have no ground truth to take a band from. The
rule, per breakdown, as TrackEval states its own:

- ``distance``: a false positive counts in the band of the *track's own* position's
  distance from the camera; one without a position (a 2D-only track) counts in no band.
- ``visibility``: no false positive can be given a visible share, so the bands are
  FP-free: a band's MOTA is ``1 - (FN + IDSW) / GT``, and it has no FP rate.
- ``motion``: a band of frames takes every error of its frames, false positives too.

Every band keeps summable counts (:class:`BandCounts`: frames, GT, matches, FN, FP, ID
switches, the similarity sum); its ratios are derived from the sums in one place,
:meth:`BandCounts.summary`, as for the overall row, so bands of several sequences add up.
A band's ``frames`` are those in which it holds a ground-truth instance or a false
positive (for ``motion``: the frames in that state); ``errors_per_frame`` is
``(FN + FP + IDSW) / frames`` (FP-free for ``visibility``).

Per person (each ground-truth id): its scored frames, the frames it was matched in
(coverage), the track ids that covered it (in order), its id switches and fragmentations
(the scorer's convention: summed over persons they equal the sequence's counts), and,
before each switch, how many frames had passed since the person's previous match
(``gap``) and how many of those it was not a scored object (``unseen``: occluded,
ignored or out of view).

Per gap: every stretch of frames without a match between two matches of a person is a
gap of N frames; it is *recovered* when the match after it has the same track id as the
match before (else the match is an id switch). Recovery rate per gap length.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields, replace
from operator import attrgetter

import numpy as np

from rgbd_eval import exact
from rgbd_eval.config import Convention, EvaluationConfig
from rgbd_eval.metrics.frames import BoolArray, FloatArray, FrameTable, IntArray, frames_of
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.types import GroundTruthObject, Pose, TrackOutput

_DEFAULTS = EvaluationConfig()
#: Default distance band edges (m): ``evaluation.distance_bands``.
DEFAULT_DISTANCE_BANDS = tuple(_DEFAULTS.distance_bands)
#: Default speed (m/s) above which the robot counts as driving: ``evaluation.driving_speed``.
DEFAULT_DRIVING_SPEED = _DEFAULTS.driving_speed
#: Default turn rate (rad/s) above which the robot counts as turning: ``evaluation.turning_rate``.
DEFAULT_TURNING_RATE = _DEFAULTS.turning_rate
#: Visibility band edges (visible share).
VISIBILITY_EDGES = (0.25, 0.5, 0.75)
#: Half-width of the window the robot's speed and turn rate are measured over (s).
MOTION_WINDOW_S = 0.25
#: Robot motion states, in the order they are shown.
MOTION_STATES = ("standing", "turning", "driving")
#: Gap lengths (frames): each bin starts at its edge and ends before the next.
GAP_EDGES = (1, 2, 5, 10, 30, 90)
#: Bands need this many frames to be named in the "where it fails" summary.
MIN_BAND_FRAMES = 10

DISTANCE, VISIBILITY, MOTION = "distance", "visibility", "motion"
FP_RULES = {
    DISTANCE: "a false positive counts in the band of the track's own distance from the "
    "camera; one without a position counts in no band",
    VISIBILITY: "false positives have no visible share: the bands are FP-free, "
    "MOTA = 1 - (FN + IDSW) / GT",
    MOTION: "a band of frames: every error of its frames counts, false positives too",
}


@dataclass(frozen=True)
class BandCounts:
    """Summable counts of one band (see the module docstring)."""

    frames: int = 0
    num_gt: int = 0
    num_matches: int = 0
    fp: int = 0
    id_switches: int = 0
    similarity_sum: float = 0.0

    @property
    def fn(self) -> int:
        return self.num_gt - self.num_matches

    def __add__(self, other: BandCounts) -> BandCounts:
        return BandCounts(
            *(getattr(self, f.name) + getattr(other, f.name) for f in fields(BandCounts))
        )

    def summary(self, with_fp: bool = True) -> dict[str, float | int | None]:
        """The band's ratios, from its sums; ``with_fp`` False for FP-free bands."""
        fp = self.fp if with_fp else 0
        errors = self.fn + fp + self.id_switches
        return {
            "mota": None if self.num_gt == 0 else 1.0 - errors / self.num_gt,
            "motp": _ratio(self.similarity_sum, self.num_matches),
            "fn_rate": _ratio(self.fn, self.num_gt),
            "fp_rate": _ratio(fp, self.num_gt) if with_fp else None,
            "id_switch_rate": _ratio(self.id_switches, self.num_gt),
            "recall": _ratio(self.num_matches, self.num_gt),
            "errors_per_frame": _ratio(errors, self.frames),
            "errors": errors,
            "fn": self.fn,
            "fp": self.fp if with_fp else None,
        }


def _ratio(numerator: float, denominator: float) -> float | None:
    return numerator / denominator if denominator > 0 else None


@dataclass(frozen=True)
class Band:
    """One band of a breakdown: its label, counts and per-frame counts (for intervals)."""

    label: str
    counts: BandCounts
    #: Per frame: ground truth, matches, false positives, id switches (``(4, frames)``).
    series: IntArray = field(compare=False, repr=False)


@dataclass(frozen=True)
class Breakdown:
    """One breakdown of one sequence (or summed): its bands, or why it is not available."""

    kind: str
    bands: tuple[Band, ...]
    with_fp: bool
    available: bool = True
    reason: str = ""
    #: Instances or false positives that fell in no band (no position, no camera).
    unassigned_gt: int = 0
    unassigned_fp: int = 0

    def __add__(self, other: Breakdown) -> Breakdown:
        if not other.available:
            return self
        if not self.available:
            return other
        labels = [b.label for b in self.bands]
        if labels != [b.label for b in other.bands]:
            raise ValueError(f"{self.kind}: bands {labels} differ from the other sequence's")
        return Breakdown(
            self.kind,
            tuple(
                Band(a.label, a.counts + b.counts, np.zeros((4, 0), dtype=np.int64))
                for a, b in zip(self.bands, other.bands, strict=True)
            ),
            self.with_fp,
            True,
            "",
            self.unassigned_gt + other.unassigned_gt,
            self.unassigned_fp + other.unassigned_fp,
        )


@dataclass(frozen=True)
class Settings:
    """The breakdowns' settings (``evaluation.*``)."""

    distance_bands: tuple[float, ...] = DEFAULT_DISTANCE_BANDS
    driving_speed: float = DEFAULT_DRIVING_SPEED
    turning_rate: float = DEFAULT_TURNING_RATE

    @staticmethod
    def of(evaluation: EvaluationConfig) -> Settings:
        """The settings of a (validated) evaluation config."""
        return Settings(
            tuple(evaluation.distance_bands), evaluation.driving_speed, evaluation.turning_rate
        )


def distance_labels(edges: Sequence[float]) -> list[str]:
    """``0-2 m``, ``2-4 m``, ..., ``6+ m``."""
    bounds = [0.0, *edges]
    out = [f"{a:g}-{b:g} m" for a, b in itertools.pairwise(bounds)]
    return [*out, f"{bounds[-1]:g}+ m"]


VISIBILITY_LABELS = ("0-25 %", "25-50 %", "50-75 %", "75-100 %")


# ----------------------------------------------------------------------------- the camera


@dataclass(frozen=True)
class CameraPath:
    """The camera's ground-plane position and heading per frame (NaN where unknown).

    ``odometry`` is False when the positions are those of a recording without odometry
    (the camera frame itself): distances hold, motion does not.
    """

    stamps_ns: tuple[int, ...]
    xy: FloatArray
    heading: FloatArray
    source: str
    odometry: bool = True

    @staticmethod
    def from_poses(
        stamps_ns: Sequence[int], poses: Sequence[Pose | None], source: str, odometry: bool = True
    ) -> CameraPath:
        """From ``world_T_sensor`` poses; the heading is that of the sensor's most
        horizontal axis of x and z (a body frame's x, an optical frame's z)."""
        n = len(poses)
        known = np.array([p is not None for p in poses], dtype=bool)
        t = np.array([p.translation if p is not None else (np.nan,) * 3 for p in poses])
        q = np.array([p.rotation if p is not None else (0.0, 0.0, 0.0, 1.0) for p in poses])
        x, y, z, w = (q[:, k] if n else np.zeros(0) for k in range(4))
        scale = 2.0 / (x * x + y * y + z * z + w * w)  # as Pose.rotation_matrix
        # The world x, y of the sensor's x axis and z axis (columns 0 and 2 of R).
        x_axis = (1.0 - scale * (y * y + z * z), scale * (x * y + z * w))
        z_axis = (scale * (x * z + y * w), scale * (y * z - x * w))
        # One axis for the whole path (a level camera's x and z are both horizontal).
        z_norm = z_axis[0] * z_axis[0] + z_axis[1] * z_axis[1]
        x_norm = x_axis[0] * x_axis[0] + x_axis[1] * x_axis[1]
        use_z = _sum(np.where(known, z_norm, 0.0)) >= _sum(np.where(known, x_norm, 0.0))
        ax, ay = z_axis if use_z else x_axis
        heading = np.where(known, exact.atan2(ay, ax), np.nan) if n else np.zeros(0)
        xy = t[:, :2] if n else np.zeros((0, 2))
        return CameraPath(tuple(int(s) for s in stamps_ns), xy, heading, source, odometry)


def _sum(values: FloatArray) -> float:
    return float(np.add.reduce(values)) if len(values) else 0.0


def motion_states(path: CameraPath, settings: Settings) -> list[str | None]:
    """Each frame's state (:data:`MOTION_STATES`), or None where it cannot be measured."""
    return [None if k < 0 else MOTION_STATES[k] for k in _motion_codes(path, settings).tolist()]


def _motion_codes(path: CameraPath, settings: Settings) -> IntArray:
    """Each frame's state as its index in :data:`MOTION_STATES` (-1: cannot be measured):
    turning above the turn rate, else driving above the speed, else standing."""
    stamps = np.array(path.stamps_ns, dtype=np.int64)
    window = int(MOTION_WINDOW_S * 1e9)
    j0 = np.searchsorted(stamps, stamps - window, side="left")
    j1 = np.searchsorted(stamps, stamps + window, side="right") - 1
    dt = (stamps[j1] - stamps[j0]) * 1e-9
    d = path.xy[j1] - path.xy[j0]
    turn = path.heading[j1] - path.heading[j0]
    turn = (turn + exact.PI) % (2 * exact.PI) - exact.PI
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]) / dt
        rate = np.abs(turn) / dt
    known = (j1 > j0) & (dt > 0) & np.isfinite(speed) & np.isfinite(rate)
    standing, turning, driving = (
        MOTION_STATES.index(s) for s in ("standing", "turning", "driving")
    )
    driven = np.where(speed > settings.driving_speed, driving, standing)
    state = np.where(rate > settings.turning_rate, turning, driven)
    codes: IntArray = np.where(known, state, -1).astype(np.int64)
    return codes


# ----------------------------------------------------------------------------- instances


@dataclass(frozen=True)
class Instances:
    """Per scored ground-truth instance and per false positive of one sequence, the
    attributes the bands are cut on (NaN where unknown)."""

    gt_visibility: FloatArray
    gt_xy: FloatArray
    fp_frame: IntArray
    fp_xy: FloatArray
    #: Per match: the row of its ground-truth instance.
    match_instance: IntArray


def instances(
    table: FrameTable,
    gt_frames: Sequence[Sequence[GroundTruthObject]],
    track_frames: Sequence[Sequence[TrackOutput]],
    positions: bool = True,
) -> Instances:
    """Look up the attributes of the table's instances in the frames they were scored from;
    the positions (``gt_xy``, ``fp_xy``, for the distance bands) only when ``positions``,
    else NaN."""
    t = table
    objects = list(itertools.chain.from_iterable(gt_frames))
    rows = _lookup(
        t.gt_ids,
        frames_of(gt_frames),
        np.fromiter(map(attrgetter("object_id"), objects), dtype=np.int64, count=len(objects)),
        t.gt_frame,
        t.gt_index,
    )
    picked = list(map(objects.__getitem__, rows.tolist()))
    vis = np.fromiter(map(attrgetter("visibility"), picked), dtype=np.float64, count=len(picked))
    # Matches -> their ground-truth instance (frame, gt).
    g = max(t.num_gt_tracks, 1)
    instance_keys = t.gt_frame * g + t.gt_index
    order = np.argsort(instance_keys, kind="stable")
    match_keys = t.match_frame * g + t.match_gt
    match_instance = order[np.searchsorted(instance_keys[order], match_keys)]
    # False positives: scored track instances without a match in their frame.
    k = max(t.num_tracks, 1)
    matched = np.isin(t.track_frame * k + t.track_index, t.match_frame * k + t.match_track)
    fp_frame = t.track_frame[~matched]
    if not positions:
        nan = np.full((len(picked) + len(fp_frame), 2), np.nan)
        return Instances(vis, nan[: len(picked)], fp_frame, nan[len(picked) :], match_instance)
    unknown = (np.nan, np.nan)
    gxy = np.fromiter(
        itertools.chain.from_iterable(
            unknown if o.world_xyz is None else o.world_xyz[:2] for o in picked
        ),
        dtype=np.float64,
        count=2 * len(picked),
    ).reshape(-1, 2)
    # Only the false positives' tracks are looked at (few, in their frames).
    fp_ids = t.track_ids[t.track_index[~matched]].tolist()
    fxy = np.array(
        [_track_xy(track_frames[f], i) for f, i in zip(fp_frame.tolist(), fp_ids, strict=True)],
        dtype=np.float64,
    )
    fxy = fxy.reshape(-1, 2)
    fxy[~np.isfinite(fxy).all(axis=1)] = np.nan
    return Instances(vis, gxy, fp_frame, fxy, match_instance)


def _track_xy(tracks: Sequence[TrackOutput], track_id: int) -> tuple[float, float]:
    """The position of the scored track ``track_id`` among one frame's tracks (it is there:
    the table was scored from these frames)."""
    track = next(o for o in tracks if o.track_id == track_id and is_scored_track(o))
    return track.x, track.y


def _lookup(
    ids: IntArray,
    frames: IntArray,
    object_ids: IntArray,
    query_frames: IntArray,
    query_index: IntArray,
) -> IntArray:
    """For each query (frame, dense id into ``ids``), the position in ``frames``/``object_ids``
    of that object (every query is among them: the table was scored from these frames)."""
    frame = np.asarray(frames, dtype=np.int64)
    oid = np.asarray(object_ids, dtype=np.int64)
    dense = np.searchsorted(ids, oid) if len(ids) else np.zeros(len(oid), dtype=np.int64)
    dense = np.minimum(dense, max(len(ids) - 1, 0))
    known = (ids[dense] == oid) if len(ids) else np.zeros(len(oid), dtype=bool)
    width = max(len(ids), 1)
    keys = np.where(known, frame * width + dense, -1)
    order = np.argsort(keys, kind="stable")
    found: IntArray = order[np.searchsorted(keys[order], query_frames * width + query_index)]
    return found


def _bands(
    kind: str,
    labels: Sequence[str],
    table: FrameTable,
    inst: Instances,
    gt_band: IntArray,
    fp_band: IntArray | None,
    with_fp: bool,
) -> Breakdown:
    """Counts per band from each instance's band (-1: none)."""
    t = table
    n, size = t.num_frames, len(labels) * t.num_frames
    match_band = gt_band[inst.match_instance]

    def per_band(band: IntArray, frames: IntArray) -> IntArray:
        """How many rows each band holds in each frame ``(bands, frames)``."""
        kept = band >= 0
        counts: IntArray = np.bincount(band[kept] * n + frames[kept], minlength=size)
        return counts.reshape(len(labels), n)

    series = np.zeros((len(labels), 4, n), dtype=np.int64)
    series[:, 0] = per_band(gt_band, t.gt_frame)
    series[:, 1] = per_band(match_band, t.match_frame)
    if fp_band is not None:
        series[:, 2] = per_band(fp_band, inst.fp_frame)
    series[:, 3] = per_band(match_band[t.match_switch], t.match_frame[t.match_switch])
    frames = ((series[:, 0] > 0) | (series[:, 2] > 0)).sum(axis=1).tolist()
    totals = series.sum(axis=2).tolist()
    bands = []
    for b, label in enumerate(labels):
        num_gt, num_matches, fp, id_switches = totals[b]
        counts = BandCounts(
            frames=frames[b],
            num_gt=num_gt,
            num_matches=num_matches,
            fp=fp,
            id_switches=id_switches,
            similarity_sum=float(np.add.reduce(t.match_value[match_band == b])),
        )
        bands.append(Band(label, counts, series[b]))
    return Breakdown(
        kind,
        tuple(bands),
        with_fp,
        unassigned_gt=int((gt_band < 0).sum()),
        unassigned_fp=0 if fp_band is None else int((fp_band < 0).sum()),
    )


def not_available(kind: str, reason: str) -> Breakdown:
    return Breakdown(kind, (), kind != VISIBILITY, available=False, reason=reason)


def distance_breakdown(
    table: FrameTable, inst: Instances, camera: CameraPath | None, settings: Settings
) -> Breakdown:
    """Counts by distance from the camera (see the module docstring)."""
    if camera is None:
        return not_available(DISTANCE, "no camera position per frame")
    if np.isnan(inst.gt_xy).all() and len(inst.gt_xy):
        return not_available(DISTANCE, "the ground truth has no world positions")
    edges = np.array(settings.distance_bands)

    def band(frames: IntArray, xy: FloatArray) -> IntArray:
        diff = xy - camera.xy[frames]
        d = exact.hypot(diff[:, 0], diff[:, 1])  # sqrt of a sum of squares: CPU-independent
        out = np.searchsorted(edges, d, side="right").astype(np.int64)
        out[np.isnan(d)] = -1
        return out

    labels = distance_labels(settings.distance_bands)
    gt_band = band(table.gt_frame, inst.gt_xy)
    fp_band = band(inst.fp_frame, inst.fp_xy)
    return _bands(DISTANCE, labels, table, inst, gt_band, fp_band, True)


def visibility_breakdown(table: FrameTable, inst: Instances) -> Breakdown:
    """Counts by the ground truth's visible share (FP-free)."""
    if len(inst.gt_visibility) and (inst.gt_visibility == 1.0).all():
        return not_available(
            VISIBILITY,
            "every ground-truth instance is 100 % visible (ground truth without a visibility, "
            "MOT15's, reads as 100 %)",
        )
    gt_band = np.searchsorted(np.array(VISIBILITY_EDGES), inst.gt_visibility, side="right")
    return _bands(VISIBILITY, VISIBILITY_LABELS, table, inst, gt_band.astype(np.int64), None, False)


def motion_breakdown(
    table: FrameTable, inst: Instances, camera: CameraPath | None, settings: Settings
) -> Breakdown:
    """Counts by the robot's motion in each frame (every error of a frame in its band)."""
    if camera is None:
        return not_available(MOTION, "no camera pose per frame")
    if not camera.odometry:
        return not_available(MOTION, "the recording has no odometry")
    frame_band = _motion_codes(camera, settings)
    if (frame_band < 0).all():
        return not_available(MOTION, "the camera's motion cannot be measured (no stamps)")
    gt_band = frame_band[table.gt_frame]
    fp_band = frame_band[inst.fp_frame]
    out = _bands(MOTION, MOTION_STATES, table, inst, gt_band, fp_band, True)
    # A band of frames: its frames are the frames in that state.
    in_state = np.bincount(frame_band + 1, minlength=len(MOTION_STATES) + 1)[1:].tolist()
    bands = tuple(
        Band(b.label, replace(b.counts, frames=frames), b.series)
        for frames, b in zip(in_state, out.bands, strict=True)
    )
    return Breakdown(
        MOTION, bands, True, unassigned_gt=out.unassigned_gt, unassigned_fp=out.unassigned_fp
    )


# ----------------------------------------------------------------------------- persons, gaps


@dataclass(frozen=True)
class Switch:
    """One id switch of a person: where, from which track id to which, after how long."""

    frame: int
    from_track: int
    to_track: int
    gap: int
    unseen: int


@dataclass(frozen=True)
class Person:
    """One ground-truth id over a sequence."""

    gt_id: int
    frames: int
    matched: int
    track_ids: tuple[int, ...]
    id_switches: int
    fragmentations: int
    switches: tuple[Switch, ...]

    @property
    def coverage(self) -> float | None:
        return _ratio(self.matched, self.frames)


@dataclass(frozen=True)
class GapBin:
    """Gaps of one length range (frames) and how many were recovered."""

    label: str
    gaps: int = 0
    recovered: int = 0

    @property
    def rate(self) -> float | None:
        return _ratio(self.recovered, self.gaps)

    def __add__(self, other: GapBin) -> GapBin:
        return GapBin(self.label, self.gaps + other.gaps, self.recovered + other.recovered)


def gap_labels() -> list[str]:
    out = []
    for a, b in zip(GAP_EDGES, (*GAP_EDGES[1:], None), strict=True):
        out.append(f"{a}+" if b is None else (str(a) if b == a + 1 else f"{a}-{b - 1}"))
    return out


def persons_and_gaps(
    table: FrameTable, convention: Convention
) -> tuple[tuple[Person, ...], tuple[GapBin, ...]]:
    """Per ground-truth id its record, and the gaps of all of them by length."""
    t = table
    # Frames in which the motchallenge matcher steps (scored ground truth and tracks).
    stepped = np.flatnonzero(
        (t.per_frame(t.gt_frame) > 0) & (t.per_frame(t.track_frame) > 0)
    ).astype(np.int64)
    m_order = np.lexsort((t.match_frame, t.match_gt))
    m_gt, m_frame = t.match_gt[m_order], t.match_frame[m_order]
    m_track, m_switch = t.match_track[m_order], t.match_switch[m_order]
    g_order = np.lexsort((t.gt_frame, t.gt_index))
    g_gt, g_frame = t.gt_index[g_order], t.gt_frame[g_order]
    m_bounds = np.searchsorted(m_gt, np.arange(t.num_gt_tracks + 1))
    g_bounds = np.searchsorted(g_gt, np.arange(t.num_gt_tracks + 1))
    persons = []
    for g in range(t.num_gt_tracks):
        frames = m_frame[m_bounds[g] : m_bounds[g + 1]]
        tracks = t.track_ids[m_track[m_bounds[g] : m_bounds[g + 1]]]
        switch = m_switch[m_bounds[g] : m_bounds[g + 1]]
        present = g_frame[g_bounds[g] : g_bounds[g + 1]]
        switches = []
        for k in np.flatnonzero(switch).tolist():
            gap = int(frames[k] - frames[k - 1] - 1) if k > 0 else 0
            seen = 0
            if k:
                seen = int(np.count_nonzero((present > frames[k - 1]) & (present < frames[k])))
            switches.append(
                Switch(
                    int(frames[k]),
                    int(tracks[k - 1]) if k else -1,
                    int(tracks[k]),
                    gap,
                    gap - seen,
                )
            )
        persons.append(
            Person(
                gt_id=int(t.gt_ids[g]),
                frames=len(present),
                matched=len(frames),
                track_ids=tuple(int(x) for x in dict.fromkeys(tracks.tolist())),
                id_switches=int(switch.sum()),
                fragmentations=_fragmentations(frames, present, stepped, convention),
                switches=tuple(switches),
            )
        )
    # Gaps between consecutive matches of a person (of all persons at once), by length.
    labels = gap_labels()
    lengths = np.diff(m_frame) - 1
    gapped = (m_gt[1:] == m_gt[:-1]) & (lengths > 0)
    bins = np.searchsorted(np.array(GAP_EDGES), lengths[gapped], side="right") - 1
    back = (m_track[1:] == m_track[:-1])[gapped]  # recovered: the same track after the gap
    gaps = np.bincount(bins, minlength=len(labels)).tolist()
    recovered_gaps = np.bincount(bins[back], minlength=len(labels)).tolist()
    return tuple(persons), tuple(
        GapBin(label, gaps[k], recovered_gaps[k]) for k, label in enumerate(labels)
    )


def _fragmentations(
    matched: IntArray, present: IntArray, stepped: IntArray, convention: Convention
) -> int:
    """One person's fragmentations under ``convention`` (see :mod:`rgbd_eval.metrics.clear`)."""
    if not len(matched):
        return 0
    if convention is Convention.MOTCHALLENGE:
        # Tracked stretches after the first; a stretch breaks at any stepped frame missed.
        position = np.searchsorted(stepped, matched)
        return int(np.count_nonzero(np.diff(position) > 1))
    # motmetrics: over the frames the person is present in, returns from missed to matched.
    is_matched = np.isin(present, matched)
    first = int(np.argmax(is_matched))
    after = is_matched[first:]
    return int(np.count_nonzero(after[1:] & ~after[:-1]))


# ----------------------------------------------------------------------------- one sequence


@dataclass(frozen=True)
class SequenceBreakdowns:
    """Every breakdown of one sequence."""

    distance: Breakdown
    visibility: Breakdown
    motion: Breakdown
    persons: tuple[Person, ...]
    gaps: tuple[GapBin, ...]

    def all(self) -> tuple[Breakdown, ...]:
        return (self.distance, self.visibility, self.motion)


def breakdowns(
    table: FrameTable,
    gt_frames: Sequence[Sequence[GroundTruthObject]],
    track_frames: Sequence[Sequence[TrackOutput]],
    camera: CameraPath | None,
    settings: Settings,
    convention: Convention,
) -> SequenceBreakdowns:
    """The breakdowns of one scored sequence (``gt_frames``/``track_frames`` as scored)."""
    inst = instances(table, gt_frames, track_frames, positions=camera is not None)
    persons, gaps = persons_and_gaps(table, convention)
    return SequenceBreakdowns(
        distance_breakdown(table, inst, camera, settings),
        visibility_breakdown(table, inst),
        motion_breakdown(table, inst, camera, settings),
        persons,
        gaps,
    )


def band_series(b: SequenceBreakdowns) -> dict[str, IntArray]:
    """Per band, its per-frame counts as bootstrap columns ``kind/label/field``."""
    out: dict[str, IntArray] = {}
    for breakdown in b.all():
        for band in breakdown.bands:
            for k, name in enumerate(("num_gt", "num_matches", "fp", "id_switches")):
                out[f"{breakdown.kind}/{band.label}/{name}"] = band.series[k]
    return out


def band_replicate_metrics(
    sums: Callable[[str], FloatArray], with_fp: BoolArray
) -> dict[str, FloatArray]:
    """MOTA, FN, id-switch and FP rates of bands per replicate ``(replicates, bands)`` (NaN
    where GT is 0; the FP rate of an FP-free band is its MOTA's 0 FP, not a rate);
    ``sums(field)`` gives the replicates' sums of each band's column ``kind/label/field``
    ``(replicates, bands)``, ``with_fp`` whether each band counts false positives."""
    gt = sums("num_gt")
    matches = sums("num_matches")
    fp = np.where(with_fp, sums("fp"), 0.0)
    switches = sums("id_switches")
    with np.errstate(divide="ignore", invalid="ignore"):
        safe = np.where(gt > 0, gt, 1.0)
        out = {
            "mota": 1.0 - (gt - matches + fp + switches) / safe,
            "fn_rate": (gt - matches) / safe,
            "id_switch_rate": switches / safe,
            "fp_rate": fp / safe,
        }
    return {k: np.where(gt > 0, v, np.nan) for k, v in out.items()}
