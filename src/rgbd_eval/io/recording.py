"""Open a recording and stream synchronised :class:`~rgbd_eval.types.Frame` objects.

Supported containers: ROS1 ``.bag`` (v2.0; none/lz4/bz2 chunks), ROS2 bag folders
(sqlite3 or mcap storage), lone ``.mcap`` / ``.db3`` files, through
:mod:`rgbd_eval.io.source` (``mcap.reader`` for lone .mcap, rosbags' AnyReader otherwise).

Reading takes two passes, so memory stays flat in the sequence length:

1. *Index pass* (:func:`open_recording`): the topic of each stream role is chosen
   (:mod:`rgbd_eval.io.streams`: colour, depth, depth_2, ..., thermal, left, right, by
   ``io.topics`` or, where unambiguous, by message type); the small messages (CameraInfo,
   odometry, tf, ground truth) are decoded and of the image topics only the header stamps
   are parsed from the raw bytes (:mod:`rgbd_eval.io.index`). Every stream is paired with
   the reference stream (:mod:`rgbd_eval.io.sync`), which gives the frames, and each
   frame's camera poses come from the tf buffer.
2. *Frame pass* (:meth:`Recording.frames`): image messages are decoded
   (:mod:`rgbd_eval.io.decode`) only when they belong to a frame, and each frame is
   yielded as soon as all its streams have been read.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import IoConfig
from rgbd_eval.errors import DecodeError, GroundTruthError, InputError, SyncError, TransformError
from rgbd_eval.files import check_input
from rgbd_eval.io import groundtruth, integrity, validate
from rgbd_eval.io.decode import NOT_DECODED, camera_models, decode_image
from rgbd_eval.io.index import MessageIndex, container_kind, index_pass
from rgbd_eval.io.integrity import SkippedMessages
from rgbd_eval.io.source import READ_ERRORS, TopicConnection, open_source
from rgbd_eval.io.streams import (
    RGBD_STREAMS,
    SelectedTopics,
    TopicSummary,
    first_images,
    select_topics,
)
from rgbd_eval.io.sync import StreamSync, SyncProblem, SyncStats, first_non_increasing, pair_streams
from rgbd_eval.io.tf import TfBuffer, TransformLookupError
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Frame, Pose, Stream


@dataclass(frozen=True)
class RecordingInfo:
    """What :func:`open_recording` found out about a recording."""

    path: str
    container: str
    duration_s: float
    topics: tuple[TopicSummary, ...]
    selected: SelectedTopics
    sync: SyncStats
    cameras: Mapping[str, CameraModel]
    world_frame: str
    camera_frame: str
    tf_chain: tuple[str, ...]
    has_odometry: bool
    num_frames: int
    warnings: tuple[str, ...] = field(default_factory=tuple)
    #: Damaged messages skipped per topic (:mod:`rgbd_eval.io.integrity`).
    skipped: tuple[SkippedMessages, ...] = field(default_factory=tuple)
    #: Where a synthetic recording came from (:mod:`rgbd_eval.io.provenance`); None otherwise.
    provenance: Mapping[str, Any] | None = None

    @property
    def rgb_camera(self) -> CameraModel | None:
        return self.cameras.get("colour")

    @property
    def depth_camera(self) -> CameraModel | None:
        return self.cameras.get("depth")


@dataclass(frozen=True)
class _FramePlan:
    """One frame to decode: its stamp, each role's message index, each role's pose."""

    stamp_ns: int
    messages: Mapping[str, int]
    stamps: Mapping[str, int]
    poses: Mapping[str, Pose]


class Recording:
    """An opened recording: its :class:`RecordingInfo` and its frame stream."""

    def __init__(
        self,
        path: Path,
        io: IoConfig,
        info: RecordingInfo,
        plan: list[_FramePlan],
        depth_to_rgb: Pose,
        ground_truth: groundtruth.GroundTruth | None,
        log_ns: Mapping[str, NDArray[np.int64]] | None = None,
    ) -> None:
        self.path = path
        self.io = io
        self.info = info
        self._plan = plan
        self._depth_to_rgb = depth_to_rgb
        self.ground_truth_topic = ground_truth
        # Per stream topic, every message's log time in reading order (see frames()).
        self._log_ns = dict(log_ns or {})
        self.empty_depth_frames: list[int] = []  # indices, filled while frames() runs
        # Indices of depth frames dropped as implausible, and the first one's reason.
        self.implausible_depth_frames: list[int] = []
        self.implausible_depth_problem = ""

    @property
    def frame_warnings(self) -> tuple[str, ...]:
        """Warnings found while decoding (after :meth:`frames` ran): empty depth frames,
        and depth frames dropped as implausible."""
        total = len(self._plan)
        warnings = (
            validate.empty_depth_warning(self.empty_depth_frames, total),
            validate.implausible_depth_warning(
                self.implausible_depth_frames, total, self.implausible_depth_problem
            ),
        )
        return tuple(w for w in warnings if w is not None)

    def __len__(self) -> int:
        return len(self._plan)

    @property
    def frame_stamps(self) -> list[int]:
        return [p.stamp_ns for p in self._plan]

    def frames(
        self, start: int = 0, stop: int | None = None, skip: Collection[str] = ()
    ) -> Iterator[Frame]:
        """Decode and yield the synchronised frames in stamp order.

        ``start``/``stop`` choose frames ``start <= index < stop`` (the messages before
        are skipped undecoded); a frame is the same whichever range it is read in.
        The images of the roles in ``skip`` are not decoded: their streams keep camera,
        stamp and pose, with a 0x0 image of encoding ``none``.
        """
        stop = len(self._plan) if stop is None else stop
        if not 0 <= start <= stop <= len(self._plan):
            raise ValueError(f"frame range {start}:{stop} outside 0:{len(self._plan)}")
        if start == stop:
            self.empty_depth_frames = []
            self.implausible_depth_frames = []
            return
        sel = self.info.selected.streams
        by_topic = {topic: role for role, topic in sel.items()}
        span = range(start, stop)
        wanted = {role: {self._plan[k].messages[role]: k for k in span} for role in sel}
        ready: dict[int, dict[str, Any]] = {}
        start_ns, counters = self._resume_at(
            {topic: min(wanted[role]) for role, topic in sel.items()}
        )
        next_k = start
        self.empty_depth_frames = []
        self.implausible_depth_frames = []
        try:
            with open_source(self.path) as src:
                msgtypes = {t: src.topics[t].msgtype for t in sel.values()}
                for topic, _, raw in src.messages(set(sel.values()), start_ns):
                    n = counters[topic]
                    counters[topic] = n + 1
                    role = by_topic[topic]
                    k = wanted[role].get(n)
                    if k is None:
                        continue
                    if role in skip:
                        decoded: tuple[Any, str] = (NOT_DECODED, "none")
                    else:
                        msg = src.deserialize(raw, msgtypes[topic])
                        decoded = decode_image(self.path, msg, topic, role, self.info.cameras[role])
                        if role == "depth":
                            decoded = self._check_depth(decoded, k)
                    ready.setdefault(k, {})[role] = decoded
                    while len(ready.get(next_k, ())) == len(sel):
                        yield self._frame(next_k, ready.pop(next_k))
                        next_k += 1
                    if next_k == stop:
                        break
        except READ_ERRORS as err:
            raise InputError(self.path, f"read failed after {next_k} frames: {err}") from err
        if next_k != stop:
            raise InputError(
                self.path, f"recording ended after {next_k} of {len(self._plan)} indexed frames"
            )
        unusable = len(self.empty_depth_frames) + len(self.implausible_depth_frames)
        if next_k and unusable == len(self._plan):
            raise self.no_depth_error()

    def _frame(self, k: int, images: Mapping[str, tuple[Any, str]]) -> Frame:
        """Frame ``k`` of the plan with its decoded ``images`` (role -> image, encoding)."""
        info = self.info
        sel = info.selected.streams
        primary = "depth" if "depth" in sel else next(iter(sel))
        plan = self._plan[k]
        streams = {
            r: Stream(images[r][0], images[r][1], info.cameras[r], plan.stamps[r], plan.poses[r])
            for r in sel
        }
        return Frame(
            index=k,
            stamp_ns=plan.stamp_ns,
            streams=streams,
            depth_to_rgb=self._depth_to_rgb,
            camera_pose=plan.poses[primary],
            world_frame=info.world_frame,
            has_odometry=info.has_odometry,
        )

    def _check_depth(self, decoded: tuple[Any, str], k: int) -> tuple[Any, str]:
        """The decoded depth of frame ``k``, noted when empty; all NaN (dropped, noted) when
        implausible."""
        depth, encoding = decoded
        problem = validate.implausible_depth(depth)
        if problem is not None:
            if not self.implausible_depth_frames:
                self.implausible_depth_problem = problem
            self.implausible_depth_frames.append(k)
            return np.full_like(depth, np.nan), encoding
        if validate.depth_is_empty(depth):
            self.empty_depth_frames.append(k)
        return decoded

    def _resume_at(self, first: Mapping[str, int]) -> tuple[int | None, dict[str, int]]:
        """Where to start reading for messages ``first[topic]`` on (positions among the
        topic's messages): a log time, and each topic's position of its first message from
        that time on.

        The earliest log time of those messages, so that a chunk late in a recording does
        not read (decompress) every message before it. From the start (None, all 0) when
        they are the first messages, or a topic's log times are unknown or out of order.
        """
        from_start: tuple[int | None, dict[str, int]] = (None, dict.fromkeys(first, 0))
        times: dict[str, NDArray[np.int64]] = {}
        for topic, k in first.items():
            t = self._log_ns.get(topic)
            if t is None or len(t) <= k or bool(np.any(np.diff(t) < 0)):
                return from_start
            times[topic] = t
        if not any(first.values()):
            return from_start
        start = min(int(times[topic][k]) for topic, k in first.items())
        return start, {
            topic: int(np.searchsorted(t, start, side="left")) for topic, t in times.items()
        }

    def no_depth_error(self, implausible: str | None = None) -> DecodeError:
        """The error of a recording none of whose depth frames holds a valid (plausible)
        pixel; ``implausible``: why a frame was dropped, when known from another pass."""
        topic = self.info.selected.streams["depth"]
        problem = implausible or (
            self.implausible_depth_problem if self.implausible_depth_frames else None
        )
        if problem is not None:
            return DecodeError(
                self.path, f"no depth frame holds plausible depth ({problem})", topic
            )
        return DecodeError(self.path, "no depth frame holds a valid pixel", topic)


# ----------------------------------------------------------------------------- opening


def open_recording(
    path: Path | str,
    io: IoConfig | None = None,
    streams: Sequence[StreamSpec] = RGBD_STREAMS,
    *,
    unpaired_ok: bool = False,
) -> Recording:
    """Index a recording for ``streams`` (see the module docstring).

    The first stream present is the reference: frames carry its stamps, and every
    other stream is paired to it by nearest header stamp within ``io.max_sync_gap_ms``.
    Raises :class:`InputError` subclasses. A stream that does not pair at all is a
    :class:`SyncError`, or with ``unpaired_ok`` a recording of no frames whose
    ``info.sync.problems`` say why (what ``inspect`` shows).
    """
    path = Path(path)
    io = io or IoConfig()
    if not path.exists():
        raise InputError(path, "no such file or folder")
    check_input(path, lambda m: InputError(path, m), "recording", allow_dir=True)
    kind = container_kind(path)
    warnings: list[str] = []
    read = _read(path, io, streams, warnings)
    selected, index = read.selected, read.index
    cameras = camera_models(path, selected, index, read.first, warnings)
    _skip_wrong_sizes(index, selected, cameras)
    chosen = selected.streams
    stamps, ordinals = _stream_stamps(path, chosen, index)
    skipped = index.skips.summary(index.totals)
    if (skip_note := integrity.skipped_warning(skipped)) is not None:
        warnings.append(skip_note)
    partner, stream_sync, problems = pair_streams(path, io, chosen, stamps, unpaired_ok)
    reference = next(iter(chosen))
    primary = "depth" if "depth" in chosen else reference
    camera_frame = cameras[primary].frame_id or chosen[primary]
    odom_topic = selected.odometry
    world_frame, has_odometry, chain = _world_chain(path, io, index, camera_frame, odom_topic)
    depth_to_rgb, extrinsics = _camera_offsets(index.tf, cameras, primary, warnings)
    frame_pose = _FramePoses(
        index.tf, world_frame, camera_frame, has_odometry, primary, extrinsics, io
    )
    plan, no_pose = _plan_frames(stamps, ordinals, partner, reference, frame_pose)
    if not plan and partner and not problems and all(partner.values()) and not no_pose:
        problem = SyncProblem("no frame has every stream within the sync gap")
        if not unpaired_ok:
            raise SyncError(path, problem.message)
        problems.append(problem)
    if not plan and not problems:
        if skipped:
            raise DecodeError(path, f"no usable frame left: {skip_note}")
        raise TransformError(path, f"no frame has a pose from {world_frame!r} to {camera_frame!r}")
    if no_pose:
        warnings.append(
            f"{no_pose} frames dropped: no pose within {io.max_pose_extrapolation_ms} ms"
        )
    if not has_odometry:
        warnings.append("no odometry: evaluated in the camera frame (x forward, y left, z up)")
    gt = _ground_truth(path, selected.ground_truth, index)
    sync = _sync_stats(io, chosen, stamps[reference], stream_sync, plan, no_pose, problems)
    if dropped := [f"{s.dropped} {s.role}" for s in sync.streams if s.dropped]:
        warnings.append(f"unpaired messages dropped: {', '.join(dropped)}")
    info = RecordingInfo(
        path=str(path),
        container=kind,
        duration_s=read.duration_s,
        topics=_topic_summaries(read.conns, index, read.duration_s),
        selected=selected,
        sync=sync,
        cameras=cameras,
        world_frame=world_frame,
        camera_frame=camera_frame,
        tf_chain=tuple(chain),
        has_odometry=has_odometry,
        num_frames=len(plan),
        warnings=tuple(warnings),
        skipped=skipped,
        provenance=index.provenance,
    )
    log_ns = {
        topic: np.asarray(index.image_log_ns.get(topic, []), dtype=np.int64)
        for topic in selected.streams.values()
    }
    return Recording(path, io, info, plan, depth_to_rgb, gt, log_ns)


@dataclass(frozen=True)
class _Read:
    """What the index pass read: the topics, each image topic's first message, the topics
    chosen and the index."""

    duration_s: float
    conns: list[TopicConnection]
    first: dict[str, Any]
    selected: SelectedTopics
    index: MessageIndex


def _read(path: Path, io: IoConfig, streams: Sequence[StreamSpec], warnings: list[str]) -> _Read:
    """Choose the streams' topics and run the index pass (read errors: InputError)."""
    try:
        with open_source(path) as src:
            conns = list(src.topics.values())
            if not conns or all(c.count == 0 for c in conns):
                raise InputError(path, "recording is empty (no messages)")
            duration_s = max(0.0, (src.end_ns - src.start_ns) / 1e9)
            first, undecodable = first_images(src, conns, warnings)
            selected = select_topics(path, io, streams, conns, first, undecodable)
            index = index_pass(path, src, selected, io)
    except READ_ERRORS as err:
        raise InputError(path, f"cannot read recording: {err}") from err
    return _Read(duration_s, conns, first, selected, index)


def _topic_summaries(
    conns: Sequence[TopicConnection], index: MessageIndex, duration_s: float
) -> tuple[TopicSummary, ...]:
    """Every topic with its type, count and rate (from the stamps read, else the count)."""

    def rate(topic: str, count: int) -> float | None:
        if topic.endswith("tf_static"):
            return None
        seen = index.stamps.get(topic) or index.log_stamps.get(topic)
        if seen is not None:
            return _rate(seen)
        return count / duration_s if duration_s > 0 else None

    by_topic = {c.topic: c for c in conns}
    return tuple(
        TopicSummary(c.topic, c.msgtype, c.count, rate(c.topic, c.count))
        for c in sorted(by_topic.values(), key=lambda c: c.topic)
    )


def _stream_stamps(
    path: Path, chosen: Mapping[str, str], index: MessageIndex
) -> tuple[dict[str, NDArray[np.int64]], dict[str, NDArray[np.int64]]]:
    """Per role, the header stamps of its usable messages and their positions on the topic
    (a DecodeError when every message is damaged, a SyncError when stamps go back)."""
    stamps = {}
    ordinals: dict[str, NDArray[np.int64]] = {}
    for role, topic in chosen.items():
        arr = np.asarray(index.stamps.get(topic, []), dtype=np.int64)
        ordinals[role] = np.asarray(index.ordinals.get(topic, []), dtype=np.int64)
        if arr.size == 0 and topic in index.skips.counts:
            raise DecodeError(
                path,
                f"no usable message: all {index.skips.counts[topic]} are damaged "
                f"({index.skips.first[topic]})",
                topic,
            )
        bad = first_non_increasing(arr)
        if bad is not None:
            raise SyncError(
                path,
                f"header stamps are not increasing at message {int(ordinals[role][bad])} "
                f"({int(arr[bad - 1])} then {int(arr[bad])} ns)",
                topic,
            )
        stamps[role] = arr
    return stamps, ordinals


def _camera_offsets(
    tf: TfBuffer, cameras: Mapping[str, CameraModel], primary: str, warnings: list[str]
) -> tuple[Pose, dict[str, Pose]]:
    """The depth camera's pose in the colour camera's frame (``Frame.depth_to_rgb``; identity
    without both), and each other camera's pose relative to the primary one (static
    extrinsics from tf)."""
    colour, depth = cameras.get("colour"), cameras.get("depth")
    depth_to_rgb = (
        _depth_to_rgb(tf, colour, depth, warnings)
        if colour is not None and depth is not None
        else Pose.identity()
    )
    extrinsics: dict[str, Pose] = {}
    for role, cam in cameras.items():
        if role != primary:
            extrinsics[role] = _extrinsics(tf, cameras[primary], cam, role, warnings)
    return depth_to_rgb, extrinsics


@dataclass(frozen=True)
class _FramePoses:
    """What places a frame's cameras in the world: the tf buffer and the frames' names."""

    tf: TfBuffer
    world_frame: str
    camera_frame: str
    has_odometry: bool
    primary: str
    extrinsics: Mapping[str, Pose]
    io: IoConfig

    def at(self, stamp: int) -> dict[str, Pose] | None:
        """Each camera's world pose at ``stamp`` (None: no pose within the extrapolation)."""
        if self.has_odometry:
            tol = int(self.io.max_pose_extrapolation_ms * 1e6)
            try:
                pose = self.tf.lookup(self.world_frame, self.camera_frame, stamp, tol)
            except TransformLookupError:
                return None
        else:
            pose = OPTICAL_TO_BODY
        poses = {self.primary: pose}
        for role, ext in self.extrinsics.items():
            poses[role] = pose.compose(ext)
        return poses


def _plan_frames(
    stamps: Mapping[str, NDArray[np.int64]],
    ordinals: Mapping[str, NDArray[np.int64]],
    partner: Mapping[str, Mapping[int, int]],
    reference: str,
    frame_poses: _FramePoses,
) -> tuple[list[_FramePlan], int]:
    """A frame per reference message paired with every stream and posed; and how many
    paired messages had no pose."""
    plan: list[_FramePlan] = []
    no_pose = 0
    ref_stamps = stamps[reference]
    for r in range(ref_stamps.size):
        if not all(r in partner[role] for role in partner):
            continue
        stamp = int(ref_stamps[r])
        kept = {reference: r, **{role: partner[role][r] for role in partner}}
        poses = frame_poses.at(stamp)
        if poses is None:
            no_pose += 1
            continue
        plan.append(
            _FramePlan(
                stamp,
                {role: int(ordinals[role][i]) for role, i in kept.items()},  # topic positions
                {role: int(stamps[role][i]) for role, i in kept.items()},
                poses,
            )
        )
    return plan, no_pose


def _ground_truth(
    path: Path, gt_topic: str | None, index: MessageIndex
) -> groundtruth.GroundTruth | None:
    """The ground truth recorded on ``gt_topic`` (a GroundTruthError, exit 5, when bad)."""
    if gt_topic is None:
        return None
    try:
        return groundtruth.from_objects(f"{path}:{gt_topic}", index.gt_objects, index.gt_frames)
    except GroundTruthError as err:  # bad ground truth (exit 5), not a bad recording
        raise GroundTruthError(path, err.message, gt_topic) from err


def _sync_stats(
    io: IoConfig,
    chosen: Mapping[str, str],
    ref_stamps: NDArray[np.int64],
    stream_sync: Sequence[StreamSync],
    plan: Sequence[_FramePlan],
    no_pose: int,
    problems: Sequence[SyncProblem],
) -> SyncStats:
    """How the streams paired, the reference stream first."""
    reference = next(iter(chosen))
    ref_sync = StreamSync(
        reference,
        chosen[reference],
        int(ref_stamps.size),
        int(ref_stamps.size) - len(plan) - no_pose,
        0.0,
        0.0,
    )
    return SyncStats(
        reference=reference,
        streams=(ref_sync, *stream_sync),
        frames=len(plan),
        no_pose_dropped=no_pose,
        max_gap_ms=io.max_sync_gap_ms,
        problems=tuple(problems),
    )


def _skip_wrong_sizes(
    index: MessageIndex, sel: SelectedTopics, cameras: Mapping[str, CameraModel]
) -> None:
    """Skip raw image messages whose size is not their camera's (CameraInfo) size."""
    for role, topic in sel.streams.items():
        sizes = index.sizes.get(topic)
        if not sizes:
            continue
        cam = cameras[role]
        keep = [k for k, size in enumerate(sizes) if size == (cam.width, cam.height)]
        if len(keep) == len(sizes):
            continue
        for w, h in sizes:
            if (w, h) != (cam.width, cam.height):
                index.skips.add(
                    topic,
                    f"image is {w}x{h} but its CameraInfo ({sel.infos.get(role)}) says "
                    f"{cam.width}x{cam.height}",
                )
        index.stamps[topic] = [index.stamps[topic][k] for k in keep]
        index.ordinals[topic] = [index.ordinals[topic][k] for k in keep]
        index.sizes[topic] = [sizes[k] for k in keep]


def _rate(stamps: list[int] | None) -> float | None:
    if not stamps or len(stamps) < 2:
        return None
    span = (max(stamps) - min(stamps)) / 1e9
    return (len(stamps) - 1) / span if span > 0 else None


def _world_chain(
    path: Path, io: IoConfig, index: MessageIndex, camera_frame: str, odom_topic: str | None
) -> tuple[str, bool, list[str]]:
    """The world frame, whether the camera moves in it (odometry or a static rig in tf), and
    the tf chain from it to the camera; a TransformError where the chain jumps."""
    world_frame, has_odometry, chain = _world(path, io, index, camera_frame)
    jump = index.tf.jump_problem(chain) if has_odometry else None
    if jump is not None:
        child, jump_message = jump
        by_odometry = index.odom_frames is not None and index.odom_frames[1] == child
        raise TransformError(path, jump_message, odom_topic if by_odometry else None)
    return world_frame, has_odometry, chain


def _world(
    path: Path, io: IoConfig, index: MessageIndex, camera_frame: str
) -> tuple[str, bool, list[str]]:
    tf = index.tf
    if io.world_frame is not None:
        world = io.world_frame.lstrip("/")
    elif index.odom_frames is not None:
        world = index.odom_frames[0]
    else:
        world = next((f for f in ("map", "odom", "world") if f in tf.frames), "")
    static_world = bool(world) and not tf.has_dynamic and world in tf.frames
    if static_world:  # a static rig: cameras placed in the world by /tf_static alone
        try:
            return world, True, tf.chain(world, camera_frame)
        except TransformLookupError:
            static_world = False
    if not world or not tf.has_dynamic:
        if io.world_frame is not None:
            raise TransformError(
                path, f"world frame {world!r} given but the recording has no odometry or /tf"
            )
        return camera_frame, False, [camera_frame]
    try:
        chain = tf.chain(world, camera_frame)
    except TransformLookupError as err:
        raise TransformError(path, f"broken tf chain: {err}") from err
    return world, True, chain


def _extrinsics(
    tf: TfBuffer, primary: CameraModel, camera: CameraModel, role: str, warnings: list[str]
) -> Pose:
    """``primary_optical_T_camera_optical`` from static tf (identity when one frame)."""
    if camera.frame_id == primary.frame_id:
        return Pose.identity()
    try:
        return tf.lookup(primary.frame_id, camera.frame_id, 0, tolerance_ns=2**62)
    except TransformLookupError:
        warnings.append(
            f"no tf between {primary.frame_id!r} and {camera.frame_id!r} ({role}): "
            "the two cameras are assumed to share one optical frame"
        )
        return Pose.identity()


def _depth_to_rgb(tf: TfBuffer, rgb: CameraModel, depth: CameraModel, warnings: list[str]) -> Pose:
    if rgb.frame_id == depth.frame_id:
        return Pose.identity()
    try:
        return tf.lookup(rgb.frame_id, depth.frame_id, 0, tolerance_ns=2**62)
    except TransformLookupError:
        warnings.append(
            f"no tf between {depth.frame_id!r} and {rgb.frame_id!r}: depth assumed registered to RGB"
        )
        return Pose.identity()
