"""Ground-truth formats: the sidecar CSV, the KTP text formats, and the ground-truth topic.

Sidecar CSV (MOTChallenge style, extended with world coordinates)::

    frame,stamp_ns,id,bb_left,bb_top,bb_width,bb_height,x,y,z,visibility,ignore

``frame`` is the recording's frame index, from 0; empty box fields mean "no box",
empty x/y/z mean "no world position"; ``ignore`` is ``0``/``1`` or ``false``/``true``
(any case) and may be omitted or empty (then 0).
A row with an empty ``id`` (and no box or position) marks a frame annotated with
nobody in it: ``run`` scores only the frames from the first annotated frame to the
last, so a sequence that starts or ends without people needs such rows.

KTP text (Kinect Tracking Precision dataset), one line per frame::

    <stamp seconds>: id x y w h, id x y w h, ...     (2D boxes)
    <stamp seconds>: id x y z, id x y z, ...         (3D positions; 0 0 0 = missing)

(a line's frame index is its position among the frame lines, from 0). Frames count from
0 in every :class:`GroundTruth`, whatever the file's own numbering (``first_frame``).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any

import numpy as np

from rgbd_eval.atomic import write_text
from rgbd_eval.errors import GroundTruthError
from rgbd_eval.files import check_input, read_text
from rgbd_eval.io.validate import MAX_FRAME, box_problem, position_problem
from rgbd_eval.types import Box2D, GroundTruthObject

CSV_COLUMNS = (
    "frame",
    "stamp_ns",
    "id",
    "bb_left",
    "bb_top",
    "bb_width",
    "bb_height",
    "x",
    "y",
    "z",
    "visibility",
    "ignore",
)
_REQUIRED = CSV_COLUMNS[:11]


@dataclass(frozen=True)
class GroundTruth:
    """Annotations of one sequence, grouped by frame (sorted by stamp, then frame)."""

    source: str
    frames: tuple[tuple[int, int, tuple[GroundTruthObject, ...]], ...]
    """Per annotated frame: (frame index from 0, stamp_ns, objects)."""
    first_frame: int = 0
    """The number the source file gives its first frame (MOTChallenge text: 1), for reports."""

    @property
    def num_objects(self) -> int:
        return sum(len(objs) for _, _, objs in self.frames)

    @property
    def ids(self) -> set[int]:
        return {o.object_id for _, _, objs in self.frames for o in objs}

    @property
    def has_boxes(self) -> bool:
        return any(o.box2d is not None for _, _, objs in self.frames for o in objs)

    @property
    def has_world(self) -> bool:
        return any(o.world_xyz is not None for _, _, objs in self.frames for o in objs)

    def align(
        self, stamps_ns: Sequence[int], max_gap_ns: int
    ) -> tuple[list[list[GroundTruthObject]], int]:
        """Annotations per recording frame, matched by nearest stamp within ``max_gap_ns``.

        When the annotations carry no stamps (all 0) they are matched by frame index.
        Returns the per-frame lists and the number of annotated frames left unmatched.
        """
        frames, unmatched, _ = self.match(stamps_ns, max_gap_ns)
        return frames, unmatched

    def match(
        self, stamps_ns: Sequence[int], max_gap_ns: int
    ) -> tuple[list[list[GroundTruthObject]], int, list[int]]:
        """:meth:`align`, and the (sorted) indices of the recording frames an annotated
        frame matched."""
        out: list[list[GroundTruthObject]] = [[] for _ in stamps_ns]
        if not self.frames:
            return out, 0, []
        unmatched = 0
        taken: set[int] = set()
        if all(stamp == 0 for _, stamp, _ in self.frames):
            for index, _, objs in self.frames:
                if 0 <= index < len(out):
                    out[index] = list(objs)
                    taken.add(index)
                else:
                    unmatched += 1
            return out, unmatched, sorted(taken)
        rec = np.asarray(stamps_ns, dtype=np.int64)
        for _, stamp, objs in self.frames:
            if rec.size == 0:
                unmatched += 1
                continue
            j = int(np.searchsorted(rec, stamp))
            cands = [k for k in (j - 1, j) if 0 <= k < rec.size]
            k = min(cands, key=lambda c: abs(int(rec[c]) - stamp))
            if abs(int(rec[k]) - stamp) <= max_gap_ns and k not in taken:
                out[k] = list(objs)
                taken.add(k)
            else:
                unmatched += 1
        return out, unmatched, sorted(taken)


#: Stamps are int64 nanoseconds (from 1970 to 2262).
MAX_STAMP_NS = 2**63 - 1


def frame_problem(frame: int, stamp_ns: int) -> str | None:
    """Why a frame number or stamp cannot be an annotated frame's (None when they can)."""
    if not 0 <= frame <= MAX_FRAME:
        return f"frame number {frame} outside 0..{MAX_FRAME}"
    if not 0 <= stamp_ns <= MAX_STAMP_NS:
        return f"stamp {stamp_ns} ns outside 0..2**63-1"
    return None


def object_problem(o: GroundTruthObject) -> str | None:
    """Why an annotation cannot be scored as given (None when it can): the values every
    ground-truth reader must check (a topic, a CSV, KTP, MOTChallenge)."""
    problem = frame_problem(o.frame, o.stamp_ns)
    if problem is None and o.box2d is not None:
        problem = box_problem(o.box2d.as_tuple())
    if problem is None and o.world_xyz is not None:
        problem = position_problem(o.world_xyz)
    if problem is None and not 0.0 <= o.visibility <= 1.0:
        problem = f"visibility {o.visibility} outside [0, 1]"
    return problem


def _group(
    source: str,
    objects: Iterable[GroundTruthObject],
    empty: Iterable[tuple[int, int]] = (),
    first_frame: int = 0,
    checked: bool = False,
) -> GroundTruth:
    """Group objects by frame (indices from 0), rejecting contradictions and values no
    annotation has.

    ``empty`` lists ``(frame, stamp_ns)`` of frames annotated with nobody in them;
    ``first_frame`` is the number the source gave the first frame (kept for reports);
    ``checked``: the caller found :func:`object_problem` None for every object.
    """
    by_frame: dict[int, list[GroundTruthObject]] = {}
    ids: dict[int, set[int]] = {}
    stamps: dict[int, int] = {}
    for frame, stamp in empty:
        if (problem := frame_problem(frame, stamp)) is not None:
            raise GroundTruthError(source, problem)
        if frame in stamps and stamps[frame] != stamp:
            raise GroundTruthError(
                source, f"frame {frame} has two stamps ({stamps[frame]} and {stamp})"
            )
        stamps[frame] = stamp
        by_frame.setdefault(frame, [])
    for o in objects:
        if not checked and (problem := object_problem(o)) is not None:
            raise GroundTruthError(source, f"frame {o.frame}, id {o.object_id}: {problem}")
        if o.frame in stamps and stamps[o.frame] != o.stamp_ns:
            raise GroundTruthError(
                source, f"frame {o.frame} has two stamps ({stamps[o.frame]} and {o.stamp_ns})"
            )
        stamps[o.frame] = o.stamp_ns
        seen = ids.setdefault(o.frame, set())
        if o.object_id in seen:
            raise GroundTruthError(source, f"id {o.object_id} appears twice in frame {o.frame}")
        seen.add(o.object_id)
        by_frame.setdefault(o.frame, []).append(o)
    order = sorted(by_frame, key=lambda f: (stamps[f], f))
    prev = -1
    for f in order:
        if stamps[f] != 0 and stamps[f] == prev:
            raise GroundTruthError(source, f"two frames share stamp {stamps[f]}")
        prev = stamps[f]
    frames = tuple((f, stamps[f], tuple(by_frame[f])) for f in order)
    return GroundTruth(source, frames, first_frame)


# ----------------------------------------------------------------------------- CSV


#: Ids must be exact in a float64 (the metrics' arrays): smaller than 2**53 in magnitude.
MAX_ID = 2**53


def _opt_float(value: str) -> float | None:
    value = value.strip()
    if value == "":
        return None
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{value!r} is not a finite number (leave the field empty if unknown)")
    return number


def _id(text: str) -> int:
    value = int(text)
    if abs(value) >= MAX_ID:
        raise ValueError(f"id {value} is not smaller than 2**53 in magnitude")
    return value


#: Spellings of the ``ignore`` column (case-insensitive): anything else is refused, as "no"
#: or "2" were silently read as "ignore".
IGNORE_VALUES = {"": False, "0": False, "false": False, "1": True, "true": True}


def _ignore(text: str | None) -> bool:
    value = (text or "").strip().lower()
    if value not in IGNORE_VALUES:
        raise ValueError(f"ignore {text!r} is not 0, 1, false or true (or empty for 0)")
    return IGNORE_VALUES[value]


def _one_box(values: Sequence[float | None], what: str) -> bool:
    """True when all of ``values`` are given, False when none is; ValueError when only some are."""
    given = sum(v is not None for v in values)
    if 0 < given < len(values):
        raise ValueError(f"{what} fields are only partly given (give all or leave all empty)")
    return given == len(values)


def read_csv(path: Path) -> GroundTruth:
    """Read the sidecar CSV; any malformed line is a :class:`GroundTruthError` naming it."""
    path = Path(path)
    text = read_text(path, lambda m: GroundTruthError(path, m), "ground truth")
    objects = []
    empty: list[tuple[int, int]] = []
    with io.StringIO(text, newline="") as handle:
        reader = csv.DictReader(handle)
        try:
            fieldnames = reader.fieldnames or []
        except csv.Error as err:
            raise GroundTruthError(path, f"line 1: not CSV ({err})") from err
        missing = [c for c in _REQUIRED if c not in fieldnames]
        if missing:
            raise GroundTruthError(
                path, f"missing columns {', '.join(missing)}; expected {','.join(CSV_COLUMNS)}"
            )
        rows = iter(reader)
        while True:
            try:
                row = next(rows)
            except StopIteration:
                break
            except csv.Error as err:
                raise GroundTruthError(path, f"line {reader.line_num}: not CSV ({err})") from err
            line = reader.line_num
            if None in row.values():
                raise GroundTruthError(
                    path, f"line {line}: fewer fields than the {len(fieldnames)} columns"
                )
            if None in row:
                raise GroundTruthError(
                    path, f"line {line}: more fields than the {len(fieldnames)} columns"
                )
            try:
                frame, stamp = int(row["frame"]), int(row["stamp_ns"] or 0)
                box_vals = [
                    _opt_float(row[c]) for c in ("bb_left", "bb_top", "bb_width", "bb_height")
                ]
                xyz = [_opt_float(row[c]) for c in ("x", "y", "z")]
                if not row["id"].strip():  # an annotated frame with nobody in it
                    if any(v is not None for v in (*box_vals, *xyz)):
                        raise ValueError("a row without id (an empty frame) has a box or position")
                    empty.append((frame, stamp))
                    continue
                box = None
                if _one_box(box_vals, "box"):
                    box = Box2D(*(float(v) for v in box_vals if v is not None))
                world = None
                if _one_box(xyz, "x/y/z"):
                    world = (float(xyz[0] or 0.0), float(xyz[1] or 0.0), float(xyz[2] or 0.0))
                visibility = float(row["visibility"]) if row["visibility"].strip() else 1.0
                obj = GroundTruthObject(
                    frame=frame,
                    stamp_ns=stamp,
                    object_id=_id(row["id"]),
                    box2d=box,
                    world_xyz=world,
                    visibility=visibility,
                    ignore=_ignore(row.get("ignore")),
                )
                if (problem := object_problem(obj)) is not None:
                    raise ValueError(problem)
                objects.append(obj)
            except (ValueError, TypeError) as err:
                raise GroundTruthError(path, f"line {line}: {err}") from err
    return _group(str(path), objects, empty)


def _fmt(value: float | None) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return repr(float(value))


def write_csv(
    path: Path,
    objects: Iterable[GroundTruthObject],
    frames: Iterable[tuple[int, int]] = (),
    owner: str | None = None,
) -> None:
    """Write the sidecar CSV atomically (temp file, then rename).

    ``frames`` lists ``(frame, stamp_ns)`` of every annotated frame: those without an
    object get a row with an empty id (annotated, nobody there). With ``owner`` (the
    command) it replaces only a sidecar that command wrote
    (:func:`rgbd_eval.atomic.write_bytes`).
    """
    rows: list[tuple[int, list[object]]] = []
    for o in objects:
        box: tuple[float | None, ...] = o.box2d.as_tuple() if o.box2d else (None,) * 4
        xyz: tuple[float | None, ...] = o.world_xyz if o.world_xyz else (None,) * 3
        rows.append(
            (
                o.frame,
                [
                    o.frame,
                    o.stamp_ns,
                    o.object_id,
                    *(_fmt(v) for v in box),
                    *(_fmt(v) for v in xyz),
                    _fmt(o.visibility),
                    int(o.ignore),
                ],
            )
        )
    occupied = {frame for frame, _ in rows}
    rows += [(f, [f, s, *[""] * (len(CSV_COLUMNS) - 2)]) for f, s in frames if f not in occupied]
    rows.sort(key=lambda r: r[0])  # stable: objects keep their order within a frame
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\r\n")
    writer.writerow(CSV_COLUMNS)
    writer.writerows(row for _, row in rows)
    write_text(Path(path), buf.getvalue(), owner)


# ----------------------------------------------------------------------------- KTP


def _stamp_ns(text: str) -> int:
    """Seconds as text -> ns; InvalidOperation unless a finite number."""
    value = Decimal(text.strip())
    if not value.is_finite():
        raise InvalidOperation(f"{text.strip()!r} is not finite")
    return int(value * 1_000_000_000)


def read_ktp(path: Path) -> GroundTruth:
    """Read a KTP ground-truth text file (2D boxes or 3D positions, detected per file)."""
    path = Path(path)
    lines = read_text(path, lambda m: GroundTruthError(path, m), "ground truth").splitlines()
    objects = []
    annotated: list[tuple[int, int]] = []  # every line is a frame, people in it or not
    arity: int | None = None
    frame = -1
    for number, line in enumerate(lines, start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        head, sep, rest = line.partition(":")
        if not sep:
            raise GroundTruthError(path, f"line {number}: expected '<stamp>: id ...'")
        try:
            stamp = _stamp_ns(head)
        except InvalidOperation as err:
            raise GroundTruthError(path, f"line {number}: bad stamp {head.strip()!r}") from err
        frame += 1
        if (problem := frame_problem(frame, stamp)) is not None:
            raise GroundTruthError(path, f"line {number}: {problem}")
        annotated.append((frame, stamp))
        for entry in filter(None, (e.strip() for e in rest.split(","))):
            values = entry.split()
            if len(values) not in (4, 5):
                raise GroundTruthError(
                    path,
                    f"line {number}: entry {entry!r} needs 'id x y w h' (2D) or 'id x y z' (3D)",
                )
            if arity is None:
                arity = len(values)
            elif arity != len(values):
                raise GroundTruthError(path, f"line {number}: mixes 2D and 3D entries")
            try:
                oid = _id(values[0])
                nums = [float(v) for v in values[1:]]
            except ValueError as err:
                raise GroundTruthError(path, f"line {number}: {err}") from err
            if not all(math.isfinite(v) for v in nums):
                raise GroundTruthError(path, f"line {number}: entry {entry!r} is not finite")
            if all(v == 0.0 for v in nums):
                continue  # 0 0 0 (0) means the person is not annotated in this frame
            if arity == 5:
                obj = GroundTruthObject(frame, stamp, oid, Box2D(*nums), None)
            else:
                obj = GroundTruthObject(frame, stamp, oid, None, (nums[0], nums[1], nums[2]))
            if (problem := object_problem(obj)) is not None:
                raise GroundTruthError(path, f"line {number}: entry {entry!r}: {problem}")
            objects.append(obj)
    return _group(str(path), objects, annotated)


# ----------------------------------------------------------------------------- topic


def objects_from_message(msg: Any, frame: int, stamp_ns: int) -> list[GroundTruthObject]:
    """Objects of one ``rgbd_eval_msgs/GroundTruthArray`` message.

    A person without a box has ``bb_width = bb_height = 0``, without a position
    ``x = y = z = NaN`` (as :class:`~rgbd_eval.io.writer.RecordingWriter` writes them);
    any other value is the box or position, checked when the frames are grouped.
    """
    out = []
    for p in msg.people:
        values = (float(p.bb_left), float(p.bb_top), float(p.bb_width), float(p.bb_height))
        box = None if values[2] == 0 and values[3] == 0 else Box2D(*values)
        xyz = (float(p.x), float(p.y), float(p.z))
        world = None if all(math.isnan(v) for v in xyz) else xyz
        if box is None and world is None:
            continue
        out.append(
            GroundTruthObject(
                frame, stamp_ns, int(p.id), box, world, float(p.visibility), bool(p.ignore)
            )
        )
    return out


def from_objects(
    source: str,
    objects: Iterable[GroundTruthObject],
    empty: Iterable[tuple[int, int]] = (),
    first_frame: int = 0,
    checked: bool = False,
) -> GroundTruth:
    """Group already decoded objects (frames from 0; e.g. from the ground-truth topic).

    ``empty`` lists ``(frame, stamp_ns)`` of frames annotated with nobody in them;
    ``first_frame`` is the number their source gave the first frame (kept for reports);
    ``checked``: the caller found :func:`object_problem` None for every object (a
    reader that checks its values as arrays).
    """
    return _group(source, objects, empty, first_frame, checked)


def require_objects(gt: GroundTruth) -> GroundTruth:
    """``gt``, or a GroundTruthError when it annotates nobody (an empty file, a header):
    scoring it would call every track a false positive."""
    if gt.num_objects == 0:
        raise GroundTruthError(gt.source, "holds no annotated object (empty, or only a header?)")
    return gt


def load_ground_truth(path: Path) -> GroundTruth:
    """Load a sidecar CSV (``.csv``) or a KTP text file (anything else); it must annotate
    somebody."""
    path = Path(path)
    if not path.exists():
        raise GroundTruthError(path, "ground-truth file not found")
    check_input(path, lambda m: GroundTruthError(path, m), "ground truth")
    if path.suffix.lower() == ".csv":
        return require_objects(read_csv(path))
    return require_objects(read_ktp(path))
