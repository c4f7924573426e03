"""Ground truth made in CVAT: ``annotate export`` writes a task, ``annotate import`` reads it back.

Export (:func:`export_task`): every ``every``-th colour frame of a recording as JPEGs in
``images.zip`` (``frame_<recording frame index>.jpg``, sorted as CVAT sorts them), the
tracks of a method (or of a tracker output file) as CVAT for video 1.1 pre-annotations in
``annotations.xml`` (task frame ``k`` is recording frame ``k * every``), and ``README.txt``
on how to load both into CVAT.

Import (:func:`import_annotations`): CVAT's export (CVAT for video 1.1 or MOT 1.1) to the
sidecar CSV. Task frame ``f`` is recording frame ``f * every``; a track's boxes are placed on
those frames and interpolated as CVAT interpolates (:func:`rgbd_eval.io.cvat.visible_boxes`)
over every recording frame from the first task frame to the last one's ``every - 1``
followers, so ground truth exists on each frame the tracker is scored on. ``occluded`` is a
visibility of :data:`OCCLUDED_VISIBILITY` (a ``visibility`` attribute in (0, 1], MOT's column,
wins); ``outside`` is absent; an ``ignored`` attribute sets the ignore flag. World positions
come from the depth image and the recording's tf (:func:`world_position`).

Frames are those of the recording read for colour and, where it has one, depth (the
reference stream is colour): the same for export and import whatever the method.
"""

from __future__ import annotations

import enum
import math
import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import RunConfig
from rgbd_eval.errors import ConfigError, GroundTruthError
from rgbd_eval.io.cvat import (
    MOT_LABELS,
    PERSON,
    CvatAnnotations,
    CvatBox,
    CvatTask,
    CvatTrack,
    cvat_xml,
    load_cvat,
    visible_boxes,
)
from rgbd_eval.io.epfl_rgbd import MIN_TORSO_PIXELS, TORSO_BAND_M, TORSO_COLUMNS, TORSO_ROWS
from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.images import encode_color_jpeg
from rgbd_eval.io.recording import Recording, open_recording
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.outdir import OutputFolder, check_output_file
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.types import (
    Box2D,
    CameraModel,
    Frame,
    GroundTruthObject,
    Pose,
    TrackOutput,
    Visibility,
)

#: The writer of task folders and imported sidecars in a folder's manifest (rgbd_eval.outdir).
OWNER = "annotate"
#: A task folder's files; the XML marks the folder as ours.
TASK_XML = "annotations.xml"
TASK_IMAGES = "images.zip"
TASK_README = "README.txt"
#: The streams annotation frames come from: colour (the reference), depth where present.
ANNOTATION_STREAMS = (StreamSpec("colour"), StreamSpec("depth", required=False))
#: JPEG quality of the exported frames (CVAT re-encodes them for its own cache anyway).
JPEG_QUALITY = 95
#: The visibility (GroundTruthObject.visibility) of a box CVAT marks ``occluded``: scored by
#: default (``evaluation.min_visibility`` 0), ignored with ``min_visibility`` above 0.5.
OCCLUDED_VISIBILITY = 0.5
#: How far (pixels) a box may reach past the image border (CVAT rounds to 0.01 px).
BORDER_TOLERANCE_PX = 1.0

Progress = Callable[[int, int], None]


class OtherLabels(enum.Enum):
    """What ``annotate import`` does with tracks of another label than the person label."""

    IGNORE = "ignore"
    REFUSE = "refuse"


@dataclass(frozen=True)
class ExportSummary:
    """What :func:`export_task` wrote."""

    folder: Path
    images: int
    every: int
    tracks: int
    boxes: int
    source: str


@dataclass(frozen=True)
class ImportSummary:
    """What :func:`import_annotations` wrote."""

    output: Path
    kind: str
    every: int
    tracks: int
    boxes: int
    frames: int
    positions: int
    has_depth: bool
    skipped: Mapping[str, int] = field(default_factory=dict)
    """Tracks left out: ``label <name>`` or a shape kind (``polygon``, ...) -> count."""
    unplaced: tuple[int, int] | None = None
    """(frame, id) of the first box that got no world position, if any."""


def open_annotation_frames(path: Path, config: RunConfig) -> Recording:
    """The recording read for annotation: colour frames (with depth where present)."""
    return open_recording(path, config.io, ANNOTATION_STREAMS)


def task_size(num_frames: int, every: int) -> int:
    """How many frames a task of every ``every``-th recording frame has."""
    return len(range(0, num_frames, every))


def _nearest(stamps: NDArray[np.int64], stamp: int, max_gap_ns: int) -> int | None:
    """Index of the stamp in ``stamps`` (ascending) nearest to ``stamp`` within the gap."""
    if stamps.size == 0:
        return None
    j = int(np.searchsorted(stamps, stamp))
    best = min(
        (k for k in (j - 1, j) if 0 <= k < stamps.size), key=lambda k: abs(int(stamps[k]) - stamp)
    )
    return best if abs(int(stamps[best]) - stamp) <= max_gap_ns else None


def tracks_on_frames(
    frames: Sequence[tuple[int, int, Sequence[TrackOutput]]],
    stamps_ns: Sequence[int],
    max_gap_ns: int,
) -> list[tuple[TrackOutput, ...]]:
    """Tracker output ``(frame, stamp, tracks)`` per recording frame: by nearest stamp within
    ``max_gap_ns``, or by frame index when the output has no stamps."""
    out: list[tuple[TrackOutput, ...]] = [() for _ in stamps_ns]
    if all(stamp == 0 for _, stamp, _ in frames):
        for index, _, tracks in frames:
            if 0 <= index < len(out):
                out[index] = tuple(tracks)
        return out
    stamps = np.asarray(stamps_ns, dtype=np.int64)
    for _, stamp, tracks in frames:
        k = _nearest(stamps, stamp, max_gap_ns)
        if k is not None:
            out[k] = tuple(tracks)
    return out


def _clipped(box: Box2D, width: int, height: int) -> tuple[float, float, float, float] | None:
    """The part of ``box`` inside the image (corners), None when less than a pixel is."""
    x0, y0 = max(box.left, 0.0), max(box.top, 0.0)
    x1, y1 = min(box.right, float(width)), min(box.bottom, float(height))
    return (x0, y0, x1, y1) if x1 - x0 >= 1.0 and y1 - y0 >= 1.0 else None


def pre_annotations(
    per_task_frame: Sequence[Sequence[TrackOutput]], width: int, height: int
) -> list[CvatTrack]:
    """CVAT tracks of the scored tracks with a box, one keyframe per task frame they are on,
    clipped to the image; an ``outside`` box closes each stretch (CVAT would otherwise carry
    the last box to the end of the task)."""
    size = len(per_task_frame)
    by_id: dict[int, dict[int, CvatBox]] = {}
    for k, tracks in enumerate(per_task_frame):
        for t in tracks:
            if t.box2d is None or not is_scored_track(t):
                continue
            corners = _clipped(t.box2d, width, height)
            if corners is None:
                continue
            occluded = t.visibility is Visibility.OCCLUDED
            by_id.setdefault(t.track_id, {})[k] = CvatBox(k, *corners, occluded=occluded)
    out = []
    for track_id in sorted(by_id):
        frames = sorted(by_id[track_id])
        boxes: list[CvatBox] = []
        for i, k in enumerate(frames):
            boxes.append(by_id[track_id][k])
            following = frames[i + 1] if i + 1 < len(frames) else None
            if (following is None or following > k + 1) and k + 1 < size:
                boxes.append(replace(by_id[track_id][k], frame=k + 1, outside=True))
        out.append(CvatTrack(track_id, PERSON, tuple(boxes), source="auto"))
    return out


def image_name(index: int) -> str:
    """The file of recording frame ``index`` in ``images.zip``."""
    return f"frame_{index:06d}.jpg"


def readme_text(
    name: str, recording: Path, every: int, images: int, source: str, tracks: int
) -> str:
    """``README.txt`` of a task folder: what it holds and how to load it into CVAT."""
    return f"""CVAT task for {name} ({recording}), written by `rgbd-eval annotate export`.

{TASK_IMAGES}       colour frames 0, {every}, {2 * every}, ... of the recording: {images} JPEGs named
                 frame_<recording frame index>.jpg; task frame k is recording frame {every} x k
{TASK_XML}  pre-annotations in CVAT for video 1.1: {tracks} tracks of {source},
                 label "{PERSON}", a box on each task frame (edit them rather than start afresh)

In CVAT (2.x; app.cvat.ai or your own server):
1. Create a task: Tasks, "+", "Create a new task". Give it a name, add the label
   "{PERSON}" and, under "Select files", upload {TASK_IMAGES}. Leave the advanced
   options (start, stop frame, frame step) as they are. Submit and open the task.
2. Load the pre-annotations: Actions, "Upload annotations", format "CVAT 1.1",
   file {TASK_XML}.
3. Annotate in the job: one track per person for the whole time they are seen
   (the id must not change); correct the boxes on keyframes, CVAT interpolates
   between them; mark a person who leaves the image "outside" from the frame they
   are gone, and a partly hidden one "occluded". Delete tracks on things that are
   not people, add tracks for people the method missed. Save.
4. Export: Actions, "Export task dataset", format "CVAT for video 1.1" (or "MOT 1.1"),
   without images.
5. rgbd-eval annotate import <the exported zip> --recording {recording} --every {every} -o <name>.gt.csv

Then `rgbd-eval run {recording} --gt <name>.gt.csv` scores a method against it.
"""


def export_task(
    recording_path: Path,
    out: Path,
    config: RunConfig,
    *,
    every: int = 1,
    tracks_file: Path | None = None,
    force: bool = False,
    progress: Progress | None = None,
) -> ExportSummary:
    """Write the task folder ``out`` (see the module docstring); published whole when done.

    The pre-annotations are the tracks of ``config``'s method, run on the recording, or those
    of ``tracks_file`` (any tracker output ``score`` reads).
    """
    from rgbd_eval.io.tracks import load_tracks
    from rgbd_eval.pipeline import detect_and_track, open_for, sequence_name

    if every < 1:
        raise ConfigError(f"--every {every}: must be at least 1")
    recording_path = Path(recording_path)
    with OutputFolder(
        out, TASK_XML, force, command=OWNER, names=[TASK_IMAGES, TASK_README]
    ) as folder:
        recording = open_annotation_frames(recording_path, config)
        stamps = recording.frame_stamps
        camera = recording.info.cameras["colour"]
        gap = int(config.io.max_sync_gap_ms * 1e6)
        if tracks_file is not None:
            source = str(tracks_file)
            output = load_tracks(tracks_file)
            per_frame = tracks_on_frames(output.frames, stamps, gap)
        else:
            source = f"method {config.method}"
            method = open_for(recording_path, config)
            detections, tracks = detect_and_track(method, config, progress)
            frames = list(zip(range(len(tracks)), detections.stamps_ns, tracks, strict=True))
            per_frame = tracks_on_frames(frames, stamps, gap)
        wanted = range(0, len(recording), every)
        cvat_tracks = pre_annotations([per_frame[i] for i in wanted], camera.width, camera.height)
        name = sequence_name(recording_path)
        task = CvatTask(len(wanted), width=camera.width, height=camera.height, name=name)
        (folder.staging / TASK_XML).write_text(cvat_xml(task, cvat_tracks), encoding="utf-8")
        _write_images(folder.staging / TASK_IMAGES, recording, set(wanted), progress)
        readme = readme_text(name, recording_path, every, len(wanted), source, len(cvat_tracks))
        (folder.staging / TASK_README).write_text(readme, encoding="utf-8")
        folder.commit()
    boxes = sum(1 for t in cvat_tracks for b in t.boxes if not b.outside)
    return ExportSummary(Path(out), len(wanted), every, len(cvat_tracks), boxes, source)


def _write_images(
    path: Path, recording: Recording, wanted: set[int], progress: Progress | None
) -> None:
    """The wanted colour frames as JPEGs in a zip (stored: JPEG does not compress further),
    with fixed dates so that the same recording gives the same bytes."""
    done = 0
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as archive:
        for frame in recording.frames(skip=("depth",)):
            if frame.index not in wanted:
                continue
            info = zipfile.ZipInfo(image_name(frame.index), date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            archive.writestr(info, bytes(encode_color_jpeg(frame.rgb, JPEG_QUALITY)["data"]))
            done += 1
            if progress is not None:
                progress(done, len(wanted))


# ----------------------------------------------------------------------------- import


def resolve_every(annotations: CvatAnnotations, num_frames: int, every: int | None) -> int:
    """The recording frames per task frame: ``every``, or inferred from the task's size.

    A task of every frame of a video (``start_frame`` or a frame step set) numbers its frames
    as the video does: 1. An image task (our export) has ``ceil(frames / every)`` frames: the
    one ``every`` that gives its size. MOT text records no task: ``every`` must be given.
    """
    task = annotations.task
    if every is not None:
        if every < 1:
            raise ConfigError(f"--every {every}: must be at least 1")
        return every
    if task is None:
        raise ConfigError(
            f"{annotations.source}: MOT 1.1 does not say which recording frames the task "
            "holds: give --every N (the step of `annotate export`, in its README.txt)"
        )
    if task.start_frame != 0 or task.step != 1:
        return 1
    fits = [n for n in range(1, num_frames + 1) if task_size(num_frames, n) == task.size]
    if len(fits) == 1:
        return fits[0]
    if not fits:
        raise GroundTruthError(
            annotations.source,
            f"the task has {task.size} frames, which no --every gives from the recording's "
            f"{num_frames} frames: another recording's annotations?",
        )
    raise ConfigError(
        f"{annotations.source}: the task's {task.size} frames fit --every {fits[0]} to "
        f"{fits[-1]}: give --every N (the step of `annotate export`, in its README.txt)"
    )


def _check_task(
    annotations: CvatAnnotations, num_frames: int, every: int, width: int, height: int
) -> None:
    """The task must be this recording's: its frame count and image size."""
    task = annotations.task
    error = lambda message: GroundTruthError(annotations.source, message)  # noqa: E731
    if task is not None:
        if task.start_frame == 0 and task.step == 1 and task.size != task_size(num_frames, every):
            raise error(
                f"the task has {task.size} frames, the recording at --every {every} "
                f"{task_size(num_frames, every)} ({num_frames} frames): another recording's "
                "annotations, or another --every?"
            )
        if task.stop_frame * every >= num_frames:
            raise error(
                f"task frame {task.stop_frame} is recording frame {task.stop_frame * every}, "
                f"past the recording's {num_frames} frames: another recording's annotations?"
            )
        if task.width is not None and (task.width, task.height) != (width, height):
            raise error(
                f"the task's images are {task.width}x{task.height}, the recording's colour "
                f"images {width}x{height}: another recording's annotations?"
            )
    else:
        last = max(
            (b.frame for t in annotations.tracks for b in t.boxes if not b.outside), default=0
        )
        if last * every >= num_frames:
            raise error(
                f"frame {last + 1} is recording frame {last * every}, past the recording's "
                f"{num_frames} frames: another recording's annotations, or another --every?"
            )


def _check_inside(track: CvatTrack, width: int, height: int, source: str) -> None:
    tol = BORDER_TOLERANCE_PX
    for b in track.boxes:
        if b.outside:
            continue
        if b.xtl < -tol or b.ytl < -tol or b.xbr > width + tol or b.ybr > height + tol:
            raise GroundTruthError(
                source,
                f"track {track.track_id}, frame {b.frame}: box ({b.xtl:g}, {b.ytl:g})-"
                f"({b.xbr:g}, {b.ybr:g}) reaches outside the {width}x{height} image: another "
                "recording's annotations?",
            )


def person_tracks(
    annotations: CvatAnnotations, label: str | None, others: OtherLabels
) -> tuple[list[CvatTrack], dict[str, int]]:
    """The tracks of the person label, and what was left out (``label X`` or a shape kind)."""
    if label is None:  # MOT text without labels.txt uses MOTChallenge's classes
        label = (
            MOT_LABELS[0]
            if annotations.task is None and not _has_label(annotations, PERSON)
            else PERSON
        )
    chosen = [t for t in annotations.tracks if t.label == label]
    skipped: dict[str, int] = {}
    for t in annotations.tracks:
        if t.label != label:
            skipped[f"label {t.label}"] = skipped.get(f"label {t.label}", 0) + 1
    if skipped and others is OtherLabels.REFUSE:
        names = ", ".join(sorted(k.removeprefix("label ") for k in skipped))
        raise GroundTruthError(
            annotations.source,
            f"tracks of other labels than {label!r} ({names}); --other-labels ignore skips them",
        )
    if not chosen:
        labels = sorted({t.label for t in annotations.tracks})
        raise GroundTruthError(
            annotations.source,
            f"no box track labelled {label!r}"
            + (f" (labels: {', '.join(labels)}; choose one with --label)" if labels else ""),
        )
    for kind, count in annotations.other_shapes.items():
        skipped[kind] = skipped.get(kind, 0) + count
    return chosen, skipped


def _has_label(annotations: CvatAnnotations, label: str) -> bool:
    return any(t.label == label for t in annotations.tracks)


def on_recording(track: CvatTrack, every: int) -> CvatTrack:
    """The track with its task frames as recording frames (``frame * every``)."""
    return replace(track, boxes=tuple(replace(b, frame=b.frame * every) for b in track.boxes))


def annotated_span(annotations: CvatAnnotations, num_frames: int, every: int) -> range:
    """The recording frames the task covers: from its first frame to the last one's followers
    (each task frame stands for itself and the ``every * step - 1`` recording frames after)."""
    task = annotations.task or CvatTask(task_size(num_frames, every))
    first = task.start_frame * every
    stop = min(num_frames, (task.stop_frame + task.step) * every)
    return range(first, stop)


def _visibility(box: CvatBox) -> float:
    value = box.attribute("visibility")
    if value is not None:
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if 0.0 < number <= 1.0:
            return number
    return OCCLUDED_VISIBILITY if box.occluded else 1.0


def _ignored(box: CvatBox) -> bool:
    return (box.attribute("ignored") or "").strip().lower() in ("true", "1")


@dataclass(frozen=True)
class _DepthPoints:
    """A frame's valid depth points in the colour camera, with their colour-image pixels."""

    uv: NDArray[np.float64]
    xyz: NDArray[np.float64]
    colour_to_world: Pose


def _depth_points(frame: Frame) -> _DepthPoints | None:
    stream = frame.streams.get("depth")
    if stream is None or stream.encoding != "depth":
        return None
    colour: CameraModel = frame.stream("colour").camera
    points = stream.camera.backproject(stream.image).reshape(-1, 3)
    points = points[np.isfinite(points[:, 2]) & (points[:, 2] > 0)]
    in_colour = frame.depth_to_rgb.transform_points(points)
    in_colour = in_colour[in_colour[:, 2] > 0]
    uv = colour.project(in_colour)
    return _DepthPoints(uv, in_colour, frame.camera_pose.compose(frame.depth_to_rgb.inverse()))


def world_position(
    points: _DepthPoints, box: Box2D, colour: CameraModel
) -> tuple[float, float, float] | None:
    """A person's world position from its box and the depth image, as the EPFL-RGBD import
    derives it (:func:`rgbd_eval.io.epfl_rgbd.ground_position`), through the cameras' models.

    The torso window of the box (columns 25-75 %, rows 20-50 %) takes the depth points whose
    pixel centres project into it (depth camera -> tf -> colour camera, lens distortion
    applied); their median depth along the colour camera's axis places the person; the
    points within 0.3 m of it are averaged and moved to the world frame for x and y; z is
    half the height of the box's top edge at that depth. None with fewer than 10 points, or
    none within 0.3 m of the median.
    """
    u0 = box.left + TORSO_COLUMNS[0] * box.width
    u1 = box.left + TORSO_COLUMNS[1] * box.width
    v0 = box.top + TORSO_ROWS[0] * box.height
    v1 = box.top + TORSO_ROWS[1] * box.height
    u, v = points.uv[:, 0], points.uv[:, 1]
    inside = (u >= u0) & (u < u1) & (v >= v0) & (v < v1)
    if int(inside.sum()) < MIN_TORSO_PIXELS:
        return None
    xyz = points.xyz[inside]
    median = float(np.median(xyz[:, 2]))
    kept = xyz[np.abs(xyz[:, 2] - median) <= TORSO_BAND_M]
    if kept.shape[0] == 0:  # an even count's median between two far layers: no surface there
        return None
    centre = points.colour_to_world.transform_points(kept.mean(axis=0, keepdims=True))[0]
    head = colour.rays_at(box.left + box.width / 2.0, box.top) * median
    top = float(points.colour_to_world.transform_points(head[None, :])[0, 2])
    return (float(centre[0]), float(centre[1]), max(top, 0.0) / 2.0)


def import_annotations(
    source: Path,
    recording_path: Path,
    out: Path,
    config: RunConfig,
    *,
    every: int | None = None,
    label: str | None = None,
    others: OtherLabels = OtherLabels.IGNORE,
    progress: Progress | None = None,
) -> ImportSummary:
    """Read a CVAT export and write the sidecar CSV ``out`` for ``recording_path``."""
    source, recording_path, out = Path(source), Path(recording_path), Path(out)
    check_output_file(out, OWNER, inputs=(source, recording_path))
    annotations = load_cvat(source)
    recording = open_annotation_frames(recording_path, config)
    num_frames = len(recording)
    colour = recording.info.cameras["colour"]
    has_depth = "depth" in recording.info.selected.streams
    every = resolve_every(annotations, num_frames, every)
    _check_task(annotations, num_frames, every, colour.width, colour.height)
    tracks, skipped = person_tracks(annotations, label, others)
    for t in tracks:
        _check_inside(t, colour.width, colour.height, annotations.source)
    span = annotated_span(annotations, num_frames, every)
    per_frame: dict[int, list[tuple[int, CvatBox]]] = {}
    for t in tracks:
        for frame, box in visible_boxes(on_recording(t, every), span).items():
            per_frame.setdefault(frame, []).append((t.track_id, box))
    stamps = recording.frame_stamps
    objects: list[GroundTruthObject] = []
    positions = 0
    unplaced: tuple[int, int] | None = None

    def add(index: int, points: _DepthPoints | None) -> None:
        nonlocal positions, unplaced
        for track_id, b in sorted(per_frame[index], key=lambda item: item[0]):
            # Micrometre-rounded: x_br - x_tl of two 0.01 px values carries float noise.
            box = Box2D(*(round(v, 6) for v in (b.xtl, b.ytl, b.xbr - b.xtl, b.ybr - b.ytl)))
            world = world_position(points, box, colour) if points is not None else None
            positions += world is not None
            if world is None and points is not None and unplaced is None:
                unplaced = (index, track_id)
            objects.append(
                GroundTruthObject(
                    index, stamps[index], track_id, box, world, _visibility(b), _ignored(b)
                )
            )

    if has_depth:  # one pass over the depth images; colour is not decoded
        for depth_frame in recording.frames(skip=("colour",)):
            if depth_frame.index in per_frame:
                add(depth_frame.index, _depth_points(depth_frame))
            if progress is not None:
                progress(depth_frame.index + 1, num_frames)
    else:
        for index in sorted(per_frame):
            add(index, None)
    # every frame of the task's span is annotated, people in view or not
    write_csv(out, objects, [(i, stamps[i]) for i in span], OWNER)
    return ImportSummary(
        output=out,
        kind=annotations.kind,
        every=every,
        tracks=len(tracks),
        boxes=len(objects),
        frames=len(per_frame),
        positions=positions,
        has_depth=has_depth,
        skipped=skipped,
        unplaced=unplaced,
    )
