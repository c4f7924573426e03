"""A run in Rerun: one ``.rrd`` per sequence with images, depth, cloud, poses, boxes and errors.

Written by ``run --rerun FILE`` from the run's results, and by ``view REPORT_DIR`` from a
finished run's folder (``report.json``, ``<name>.tracks.csv``, ``<name>.detections.csv``,
``<name>.events.csv``, the ground truth) without running the method again. Both re-read the
recording for its images, depth and camera poses. The Rerun SDK is an optional dependency
(``pip install rgbd-eval[rerun]``).

Timelines: ``frame`` (the recording's frame index, as in the CSVs) and ``time`` (the frame's
stamp). Entity paths (the README lists them too)::

    world                            view coordinates: x forward, y left, z up (static)
    world/robot/path                 the colour (else depth) camera's path (static)
    world/colour                     world_T_colour_optical per frame (the robot's pose)
    world/colour/image               pinhole of the colour camera (its distortion is not drawn)
    world/colour/image/rgb           the colour image (JPEG)
    world/colour/image/detections    detection boxes, with confidence
    world/colour/image/tracks        scored track boxes: "id N", "occl" when occluded, FP, SW
    world/colour/image/ground_truth  ground-truth boxes: "gt N", "occl", "miss", "ign"
    world/depth                      world_T_depth_optical (depth_2, ... for more cameras)
    world/depth/image/depth          the depth image (millimetres; no pinhole, so the viewer
                                     does not draw it in 3D over world/cloud)
    world/cloud                      depth points in the world frame, decimated, coloured
    world/detections                 detections' world positions
    world/tracks                     scored tracks at (x, y, height / 2), coloured by id
    world/tracks/trails              each track's last 3 s on the ground plane (z = 0)
    world/ground_truth               ground truth's world positions (misses red)
    world/ground_truth/trails        the same trails for ground truth
    errors/fp, errors/fn, errors/id_switches   per frame counts (scalars)
    events                           one text line per frame with errors (FP, FN, ID switch)

Everything computed here (the decimated cloud, positions, trails) is a deterministic function
of the run; the ``.rrd`` also holds the SDK's own ids and times.
"""

from __future__ import annotations

import csv
import math
import uuid
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import RunConfig
from rgbd_eval.errors import ExtraError, GroundTruthError, InputError, OutputError
from rgbd_eval.io.images import depth_to_mm, encode_color_jpeg
from rgbd_eval.metrics import FrameEvents, Match
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.types import (
    Box2D,
    Detection,
    Frame,
    GroundTruthObject,
    Pose,
    Stream,
    TrackOutput,
    Visibility,
)

if TYPE_CHECKING:
    import rerun as rr

    from rgbd_eval.pipeline import SequenceResult

#: Points of the cloud per frame at most: the depth image is sampled every ``s`` rows and
#: columns, ``s`` the smallest that keeps it under this.
MAX_CLOUD_POINTS = 5000
#: Trails show each track's and person's last seconds on the ground.
TRAIL_SECONDS = 3.0
JPEG_QUALITY = 85
INSTALL_HINT = "pip install 'rgbd-eval[rerun]'"
GREY = (160, 160, 160)
Progress = Callable[[int, int], None]


def require_rerun() -> ModuleType:
    """The Rerun SDK, or :class:`ExtraError` (exit 2) saying how to install it."""
    try:
        import rerun
    except ImportError as err:
        raise ExtraError(
            f"the Rerun SDK (rerun-sdk) is not installed; {INSTALL_HINT} adds it"
        ) from err
    return rerun


@dataclass(frozen=True)
class RunView:
    """What one sequence of a run shows: per frame of the recording, its outputs."""

    name: str
    recording: Path
    method: str
    stamps_ns: tuple[int, ...]
    detections: Sequence[Sequence[Detection]]
    tracks: Sequence[Sequence[TrackOutput]]
    ground_truth: Sequence[Sequence[GroundTruthObject]] | None = None
    events: Sequence[FrameEvents] | None = None


def view_of_result(result: SequenceResult, config: RunConfig) -> RunView:
    """The view of a sequence just run."""
    return RunView(
        name=result.name,
        recording=Path(result.path),
        method=config.method,
        stamps_ns=result.detections.stamps_ns,
        detections=result.detections.detections,
        tracks=result.tracks,
        ground_truth=None if result.ground_truth is None else result.ground_truth.frames,
        events=None if result.scores is None else result.scores.frames,
    )


# ----------------------------------------------------------------------------- a run's files


def _rows(path: Path) -> list[dict[str, str]]:
    try:
        with path.open(encoding="utf-8", newline="") as handle:
            return list(csv.DictReader(handle))
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise InputError(path, f"cannot read ({err})") from err


def read_detections_csv(path: Path, num_frames: int) -> list[list[Detection]]:
    """``<name>.detections.csv`` of a run, per frame."""
    out: list[list[Detection]] = [[] for _ in range(num_frames)]
    for number, row in enumerate(_rows(path), start=2):
        try:
            frame = int(row["frame"])
            box = Box2D(*(float(row[k]) for k in ("bb_left", "bb_top", "bb_width", "bb_height")))
            detection = Detection(
                position=(float(row["x"]), float(row["y"]), float(row["z"])),
                height=float(row["height"]),
                confidence=float(row["confidence"]),
                box2d=box,
                distance=float(row["distance"]),
                occluded=row["occluded"].strip() == "1",
            )
        except (KeyError, ValueError, TypeError, AttributeError) as err:
            raise InputError(path, f"line {number}: {err}") from err
        if not 0 <= frame < num_frames:
            raise InputError(path, f"line {number}: frame {frame} is not one of the run's")
        out[frame].append(detection)
    return out


def read_events_csv(path: Path, num_frames: int) -> list[FrameEvents]:
    """``<name>.events.csv`` of a run back into per-frame scoring events."""
    matches: list[list[Match]] = [[] for _ in range(num_frames)]
    lists: dict[str, list[list[int]]] = {
        k: [[] for _ in range(num_frames)] for k in ("miss", "fp", "ignored_gt", "ignored_track")
    }
    for number, row in enumerate(_rows(path), start=2):
        try:
            frame, event = int(row["frame"]), row["event"]
            if not 0 <= frame < num_frames:
                raise ValueError(f"frame {frame} is not one of the run's")
            if event in ("match", "switch"):
                matches[frame].append(
                    Match(
                        int(row["gt_id"]),
                        int(row["track_id"]),
                        float(row["similarity"]),
                        event == "switch",
                        row["recall_error"].strip() == "1",
                    )
                )
            elif event in ("miss", "ignored_gt"):
                lists[event][frame].append(int(row["gt_id"]))
            elif event in ("fp", "ignored_track"):
                lists[event][frame].append(int(row["track_id"]))
            else:
                raise ValueError(f"unknown event {event!r}")
        except (KeyError, ValueError, TypeError, AttributeError) as err:
            raise InputError(path, f"line {number}: {err}") from err
    return [
        FrameEvents(
            i,
            tuple(matches[i]),
            tuple(lists["miss"][i]),
            tuple(lists["fp"][i]),
            tuple(lists["ignored_gt"][i]),
            tuple(lists["ignored_track"][i]),
        )
        for i in range(num_frames)
    ]


def _per_frame(
    frames: Iterable[tuple[int, int, Sequence[TrackOutput]]],
    stamps_ns: Sequence[int],
    source: Path,
) -> list[list[TrackOutput]]:
    out: list[list[TrackOutput]] = [[] for _ in stamps_ns]
    for index, stamp, tracks in frames:
        if not 0 <= index < len(out) or (stamp and stamp != stamps_ns[index]):
            raise InputError(source, f"frame {index} is not a frame of the run's recording")
        out[index] = list(tracks)
    return out


def _sequence_view(folder: Path, record: dict[str, Any], config: RunConfig, method: str) -> RunView:
    """One sequence of a run folder, checked against its recording (present, unchanged)."""
    from rgbd_eval.files import file_digest
    from rgbd_eval.io.groundtruth import GroundTruth, load_ground_truth
    from rgbd_eval.io.tracks import read_tracks_csv
    from rgbd_eval.pipeline import match_ground_truth, open_for

    name, path = str(record["name"]), Path(str(record["path"]))
    if not path.exists():
        raise InputError(
            path, f"the recording of sequence {name!r} is not there (moved?); view reads it again"
        )
    if file_digest(path) != record.get("sha256"):
        raise InputError(
            path,
            "changed since the run (its sha256 is not the one in report.json): its frames "
            "would not be the run's",
        )
    recording = open_for(path, config)
    stamps = tuple(recording.frame_stamps)
    if len(stamps) != record.get("frames"):
        raise InputError(path, f"has {len(stamps)} frames, the run had {record.get('frames')}")
    tracks = _per_frame(read_tracks_csv(folder / f"{name}.tracks.csv").frames, stamps, folder)
    detections = read_detections_csv(folder / f"{name}.detections.csv", len(stamps))
    events = None
    if record.get("scored"):
        events = read_events_csv(folder / f"{name}.events.csv", len(stamps))
    ground_truth = None
    gt_record = record.get("ground_truth")
    if isinstance(gt_record, dict):
        source = str(gt_record.get("source"))
        gt: GroundTruth | None
        if Path(source).is_file():
            gt = load_ground_truth(Path(source))
        elif source.startswith(f"{path}:"):  # the recording's ground-truth topic
            gt = recording.ground_truth_topic
        else:
            raise GroundTruthError(source, "the run's ground truth is not there (moved?)")
        if gt is not None:
            ground_truth = match_ground_truth(gt, stamps, config).frames
    return RunView(name, path, method, stamps, detections, tracks, ground_truth, events)


def load_run(folder: Path, sequence: str | None = None) -> tuple[list[RunView], RunConfig]:
    """The sequences of a run's output folder (``sequence`` only, when given) and its config."""
    import json

    from rgbd_eval.config import build_config
    from rgbd_eval.files import read_text

    folder = Path(folder)
    report_path = folder / "report.json"
    if not report_path.is_file():
        raise InputError(folder, "holds no report.json: not the output folder of `rgbd-eval run`")
    try:
        report = json.loads(read_text(report_path, lambda m: InputError(report_path, m), "report"))
    except json.JSONDecodeError as err:
        raise InputError(report_path, f"not JSON ({err})") from err
    records = report.get("sequences") if isinstance(report, dict) else None
    if not isinstance(records, list) or not isinstance(report.get("config"), dict):
        raise InputError(report_path, "not a run's report (no config and sequences)")
    if any(not isinstance(r, dict) or "path" not in r for r in records):
        raise InputError(report_path, "written by `rgbd-eval score`: it names no recording to show")
    config = build_config(report["config"], source=str(report_path))
    names = [str(r.get("name")) for r in records]
    if sequence is not None:
        if sequence not in names:
            raise InputError(report_path, f"no sequence {sequence!r} (it has {', '.join(names)})")
        records = [r for r in records if r.get("name") == sequence]
    views = [_sequence_view(folder, r, config, config.method) for r in records]
    return views, config


# ----------------------------------------------------------------------------- logging


def _rgb(colour: tuple[int, int, int]) -> list[int]:
    return [int(c) for c in colour]


def _jpeg(rgb: NDArray[np.uint8]) -> bytes:
    return bytes(encode_color_jpeg(rgb, JPEG_QUALITY)["data"])


def _transform(rr: Any, pose: Pose) -> Any:
    return rr.Transform3D(
        translation=list(pose.translation), quaternion=rr.Quaternion(xyzw=list(pose.rotation))
    )


def _pinhole(rr: Any, stream: Stream) -> Any:
    cam = stream.camera
    return rr.Pinhole(
        image_from_camera=cam.K,
        resolution=[cam.width, cam.height],
        camera_xyz=rr.ViewCoordinates.RDF,
    )


def _xywh(boxes: Sequence[Box2D]) -> NDArray[np.float64]:
    return np.array([b.as_tuple() for b in boxes], dtype=np.float64).reshape(-1, 4)


def cloud_stride(width: int, height: int) -> int:
    """Rows and columns between sampled depth pixels (see :data:`MAX_CLOUD_POINTS`)."""
    return max(1, math.ceil(math.sqrt(width * height / MAX_CLOUD_POINTS)))


def world_cloud(frame: Frame) -> tuple[NDArray[np.float64], NDArray[np.uint8]]:
    """Every depth camera's valid points (sampled, :func:`cloud_stride`) in the world frame,
    coloured from the colour image where they project into it (grey elsewhere)."""
    positions: list[NDArray[np.float64]] = []
    colours: list[NDArray[np.uint8]] = []
    colour = frame.streams.get("colour")
    for _, stream in frame.depth_streams():
        if stream.encoding != "depth":
            continue
        s = cloud_stride(stream.camera.width, stream.camera.height)
        points = stream.camera.backproject(stream.image)[::s, ::s].reshape(-1, 3)
        points = points[np.isfinite(points[:, 2]) & (points[:, 2] > 0)]
        paint = np.tile(np.array(GREY, dtype=np.uint8), (points.shape[0], 1))
        if colour is not None and colour.image.ndim == 3 and points.shape[0]:
            # depth optical -> world -> colour optical (each stream carries its own pose)
            in_colour = colour.pose.inverse().compose(stream.pose).transform_points(points)
            uv = colour.camera.project(in_colour)
            with np.errstate(invalid="ignore"):
                u = np.floor(uv[:, 0] + 0.5)
                v = np.floor(uv[:, 1] + 0.5)
            h, w = colour.image.shape[:2]
            seen = (in_colour[:, 2] > 0) & (u >= 0) & (u < w) & (v >= 0) & (v < h)
            paint[seen] = colour.image[v[seen].astype(np.int64), u[seen].astype(np.int64)]
        positions.append(stream.pose.transform_points(points))
        colours.append(paint)
    if not positions:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint8)
    return np.concatenate(positions), np.concatenate(colours)


class _Trails:
    """The last :data:`TRAIL_SECONDS` of each id's ground-plane positions."""

    def __init__(self) -> None:
        self._points: dict[int, deque[tuple[int, float, float]]] = {}

    def add(self, stamp_ns: int, positions: Iterable[tuple[int, float, float]]) -> None:
        for key, x, y in positions:
            self._points.setdefault(key, deque()).append((stamp_ns, x, y))
        oldest = stamp_ns - int(TRAIL_SECONDS * 1e9)
        for key in list(self._points):
            trail = self._points[key]
            while trail and trail[0][0] < oldest:
                trail.popleft()
            if not trail:
                del self._points[key]

    def strips(self) -> tuple[list[list[list[float]]], list[int]]:
        keys = sorted(k for k, t in self._points.items() if len(t) > 1)
        return [[[x, y, 0.0] for _, x, y in self._points[k]] for k in keys], keys


def error_text(events: FrameEvents) -> str | None:
    """The frame's errors in words (None when it has none)."""
    parts = [f"FP track {t}" for t in events.false_positives]
    parts += [f"FN gt {g}" for g in events.misses]
    parts += [
        f"ID switch: gt {m.gt_id} now track {m.track_id}" for m in events.matches if m.id_switch
    ]
    return "; ".join(parts) if parts else None


class _Logger:
    """Logs one sequence frame by frame into a recording stream."""

    def __init__(self, rr: Any, stream: rr.RecordingStream, view: RunView) -> None:
        from rgbd_eval.report.html.overlay import GT_COLOUR, MISS_COLOUR, track_colour

        self.rr = rr
        self.rec = stream
        self.view = view
        self.track_colour = track_colour
        self.gt_colour = GT_COLOUR
        self.miss_colour = MISS_COLOUR
        self.track_trails = _Trails()
        self.gt_trails = _Trails()
        self.path: list[tuple[float, float, float]] = []
        self.pinholes: set[str] = set()

    def log(self, path: str, *what: Any, static: bool = False) -> None:
        self.rec.log(path, *what, static=static)

    def start(self) -> None:
        rr = self.rr
        self.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for name in ("fp", "fn", "id_switches"):
            self.log(f"errors/{name}", rr.SeriesLines(names=name), static=True)

    def _camera(self, entity: str, stream: Stream, pinhole: bool = True) -> None:
        self.log(entity, _transform(self.rr, stream.pose))
        if pinhole and entity not in self.pinholes:  # intrinsics do not change
            self.log(f"{entity}/image", _pinhole(self.rr, stream), static=True)
            self.pinholes.add(entity)

    def frame(self, frame: Frame) -> None:
        rr, view, i = self.rr, self.view, frame.index
        self.rec.set_time("frame", sequence=i)
        self.rec.set_time("time", timestamp=np.datetime64(frame.stamp_ns, "ns"))
        events = view.events[i] if view.events is not None else None
        gt = list(view.ground_truth[i]) if view.ground_truth is not None else []
        tracks = [t for t in view.tracks[i] if is_scored_track(t)]
        detections = list(view.detections[i])
        colour = frame.streams.get("colour")
        if colour is not None and colour.image.ndim == 3:
            self._camera("world/colour", colour)
            self.path.append(colour.pose.translation)
            self.log(
                "world/colour/image/rgb",
                rr.EncodedImage(contents=_jpeg(colour.image), media_type="image/jpeg"),
            )
            self._image_boxes(detections, tracks, gt, events)
        for role, stream in frame.depth_streams():
            if stream.encoding != "depth":
                continue
            # No pinhole: the viewer would draw the depth image in 3D too, over world/cloud.
            self._camera(f"world/{role}", stream, pinhole=False)
            if colour is None and role == "depth":
                self.path.append(stream.pose.translation)
            self.log(
                f"world/{role}/image/depth",
                rr.DepthImage(depth_to_mm(stream.image), meter=1000.0),
            )
        positions, colours = world_cloud(frame)
        self.log(
            "world/cloud", rr.Points3D(positions, colors=colours, radii=rr.Radius.ui_points(2.5))
        )
        self._world(frame.stamp_ns, detections, tracks, gt, events)
        self._errors(events)

    def _image_boxes(
        self,
        detections: Sequence[Detection],
        tracks: Sequence[TrackOutput],
        gt: Sequence[GroundTruthObject],
        events: FrameEvents | None,
    ) -> None:
        rr = self.rr
        self.log(
            "world/colour/image/detections",
            rr.Boxes2D(
                array=_xywh([d.box2d for d in detections]),
                array_format=rr.Box2DFormat.XYWH,
                labels=[f"{d.confidence:.2f}" for d in detections],
                colors=[_rgb(GREY)] * len(detections),
            ),
        )
        fp = set(events.false_positives) if events is not None else set()
        switched = {m.track_id for m in events.matches if m.id_switch} if events else set()
        boxed = [t for t in tracks if t.box2d is not None]
        labels = []
        for t in boxed:
            text = f"id {t.track_id}" + (" occl" if t.visibility is Visibility.OCCLUDED else "")
            text += " FP" if t.track_id in fp else ""
            text += " SW" if t.track_id in switched else ""
            labels.append(text)
        self.log(
            "world/colour/image/tracks",
            rr.Boxes2D(
                array=_xywh([t.box2d for t in boxed if t.box2d is not None]),
                array_format=rr.Box2DFormat.XYWH,
                labels=labels,
                colors=[_rgb(self.track_colour(t.track_id)) for t in boxed],
                class_ids=[t.track_id for t in boxed],
            ),
        )
        missed = set(events.misses) if events is not None else set()
        boxes = [o for o in gt if o.box2d is not None]
        gt_labels = []
        for o in boxes:
            tag = "miss" if o.object_id in missed else ("ign" if o.ignore else "gt")
            gt_labels.append(f"{tag} {o.object_id}" + (" occl" if o.visibility < 1.0 else ""))
        self.log(
            "world/colour/image/ground_truth",
            rr.Boxes2D(
                array=_xywh([o.box2d for o in boxes if o.box2d is not None]),
                array_format=rr.Box2DFormat.XYWH,
                labels=gt_labels,
                colors=[
                    _rgb(self.miss_colour if o.object_id in missed else self.gt_colour)
                    for o in boxes
                ],
            ),
        )

    def _world(
        self,
        stamp_ns: int,
        detections: Sequence[Detection],
        tracks: Sequence[TrackOutput],
        gt: Sequence[GroundTruthObject],
        events: FrameEvents | None,
    ) -> None:
        rr = self.rr
        self.log(
            "world/detections",
            rr.Points3D(
                [list(d.position) for d in detections] or np.zeros((0, 3)),
                colors=[_rgb(GREY)] * len(detections),
                radii=0.05,
            ),
        )
        self.log(
            "world/tracks",
            rr.Points3D(
                [[t.x, t.y, t.height / 2.0] for t in tracks] or np.zeros((0, 3)),
                labels=[f"id {t.track_id}" for t in tracks],
                colors=[_rgb(self.track_colour(t.track_id)) for t in tracks],
                class_ids=[t.track_id for t in tracks],
                radii=0.12,
            ),
        )
        self.track_trails.add(stamp_ns, ((t.track_id, t.x, t.y) for t in tracks))
        strips, keys = self.track_trails.strips()
        self.log(
            "world/tracks/trails",
            rr.LineStrips3D(strips, colors=[_rgb(self.track_colour(k)) for k in keys], radii=0.03),
        )
        missed = set(events.misses) if events is not None else set()
        placed = [o for o in gt if o.world_xyz is not None]
        self.log(
            "world/ground_truth",
            rr.Points3D(
                [list(o.world_xyz) for o in placed if o.world_xyz is not None] or np.zeros((0, 3)),
                labels=[f"gt {o.object_id}" for o in placed],
                colors=[
                    _rgb(self.miss_colour if o.object_id in missed else self.gt_colour)
                    for o in placed
                ],
                radii=0.08,
            ),
        )
        self.gt_trails.add(
            stamp_ns,
            ((o.object_id, o.world_xyz[0], o.world_xyz[1]) for o in placed if o.world_xyz),
        )
        strips, keys = self.gt_trails.strips()
        self.log(
            "world/ground_truth/trails",
            rr.LineStrips3D(strips, colors=[_rgb(self.gt_colour)] * len(keys), radii=0.02),
        )

    def _errors(self, events: FrameEvents | None) -> None:
        if events is None:
            return
        rr = self.rr
        switches = sum(m.id_switch for m in events.matches)
        self.log("errors/fp", rr.Scalars(float(len(events.false_positives))))
        self.log("errors/fn", rr.Scalars(float(len(events.misses))))
        self.log("errors/id_switches", rr.Scalars(float(switches)))
        text = error_text(events)
        if text is not None:
            level = rr.TextLogLevel.ERROR if switches else rr.TextLogLevel.WARN
            self.log("events", rr.TextLog(text, level=level))

    def finish(self) -> None:
        if len(self.path) > 1:
            self.log(
                "world/robot/path",
                self.rr.LineStrips3D([[list(p) for p in self.path]], radii=0.02),
                static=True,
            )


def recording_id(view: RunView) -> str:
    """A recording id that names the same run the same way."""
    first = view.stamps_ns[0] if view.stamps_ns else 0
    return str(uuid.uuid5(uuid.NAMESPACE_URL, f"rgbd-eval:{view.name}:{view.method}:{first}"))


def log_run(
    stream: rr.RecordingStream,
    view: RunView,
    frames: Iterable[Frame],
    progress: Progress | None = None,
) -> int:
    """Log ``view`` with the recording's ``frames`` into ``stream``; the frames logged."""
    rr = require_rerun()
    logger = _Logger(rr, stream, view)
    logger.start()
    total = len(view.tracks)
    done = 0
    for frame in frames:
        if frame.index >= total:
            break
        if frame.stamp_ns != view.stamps_ns[frame.index]:
            raise InputError(
                view.recording,
                f"frame {frame.index} is not the one the run read (its stamp changed)",
            )
        logger.frame(frame)
        done += 1
        if progress is not None:
            progress(done, total)
    logger.finish()
    if done != total:
        raise InputError(
            view.recording, f"the recording gave {done} frames on re-reading, the run had {total}"
        )
    return done


class RrdOutput:
    """A ``.rrd`` a command writes: checked before the work (the SDK installed, the path
    one it may write), written beside the target under a staging name, then published."""

    def __init__(self, path: Path, owner: str, inputs: Iterable[Path] = ()) -> None:
        from rgbd_eval.outdir import check_output_file, staging_name

        require_rerun()
        self.path = Path(path)
        self.owner = owner
        if self.path.suffix != ".rrd":  # the viewer loads Rerun recordings by this suffix
            raise OutputError(self.path, "name a .rrd file (Rerun opens recordings by suffix)")
        check_output_file(self.path, owner, inputs)
        self.staging = self.path.with_name(staging_name(self.path.name))

    def write(
        self, run: SequenceResult | RunView, config: RunConfig, progress: Progress | None = None
    ) -> None:
        """Write the ``.rrd`` of ``run`` (a sequence just run, or a view of a finished one)."""
        from rgbd_eval.outdir import publish_file

        view = run if isinstance(run, RunView) else view_of_result(run, config)
        try:
            write_rrd(self.staging, view, config, progress)
            publish_file(self.staging, self.path, self.owner)
        finally:
            self.staging.unlink(missing_ok=True)


def blueprint() -> Any:
    """The viewer's layout: the 3D world beside the colour image with its boxes, the depth
    image, the error counts over time and the error lines."""
    import rerun.blueprint as rrb

    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(origin="world", name="world"),
            rrb.Vertical(
                rrb.Spatial2DView(origin="world/colour/image", name="colour"),
                rrb.Spatial2DView(origin="world/depth/image", name="depth"),
                rrb.TimeSeriesView(origin="errors", name="errors"),
                rrb.TextLogView(origin="events", name="events"),
            ),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


def write_rrd(
    path: Path, view: RunView, config: RunConfig, progress: Progress | None = None
) -> None:
    """Write ``view`` as a Rerun recording file at ``path`` (re-reading the recording)."""
    from rgbd_eval.pipeline import open_for

    rr = require_rerun()
    stream = rr.RecordingStream("rgbd-eval", recording_id=recording_id(view))
    stream.set_log_time_enabled(False)
    try:
        stream.save(str(path), default_blueprint=blueprint())
    except (OSError, RuntimeError, ValueError) as err:
        raise OutputError(path, f"cannot write ({err})") from err
    try:
        stream.send_recording_name(f"{view.name} ({view.method})")
        log_run(stream, view, open_for(view.recording, config).frames(), progress)
    finally:  # the file is complete (or, after an error, the SDK lets go of it)
        stream.flush()
        stream.disconnect()
