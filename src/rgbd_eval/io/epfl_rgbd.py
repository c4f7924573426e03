"""EPFL RGB-D pedestrian dataset (EPFL-LAB, EPFL-CORRIDOR): a sequence folder to a recording.

The dataset of Bagautdinov, Fleuret and Fua, "Probability occupancy maps for occluded depth
images", CVPR 2015 (seed 003, reference [13]; https://www.epfl.ch/labs/cvlab/data/data-rgbd-pedestrian/).
Its archives (``epfl_lab.tar.gz``, ``epfl_corridor.tar.gz``) unpack to one folder per
environment::

    epfl_lab/
      ground_truth_image_plane.yaml     boxes of every sequence of the environment
      20140804_160621_00/               one sequence, named <date>_<time>_<nn>
        rgb000000.png  depth000000.png  rgb000001.png  depth000001.png  ...

No documentation shipped with the files could be reached; every fact used here is read the
same way by at least two independent users' code (docs/datasets.md lists the searches):

- ``depth<N>.png``: one channel, 16 bit, millimetres, 0 = no return; ``rgb<N>.png``: 8-bit
  colour registered to the depth image (same pixel grid); both 512x424 (Kinect v2); N is the
  frame number, zero-padded to six digits. JCLArriaga5/cimat_sort_rgbd
  ``test/pcl_people_detector/Dataset-Simulation/dataset_pcl_people_detection.cpp`` (reads
  ``rgb%06d.png``/``depth%06d.png`` of ``epfl_lab/20140804_160621_00``, 512x424, depth / 1000
  as metres, 0 skipped, colour read at the depth pixel); grupesh/social-distancing-monitoring
  ``ipm.py`` (``rgb%06d.png``; ``depth*.png`` read unchanged as depth).
- Intrinsics fx = fy = 365.8046, cx = 254.3151, cy = 206.9851 and plumb-bob distortion
  (0.0879, -0.2703, 0, 0, 0.0994): cimat_sort_rgbd (same file, "Camera matrix of dataset
  epfl_lab"), grupesh/social-distancing-monitoring ``calibration/calibration.yaml`` (K and dist
  of epfl_lab), an INRIA STARS script reading ``ground_truth_ground_plane.mat`` (same K and
  dist), and a MATLAB HHA script using the same K for epfl_lab and epfl_corridor.
- ``ground_truth_image_plane.yaml``, beside the sequence folders:
  ``{<sequence>: {<frame>: {<person id>: [x, y, w, h]}}}``, a box in pixels with (x, y) its
  top-left corner: grupesh/social-distancing-monitoring ``README_EPFL_DATASET`` ("bounding
  boxes in the image coordinates"); a C++ yaml-cpp parser (``file.front()["20140804_160621_00"]``,
  each entry ``Rect(v[0], v[1], v[2], v[3])``); a Python script drawing ``(x, y)-(x + w, y + h)``
  for ``file_dict_GT['20140804_160621_00'][frame]``; a tracker-tuning script reading
  ``<environment>/ground_truth_image_plane.yaml`` -> sequence -> frame -> {id: [x, y, w, h]}.
  The frame keys are read as the image numbers N (the Python script indexes the dict with the
  video frame counter); annotations start at frame 33/34 of EPFL-LAB, after an empty room.

Not read: ``ground_truth_image_plane.mat`` and ``ground_truth_ground_plane.mat`` (the one user
of the latter reads it as image boxes shifted by 60 rows, so its format is not established).
World positions are therefore derived, not read: see :func:`ground_position`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.errors import DecodeError, GroundTruthError, InputError, OutputError
from rgbd_eval.files import check_input, parse_yaml, read_text
from rgbd_eval.io.groundtruth import MAX_ID, write_csv
from rgbd_eval.io.writer import RecordingWriter, StreamOptions
from rgbd_eval.outdir import check_output_file
from rgbd_eval.types import Box2D, CameraModel, GroundTruthObject, Pose

#: The annotation file of an environment folder.
ANNOTATION_FILE = "ground_truth_image_plane.yaml"
#: The writer of imported recordings and sidecars in a folder's manifest (rgbd_eval.outdir).
OWNER = "import"
#: Image size of the Kinect v2 depth camera (and of the registered colour images).
WIDTH, HEIGHT = 512, 424
#: The optical frame both images are written in (colour is registered to depth).
CAMERA_FRAME = "kinect2_depth_optical_frame"
#: The floor-aligned world frame of the static tf (z up, z = 0 on the floor).
WORLD_FRAME = "world"
#: Kinect v2 depth intrinsics of the dataset (see the module docstring for the sources).
EPFL_KINECT2 = CameraModel(
    WIDTH,
    HEIGHT,
    fx=365.8046307762528,
    fy=365.80463336811664,
    cx=254.31510758228475,
    cy=206.98513348550657,
    distortion=(0.0878958787229031, -0.2702768047075843, 0.0, 0.0, 0.09939543207758726),
    frame_id=CAMERA_FRAME,
)
#: The Kinect v2's nominal depth rate (issue 14 models seed 003 4.3's Kinect for Xbox One as
#: 512x424 at 30 Hz; the seed text is cut after "512"). The folders carry no stamps.
DEFAULT_FPS = 30.0
#: Frame rates accepted for the stamps (Hz): a rate near 0 put the stamps past any clock
#: (``--fps 1e-300`` overflowed).
FPS_RANGE = (0.1, 1000.0)
#: Largest frame number in an image name (92 hours at 30 fps): with the slowest rate the
#: stamps stay within ROS's 32-bit seconds.
MAX_FRAME_NUMBER = 10_000_000
#: Annotation files are data, not configuration: allow far more values than a config YAML.
MAX_ANNOTATION_VALUES = 20_000_000

#: The part of a person's box whose depth places the person: the middle half of the columns,
#: rows 20% to 50% from the top (the torso: no floor, little background between the legs).
TORSO_COLUMNS = (0.25, 0.75)
TORSO_ROWS = (0.2, 0.5)
#: Torso pixels farther than this from their median depth are background, not the person.
TORSO_BAND_M = 0.3
#: Fewer valid torso pixels than this: no world position for that box.
MIN_TORSO_PIXELS = 10

_IMAGE_NAME = re.compile(r"^(rgb|depth)(\d+)\.png$")
_TAG_TIME = re.compile(r"^(\d{8}_\d{6})")


@dataclass(frozen=True)
class EpflFrame:
    """One frame of a sequence: its number and its image files (colour may be absent)."""

    number: int
    depth: Path
    rgb: Path | None


@dataclass(frozen=True)
class EpflSequence:
    """A sequence folder: its tag (folder name) and frames sorted by number."""

    folder: Path
    frames: tuple[EpflFrame, ...]

    @property
    def tag(self) -> str:
        return self.folder.name

    @property
    def has_rgb(self) -> bool:
        return all(f.rgb is not None for f in self.frames)


@dataclass(frozen=True)
class ImportSummary:
    """What :func:`import_sequence` wrote."""

    recording: Path
    ground_truth_csv: Path | None
    frames: int
    annotated_frames: int
    boxes: int
    positions: int
    """Boxes that also got a world position (needs the floor)."""


def scan_sequence(folder: Path) -> EpflSequence:
    """The frames of a sequence folder; :class:`InputError` unless it holds the published layout.

    Every ``depth<N>.png`` is a frame. Colour is optional, but when any ``rgb<N>.png`` is
    present every frame must have one (a half-coloured sequence is a broken copy).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(folder, "not a folder; expected an EPFL-RGBD sequence folder")
    depth: dict[int, Path] = {}
    rgb: dict[int, Path] = {}
    try:
        names = sorted(folder.iterdir())
    except OSError as err:
        raise InputError(folder, f"cannot list the folder ({err.strerror})") from err
    for path in names:
        match = _IMAGE_NAME.match(path.name)
        if match is None:
            continue
        kind, number = match.group(1), int(match.group(2))
        if number > MAX_FRAME_NUMBER:
            raise InputError(path, f"frame number {number} is above {MAX_FRAME_NUMBER}")
        table = depth if kind == "depth" else rgb
        if number in table:
            raise InputError(path, f"frame {number} twice ({table[number].name} and {path.name})")
        table[number] = path
    if not depth:
        raise InputError(folder, "no depth<N>.png images; expected an EPFL-RGBD sequence folder")
    if rgb:
        lonely = sorted(set(depth) ^ set(rgb))
        if lonely:
            n = lonely[0]
            missing = f"rgb{n:06d}.png" if n in depth else f"depth{n:06d}.png"
            raise InputError(
                folder, f"{missing} is missing ({len(lonely)} frames lack colour or depth)"
            )
    frames = tuple(EpflFrame(n, depth[n], rgb.get(n)) for n in sorted(depth))
    return EpflSequence(folder, frames)


def annotation_path(sequence: EpflSequence) -> Path | None:
    """``ground_truth_image_plane.yaml`` beside the sequence folder, if present."""
    candidate = sequence.folder.parent / ANNOTATION_FILE
    return candidate if candidate.is_file() else None


def _int_key(value: Any, what: str) -> int:
    """A YAML key that is an integer (or a string of digits); ValueError otherwise."""
    if isinstance(value, bool):
        raise ValueError(f"{what} {value!r} is not an integer")
    if isinstance(value, int):
        return value
    if isinstance(value, str) and value.strip().isdigit():
        return int(value.strip())
    raise ValueError(f"{what} {value!r} is not an integer")


def _box(value: Any) -> Box2D:
    """``[x, y, w, h]`` of finite numbers with a positive size; ValueError otherwise."""
    if not isinstance(value, list) or len(value) != 4:
        raise ValueError(f"box {value!r} is not a list [x, y, w, h]")
    if any(isinstance(v, bool) or not isinstance(v, int | float) for v in value):
        raise ValueError(f"box {value!r} holds a non-number")
    x, y, w, h = (float(v) for v in value)
    if not all(math.isfinite(v) for v in (x, y, w, h)):
        raise ValueError(f"box {value!r} is not finite")
    if w <= 0 or h <= 0:
        raise ValueError(f"box {value!r} has no area (width and height must be positive)")
    return Box2D(x, y, w, h)


def _sequence_key(data: Mapping[Any, Any], tag: str) -> Any:
    """The key of sequence ``tag``: the tag itself, or, unquoted, the integer YAML 1.1 makes of
    it (``20140804_160621_00`` reads as 2014080416062100; the Python users index the file by
    the string, so the published keys are quoted, but a re-saved file may not be)."""
    if tag in data:
        return tag
    digits = tag.replace("_", "")
    if digits.isdigit() and int(digits) in data:
        return int(digits)
    return None


def read_image_plane_annotations(path: Path, tag: str) -> dict[int, dict[int, Box2D]]:
    """Boxes of sequence ``tag``: frame number -> person id -> box.

    :class:`GroundTruthError` naming the file, and the frame and person where one is at fault,
    for anything but the published structure (see the module docstring).
    """
    path = Path(path)

    def error(message: str) -> GroundTruthError:
        return GroundTruthError(path, message)

    check_input(path, error, "ground truth")
    data = parse_yaml(read_text(path, error, "ground truth"), error, limit=MAX_ANNOTATION_VALUES)
    if not isinstance(data, dict):
        raise error("expected a mapping {sequence: {frame: {person id: [x, y, w, h]}}}")
    key = _sequence_key(data, tag)
    if key is None:
        known = ", ".join(sorted(str(k) for k in data)) or "none"
        raise error(f"no sequence {tag!r} (sequences: {known})")
    frames = data[key]
    if frames is None:
        return {}
    if not isinstance(frames, dict):
        raise error(f"sequence {tag}: expected a mapping {{frame: {{person id: [x, y, w, h]}}}}")
    out: dict[int, dict[int, Box2D]] = {}
    for frame_key, people in frames.items():
        try:
            frame = _int_key(frame_key, "frame")
        except ValueError as err:
            raise error(f"sequence {tag}: {err}") from err
        if frame in out:
            raise error(f"sequence {tag}: frame {frame} given twice")
        if people is None:
            out[frame] = {}
            continue
        if not isinstance(people, dict):
            raise error(f"sequence {tag}, frame {frame}: expected {{person id: [x, y, w, h]}}")
        boxes: dict[int, Box2D] = {}
        for person_key, value in people.items():
            try:
                person = _int_key(person_key, "person id")
                if abs(person) >= MAX_ID:
                    raise ValueError(f"person id {person} is not smaller than 2**53")
                if person in boxes:
                    raise ValueError(f"person id {person} given twice")
                boxes[person] = _box(value)
            except ValueError as err:
                raise error(f"sequence {tag}, frame {frame}: {err}") from err
        out[frame] = boxes
    return out


def read_depth(path: Path) -> NDArray[np.float32]:
    """``depth<N>.png`` in metres (NaN where the PNG holds 0); :class:`DecodeError` otherwise."""
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise DecodeError(path, "cannot read as a PNG image")
    if image.ndim != 2 or image.dtype != np.uint16:
        channels = 1 if image.ndim == 2 else image.shape[2]
        raise DecodeError(
            path, f"expected a 16-bit one-channel depth PNG (mm), got {channels}x{image.dtype}"
        )
    depth = image.astype(np.float32) / np.float32(1000.0)
    depth[image == 0] = np.nan
    return depth


def read_rgb(path: Path) -> NDArray[np.uint8]:
    """``rgb<N>.png`` as ``HxWx3`` RGB; :class:`DecodeError` unless an 8-bit colour PNG."""
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise DecodeError(path, "cannot read as a PNG image")
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] not in (3, 4):
        raise DecodeError(path, f"expected an 8-bit colour PNG, got {image.shape} {image.dtype}")
    code = cv2.COLOR_BGR2RGB if image.shape[2] == 3 else cv2.COLOR_BGRA2RGB
    return np.ascontiguousarray(cv2.cvtColor(image, code), dtype=np.uint8)


def ground_position(
    depth: NDArray[np.floating], box: Box2D, camera: CameraModel, world_T_optical: Pose
) -> tuple[float, float, float] | None:
    """A person's world position derived from its box and the depth image, or None.

    The torso window of the box (:data:`TORSO_COLUMNS` x :data:`TORSO_ROWS`) gives the
    person's depth: the median of its valid pixels; pixels within :data:`TORSO_BAND_M` of that
    median are back-projected and their centroid, moved to the floor-aligned world frame,
    gives x and y. z is half the height of the box's top edge at that depth (the project's
    convention: the centroid of a standing person, seed 000 5.3). None when fewer than
    :data:`MIN_TORSO_PIXELS` torso pixels hold depth.
    """
    u0 = max(0, math.floor(box.left + TORSO_COLUMNS[0] * box.width))
    u1 = min(camera.width, math.ceil(box.left + TORSO_COLUMNS[1] * box.width))
    v0 = max(0, math.floor(box.top + TORSO_ROWS[0] * box.height))
    v1 = min(camera.height, math.ceil(box.top + TORSO_ROWS[1] * box.height))
    if u1 <= u0 or v1 <= v0:
        return None
    window = np.asarray(depth[v0:v1, u0:u1], dtype=np.float64)
    valid = np.isfinite(window) & (window > 0)
    if int(valid.sum()) < MIN_TORSO_PIXELS:
        return None
    median = float(np.median(window[valid]))
    keep = valid & (np.abs(window - median) <= TORSO_BAND_M)
    vv, uu = np.nonzero(keep)
    z = window[vv, uu]
    points = camera.points_at(uu + u0, vv + v0, z)
    centre = world_T_optical.transform_points(points.mean(axis=0, keepdims=True))[0]
    head = camera.points_at(box.left + box.width / 2.0, box.top, median)
    height = float(world_T_optical.transform_points(head[None, :])[0, 2])
    return (float(centre[0]), float(centre[1]), max(height, 0.0) / 2.0)


def start_stamp_ns(tag: str) -> int:
    """The sequence's start from its tag ``YYYYMMDD_HHMMSS_nn`` (read as UTC), else 0."""
    match = _TAG_TIME.match(tag)
    if match is None:
        return 0
    try:
        start = datetime.strptime(match.group(1), "%Y%m%d_%H%M%S").replace(tzinfo=UTC)
    except ValueError:
        return 0
    return int(start.timestamp()) * 1_000_000_000


def frame_stamp_ns(start_ns: int, number: int, fps: float) -> int:
    """Stamp of frame ``number``: frames are ``1 / fps`` apart (the folders carry no stamps)."""
    return start_ns + round(number * 1e9 / fps)


def _check_annotations(
    boxes: Mapping[int, Mapping[int, Box2D]], frames: tuple[EpflFrame, ...], source: Path
) -> None:
    """Every annotated frame must have its image in the folder (converted or not)."""
    numbers = {f.number for f in frames}
    orphans = sorted(n for n in boxes if n not in numbers)
    if orphans:
        raise GroundTruthError(
            source,
            f"frame {orphans[0]} is annotated but depth{orphans[0]:06d}.png is missing "
            f"({len(orphans)} annotated frames without images)",
        )


def _frames(
    sequence: EpflSequence, camera: CameraModel, with_rgb: bool
) -> Iterator[tuple[EpflFrame, NDArray[np.float32], NDArray[np.uint8] | None]]:
    for frame in sequence.frames:
        depth = read_depth(frame.depth)
        if depth.shape != (camera.height, camera.width):
            raise DecodeError(
                frame.depth,
                f"depth image is {depth.shape[1]}x{depth.shape[0]}, the camera model "
                f"{camera.width}x{camera.height} (give --intrinsics for another size)",
            )
        rgb = None
        if with_rgb and frame.rgb is not None:
            rgb = read_rgb(frame.rgb)
            if rgb.shape[:2] != depth.shape:
                raise DecodeError(
                    frame.rgb,
                    f"colour image is {rgb.shape[1]}x{rgb.shape[0]}, depth {depth.shape[1]}x"
                    f"{depth.shape[0]}: not registered to depth (use --no-rgb)",
                )
        yield frame, depth, rgb


def _people(
    index: int,
    stamp_ns: int,
    boxes: Mapping[int, Box2D],
    depth: NDArray[np.float32],
    camera: CameraModel,
    world_T_optical: Pose | None,
) -> list[GroundTruthObject]:
    """One frame's ground truth: each box, with its derived position when the floor is known."""
    people = []
    for person, box in sorted(boxes.items()):
        world = (
            ground_position(depth, box, camera, world_T_optical)
            if world_T_optical is not None
            else None
        )
        people.append(GroundTruthObject(index, stamp_ns, person, box, world))
    return people


def import_sequence(
    sequence: EpflSequence,
    out: Path,
    *,
    annotations: Path | None = None,
    camera: CameraModel = EPFL_KINECT2,
    fps: float = DEFAULT_FPS,
    world_T_optical: Pose | None = None,
    with_rgb: bool = True,
    max_frames: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> ImportSummary:
    """Write ``sequence`` as a recording at ``out`` (``.mcap`` or ``.bag``) plus ``<stem>.gt.csv``.

    The recording holds 16UC1 depth and (when present and ``with_rgb``) rgb8 colour, both in
    the one optical frame :data:`CAMERA_FRAME` with their CameraInfo, and the ground truth on
    ``/ground_truth``. ``world_T_optical`` (the camera in a floor-aligned world, z up, z = 0 on
    the floor) adds a static tf from :data:`WORLD_FRAME` and a world position per box
    (:func:`ground_position`); without it the boxes are written alone.
    """
    if not FPS_RANGE[0] <= fps <= FPS_RANGE[1]:
        raise ValueError(f"fps={fps} must be within {FPS_RANGE[0]:g}..{FPS_RANGE[1]:g}")
    if max_frames is not None and max_frames < 1:
        raise ValueError(f"max_frames={max_frames} must be at least 1")
    camera = replace(camera, frame_id=CAMERA_FRAME)
    boxes: dict[int, dict[int, Box2D]] = {}
    if annotations is not None:
        boxes = read_image_plane_annotations(annotations, sequence.tag)
        _check_annotations(boxes, sequence.frames, annotations)
    frames = sequence.frames[:max_frames] if max_frames is not None else sequence.frames
    sequence = EpflSequence(sequence.folder, frames)
    start = start_stamp_ns(sequence.tag)
    out = Path(out)
    csv_path = out.with_name(f"{out.stem}.gt.csv") if annotations is not None else None
    objects: list[GroundTruthObject] = []
    annotated: list[tuple[int, int]] = []  # as on the topic: every frame written
    positions = 0
    if csv_path is not None:  # before any work, as the recording is (by its writer)
        check_output_file(csv_path, OWNER)
    try:
        writer = RecordingWriter(out, options=StreamOptions(depth_encoding="16UC1"), owner=OWNER)
    except (IsADirectoryError, ValueError) as err:
        raise OutputError(out, str(err)) from err
    try:
        with writer as w:
            if world_T_optical is not None:
                w.write_static_transform(
                    frame_stamp_ns(start, frames[0].number, fps),
                    WORLD_FRAME,
                    CAMERA_FRAME,
                    world_T_optical,
                )
            for index, (frame, depth, rgb) in enumerate(_frames(sequence, camera, with_rgb)):
                stamp = frame_stamp_ns(start, frame.number, fps)
                if rgb is not None:
                    w.write_rgb(stamp, rgb, camera)
                w.write_depth(stamp, depth, camera)
                if annotations is not None:
                    people = _people(
                        index, stamp, boxes.get(frame.number, {}), depth, camera, world_T_optical
                    )
                    positions += sum(p.world_xyz is not None for p in people)
                    w.write_ground_truth(stamp, WORLD_FRAME, people)
                    objects.extend(people)
                    annotated.append((index, stamp))
                if progress is not None:
                    progress(index + 1, len(frames))
        if csv_path is not None:
            write_csv(csv_path, objects, annotated, OWNER)
    except OSError as err:  # disk full, permissions: the writer removed its temp file
        raise OutputError(out, f"cannot write ({err.strerror or err})") from err
    last = frames[-1].number
    return ImportSummary(
        recording=out,
        ground_truth_csv=csv_path,
        frames=len(frames),
        annotated_frames=sum(1 for n in boxes if n <= last),
        boxes=len(objects),
        positions=positions,
    )
