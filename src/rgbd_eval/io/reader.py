"""Open a recording and stream synchronised :class:`~rgbd_eval.types.Frame` objects.

Supported containers: ROS1 ``.bag`` (v2.0; none/lz4/bz2 chunks), ROS2 bag folders
(sqlite3 or mcap storage), lone ``.mcap`` / ``.db3`` files, through
:mod:`rgbd_eval.io.source` (``mcap.reader`` for lone .mcap, rosbags' AnyReader otherwise).

Reading takes two passes, so memory stays flat in the sequence length:

1. *Index pass* (:func:`open_recording`): the small messages (CameraInfo,
   odometry, tf, ground truth) are decoded; of the image topics only the header
   stamps are parsed from the raw bytes. This gives topic selection, the
   RGB/depth pairing, the tf buffer and every frame's camera pose.
2. *Frame pass* (:meth:`Recording.frames`): image messages are decoded only
   when they belong to a pair, and each frame is yielded as soon as both halves
   have been read.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import IoConfig
from rgbd_eval.errors import (
    DecodeError,
    GroundTruthError,
    InputError,
    SyncError,
    TopicError,
    TransformError,
)
from rgbd_eval.files import check_input
from rgbd_eval.io import groundtruth, images, validate
from rgbd_eval.io.messages import (
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    GT_ARRAY_TYPE,
    IMAGE_TYPE,
    ODOMETRY_TYPE,
    TF_TYPE,
)
from rgbd_eval.io.source import READ_ERRORS, MessageSource, open_source
from rgbd_eval.io.sync import Pairing, first_non_increasing, pair_nearest
from rgbd_eval.io.tf import TfBuffer, TransformLookupError
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Frame, Pose

_IMAGE_TYPES = (IMAGE_TYPE, COMPRESSED_IMAGE_TYPE)


@dataclass(frozen=True)
class TopicSummary:
    """One topic of the recording."""

    name: str
    msgtype: str
    count: int
    rate_hz: float | None = None


@dataclass(frozen=True)
class SelectedTopics:
    """The topics the reader uses."""

    rgb: str
    depth: str
    rgb_info: str | None
    depth_info: str | None
    odometry: str | None
    tf: tuple[str, ...]
    ground_truth: str | None


@dataclass(frozen=True)
class SyncStats:
    """How well RGB and depth pair up."""

    rgb_messages: int
    depth_messages: int
    paired: int
    rgb_dropped: int
    depth_dropped: int
    no_pose_dropped: int
    worst_gap_ms: float
    mean_gap_ms: float
    max_gap_ms: float


@dataclass(frozen=True)
class RecordingInfo:
    """What :func:`open_recording` found out about a recording."""

    path: str
    container: str
    duration_s: float
    topics: tuple[TopicSummary, ...]
    selected: SelectedTopics
    sync: SyncStats
    rgb_camera: CameraModel
    depth_camera: CameraModel
    world_frame: str
    camera_frame: str
    tf_chain: tuple[str, ...]
    has_odometry: bool
    num_frames: int
    warnings: tuple[str, ...] = field(default_factory=tuple)


def container_kind(path: Path) -> str:
    """A short name of the container at ``path`` (raises InputError when unsupported)."""
    if path.is_dir():
        if not (path / "metadata.yaml").exists():
            raise InputError(path, "folder is not a ROS2 bag (no metadata.yaml)")
        return "ros2"
    if path.suffix == ".bag":
        return "ros1"
    if path.suffix in (".mcap", ".db3"):
        return path.suffix[1:]
    raise InputError(
        path, "unsupported file type (expected .bag, .mcap, .db3 or a ROS2 bag folder)"
    )


def _header_stamp(raw: bytes | memoryview, ros1: bool) -> int:
    """Header stamp of a message whose first field is ``std_msgs/Header``, from the raw bytes."""
    if ros1:  # uint32 seq, uint32 sec, uint32 nsec
        sec, nsec = struct.unpack_from("<II", raw, 4)
    else:  # 4-byte CDR encapsulation header, then int32 sec, uint32 nanosec
        endian = "<" if raw[1] & 1 else ">"
        sec, nsec = struct.unpack_from(endian + "iI", raw, 4)
    return int(sec) * 1_000_000_000 + int(nsec)


def _stamp_of(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _pose_of(translation: Any, rotation: Any) -> Pose:
    return Pose(
        (float(translation.x), float(translation.y), float(translation.z)),
        (float(rotation.x), float(rotation.y), float(rotation.z), float(rotation.w)),
    )


def camera_model_from_info(msg: Any) -> CameraModel:
    """``sensor_msgs/CameraInfo`` (ROS1 ``K``/``D`` or ROS2 ``k``/``d``) -> CameraModel."""
    K = np.asarray(msg.K if hasattr(msg, "K") else msg.k, dtype=np.float64).reshape(3, 3)
    D = np.asarray(msg.D if hasattr(msg, "D") else msg.d, dtype=np.float64)
    return CameraModel(
        width=int(msg.width),
        height=int(msg.height),
        fx=float(K[0, 0]),
        fy=float(K[1, 1]),
        cx=float(K[0, 2]),
        cy=float(K[1, 2]),
        distortion=tuple(float(v) for v in D),
        frame_id=msg.header.frame_id.lstrip("/"),
    )


def _namespace(topic: str) -> str:
    parts = topic.rstrip("/").split("/")
    if parts and parts[-1] in ("compressed", "compressedDepth"):
        parts = parts[:-1]
    return "/".join(parts[:-1])


@dataclass
class _Index:
    """Everything the index pass collects."""

    stamps: dict[str, list[int]] = field(default_factory=dict)
    log_stamps: dict[str, list[int]] = field(default_factory=dict)
    first_msgs: dict[str, Any] = field(default_factory=dict)
    tf: TfBuffer = field(default_factory=TfBuffer)
    odom_frames: tuple[str, str] | None = None
    gt_objects: list[Any] = field(default_factory=list)
    gt_messages: int = 0


class Recording:
    """An opened recording: its :class:`RecordingInfo` and its frame stream."""

    def __init__(
        self,
        path: Path,
        io: IoConfig,
        info: RecordingInfo,
        pairs: list[tuple[int, int, int]],
        poses: list[Pose],
        depth_to_rgb: Pose,
        ground_truth: groundtruth.GroundTruth | None,
    ) -> None:
        self.path = path
        self.io = io
        self.info = info
        self._pairs = pairs  # (frame stamp, rgb message index, depth message index)
        self._poses = poses
        self._depth_to_rgb = depth_to_rgb
        self.ground_truth_topic = ground_truth
        self.empty_depth_frames: list[int] = []  # indices, filled while frames() runs

    @property
    def frame_warnings(self) -> tuple[str, ...]:
        """Warnings found while decoding (after :meth:`frames` ran): empty depth frames."""
        warning = validate.empty_depth_warning(self.empty_depth_frames, len(self._pairs))
        return () if warning is None else (warning,)

    def __len__(self) -> int:
        return len(self._pairs)

    @property
    def frame_stamps(self) -> list[int]:
        return [p[0] for p in self._pairs]

    def frames(self) -> Iterator[Frame]:
        """Decode and yield the synchronised frames in stamp order."""
        sel = self.info.selected
        rgb_want = {r: k for k, (_, r, _) in enumerate(self._pairs)}
        depth_want = {d: k for k, (_, _, d) in enumerate(self._pairs)}
        rgb_ready: dict[int, NDArray[np.uint8]] = {}
        depth_ready: dict[int, NDArray[np.float32]] = {}
        counters = {sel.rgb: 0, sel.depth: 0}
        next_k = 0
        self.empty_depth_frames = []
        info = self.info
        try:
            with open_source(self.path) as src:
                msgtypes = {t: src.topics[t].msgtype for t in (sel.rgb, sel.depth)}
                for topic, _, raw in src.messages({sel.rgb, sel.depth}):
                    n = counters[topic]
                    counters[topic] = n + 1
                    is_rgb = topic == sel.rgb
                    k = (rgb_want if is_rgb else depth_want).get(n)
                    if k is None:
                        continue
                    msg = src.deserialize(raw, msgtypes[topic])
                    if is_rgb:
                        rgb_ready[k] = self._decode(msg, topic, info.rgb_camera, color=True)
                    else:
                        depth_ready[k] = self._decode(msg, topic, info.depth_camera, color=False)
                        if validate.depth_is_empty(depth_ready[k]):
                            self.empty_depth_frames.append(k)
                    while next_k in rgb_ready and next_k in depth_ready:
                        yield Frame(
                            index=next_k,
                            stamp_ns=self._pairs[next_k][0],
                            rgb=rgb_ready.pop(next_k),
                            depth=depth_ready.pop(next_k),
                            rgb_camera=info.rgb_camera,
                            depth_camera=info.depth_camera,
                            depth_to_rgb=self._depth_to_rgb,
                            camera_pose=self._poses[next_k],
                            world_frame=info.world_frame,
                            has_odometry=info.has_odometry,
                        )
                        next_k += 1
        except READ_ERRORS as err:
            raise InputError(self.path, f"read failed after {next_k} frames: {err}") from err
        if next_k != len(self._pairs):
            raise InputError(
                self.path, f"recording ended after {next_k} of {len(self._pairs)} indexed frames"
            )
        if next_k and len(self.empty_depth_frames) == next_k:
            raise DecodeError(self.path, "no depth frame holds a valid pixel", sel.depth)

    def _decode(self, msg: Any, topic: str, camera: CameraModel, color: bool) -> Any:
        try:
            img = images.decode_color(msg) if color else images.decode_depth(msg)
        except images.ImageFormatError as err:
            raise DecodeError(self.path, str(err), topic) from err
        if (problem := validate.image_size_problem(img)) is not None:
            raise DecodeError(self.path, problem, topic)
        if img.shape[:2] != (camera.height, camera.width):
            raise DecodeError(
                self.path,
                f"image is {img.shape[1]}x{img.shape[0]} but its CameraInfo says "
                f"{camera.width}x{camera.height}",
                topic,
            )
        return img


# ----------------------------------------------------------------------------- opening


def _choose(
    path: Path, role: str, override: str | None, candidates: list[str], flag: str, required: bool
) -> str | None:
    if override is not None:
        if override not in candidates:
            raise TopicError(
                path,
                f"{flag} {override!r} is not a {role} topic here (candidates: "
                f"{', '.join(candidates) or 'none'})",
                override,
            )
        return override
    if not candidates:
        if required:
            raise TopicError(path, f"no {role} topic found")
        return None
    if len(candidates) > 1:
        raise TopicError(
            path, f"several {role} topics: {', '.join(sorted(candidates))}; choose one with {flag}"
        )
    return candidates[0]


def _is_depth_message(msg: Any) -> bool:
    if hasattr(msg, "format"):
        return "compressedDepth" in str(msg.format)
    return str(msg.encoding) in images.DEPTH_ENCODINGS


def _info_for(image_topic: str, infos: list[str], override: str | None) -> str | None:
    if override is not None:
        return override
    ns = _namespace(image_topic)
    same = [t for t in infos if _namespace(t) == ns]
    return same[0] if len(same) == 1 else None


def open_recording(path: Path | str, io: IoConfig | None = None) -> Recording:
    """Index a recording (see the module docstring); raises :class:`InputError` subclasses."""
    path = Path(path)
    io = io or IoConfig()
    if not path.exists():
        raise InputError(path, "no such file or folder")
    check_input(path, lambda m: InputError(path, m), "recording", allow_dir=True)
    kind = container_kind(path)
    warnings: list[str] = []
    try:
        with open_source(path) as src:
            conns = list(src.topics.values())
            if not conns or all(c.count == 0 for c in conns):
                raise InputError(path, "recording is empty (no messages)")
            by_topic = {c.topic: c for c in conns}
            duration_s = max(0.0, (src.end_ns - src.start_ns) / 1e9)
            # Classify image topics by their first message.
            image_conns = [c for c in conns if c.msgtype in _IMAGE_TYPES and c.count > 0]
            first: dict[str, Any] = {}
            for conn in image_conns:
                for _, _, raw in src.messages({conn.topic}):
                    first[conn.topic] = src.deserialize(raw, conn.msgtype)
                    break
            depth_cands = [t for t, m in first.items() if _is_depth_message(m)]
            rgb_cands = [t for t, m in first.items() if not _is_depth_message(m)]
            rgb_topic = _choose(path, "RGB image", io.rgb_topic, rgb_cands, "--rgb-topic", True)
            depth_topic = _choose(
                path, "depth image", io.depth_topic, depth_cands, "--depth-topic", True
            )
            assert rgb_topic is not None and depth_topic is not None  # required=True
            infos = [c.topic for c in conns if c.msgtype == CAMERA_INFO_TYPE]
            rgb_info = _info_for(rgb_topic, infos, io.rgb_info_topic)
            depth_info = _info_for(depth_topic, infos, io.depth_info_topic)
            odoms = [c.topic for c in conns if c.msgtype == ODOMETRY_TYPE]
            odom_topic = _choose(path, "odometry", io.odom_topic, odoms, "--odom-topic", False)
            tf_topics = tuple(c.topic for c in conns if c.msgtype == TF_TYPE)
            gts = [c.topic for c in conns if c.msgtype == GT_ARRAY_TYPE]
            gt_topic = _choose(path, "ground-truth", io.gt_topic, gts, "--gt-topic", False)
            selected = SelectedTopics(
                rgb_topic, depth_topic, rgb_info, depth_info, odom_topic, tf_topics, gt_topic
            )
            index = _index_pass(path, src, selected)
    except READ_ERRORS as err:
        raise InputError(path, f"cannot read recording: {err}") from err

    def rate(topic: str, count: int) -> float | None:
        if topic.endswith("tf_static"):
            return None
        seen = index.stamps.get(topic) or index.log_stamps.get(topic)
        if seen is not None:
            return _rate(seen)
        return count / duration_s if duration_s > 0 else None

    topics = tuple(
        TopicSummary(c.topic, c.msgtype, c.count, rate(c.topic, c.count))
        for c in sorted(by_topic.values(), key=lambda c: c.topic)
    )
    rgb_camera = _camera(path, selected.rgb_info, index, first[rgb_topic], rgb_topic, warnings)
    depth_camera = _camera(
        path, selected.depth_info, index, first[depth_topic], depth_topic, warnings
    )

    stamps = {}
    for topic in (rgb_topic, depth_topic):
        arr = np.asarray(index.stamps.get(topic, []), dtype=np.int64)
        bad = first_non_increasing(arr)
        if bad is not None:
            raise SyncError(
                path,
                f"header stamps are not increasing at message {bad} "
                f"({int(arr[bad - 1])} then {int(arr[bad])} ns)",
                topic,
            )
        stamps[topic] = arr
    max_gap_ns = int(io.max_sync_gap_ms * 1e6)
    pairing: Pairing = pair_nearest(stamps[rgb_topic], stamps[depth_topic], max_gap_ns)
    if not pairing.pairs:
        raise SyncError(
            path,
            f"no RGB/depth pair within {io.max_sync_gap_ms} ms "
            f"({rgb_topic}: {stamps[rgb_topic].size} messages, {depth_topic}: {stamps[depth_topic].size})",
        )

    camera_frame = depth_camera.frame_id or depth_topic
    world_frame, has_odometry, chain = _world(path, io, index, camera_frame, odom_topic, warnings)
    depth_to_rgb = _depth_to_rgb(index.tf, rgb_camera, depth_camera, warnings)

    tol = int(io.max_pose_extrapolation_ms * 1e6)
    pairs: list[tuple[int, int, int]] = []
    poses: list[Pose] = []
    no_pose = 0
    for r, d in pairing.pairs:
        stamp = int(stamps[rgb_topic][r])
        if has_odometry:
            try:
                pose = index.tf.lookup(world_frame, camera_frame, stamp, tol)
            except TransformLookupError:
                no_pose += 1
                continue
        else:
            pose = OPTICAL_TO_BODY
        pairs.append((stamp, r, d))
        poses.append(pose)
    if not pairs:
        raise TransformError(path, f"no frame has a pose from {world_frame!r} to {camera_frame!r}")
    if no_pose:
        warnings.append(
            f"{no_pose} frames dropped: no pose within {io.max_pose_extrapolation_ms} ms"
        )
    if not has_odometry:
        warnings.append("no odometry: evaluated in the camera frame (x forward, y left, z up)")

    gt = None
    if gt_topic is not None:
        try:
            gt = groundtruth.from_objects(f"{path}:{gt_topic}", index.gt_objects)
        except GroundTruthError as err:
            raise InputError(path, str(err), gt_topic) from err

    sync = SyncStats(
        rgb_messages=int(stamps[rgb_topic].size),
        depth_messages=int(stamps[depth_topic].size),
        paired=len(pairing.pairs),
        rgb_dropped=pairing.rgb_unpaired,
        depth_dropped=pairing.depth_unpaired,
        no_pose_dropped=no_pose,
        worst_gap_ms=pairing.worst_gap_ns / 1e6,
        mean_gap_ms=pairing.mean_gap_ns / 1e6,
        max_gap_ms=io.max_sync_gap_ms,
    )
    if pairing.rgb_unpaired or pairing.depth_unpaired:
        warnings.append(
            f"unpaired messages dropped: {pairing.rgb_unpaired} RGB, {pairing.depth_unpaired} depth"
        )
    info = RecordingInfo(
        path=str(path),
        container=kind,
        duration_s=duration_s,
        topics=topics,
        selected=selected,
        sync=sync,
        rgb_camera=rgb_camera,
        depth_camera=depth_camera,
        world_frame=world_frame,
        camera_frame=camera_frame,
        tf_chain=tuple(chain),
        has_odometry=has_odometry,
        num_frames=len(pairs),
        warnings=tuple(warnings),
    )
    return Recording(path, io, info, pairs, poses, depth_to_rgb, gt)


def _rate(stamps: list[int] | None) -> float | None:
    if not stamps or len(stamps) < 2:
        return None
    span = (max(stamps) - min(stamps)) / 1e9
    return (len(stamps) - 1) / span if span > 0 else None


def _index_pass(path: Path, src: MessageSource, sel: SelectedTopics) -> _Index:
    index = _Index()
    small = {t for t in (sel.rgb_info, sel.depth_info, sel.odometry, sel.ground_truth) if t}
    small.update(sel.tf)
    wanted = small | {sel.rgb, sel.depth}
    for topic, log_ns, raw in src.messages(wanted):
        msgtype = src.topics[topic].msgtype
        if topic in (sel.rgb, sel.depth):
            index.stamps.setdefault(topic, []).append(_header_stamp(raw, src.ros1))
            continue
        index.log_stamps.setdefault(topic, []).append(log_ns)
        msg: Any = src.deserialize(raw, msgtype)
        if topic in (sel.rgb_info, sel.depth_info):
            index.first_msgs.setdefault(topic, msg)
        elif topic == sel.odometry:
            parent, child = msg.header.frame_id.lstrip("/"), msg.child_frame_id.lstrip("/")
            index.odom_frames = (parent, child)
            p = msg.pose.pose
            _add_tf(
                path,
                index.tf,
                parent,
                child,
                _stamp_of(msg),
                _pose_of(p.position, p.orientation),
                False,
                topic,
            )
        elif msgtype == TF_TYPE:
            static = topic.endswith("tf_static")
            for t in msg.transforms:
                tr = t.transform
                _add_tf(
                    path,
                    index.tf,
                    t.header.frame_id,
                    t.child_frame_id,
                    _stamp_of(t),
                    _pose_of(tr.translation, tr.rotation),
                    static,
                    topic,
                )
        elif topic == sel.ground_truth:
            frame = index.gt_messages
            index.gt_messages += 1
            index.gt_objects.extend(groundtruth.objects_from_message(msg, frame, _stamp_of(msg)))
    return index


def _add_tf(
    path: Path,
    tf: TfBuffer,
    parent: str,
    child: str,
    stamp: int,
    pose: Pose,
    static: bool,
    topic: str,
) -> None:
    try:
        tf.add(parent, child, stamp, pose, static)
    except TransformLookupError as err:
        raise TransformError(path, str(err), topic) from err


def _camera(
    path: Path, info_topic: str | None, index: _Index, first: Any, topic: str, warnings: list[str]
) -> CameraModel:
    msg = index.first_msgs.get(info_topic) if info_topic else None
    if msg is None:
        raise TopicError(
            path,
            "no CameraInfo for this image topic (set it with --rgb-info-topic/--depth-info-topic)",
            topic,
        )
    try:
        camera = camera_model_from_info(msg)
    except ValueError as err:
        raise DecodeError(path, f"bad CameraInfo: {err}", info_topic) from err
    if not hasattr(first, "format") and (int(first.width), int(first.height)) != (
        camera.width,
        camera.height,
    ):
        raise DecodeError(
            path,
            f"image is {first.width}x{first.height} but its CameraInfo ({info_topic}) says "
            f"{camera.width}x{camera.height}",
            topic,
        )
    if not camera.frame_id:
        camera = CameraModel(
            camera.width,
            camera.height,
            camera.fx,
            camera.fy,
            camera.cx,
            camera.cy,
            camera.distortion,
            first.header.frame_id.lstrip("/"),
        )
    return camera


def _world(
    path: Path,
    io: IoConfig,
    index: _Index,
    camera_frame: str,
    odom_topic: str | None,
    warnings: list[str],
) -> tuple[str, bool, list[str]]:
    tf = index.tf
    if io.world_frame is not None:
        world = io.world_frame.lstrip("/")
    elif index.odom_frames is not None:
        world = index.odom_frames[0]
    else:
        world = next((f for f in ("map", "odom", "world") if f in tf.frames), "")
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
