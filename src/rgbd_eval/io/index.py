"""Container access: what a recording holds, read in one pass over its messages.

The *index pass* decodes the small messages (CameraInfo, odometry, wheel speeds, tf,
ground truth, provenance); of the image topics it parses only the header stamps and
sizes. Damaged messages are skipped and counted (:mod:`rgbd_eval.io.integrity`), except
ground truth, which is never dropped silently.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rgbd_eval.config import IoConfig
from rgbd_eval.errors import DecodeError, InputError, TransformError
from rgbd_eval.io import groundtruth, integrity, provenance, wheels
from rgbd_eval.io.messages import TF_TYPE
from rgbd_eval.io.source import MESSAGE_ERRORS, MessageSource
from rgbd_eval.io.streams import SelectedTopics
from rgbd_eval.io.tf import TfBuffer, TransformLookupError
from rgbd_eval.types import Pose


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


def stamp_of(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def pose_of(translation: Any, rotation: Any) -> Pose:
    return Pose(
        (float(translation.x), float(translation.y), float(translation.z)),
        (float(rotation.x), float(rotation.y), float(rotation.z), float(rotation.w)),
    )


@dataclass
class MessageIndex:
    """Everything the index pass collects."""

    stamps: dict[str, list[int]] = field(default_factory=dict)
    #: Per image topic: the position among the topic's messages of each stamp kept.
    ordinals: dict[str, list[int]] = field(default_factory=dict)
    #: Per raw image topic: (width, height) of each message kept.
    sizes: dict[str, list[tuple[int, int]]] = field(default_factory=dict)
    totals: dict[str, int] = field(default_factory=dict)
    #: Per image topic: the log time of every message, damaged ones included, in order.
    image_log_ns: dict[str, list[int]] = field(default_factory=dict)
    skips: integrity.SkipLog = field(default_factory=integrity.SkipLog)
    log_stamps: dict[str, list[int]] = field(default_factory=dict)
    first_msgs: dict[str, Any] = field(default_factory=dict)
    tf: TfBuffer = field(default_factory=TfBuffer)
    odom_frames: tuple[str, str] | None = None
    gt_objects: list[Any] = field(default_factory=list)
    #: (frame, stamp) of every ground-truth message: annotated frames, people in them or not.
    gt_frames: list[tuple[int, int]] = field(default_factory=list)
    gt_messages: int = 0
    #: The recording's provenance (:mod:`rgbd_eval.io.provenance`), when it has one.
    provenance: dict[str, Any] | None = None


def index_pass(path: Path, src: MessageSource, sel: SelectedTopics, io: IoConfig) -> MessageIndex:
    """Read every message of the selected topics once (see the module docstring)."""
    index = MessageIndex()
    images_ = set(sel.streams.values())
    infos = set(sel.infos.values()) | ({sel.registration[1]} if sel.registration else set())
    small = {t for t in (sel.odometry, sel.ground_truth, sel.joint_states) if t} | infos
    odometer = wheels.WheelOdometry(0.5 * io.wheels.separation_m) if io.wheels is not None else None
    small.update(sel.tf)
    prov = src.topics.get(provenance.PROVENANCE_TOPIC)
    if prov is not None and prov.msgtype == provenance.PROVENANCE_TYPE:
        small.add(provenance.PROVENANCE_TOPIC)
    wanted = small | images_
    for topic, log_ns, raw in src.messages(wanted):
        msgtype = src.topics[topic].msgtype
        ordinal = index.totals.get(topic, 0)
        index.totals[topic] = ordinal + 1
        if topic in images_:
            index.image_log_ns.setdefault(topic, []).append(log_ns)
        try:  # against its definition: the bytes must deserialise, exactly consumed
            msg: Any = src.deserialize(raw, msgtype)
        except MESSAGE_ERRORS as err:
            if topic == sel.ground_truth:  # annotations are never dropped silently
                raise InputError(path, f"ground-truth message {ordinal}: {err}", topic) from err
            index.skips.add(topic, str(err))
            continue
        if topic in images_:
            _index_image(index, topic, msg, ordinal)
            continue
        index.log_stamps.setdefault(topic, []).append(log_ns)
        if topic in infos:
            problem = integrity.camera_info_problem(msg)
            if problem is not None:
                index.skips.add(topic, problem)
            else:
                index.first_msgs.setdefault(topic, msg)
        elif topic == sel.odometry:
            _index_odometry(path, index, topic, msg)
        elif topic == sel.joint_states and odometer is not None and io.wheels is not None:
            w = io.wheels
            try:
                v_L, v_R = wheels.wheel_speeds(msg, w.left_joint, w.right_joint, w.radius_m)
                pose = odometer.add(stamp_of(msg), v_L, v_R).pose()
            except ValueError as err:
                raise DecodeError(path, str(err), topic) from err
            index.odom_frames = (w.odom_frame, w.base_frame)
            _add_tf(path, index.tf, w.odom_frame, w.base_frame, stamp_of(msg), pose, False, topic)
        elif msgtype == TF_TYPE:
            _index_tf(path, index, topic, msg)
        elif topic == provenance.PROVENANCE_TOPIC:
            if index.provenance is None:
                try:
                    index.provenance = provenance.decode(str(msg.data))
                except ValueError as err:
                    index.skips.add(topic, str(err))
        elif topic == sel.ground_truth:
            frame = index.gt_messages
            index.gt_messages += 1
            index.gt_frames.append((frame, stamp_of(msg)))
            index.gt_objects.extend(groundtruth.objects_from_message(msg, frame, stamp_of(msg)))
    return index


def _index_image(index: MessageIndex, topic: str, msg: Any, ordinal: int) -> None:
    """Note an image message's stamp, position and size (skipped when it is damaged)."""
    image = msg.image if hasattr(msg, "f") else msg  # a DisparityImage's image
    problem = integrity.image_problem(image)
    if problem is not None:
        index.skips.add(topic, problem)
        return
    index.stamps.setdefault(topic, []).append(stamp_of(msg))
    index.ordinals.setdefault(topic, []).append(ordinal)
    if not hasattr(image, "format"):
        index.sizes.setdefault(topic, []).append((int(image.width), int(image.height)))


def _index_odometry(path: Path, index: MessageIndex, topic: str, msg: Any) -> None:
    """A ``nav_msgs/Odometry`` message as a tf from its frame to its child frame."""
    parent, child = msg.header.frame_id.lstrip("/"), msg.child_frame_id.lstrip("/")
    index.odom_frames = (parent, child)
    p = msg.pose.pose
    _add_tf(
        path,
        index.tf,
        parent,
        child,
        stamp_of(msg),
        pose_of(p.position, p.orientation),
        False,
        topic,
    )


def _index_tf(path: Path, index: MessageIndex, topic: str, msg: Any) -> None:
    """Every transform of a ``tf2_msgs/TFMessage`` (static on ``/tf_static``)."""
    static = topic.endswith("tf_static")
    for t in msg.transforms:
        tr = t.transform
        _add_tf(
            path,
            index.tf,
            t.header.frame_id,
            t.child_frame_id,
            stamp_of(t),
            pose_of(tr.translation, tr.rotation),
            static,
            topic,
        )


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
