"""Stream selection: which topic plays which role (colour, depth, depth_2, ..., thermal, left,
right, disparity), with its CameraInfo, and the odometry, tf and ground-truth topics.

A role's topic is the one ``io.topics`` names, else the only topic whose first message and
name fit the role (:func:`image_kinds`); an ambiguous choice is never guessed: the error
names the candidates and the ``--topic ROLE=/name`` option that chooses.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rgbd_eval.config import IoConfig
from rgbd_eval.errors import DecodeError, TopicError
from rgbd_eval.io import wheels
from rgbd_eval.io.messages import (
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    DISPARITY_TYPE,
    GT_ARRAY_TYPE,
    IMAGE_TYPE,
    ODOMETRY_TYPE,
    TF_TYPE,
)
from rgbd_eval.io.source import MESSAGE_ERRORS, MessageSource, TopicConnection
from rgbd_eval.plugins import StreamSpec, role_kind

IMAGE_TYPES = (IMAGE_TYPE, COMPRESSED_IMAGE_TYPE, DISPARITY_TYPE)

#: The streams read when a caller names none: colour and depth (the RGB-D methods).
RGBD_STREAMS = (StreamSpec("colour"), StreamSpec("depth"))
#: Every role, none required: what ``inspect`` shows.
ALL_STREAMS = (
    StreamSpec("colour", required=False),
    StreamSpec("depth", required=False, multiple=True),
    StreamSpec("thermal", required=False),
    StreamSpec("left", required=False),
    StreamSpec("right", required=False),
    StreamSpec("disparity", required=False),
)


@dataclass(frozen=True)
class TopicSummary:
    """One topic of the recording."""

    name: str
    msgtype: str
    count: int
    rate_hz: float | None = None


@dataclass(frozen=True)
class SelectedTopics:
    """The topics the reader uses: an image topic and its CameraInfo per role."""

    streams: Mapping[str, str]
    infos: Mapping[str, str]
    odometry: str | None
    tf: tuple[str, ...]
    ground_truth: str | None
    #: JointState of the wheels, integrated into odometry (``io.wheels``).
    joint_states: str | None = None
    #: The colour image topic and its CameraInfo whose camera model a depth image without
    #: CameraInfo of its own may take (registered depth), whether or not colour is read.
    registration: tuple[str, str] | None = None

    @property
    def rgb(self) -> str | None:
        return self.streams.get("colour")

    @property
    def depth(self) -> str | None:
        return self.streams.get("depth")


def _namespace(topic: str) -> str:
    parts = topic.rstrip("/").split("/")
    if parts and parts[-1] in ("compressed", "compressedDepth"):
        parts = parts[:-1]
    return "/".join(parts[:-1])


def topic_flag(role: str) -> str:
    """The command-line option that chooses the topic of ``role``."""
    return f"--topic {role}=/name"


def choose_topic(
    path: Path, role: str, what: str, override: str | None, candidates: list[str], required: bool
) -> str | None:
    if override is not None:
        if override not in candidates:
            raise TopicError(
                path,
                f"{topic_flag(role).replace('/name', override)}: not a {what} topic here "
                f"(candidates: {', '.join(candidates) or 'none'})",
                override,
            )
        return override
    if not candidates:
        if required:
            raise TopicError(path, f"no {what} topic found (choose one with {topic_flag(role)})")
        return None
    if len(candidates) > 1:
        raise TopicError(
            path,
            f"several {what} topics: {', '.join(sorted(candidates))}; choose one with "
            f"{topic_flag(role)}",
        )
    return candidates[0]


_THERMAL_WORDS = ("thermal", "lwir", "flir", "temperature", "ir/")
_DEPTH_WORDS = ("depth",)


def image_kinds(topic: str, msg: Any) -> tuple[str, ...]:
    """The roles an image topic can play, judged by its first message and its name.

    16UC1/32FC1 and ``compressedDepth`` are depth; ``mono16`` is depth only when the
    topic says so, thermal when it says so, and either otherwise (ambiguous: the user
    chooses with ``--topic``); colour images on ``left``/``right`` topics are a stereo
    pair; ``mono8`` is thermal on a thermal topic, else colour.
    """
    name = topic.lower()
    if hasattr(msg, "image") and hasattr(msg, "f"):  # stereo_msgs/DisparityImage
        return ("disparity",)
    if hasattr(msg, "format"):
        if "compressedDepth" in str(msg.format):
            return ("depth",)
        encoding = "compressed"
    else:
        encoding = str(msg.encoding)
    thermal = any(w in name for w in _THERMAL_WORDS)
    if encoding in ("16UC1", "32FC1"):
        return ("depth",)
    if encoding == "mono16":
        if thermal:
            return ("thermal",)
        return ("depth",) if any(w in name for w in _DEPTH_WORDS) else ("depth", "thermal")
    if thermal:
        return ("thermal",)
    parts = name.replace("-", "/").replace("_", "/").split("/")
    for side in ("left", "right"):
        if side in parts:
            return (side,)
    return ("colour",)


_KIND_NAMES = {
    "colour": "colour image",
    "depth": "depth image",
    "thermal": "thermal image",
    "left": "left stereo image",
    "right": "right stereo image",
    "disparity": "disparity image",
}


def choose_streams(
    path: Path, io: IoConfig, wanted: Sequence[StreamSpec], first: Mapping[str, Any]
) -> dict[str, str]:
    """Role -> topic for the wanted streams, by ``io.topics`` or by unambiguous message type."""
    kinds = {t: image_kinds(t, m) for t, m in first.items()}
    chosen: dict[str, str] = {}
    for spec in wanted:
        cands = sorted(t for t, k in kinds.items() if spec.role in k)
        what = _KIND_NAMES[spec.role]
        if spec.multiple:
            extra = sorted(r for r in io.topics if role_kind(r) == spec.role and r != spec.role)
            named = [io.topics[r] for r in (spec.role, *extra) if r in io.topics]
            for topic in named:
                if topic not in first:
                    raise TopicError(path, f"--topic ...={topic}: not an image topic here", topic)
            if named:
                roles = [spec.role, *extra] if spec.role in io.topics else extra
                chosen.update(zip(roles, named, strict=True))
                continue
            unambiguous = [t for t in cands if kinds[t] == (spec.role,)]
            if not unambiguous and cands and spec.required:
                raise TopicError(
                    path,
                    f"{', '.join(cands)} could be {what} or another kind; choose with "
                    f"{topic_flag(spec.role)}",
                )
            if not unambiguous:
                if spec.required:
                    raise TopicError(path, f"no {what} topic found")
                continue
            for i, topic in enumerate(unambiguous):
                chosen[spec.role if i == 0 else f"{spec.role}_{i + 1}"] = topic
            continue
        override = io.topic(spec.role)
        if override is None and len(cands) > 1:
            sure = [t for t in cands if kinds[t] == (spec.role,)]
            cands = sure if len(sure) == 1 else cands
        if override is None and len(cands) == 1 and len(kinds[cands[0]]) > 1:
            if not spec.required:
                continue  # an optional stream is never guessed
            raise TopicError(
                path,
                f"{cands[0]} could be {what} or another kind; choose with {topic_flag(spec.role)}",
            )
        picked = choose_topic(path, spec.role, what, override, cands, spec.required)
        if picked is not None:
            chosen[spec.role] = picked
    used: dict[str, str] = {}
    for role, topic in chosen.items():
        if topic in used:
            raise TopicError(
                path,
                f"{topic} was chosen for both {used[topic]} and {role}; choose with "
                f"{topic_flag(role)}",
            )
        used[topic] = role
    return chosen


def info_topic_for(image_topic: str, infos: list[str], override: str | None) -> str | None:
    if override is not None:
        return override
    ns = _namespace(image_topic)
    same = [t for t in infos if _namespace(t) == ns]
    return same[0] if len(same) == 1 else None


def registration_of(
    chosen: Mapping[str, str],
    info_topics: Mapping[str, str],
    first: Mapping[str, Any],
    infos: list[str],
    io: IoConfig,
) -> tuple[str, str] | None:
    """The colour camera a depth image without CameraInfo of its own may be registered to.

    One rule for every method: the colour stream when the method reads one, else the
    recording's colour topic (``io.topics.colour``, or the only one), with its CameraInfo.
    None when no depth stream lacks CameraInfo, or there is no such colour camera.
    """
    if all(r in info_topics for r in chosen if role_kind(r) == "depth"):
        return None
    if "colour" in chosen:
        topic: str | None = chosen["colour"]
        info = info_topics.get("colour")
    else:
        colours = [t for t in sorted(first) if image_kinds(t, first[t]) == ("colour",)]
        named = io.topic("colour")
        if named is not None:
            colours = [named] if named in first else []
        topic = colours[0] if len(colours) == 1 else None
        info = None if topic is None else info_topic_for(topic, infos, io.topic("colour_info"))
    return (topic, info) if topic is not None and info is not None else None


def first_images(
    src: MessageSource, conns: Iterable[TopicConnection], warnings: list[str]
) -> tuple[dict[str, Any], dict[str, str]]:
    """Each image topic's first message that deserialises (what classifies the topic), and
    why the others' did not. A topic none of whose messages does is left out, with a
    warning, and named when a role lacks a topic."""
    image_conns = [c for c in conns if c.msgtype in IMAGE_TYPES and c.count > 0]
    first: dict[str, Any] = {}
    undecodable: dict[str, str] = {}
    for conn in image_conns:
        for _, _, raw in src.messages({conn.topic}):
            try:
                first[conn.topic] = src.deserialize(raw, conn.msgtype)
            except MESSAGE_ERRORS as err:
                undecodable.setdefault(conn.topic, str(err))
                continue
            break
    if undecodable.keys() - first.keys():
        warnings.append(
            "image topics with no decodable message left out: "
            + ", ".join(
                f"{t} ({undecodable[t]})" for t in sorted(undecodable.keys() - first.keys())
            )
        )
    return first, undecodable


def select_topics(
    path: Path,
    io: IoConfig,
    streams: Sequence[StreamSpec],
    conns: Sequence[TopicConnection],
    first: Mapping[str, Any],
    undecodable: Mapping[str, str],
) -> SelectedTopics:
    """The topic of each wanted stream and its CameraInfo, and the odometry (or wheel
    speeds), tf and ground-truth topics (TopicError when a choice is missing or ambiguous)."""
    try:
        chosen = choose_streams(path, io, streams, first)
    except TopicError as err:
        lost = sorted(undecodable.keys() - first.keys())
        if not lost:
            raise
        raise DecodeError(  # the topic the role needed may be the damaged one
            path,
            f"no usable message: every message is damaged ({undecodable[lost[0]]})",
            lost[0],
        ) from err
    if not chosen:
        raise TopicError(
            path,
            f"no image topic of the roles needed ({', '.join(s.role for s in streams)}) found",
        )
    infos = [c.topic for c in conns if c.msgtype == CAMERA_INFO_TYPE]
    info_topics = {}
    for role, topic in chosen.items():
        named = io.topic(f"{role}_info")
        if named is not None and named not in infos:
            raise TopicError(
                path,
                f"--topic {role}_info={named}: not a CameraInfo topic here "
                f"(candidates: {', '.join(sorted(infos)) or 'none'})",
                named,
            )
        info_topic = info_topic_for(topic, infos, named)
        if info_topic is not None:
            info_topics[role] = info_topic
    odoms = [c.topic for c in conns if c.msgtype == ODOMETRY_TYPE]
    joints = [c.topic for c in conns if c.msgtype == wheels.JOINT_STATE_TYPE]
    joint_topic = None
    if io.wheels is not None:  # wheel speeds replace nav_msgs/Odometry
        joint_topic = choose_topic(
            path, "joint_states", "JointState", io.topic("joint_states"), joints, True
        )
        odoms = []
    odom_topic = choose_topic(path, "odometry", "odometry", io.topic("odometry"), odoms, False)
    tf_topics = tuple(c.topic for c in conns if c.msgtype == TF_TYPE)
    gts = [c.topic for c in conns if c.msgtype == GT_ARRAY_TYPE]
    gt_topic = choose_topic(
        path, "ground_truth", "ground-truth", io.topic("ground_truth"), gts, False
    )
    return SelectedTopics(
        chosen,
        info_topics,
        odom_topic,
        tf_topics,
        gt_topic,
        joint_topic,
        registration_of(chosen, info_topics, first, infos, io),
    )
