"""Tracker output and benchmark ground truth read back for ``rgbd-eval score``.

Tracker output formats (detected from the content):

- MOTChallenge 2D text: ``frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z``
  (frames from 1; world ``x, y, z`` where they are not ``-1``; ``conf`` as the track's
  confidence, for ``--curve``);
- our ``tracks.csv`` (``rgbd-eval run`` writes it; a header line names the columns);
- KTP text (``<stamp>: id x y w h, ...`` or ``<stamp>: id x y z, ...``).

Ground truth: MOTChallenge text, with the devkit's rules for MOT16/17/20
(TrackEval's ``MotChallenge2DBox`` preprocessing): pedestrians (class 1) with the
consider flag set are scored; the distractor classes (person on vehicle 2, static
person 7, distractor 8, reflection 12; MOT20 also non-motorised vehicle 6) are
ignored and drop the tracks matched to them; everything else is ignored without
dropping tracks. MOT15 ground truth (no class column) is scored except rows whose
consider flag is 0. Other
ground truth goes through :func:`rgbd_eval.io.groundtruth.load_ground_truth`
(our CSV sidecar, KTP).

Frame numbers: every reader converts its format's numbering to one convention, the
recording's frame index from 0 (as the CSV sidecar, KTP, ``tracks.csv`` and tracks in a bag
count). MOTChallenge text counts from 1 (:data:`MOT_FIRST_FRAME`): its frame ``f`` is
index ``f - 1``, and a frame below 1 is refused. Reports number frames as the ground-truth
file does (``GroundTruth.first_frame``).
"""

from __future__ import annotations

import configparser
import csv
import enum
import io
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rgbd_eval.errors import GroundTruthError, InputError, RgbdEvalError
from rgbd_eval.files import read_text
from rgbd_eval.io.groundtruth import (
    MAX_ID,
    GroundTruth,
    frame_problem,
    from_objects,
    load_ground_truth,
    read_ktp,
    require_objects,
)
from rgbd_eval.io.validate import MAX_FRAME, MAX_PIXELS, position_problem
from rgbd_eval.types import (
    Box2D,
    GroundTruthObject,
    Pose,
    TrackerOutput,
    TrackOutput,
    Visibility,
)


class Benchmark(enum.Enum):
    """Which MOTChallenge ground-truth rules apply (``auto``: MOT17 when classes are present)."""

    AUTO = "auto"
    MOT15 = "mot15"
    MOT16 = "mot16"
    MOT17 = "mot17"
    MOT20 = "mot20"


_PEDESTRIAN = 1
#: The number MOTChallenge text gives the first frame (its readers subtract it).
MOT_FIRST_FRAME = 1
_DISTRACTORS = {
    Benchmark.MOT16: frozenset({2, 7, 8, 12}),
    Benchmark.MOT17: frozenset({2, 7, 8, 12}),
    Benchmark.MOT20: frozenset({2, 6, 7, 8, 12}),
}


@dataclass(frozen=True)
class Aligned:
    """Ground truth and tracks on one timeline, ready for ``evaluate_sequence``."""

    stamps_ns: tuple[int, ...]
    frame_numbers: tuple[int, ...]
    gt: list[list[GroundTruthObject]]
    tracks: list[list[TrackOutput]]
    unmatched_track_frames: int
    #: Per frame, the tracks' sensor pose (see :attr:`TrackerOutput.sensor_poses`); empty: none.
    sensor_poses: tuple[Pose | None, ...] = ()


# ----------------------------------------------------------------------------- detection

#: Builds the error of one input (GroundTruthError for ground truth, InputError for tracks).
Err = Callable[[str], RgbdEvalError]

#: Longest timeline of frames scored by frame number (MOTChallenge text, ``seqinfo.ini``):
#: 55 minutes at 30 fps; MOTChallenge's longest sequence has 3,315 frames. Scoring costs
#: about 0.25 ms a frame, empty or not, so a frame number of 10^8 was a MemoryError.
MAX_TIMELINE_FRAMES = 100_000


def _gt_error(path: Path) -> Err:
    return lambda message: GroundTruthError(path, message)


def _tracks_error(path: Path) -> Err:
    return lambda message: InputError(path, message)


def _first_data_line(text: str) -> str:
    for line in text.splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            return line.strip()
    return ""


def _looks_like_mot(text: str) -> bool:
    fields = _first_data_line(text).split(",")
    if len(fields) < 6:
        return False
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return True


def is_mot_text(path: Path) -> bool:
    """Whether a file looks like MOTChallenge text (comma-separated numbers, no header)."""
    path = Path(path)
    return _looks_like_mot(read_text(path, _tracks_error(path), "tracker output"))


# ----------------------------------------------------------------------------- MOTChallenge


def _mot_rows(text: str, error: Err) -> np.ndarray:
    """The rows of MOTChallenge text, every value the readers take on trust checked:
    frame and id whole numbers in range, finite box values within image coordinates."""
    try:
        rows = np.loadtxt(io.StringIO(text), delimiter=",", ndmin=2, dtype=np.float64)
    except ValueError as err:
        raise error(f"not MOTChallenge text ({' '.join(str(err).split())[:200]})") from err
    if rows.size and rows.shape[1] < 6:
        raise error("MOTChallenge text needs at least 6 columns")
    if not rows.size:
        return rows
    if not np.isfinite(rows[:, :6]).all():
        raise error("non-finite frame, id or box value")
    if rows[:, 0].min() < MOT_FIRST_FRAME:
        raise error(
            f"frame {rows[:, 0].min():g}: MOTChallenge frames count from {MOT_FIRST_FRAME} "
            "(a file numbered from 0 would be scored one frame off)"
        )
    for column, what, low, high in ((0, "frame", 0, MAX_FRAME), (1, "id", -MAX_ID, MAX_ID)):
        values = rows[:, column]
        bad = np.flatnonzero((values != np.round(values)) | (values < low) | (values > high))
        if bad.size:
            k = int(bad[0])
            raise error(f"row {k + 1}: {what} {values[k]:g} is not a whole number in {low}..{high}")
    boxes = rows[:, 2:6]
    bad = np.flatnonzero((np.abs(boxes) > MAX_PIXELS).any(axis=1))
    if bad.size:
        k = int(bad[0])
        raise error(f"row {k + 1}: box {tuple(boxes[k])} lies beyond {MAX_PIXELS:g} pixels")
    return rows


def seq_length(gt_path: Path) -> int | None:
    """``seqLength`` from the ``seqinfo.ini`` of a MOTChallenge sequence folder, if any
    (1..:data:`MAX_TIMELINE_FRAMES`)."""
    for folder in (gt_path.parent, gt_path.parent.parent):
        ini = folder / "seqinfo.ini"
        if ini.is_file():
            parser = configparser.ConfigParser()
            try:
                parser.read_string(read_text(ini, _gt_error(ini), "seqinfo.ini"))
                length = int(parser["Sequence"]["seqLength"])
            except (KeyError, ValueError, configparser.Error) as err:
                message = " ".join(str(err).split())[:200]
                raise GroundTruthError(ini, f"no integer [Sequence] seqLength ({message})") from err
            if not 1 <= length <= MAX_TIMELINE_FRAMES:
                raise GroundTruthError(
                    ini, f"seqLength {length} outside 1..{MAX_TIMELINE_FRAMES} frames"
                )
            return length
    return None


def read_mot_tracks(path: Path, text: str | None = None) -> TrackerOutput:
    """MOTChallenge tracker output (``text``: the file's, when already read); world x, y, z
    from columns 8-10 where not -1."""
    path = Path(path)
    error = _tracks_error(path)
    rows = _mot_rows(text if text is not None else read_text(path, error, "tracker output"), error)
    by_frame: dict[int, list[TrackOutput]] = {}
    for line, row in enumerate(rows, start=1):
        world = row.shape[0] >= 10 and not np.all(row[7:10] == -1)
        x, y, z = (float(v) for v in row[7:10]) if world else (math.nan,) * 3
        if row[4] < 0 or row[5] < 0:
            raise InputError(path, f"frame {int(row[0])} id {int(row[1])}: negative box size")
        if world and (problem := position_problem((x, y, z))) is not None:
            raise InputError(path, f"row {line}: {problem}")
        by_frame.setdefault(int(row[0]) - MOT_FIRST_FRAME, []).append(
            TrackOutput(
                track_id=int(row[1]),
                x=x,
                y=y,
                height=2.0 * z if world else math.nan,
                box2d=Box2D(float(row[2]), float(row[3]), float(row[4]), float(row[5])),
                visibility=Visibility.VISIBLE,
                confidence=float(row[6]) if row.shape[0] >= 7 and math.isfinite(row[6]) else None,
            )
        )
    frames = tuple((f, 0, tuple(by_frame[f])) for f in sorted(by_frame))
    return TrackerOutput(str(path), frames)


#: MOTChallenge's class ids (MOT16/17/20 ground truth, column 8).
_CLASSES = range(1, 13)


def _has_classes(rows: np.ndarray) -> bool:
    """Whether the rows have MOT16/17/20's layout: 9 columns, column 8 a class id."""
    return (
        bool(rows.size)
        and rows.shape[1] == 9
        and bool(np.isin(rows[:, 7], np.array(_CLASSES, dtype=np.float64)).all())
    )


def _mot_benchmark(rows: np.ndarray, benchmark: Benchmark, error: Err) -> Benchmark:
    """The rules to apply; an error when the file's layout contradicts the chosen ones."""
    # MOT16/17/20 ground truth has 9 columns (class and visibility in 8 and 9); MOT15 has
    # 10 (world x, y, z in 8-10, -1 when unknown).
    if benchmark is Benchmark.AUTO:
        return Benchmark.MOT17 if _has_classes(rows) else Benchmark.MOT15
    if rows.size and benchmark is not Benchmark.MOT15:
        if rows.shape[1] < 8:
            raise error(f"{benchmark.value} ground truth needs the class column (8)")
        classes = rows[:, 7]
        bad = np.flatnonzero(~np.isin(classes, np.array(_CLASSES, dtype=np.float64)))
        if bad.size:
            k = int(bad[0])
            raise error(
                f"--benchmark {benchmark.value}: row {k + 1} has class {classes[k]:g} in "
                f"column 8, not a MOTChallenge class 1..12 (MOT15 ground truth? use "
                "--benchmark mot15 or auto)"
            )
    return benchmark


def read_mot_gt(
    path: Path, benchmark: Benchmark = Benchmark.AUTO, text: str | None = None
) -> GroundTruth:
    """MOTChallenge ground truth with the devkit's rules (see the module docstring);
    ``text``: the file's, when already read.

    A GroundTruthError when the file does not have the chosen benchmark's layout, holds
    a box of no size, or leaves nothing to score under its rules.
    """
    path = Path(path)
    error = _gt_error(path)
    rows = _mot_rows(text if text is not None else read_text(path, error, "ground truth"), error)
    rules = _mot_benchmark(rows, benchmark, error)
    objects = []
    for row in rows:
        frame, oid = int(row[0]) - MOT_FIRST_FRAME, int(row[1])
        ignore, distractor, visibility = False, True, 1.0
        world = None
        if rules is Benchmark.MOT15:
            if row.shape[0] >= 10 and not np.all(row[7:10] == -1):
                world = (float(row[7]), float(row[8]), float(row[9]))
            # TrackEval drops MOT15 rows whose consider flag is 0 (no distractor matching).
            ignore, distractor = row.shape[0] >= 7 and row[6] == 0, False
        if rules is not Benchmark.MOT15:
            cls = int(row[7])
            scored = cls == _PEDESTRIAN and row[6] != 0
            ignore = not scored
            distractor = cls in _DISTRACTORS[rules]
            if row.shape[0] >= 9:
                visibility = min(1.0, max(0.0, float(row[8])))
        objects.append(
            GroundTruthObject(
                frame=frame,
                stamp_ns=0,
                object_id=oid,
                box2d=Box2D(float(row[2]), float(row[3]), float(row[4]), float(row[5])),
                world_xyz=world,
                visibility=visibility,
                ignore=ignore,
                distractor=distractor,
            )
        )
    if objects and all(o.ignore for o in objects):
        raise error(
            f"no row is scored under {rules.value} rules (every row is ignored: "
            + (
                "consider flag 0)"
                if rules is Benchmark.MOT15
                else "not a pedestrian, class 1, with the consider flag set)"
            )
        )
    return from_objects(str(path), objects, first_frame=MOT_FIRST_FRAME)


# ----------------------------------------------------------------------------- tracks.csv, KTP

_TRACKS_CSV_REQUIRED = ("frame", "id", "bb_left", "bb_top", "bb_width", "bb_height", "x", "y")


def _float(text: str | None) -> float | None:
    if text is None or text.strip() == "":
        return None
    return float(text)


def track_problem(track: TrackOutput) -> str | None:
    """Why a track read from a file cannot be scored as given (None when it can): a box
    that is not finite, negative or beyond image coordinates, a position beyond
    :data:`~rgbd_eval.io.validate.MAX_POSITION_M` (NaN: no position)."""
    if abs(track.track_id) >= MAX_ID:
        return f"id {track.track_id} is not smaller than 2**53 in magnitude"
    if track.box2d is not None:
        values = track.box2d.as_tuple()
        if not all(math.isfinite(v) for v in values):
            return f"box {values} is not finite"
        if values[2] < 0 or values[3] < 0:
            return f"box size {values[2]}x{values[3]} is negative"
        if any(abs(v) > MAX_PIXELS for v in values):
            return f"box {values} lies beyond {MAX_PIXELS:g} pixels"
    position = (track.x, track.y)
    if not all(math.isnan(v) for v in position):
        problem = position_problem(position)
        if problem is not None:
            return problem
    if math.isinf(track.height):
        return f"height {track.height} is not finite"
    if track.confidence is not None and not math.isfinite(track.confidence):
        return f"confidence {track.confidence} is not finite"
    return None


def read_tracks_csv(path: Path, text: str | None = None) -> TrackerOutput:
    """Our ``tracks.csv``: frame, id, box, confidence, world x/y/z, stamp, height,
    visibility, status (``text``: the file's, when already read)."""
    from rgbd_eval.types import TrackStatus

    path = Path(path)
    if text is None:
        text = read_text(path, _tracks_error(path), "tracker output")
    with io.StringIO(text, newline="") as handle:
        reader = csv.DictReader(handle)
        missing = [c for c in _TRACKS_CSV_REQUIRED if c not in (reader.fieldnames or [])]
        if missing:
            raise InputError(path, f"tracks CSV lacks the column(s) {missing}")
        by_frame: dict[int, tuple[int, list[TrackOutput]]] = {}
        for number, row in enumerate(reader, start=2):
            if None in row:  # csv.DictReader files extra fields under the key None
                raise InputError(path, f"line {number}: more fields than the header")
            if None in row.values():  # ... and fills missing ones with None
                raise InputError(path, f"line {number}: fewer fields than the header")
            try:
                frame = int(row["frame"])
                box = [_float(row[k]) for k in _TRACKS_CSV_REQUIRED[2:6]]
                stamp = int(row.get("stamp_ns") or 0)
                z = _float(row.get("z"))
                height = _float(row.get("height"))
                track = TrackOutput(
                    track_id=int(row["id"]),
                    x=float(row["x"]),
                    y=float(row["y"]),
                    height=height if height is not None else (2 * z if z is not None else math.nan),
                    box2d=None if any(v is None for v in box) else Box2D(*box),  # type: ignore[arg-type]
                    visibility=Visibility[(row.get("visibility") or "visible").upper()],
                    status=TrackStatus(row.get("status") or "validated"),
                    confidence=_float(row.get("conf")),
                )
                problem = frame_problem(frame, stamp) or track_problem(track)
                if problem is not None:
                    raise ValueError(problem)
            except (ValueError, KeyError) as err:
                raise InputError(path, f"line {number}: {err}") from err
            entry = by_frame.setdefault(frame, (stamp, []))
            if entry[0] != stamp:
                raise InputError(path, f"line {number}: frame {frame} has two stamps")
            entry[1].append(track)
    frames = tuple(
        (f, s, tuple(t)) for f, (s, t) in sorted(by_frame.items(), key=lambda i: (i[1][0], i[0]))
    )
    return TrackerOutput(str(path), frames)


def read_ktp_tracks(path: Path) -> TrackerOutput:
    """KTP text used for tracker output: boxes, or 3D positions (x, y on the ground)."""
    try:
        parsed = read_ktp(path)
    except GroundTruthError as err:
        raise InputError(path, err.message) from err
    frames = tuple(
        (
            f,
            s,
            tuple(
                TrackOutput(
                    track_id=o.object_id,
                    x=o.world_xyz[0] if o.world_xyz else math.nan,
                    y=o.world_xyz[1] if o.world_xyz else math.nan,
                    height=2 * o.world_xyz[2] if o.world_xyz else math.nan,
                    box2d=o.box2d,
                    visibility=Visibility.VISIBLE,
                )
                for o in objs
            ),
        )
        for f, s, objs in parsed.frames
        if objs  # a line with no entry: no track in that frame
    )
    return TrackerOutput(str(path), frames)


RECORDING_SUFFIXES = (".bag", ".mcap", ".db3")


def is_recording(path: Path) -> bool:
    """Whether ``path`` is a ROS1 bag, an MCAP/db3 file or a ROS2 bag folder."""
    return (path.is_file() and path.suffix in RECORDING_SUFFIXES) or (
        path.is_dir() and (path / "metadata.yaml").is_file()
    )


def load_tracks(
    path: Path, topic: str | None = None, world_frame: str | None = None
) -> TrackerOutput:
    """Tracker output from a file or recording, its format detected from the content.

    ``topic`` and ``world_frame`` apply to recordings (see
    :mod:`rgbd_eval.io.track_messages`).
    """
    path = Path(path)
    if is_recording(path):
        from rgbd_eval.io.track_messages import read_bag_tracks

        return read_bag_tracks(path, topic, world_frame)
    text = read_text(path, _tracks_error(path), "tracker output")  # no pipe, bounded, UTF-8
    if _looks_like_mot(text):
        return read_mot_tracks(path, text)
    first = _first_data_line(text)
    if "," in first and ":" not in first:
        return read_tracks_csv(path, text)
    return read_ktp_tracks(path)


def load_gt(path: Path, benchmark: Benchmark = Benchmark.AUTO) -> tuple[GroundTruth, int | None]:
    """Ground truth for scoring and the sequence length where a ``seqinfo.ini`` states it.

    It must annotate somebody (an empty file is a GroundTruthError, not all false positives).
    """
    path = Path(path)
    text = read_text(path, _gt_error(path), "ground truth")  # no pipe, bounded, UTF-8
    if _looks_like_mot(text):
        return require_objects(read_mot_gt(path, benchmark, text)), seq_length(path)
    return load_ground_truth(path), None


# ----------------------------------------------------------------------------- alignment


def _check_timeline(gt: GroundTruth, tracks: TrackerOutput, length: int | None) -> None:
    """An error before a timeline of more than :data:`MAX_TIMELINE_FRAMES` frames is built,
    or when a frame lies outside ``seqinfo.ini``'s ``1..length``; it names the input."""
    for source, numbers, error in (
        (gt.source, [f for f, _, _ in gt.frames], _gt_error),
        (tracks.source, [f for f, _, _ in tracks.frames], _tracks_error),
    ):
        if not numbers:
            continue
        # frames are indices from 0 here; seqinfo.ini numbers them from MOT_FIRST_FRAME
        if length is not None and not (min(numbers) >= 0 and max(numbers) < length):
            outside = next(f for f in numbers if not 0 <= f < length) + MOT_FIRST_FRAME
            raise error(Path(source))(
                f"frame {outside} outside {MOT_FIRST_FRAME}..{length} (seqinfo.ini)"
            )
    if length is not None:
        return
    annotated = [f for f, _, _ in gt.frames]
    both = annotated + [f for f, _, _ in tracks.frames]
    for source, numbers, error in (
        (gt.source, annotated, _gt_error),  # the ground truth's own span first
        (tracks.source, both, _tracks_error),  # else the tracks reach too far from it
    ):
        if numbers and max(numbers) - min(numbers) + 1 > MAX_TIMELINE_FRAMES:
            raise error(Path(source))(
                f"frames {min(numbers)}..{max(numbers)} span more than the "
                f"{MAX_TIMELINE_FRAMES} frames a sequence scored by frame number may have"
            )


def _by_frame_number(gt: GroundTruth, tracks: TrackerOutput, length: int | None) -> Aligned:
    _check_timeline(gt, tracks, length)
    gt_frames = {f: list(objs) for f, _, objs in gt.frames}
    track_frames = {f: list(t) for f, _, t in tracks.frames}
    numbers = set(gt_frames) | set(track_frames)
    first = 0 if length is not None else min(numbers, default=0)
    last = max(max(numbers, default=0), first + length - 1 if length is not None else 0)
    timeline = range(first, last + 1) if numbers or length else range(0)
    poses: tuple[Pose | None, ...] = ()
    if tracks.sensor_poses:
        by_frame = {f: p for (f, _, _), p in zip(tracks.frames, tracks.sensor_poses, strict=True)}
        poses = tuple(by_frame.get(f) for f in timeline)
    return Aligned(
        stamps_ns=tuple(0 for _ in timeline),
        frame_numbers=tuple(f + gt.first_frame for f in timeline),
        gt=[gt_frames.get(f, []) for f in timeline],
        tracks=[track_frames.get(f, []) for f in timeline],
        unmatched_track_frames=0,
        sensor_poses=poses,
    )


def align(
    gt: GroundTruth, tracks: TrackerOutput, max_gap_ns: int, length: int | None = None
) -> Aligned:
    """Put ground truth and tracks on one timeline.

    When either side has no stamps (all 0) both are matched by frame index (each
    reader counts from 0, see the module docstring), over every frame from the first
    to the last (or the ``length`` frames of the sequence). Otherwise
    the annotated frames are the timeline and each tracker frame goes to the
    annotated frame nearest in stamp within ``max_gap_ns``; tracker frames with no
    annotated frame that near are counted in ``unmatched_track_frames``.
    """
    if all(s == 0 for _, s, _ in gt.frames) or all(s == 0 for _, s, _ in tracks.frames):
        return _by_frame_number(gt, tracks, length)
    stamps = np.array([s for _, s, _ in gt.frames], dtype=np.int64)
    out: list[list[TrackOutput]] = [[] for _ in gt.frames]
    poses: list[Pose | None] = [None for _ in gt.frames]
    taken: set[int] = set()
    unmatched = 0
    sensor = tracks.sensor_poses or (None,) * len(tracks.frames)
    for (_, stamp, frame_tracks), pose in zip(tracks.frames, sensor, strict=True):
        j = int(np.searchsorted(stamps, stamp))
        candidates = [k for k in (j - 1, j) if 0 <= k < len(stamps)]
        k = min(candidates, key=lambda c: abs(int(stamps[c]) - stamp))
        if abs(int(stamps[k]) - stamp) <= max_gap_ns and k not in taken:
            out[k] = list(frame_tracks)
            poses[k] = pose
            taken.add(k)
        else:
            unmatched += 1
    return Aligned(
        stamps_ns=tuple(int(s) for s in stamps),
        frame_numbers=tuple(f + gt.first_frame for f, _, _ in gt.frames),
        gt=[list(objs) for _, _, objs in gt.frames],
        tracks=out,
        unmatched_track_frames=unmatched,
        sensor_poses=tuple(poses) if tracks.sensor_poses else (),
    )


def sequence_pairs(tracks: Path, gt: Path) -> list[tuple[str, Path, Path]]:
    """(name, tracks file, ground-truth file) for a file pair or a folder of tracker output.

    In a folder, ``<name>.txt`` / ``<name>.csv`` / ``<name>.tracks.csv`` pairs with the
    first of ``GT/<name>/gt/gt.txt``, ``GT/<name>.gt.csv``, ``GT/<name>.txt``,
    ``GT/<name>.csv`` that exists.
    """
    if not tracks.is_dir() or is_recording(tracks):
        if gt.is_dir():
            raise GroundTruthError(gt, "a folder of ground truth needs a folder of tracker output")
        return [(_name(tracks), tracks, gt)]
    if not gt.is_dir():
        raise GroundTruthError(gt, "a folder of tracker output needs a folder of ground truth")
    # A `run` output folder also holds detections and events CSVs: not tracker output.
    files = sorted(
        p
        for p in tracks.iterdir()
        if (p.is_file() and p.suffix in (".txt", ".csv") and not p.name.endswith(_NOT_TRACKS))
        or is_recording(p)
    )
    if not files:
        raise InputError(tracks, "folder holds no tracker output (.txt, .csv or recordings)")
    pairs = []
    for f in files:
        name = _name(f)
        options = (
            gt / name / "gt" / "gt.txt",
            gt / f"{name}.gt.csv",
            gt / f"{name}.txt",
            gt / f"{name}.csv",
        )
        found = next((o for o in options if o.is_file()), None)
        if found is None:
            raise GroundTruthError(
                gt, f"no ground truth for sequence {name!r} (tried {options[0].name}, ...)"
            )
        pairs.append((name, f, found))
    return pairs


_NOT_TRACKS = (".detections.csv", ".events.csv")


def _name(path: Path) -> str:
    name = path.name
    for suffix in (".tracks.csv", ".csv", ".txt", *RECORDING_SUFFIXES):
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return path.stem
