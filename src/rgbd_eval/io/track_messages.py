"""Tracks recorded in a bag: the people-tracker message types, and reading them back.

Supported types (definitions registered with the package's typestores, so that
``.db3`` bags without embedded definitions and our own test writers work; bags
that embed their definitions are read with those):

- ``spencer_tracking_msgs/TrackedPersons`` (SPENCER): ``track_id``, pose position;
- ``people_msgs/People`` (ROS people stack): ``name`` as the id (an integer name is
  used as is, other names get ids in order of appearance), ``position``;
- ``vision_msgs/Detection3DArray`` with tracking ids (ROS2 ``id``, ROS1
  ``tracking_id``): the box centre, height from the box size;
- ``vision_msgs/Detection2DArray`` with tracking ids: the image box (IoU gating);
- ``opt_msgs/TrackArray`` (OpenPTrack): ``id``, ``x``, ``y``, ``height``,
  ``visibility`` and the 2D box where its width is positive.

World positions are brought from the message's ``header.frame_id`` into the
ground truth's frame through the recording's ``/tf`` and ``/tf_static``, at the
header stamp. The ground truth's frame is ``io.world_frame`` when set, else the
first of ``map``, ``odom``, ``world`` in the tf tree (as ``rgbd-eval run`` chooses),
else ``odom`` (``io.world_frame``'s default). Positions in another frame with no tf
to it are refused (:class:`TransformError`, exit 3), never scored as they are.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from rgbd_eval.errors import InputError, TransformError
from rgbd_eval.io.source import open_source
from rgbd_eval.io.tf import TfBuffer, TransformLookupError
from rgbd_eval.io.track_message_types import (
    DETECTION2D_TYPE,
    DETECTION3D_TYPE,
    OPT_TYPE,
    PEOPLE_TYPE,
    SPENCER_TYPE,
    TRACK_TYPES,
)
from rgbd_eval.types import Box2D, Pose, TrackerOutput, TrackOutput, Visibility


def _stamp(msg: Any) -> int:
    stamp = msg.header.stamp
    nsec = getattr(stamp, "nanosec", None)
    return int(stamp.sec) * 1_000_000_000 + int(nsec if nsec is not None else stamp.nsec)


def _tracking_id(det: Any) -> str:
    if hasattr(det, "tracking_id"):
        return str(det.tracking_id) if getattr(det, "is_tracking", True) else ""
    return str(getattr(det, "id", ""))


class _Ids:
    """Integer ids for string ids: integers as they are, other names in order of appearance."""

    def __init__(self) -> None:
        self._names: dict[str, int] = {}

    def __call__(self, name: str) -> int:
        text = name.strip()
        if text.lstrip("-").isdigit():
            return int(text)
        return self._names.setdefault(text, 1_000_000_000 + len(self._names))


# One decoded track: id, position in the message frame (or None), height, box, visibility.
_Raw = tuple[int, tuple[float, float, float] | None, float, Box2D | None, Visibility]


def _decode(msgtype: str, msg: Any, ids: _Ids) -> list[_Raw]:
    out: list[_Raw] = []
    if msgtype == SPENCER_TYPE:
        for t in msg.tracks:
            p = t.pose.pose.position
            vis = Visibility.OCCLUDED if t.is_occluded else Visibility.VISIBLE
            out.append((int(t.track_id), (p.x, p.y, p.z), math.nan, None, vis))
    elif msgtype == PEOPLE_TYPE:
        for person in msg.people:
            p = person.position
            out.append((ids(person.name), (p.x, p.y, p.z), math.nan, None, Visibility.VISIBLE))
    elif msgtype == OPT_TYPE:
        for t in msg.tracks:
            b = t.box_2D
            box = Box2D(b.x, b.y, b.width, b.height) if b.width > 0 and b.height > 0 else None
            vis = (
                Visibility(int(t.visibility))
                if int(t.visibility) in (0, 1, 2)
                else Visibility.VISIBLE
            )
            out.append((int(t.id), (t.x, t.y, 0.0), float(t.height), box, vis))
    elif msgtype == DETECTION3D_TYPE:
        for d in msg.detections:
            name = _tracking_id(d)
            if not name:
                raise ValueError("a Detection3D has no tracking id")
            c, s = d.bbox.center.position, d.bbox.size
            out.append((ids(name), (c.x, c.y, c.z), float(s.z), None, Visibility.VISIBLE))
    elif msgtype == DETECTION2D_TYPE:
        for d in msg.detections:
            name = _tracking_id(d)
            if not name:
                raise ValueError("a Detection2D has no tracking id")
            center = d.bbox.center
            pos = getattr(center, "position", center)  # ROS2 Pose2D.position, ROS1 Pose2D
            w, h = float(d.bbox.size_x), float(d.bbox.size_y)
            box = Box2D(pos.x - w / 2, pos.y - h / 2, w, h)
            out.append((ids(name), None, math.nan, box, Visibility.VISIBLE))
    return out


#: ``io.world_frame``'s default where the recording does not name a world frame.
DEFAULT_WORLD_FRAME = "odom"


def _target_frame(world_frame: str | None, tf: TfBuffer) -> tuple[str, str]:
    """The ground truth's frame (see the module docstring) and where that choice came from."""
    if world_frame and world_frame.lstrip("/"):
        return world_frame.lstrip("/"), "io.world_frame"
    found = next((f for f in ("map", "odom", "world") if f in tf.frames), None)
    if found is not None:
        return found, "the world frame of the recording's tf"
    return DEFAULT_WORLD_FRAME, "io.world_frame's default: the recording's tf names no world frame"


def read_bag_tracks(
    path: Path, topic: str | None = None, world_frame: str | None = None
) -> TrackerOutput:
    """Tracks of one topic of a supported type (see the module docstring).

    ``topic`` may be omitted when exactly one topic has a supported type.
    """
    path = Path(path)
    with open_source(path) as src:
        candidates = {t: c.msgtype for t, c in src.topics.items() if c.msgtype in TRACK_TYPES}
        if topic is None:
            if len(candidates) != 1:
                found = ", ".join(sorted(candidates)) or "none"
                raise InputError(
                    path,
                    f"expected one topic of a tracker output type ({', '.join(TRACK_TYPES)}), "
                    f"found {found}; choose one with --tracks-topic",
                )
            topic = next(iter(candidates))
        if topic not in candidates:
            raise InputError(path, "not a tracker output type or not in the recording", topic)
        msgtype = candidates[topic]
        tf = TfBuffer()
        tf_topics = {t for t, c in src.topics.items() if c.msgtype == "tf2_msgs/msg/TFMessage"}
        ids = _Ids()
        frames: list[tuple[int, str, list[_Raw]]] = []
        for name, _, raw in src.messages({topic, *tf_topics}):
            msg = src.deserialize(raw, src.topics[name].msgtype)
            if name in tf_topics:
                for t in msg.transforms:
                    tr, q = t.transform.translation, t.transform.rotation
                    edge = Pose((tr.x, tr.y, tr.z), (q.x, q.y, q.z, q.w))
                    parent, child = t.header.frame_id.lstrip("/"), t.child_frame_id.lstrip("/")
                    try:
                        tf.add(parent, child, _stamp(t), edge, static=name == "/tf_static")
                    except TransformLookupError as err:
                        raise TransformError(path, str(err), name) from err
                continue
            try:
                decoded = _decode(msgtype, msg, ids)
            except ValueError as err:
                raise InputError(path, str(err), topic) from err
            frames.append((_stamp(msg), msg.header.frame_id.lstrip("/"), decoded))
    target, why = _target_frame(world_frame, tf)
    out = []
    sensor: list[Pose | None] = []
    for index, (stamp, frame_id, decoded) in enumerate(sorted(frames, key=lambda f: f[0])):
        pose: Pose | None = None
        if frame_id != target and any(p is not None for _, p, *_ in decoded):
            try:
                pose = tf.lookup(target, frame_id, stamp, tolerance_ns=200_000_000)
            except TransformLookupError as err:
                raise TransformError(
                    path,
                    f"no transform from the tracks' frame {frame_id!r} to the ground truth's "
                    f"frame {target!r} ({why}; set io.world_frame to the ground truth's frame "
                    f"if it is another): {err}",
                    topic,
                ) from err
        tracks = []
        for track_id, position, height, box, vis in decoded:
            x = y = math.nan
            if position is not None:
                point = np.array([position], dtype=np.float64)
                if pose is not None:
                    point = pose.transform_points(point)
                x, y = float(point[0, 0]), float(point[0, 1])
            tracks.append(TrackOutput(track_id, x, y, height, box, vis))
        out.append((index, stamp, tuple(tracks)))
        sensor.append(pose)  # the tracks' own frame in the world: the sensor, where not the world
    return TrackerOutput(f"{path} [{topic}]", tuple(out), sensor_poses=tuple(sensor))
