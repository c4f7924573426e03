"""The per-frame contributions of one scored sequence, kept compact for intervals and breakdowns.

:class:`FrameTable` lists, with dense ids (``0..G-1`` for ground truth, ``0..T-1`` for
tracks, in sorted id order; ``gt_ids``/``track_ids`` give the original ids), every
scored ground-truth and track instance, every CLEAR match (with its id-switch and
recall-error flags and its IoU or distance), every pair inside the gate (what IDF1's
global assignment is made of) and every pair of HOTA's per-frame assignment with its
similarity. These are exactly what :func:`rgbd_eval.metrics.clear.score_selections`
computed, recorded as it scores, never re-derived: summed over all frames they give the
sequence's :class:`~rgbd_eval.metrics.counts.Counts` (IDF1's IDTP and HOTA's sums after
their global assignment and alignment), and weighted per frame they give a bootstrap
replicate (:mod:`rgbd_eval.metrics.bootstrap`).

:meth:`FrameTable.save` writes it as a flat ``.npz`` (no pickle), ``<name>.frames.npz``
beside a report, which ``compare --significance`` reads for its paired bootstrap.
"""

from __future__ import annotations

import io
import struct
import zipfile
import zlib
from collections.abc import Sequence, Sized
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.metrics.gating import EPS
from rgbd_eval.metrics.hota import ALPHAS

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Layout version of the saved table.
FRAMES_SCHEMA = 1

_INT = "int"
_FLOAT = "float"
_BOOL = "bool"
#: The array fields and their kinds, in the order they are saved.
_ARRAYS: tuple[tuple[str, str], ...] = (
    ("gt_ids", _INT),
    ("track_ids", _INT),
    ("gt_frame", _INT),
    ("gt_index", _INT),
    ("track_frame", _INT),
    ("track_index", _INT),
    ("match_frame", _INT),
    ("match_gt", _INT),
    ("match_track", _INT),
    ("match_switch", _BOOL),
    ("match_recall", _BOOL),
    ("match_value", _FLOAT),
    ("potential_frame", _INT),
    ("potential_gt", _INT),
    ("potential_track", _INT),
    ("hota_frame", _INT),
    ("hota_gt", _INT),
    ("hota_track", _INT),
    ("hota_similarity", _FLOAT),
)


@dataclass(frozen=True, eq=False)
class FrameTable:
    """Per-frame scoring contributions of one sequence (see the module docstring).

    ``*_frame`` arrays hold frame indices ``0..num_frames-1``, row-aligned with the
    other arrays of their group: scored ground-truth instances (``gt_*``), scored track
    instances (``track_*``), matches (``match_*``; ``match_value`` is the IoU or the
    distance in metres that MOTP averages), pairs inside the gate (``potential_*``)
    and the pairs of HOTA's per-frame assignment with a similarity reaching its first
    localisation threshold (``hota_*``).
    """

    num_frames: int
    gt_ids: IntArray
    track_ids: IntArray
    gt_frame: IntArray
    gt_index: IntArray
    track_frame: IntArray
    track_index: IntArray
    match_frame: IntArray
    match_gt: IntArray
    match_track: IntArray
    match_switch: BoolArray
    match_recall: BoolArray
    match_value: FloatArray
    potential_frame: IntArray
    potential_gt: IntArray
    potential_track: IntArray
    hota_frame: IntArray
    hota_gt: IntArray
    hota_track: IntArray
    hota_similarity: FloatArray

    def __post_init__(self) -> None:
        check_table(self)

    @property
    def num_gt_tracks(self) -> int:
        return len(self.gt_ids)

    @property
    def num_tracks(self) -> int:
        return len(self.track_ids)

    def per_frame(self, frames: IntArray, weights: NDArray[Any] | None = None) -> NDArray[Any]:
        """How many rows (or how much ``weights``) each frame holds, for one group's frames."""
        return np.bincount(frames, weights=weights, minlength=self.num_frames)

    def hota_levels(self) -> IntArray:
        """Per HOTA pair: how many of the 19 localisation thresholds its similarity reaches."""
        alphas = np.array(ALPHAS)
        levels: IntArray = (self.hota_similarity[:, None] >= alphas[None, :] - EPS).sum(axis=1)
        return levels

    def save(self) -> bytes:
        """The table as ``.npz`` bytes (no pickle; uncompressed: compressing costs more time
        than the bytes are worth)."""
        arrays: dict[str, Any] = {
            "schema": np.array([FRAMES_SCHEMA], dtype=np.int64),
            "num_frames": np.array([self.num_frames], dtype=np.int64),
        }
        # Indices are in range (check_table): they fit int32 when their largest possible do.
        limits = np.array([self.num_frames, self.num_gt_tracks, self.num_tracks])
        indices_fit = _fits32(limits - 1)
        for name, kind in _ARRAYS:
            value = getattr(self, name)
            narrow = kind == _INT and (
                (indices_fit and name not in ("gt_ids", "track_ids")) or _fits32(value)
            )
            arrays[name] = value.astype(np.int32 if narrow else value.dtype)
        return _npz(arrays)

    @staticmethod
    def load(data: bytes) -> FrameTable:
        """Read :meth:`save`'s bytes back; ``ValueError`` saying what is wrong."""
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as npz:
                arrays = {name: npz[name] for name in npz.files}
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as err:
            raise ValueError(f"not a frames table ({err})") from err
        expected = {"schema", "num_frames", *(name for name, _ in _ARRAYS)}
        if set(arrays) != expected:
            raise ValueError(
                f"frames table: keys {sorted(arrays)} differ from the expected {sorted(expected)}"
            )
        schema = arrays.pop("schema")
        if schema.shape != (1,) or int(schema[0]) != FRAMES_SCHEMA:
            raise ValueError(f"frames table: schema {schema.tolist()}, expected [{FRAMES_SCHEMA}]")
        num_frames = arrays.pop("num_frames")
        if num_frames.shape != (1,) or num_frames.dtype.kind not in "iu":
            raise ValueError("frames table: num_frames must be one integer")
        out: dict[str, Any] = {}
        for name, kind in _ARRAYS:
            value = arrays[name]
            if value.ndim != 1 or value.dtype.kind != {_INT: "i", _FLOAT: "f", _BOOL: "b"}[kind]:
                raise ValueError(f"frames table: {name} must be a 1-D {kind} array")
            out[name] = value.astype(
                {_INT: np.int64, _FLOAT: np.float64, _BOOL: np.bool_}[kind], copy=False
            )
        return FrameTable(num_frames=int(num_frames[0]), **out)


#: The fixed start of a ZIP local file header and of a central directory entry (little-endian):
#: version needed 4.5 (ZIP64) and made by 4.5 on Unix, no flags, stored, dated 1980-01-01.
_LOCAL_START = b"PK\x03\x04" + struct.pack("<2B4H", 45, 0, 0, 0, 0, (1 << 5) | 1)
_CENTRAL_START = b"PK\x01\x02" + struct.pack("<4B4H", 45, 3, 45, 0, 0, 0, 0, (1 << 5) | 1)


def _npz(arrays: dict[str, NDArray[Any]]) -> bytes:
    """The bytes ``numpy.savez`` writes for ``arrays`` (``zipfile`` with ``force_zip64``),
    without its file objects per entry: each ``<name>.npy`` stored uncompressed, its sizes
    in a ZIP64 extra field, a central directory, the end record. ``numpy.load`` reads it."""
    entries: list[bytes] = []
    central: list[bytes] = []
    offset = 0
    for name, array in arrays.items():
        npy = io.BytesIO()
        np.lib.format.write_array_header_1_0(npy, np.lib.format.header_data_from_array_1_0(array))
        data = npy.getvalue() + array.tobytes()
        crc, size, filename = zlib.crc32(data), len(data), f"{name}.npy".encode("ascii")
        local = struct.pack("<3L2H", crc, 0xFFFFFFFF, 0xFFFFFFFF, len(filename), 20)
        sizes = struct.pack("<2H2Q", 1, 16, size, size)  # ZIP64 extra field: the sizes
        entries.append(_LOCAL_START + local + filename + sizes + data)
        entry = struct.pack(
            "<3L5H2L", crc, size, size, len(filename), 0, 0, 0, 0, 0o600 << 16, offset
        )
        central.append(_CENTRAL_START + entry + filename)
        offset += len(entries[-1])
    directory = b"".join(central)
    count = len(central)
    end = b"PK\x05\x06" + struct.pack("<4H2LH", 0, 0, count, count, len(directory), offset, 0)
    return b"".join(entries) + directory + end


def _fits32(value: IntArray) -> bool:
    info = np.iinfo(np.int32)
    return not len(value) or (int(value.min()) >= info.min and int(value.max()) <= info.max)


def check_table(t: FrameTable) -> None:
    """``ValueError`` unless the groups are row-aligned and the indices in range."""
    if isinstance(t.num_frames, bool) or not isinstance(t.num_frames, int) or t.num_frames < 0:
        raise ValueError(f"frames table: num_frames={t.num_frames!r} must be an integer >= 0")
    groups = {
        "gt": ("gt_frame", "gt_index"),
        "track": ("track_frame", "track_index"),
        "match": (
            "match_frame",
            "match_gt",
            "match_track",
            "match_switch",
            "match_recall",
            "match_value",
        ),
        "potential": ("potential_frame", "potential_gt", "potential_track"),
        "hota": ("hota_frame", "hota_gt", "hota_track", "hota_similarity"),
    }
    for group, names in groups.items():
        lengths = {len(getattr(t, n)) for n in names}
        if len(lengths) != 1:
            raise ValueError(f"frames table: the {group} arrays differ in length")
    limits = {"gt": len(t.gt_ids), "track": len(t.track_ids), "frame": t.num_frames}
    ranged = (
        ("gt_frame", "frame"),
        ("gt_index", "gt"),
        ("track_frame", "frame"),
        ("track_index", "track"),
        ("match_frame", "frame"),
        ("match_gt", "gt"),
        ("match_track", "track"),
        ("potential_frame", "frame"),
        ("potential_gt", "gt"),
        ("potential_track", "track"),
        ("hota_frame", "frame"),
        ("hota_gt", "gt"),
        ("hota_track", "track"),
    )
    for name, kind in ranged:
        value, limit = getattr(t, name), limits[kind]
        if len(value) and (int(value.min()) < 0 or int(value.max()) >= limit):
            raise ValueError(f"frames table: {name} holds an index outside 0..{limit - 1}")
    for name in ("match_value", "hota_similarity"):
        if not np.isfinite(getattr(t, name)).all():
            raise ValueError(f"frames table: {name} holds a non-finite value")


def frames_of(per_frame: Sequence[Sized]) -> IntArray:
    """The frame of each row of ``per_frame`` (one collection per frame) flattened."""
    lengths = np.fromiter((len(a) for a in per_frame), dtype=np.int64, count=len(per_frame))
    return np.repeat(np.arange(len(per_frame), dtype=np.int64), lengths)


def _cat(per_frame: Sequence[NDArray[Any]], dtype: Any) -> NDArray[Any]:
    if not per_frame:
        return np.zeros(0, dtype=dtype)
    return np.concatenate(per_frame).astype(dtype, copy=False)


def build_table(
    gt_ids: IntArray,
    track_ids: IntArray,
    gts: Sequence[IntArray],
    tracks: Sequence[IntArray],
    match_gt: Sequence[IntArray],
    match_track: Sequence[IntArray],
    match_switch: Sequence[BoolArray],
    match_recall: Sequence[BoolArray],
    match_value: Sequence[FloatArray],
    potential: Sequence[IntArray],
    hota_pairs: Sequence[tuple[int, IntArray, IntArray, FloatArray]],
) -> FrameTable:
    """The table of one sequence from the scorer's per-frame dense arrays.

    ``potential`` holds per frame the pair keys ``gt * T + track`` inside the gate;
    ``hota_pairs`` the ``(frame, gt, track, similarity)`` of HOTA's per-frame assignments.
    """
    num_tracks = max(len(track_ids), 1)
    keys = _cat(potential, np.int64)
    h_frames = [np.full(len(g), f, dtype=np.int64) for f, g, _, _ in hota_pairs]
    h_gt = _cat([g for _, g, _, _ in hota_pairs], np.int64)
    h_track = _cat([t for _, _, t, _ in hota_pairs], np.int64)
    h_sim = _cat([s for _, _, _, s in hota_pairs], np.float64)
    useful = h_sim >= ALPHAS[0] - EPS  # a pair below every threshold adds nothing to HOTA
    return FrameTable(
        num_frames=len(gts),
        gt_ids=np.asarray(gt_ids, dtype=np.int64),
        track_ids=np.asarray(track_ids, dtype=np.int64),
        gt_frame=frames_of(gts),
        gt_index=_cat(gts, np.int64),
        track_frame=frames_of(tracks),
        track_index=_cat(tracks, np.int64),
        match_frame=frames_of(match_gt),
        match_gt=_cat(match_gt, np.int64),
        match_track=_cat(match_track, np.int64),
        match_switch=_cat(match_switch, np.bool_),
        match_recall=_cat(match_recall, np.bool_),
        match_value=_cat(match_value, np.float64),
        potential_frame=frames_of(potential),
        potential_gt=keys // num_tracks,
        potential_track=keys % num_tracks,
        hota_frame=_cat(h_frames, np.int64)[useful],
        hota_gt=h_gt[useful],
        hota_track=h_track[useful],
        hota_similarity=h_sim[useful],
    )


def empty_table(num_frames: int = 0) -> FrameTable:
    """The table of a sequence with nothing scored."""
    arrays: dict[str, Any] = {
        name: np.zeros(0, dtype={_INT: np.int64, _FLOAT: np.float64, _BOOL: np.bool_}[kind])
        for name, kind in _ARRAYS
    }
    return FrameTable(num_frames=num_frames, **arrays)
