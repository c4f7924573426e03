"""Open a recording and stream synchronised :class:`~rgbd_eval.types.Frame` objects.

Supported containers: ROS1 ``.bag`` (v2.0; none/lz4/bz2 chunks), ROS2 bag folders
(sqlite3 or mcap storage), lone ``.mcap`` / ``.db3`` files, through
:mod:`rgbd_eval.io.source` (``mcap.reader`` for lone .mcap, rosbags' AnyReader otherwise).

Reading takes two passes, so memory stays flat in the sequence length:

1. *Index pass* (:func:`open_recording`): the small messages (CameraInfo,
   odometry, tf, ground truth) are decoded; of the image topics only the header
   stamps are parsed from the raw bytes. This gives the topic of each stream role
   (colour, depth, depth_2, ..., thermal, left, right: chosen by ``io.topics`` or,
   where unambiguous, by message type), the pairing of every stream with the
   reference stream, the tf buffer and every frame's camera poses.
2. *Frame pass* (:meth:`Recording.frames`): image messages are decoded only
   when they belong to a frame, and each frame is yielded as soon as all its
   streams have been read.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
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
from rgbd_eval.io import groundtruth, images, integrity, provenance, validate, wheels
from rgbd_eval.io.integrity import SkippedMessages
from rgbd_eval.io.messages import (
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    DISPARITY_TYPE,
    GT_ARRAY_TYPE,
    IMAGE_TYPE,
    ODOMETRY_TYPE,
    TF_TYPE,
)
from rgbd_eval.io.source import MESSAGE_ERRORS, READ_ERRORS, MessageSource, open_source
from rgbd_eval.io.sync import Pairing, first_non_increasing, pair_nearest
from rgbd_eval.io.tf import TfBuffer, TransformLookupError
from rgbd_eval.plugins import StreamSpec, role_kind
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Frame, Pose, Stream

_IMAGE_TYPES = (IMAGE_TYPE, COMPRESSED_IMAGE_TYPE, DISPARITY_TYPE)

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


@dataclass(frozen=True)
class StreamSync:
    """How one stream paired with the reference stream."""

    role: str
    topic: str
    messages: int
    dropped: int
    worst_gap_ms: float
    mean_gap_ms: float


@dataclass(frozen=True)
class SyncProblem:
    """A stream none of whose messages pairs with the reference stream within the sync gap.

    ``smallest_gap_ms`` is the smallest offset between the two streams' stamps and
    ``needed_gap_ms`` the smallest sync gap at which as many messages pair as can;
    ``accept_with`` sets ``option`` to it, which pairs ``pairs_accepted`` reference
    messages. Without a role: no frame has every stream.
    """

    message: str
    role: str | None = None
    topic: str | None = None
    smallest_gap_ms: float | None = None
    needed_gap_ms: float | None = None
    option: str = "io.max_sync_gap_ms"
    accept_with: str | None = None
    pairs_accepted: int | None = None


@dataclass(frozen=True)
class SyncStats:
    """How the streams pair up: per stream, against the reference (the first stream)."""

    reference: str
    streams: tuple[StreamSync, ...]
    frames: int
    no_pose_dropped: int
    max_gap_ms: float
    #: Why nothing pairs (only with ``open_recording(..., unpaired_ok=True)``).
    problems: tuple[SyncProblem, ...] = ()

    @property
    def worst_gap_ms(self) -> float:
        return max((s.worst_gap_ms for s in self.streams), default=0.0)


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


def _stamp_of(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _pose_of(translation: Any, rotation: Any) -> Pose:
    return Pose(
        (float(translation.x), float(translation.y), float(translation.z)),
        (float(rotation.x), float(rotation.y), float(rotation.z), float(rotation.w)),
    )


def camera_model_from_info(msg: Any, rectified: bool = False) -> CameraModel:
    """``sensor_msgs/CameraInfo`` (ROS1 ``K``/``D``/``P`` or ROS2 ``k``/``d``/``p``) -> CameraModel.

    ``rectified``: the image is a rectified one (:func:`is_rectified`). Its CameraInfo (shared
    with the raw image, as image_proc publishes it) has the raw image's ``K`` and ``D``; the
    rectified image has no distortion left and the intrinsics of ``P`` (of ``K`` when ``P``
    is not set). Without distortion in ``D``, ``K`` is taken as for any image.
    """
    K = np.asarray(msg.K if hasattr(msg, "K") else msg.k, dtype=np.float64).reshape(3, 3)
    D = tuple(float(v) for v in (msg.D if hasattr(msg, "D") else msg.d))
    P = np.asarray(msg.P if hasattr(msg, "P") else getattr(msg, "p", ()), dtype=np.float64)
    fx, fy, cx, cy = float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2])
    if rectified and any(D):
        D = ()
        if P.size == 12 and P[0] > 0 and P[5] > 0:
            fx, fy, cx, cy = float(P[0]), float(P[5]), float(P[2]), float(P[6])
    return CameraModel(
        width=int(msg.width),
        height=int(msg.height),
        fx=fx,
        fy=fy,
        cx=cx,
        cy=cy,
        distortion=D,
        frame_id=msg.header.frame_id.lstrip("/"),
        tx=float(P[3]) if P.size == 12 else 0.0,
        distortion_model=str(getattr(msg, "distortion_model", "")),
    )


def is_rectified(topic: str) -> bool:
    """An image topic image_proc rectified: ``.../image_rect``, ``image_rect_color``,
    ``image_rect_raw`` (a ``compressed`` transport aside)."""
    parts = topic.rstrip("/").split("/")
    if parts[-1] in ("compressed", "compressedDepth"):
        parts = parts[:-1]
    return bool(parts) and parts[-1].startswith("image_rect")


def _namespace(topic: str) -> str:
    parts = topic.rstrip("/").split("/")
    if parts and parts[-1] in ("compressed", "compressedDepth"):
        parts = parts[:-1]
    return "/".join(parts[:-1])


@dataclass
class _Index:
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


@dataclass(frozen=True)
class _FramePlan:
    """One frame to decode: its stamp, each role's message index, each role's pose."""

    stamp_ns: int
    messages: Mapping[str, int]
    stamps: Mapping[str, int]
    poses: Mapping[str, Pose]


#: The image of a stream read with ``Recording.frames(skip=...)``.
_NOT_DECODED = np.zeros((0, 0), dtype=np.uint8)


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
        primary = "depth" if "depth" in sel else next(iter(sel))
        next_k = start
        self.empty_depth_frames = []
        self.implausible_depth_frames = []
        info = self.info
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
                        decoded: tuple[Any, str] = (_NOT_DECODED, "none")
                    else:
                        msg = src.deserialize(raw, msgtypes[topic])
                        decoded = self._decode(msg, topic, role, info.cameras[role])
                        if role == "depth":
                            decoded = self._check_depth(decoded, k)
                    ready.setdefault(k, {})[role] = decoded
                    while len(ready.get(next_k, ())) == len(sel):
                        plan = self._plan[next_k]
                        images = ready.pop(next_k)
                        streams = {
                            r: Stream(
                                images[r][0],
                                images[r][1],
                                info.cameras[r],
                                plan.stamps[r],
                                plan.poses[r],
                            )
                            for r in sel
                        }
                        yield Frame(
                            index=next_k,
                            stamp_ns=plan.stamp_ns,
                            streams=streams,
                            depth_to_rgb=self._depth_to_rgb,
                            camera_pose=plan.poses[primary],
                            world_frame=info.world_frame,
                            has_odometry=info.has_odometry,
                        )
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

    def _decode(self, msg: Any, topic: str, role: str, camera: CameraModel) -> tuple[Any, str]:
        kind = role_kind(role)
        try:
            img: Any
            if kind == "disparity":
                img = images.depth_from_disparity_message(msg)
                encoding = "depth"
            elif kind == "depth":
                img = images.decode_depth(msg)
                encoding = "depth"
            elif kind == "thermal":
                img = images.decode_mono(msg)
                encoding = "mono16" if img.dtype == np.uint16 else "mono8"
            else:
                img = images.decode_color(msg)
                encoding = "rgb8"
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
        return img, encoding


# ----------------------------------------------------------------------------- opening


def topic_flag(role: str) -> str:
    """The command-line option that chooses the topic of ``role``."""
    return f"--topic {role}=/name"


def _choose(
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


def _choose_streams(
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
        picked = _choose(path, spec.role, what, override, cands, spec.required)
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


def _info_for(image_topic: str, infos: list[str], override: str | None) -> str | None:
    if override is not None:
        return override
    ns = _namespace(image_topic)
    same = [t for t in infos if _namespace(t) == ns]
    return same[0] if len(same) == 1 else None


def _registration(
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
        info = None if topic is None else _info_for(topic, infos, io.topic("colour_info"))
    return (topic, info) if topic is not None and info is not None else None


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
    try:
        with open_source(path) as src:
            conns = list(src.topics.values())
            if not conns or all(c.count == 0 for c in conns):
                raise InputError(path, "recording is empty (no messages)")
            by_topic = {c.topic: c for c in conns}
            duration_s = max(0.0, (src.end_ns - src.start_ns) / 1e9)
            # Classify image topics by their first message that deserialises (a topic
            # none of whose messages does is left out, and named when a role lacks a topic).
            image_conns = [c for c in conns if c.msgtype in _IMAGE_TYPES and c.count > 0]
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
            try:
                chosen = _choose_streams(path, io, streams, first)
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
                    "no image topic of the roles needed "
                    f"({', '.join(s.role for s in streams)}) found",
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
                info_topic = _info_for(topic, infos, named)
                if info_topic is not None:
                    info_topics[role] = info_topic
            odoms = [c.topic for c in conns if c.msgtype == ODOMETRY_TYPE]
            joints = [c.topic for c in conns if c.msgtype == wheels.JOINT_STATE_TYPE]
            joint_topic = None
            if io.wheels is not None:  # wheel speeds replace nav_msgs/Odometry
                joint_topic = _choose(
                    path, "joint_states", "JointState", io.topic("joint_states"), joints, True
                )
                odoms = []
            odom_topic = _choose(path, "odometry", "odometry", io.topic("odometry"), odoms, False)
            tf_topics = tuple(c.topic for c in conns if c.msgtype == TF_TYPE)
            gts = [c.topic for c in conns if c.msgtype == GT_ARRAY_TYPE]
            gt_topic = _choose(
                path, "ground_truth", "ground-truth", io.topic("ground_truth"), gts, False
            )
            selected = SelectedTopics(
                chosen,
                info_topics,
                odom_topic,
                tf_topics,
                gt_topic,
                joint_topic,
                _registration(chosen, info_topics, first, infos, io),
            )
            index = _index_pass(path, src, selected, io)
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
    cameras = _cameras(path, selected, index, first, warnings)

    _skip_wrong_sizes(index, selected, cameras)
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
    skipped = index.skips.summary(index.totals)
    if (skip_note := integrity.skipped_warning(skipped)) is not None:
        warnings.append(skip_note)
    reference = next(iter(chosen))
    max_gap_ns = int(io.max_sync_gap_ms * 1e6)
    partner: dict[str, dict[int, int]] = {}
    stream_sync = []
    problems: list[SyncProblem] = []
    for role in list(chosen)[1:]:
        pairing: Pairing = pair_nearest(stamps[reference], stamps[role], max_gap_ns)
        if not pairing.pairs:
            problem = _unpaired(io, reference, role, chosen, stamps)
            if not unpaired_ok:
                raise SyncError(path, problem.message)
            problems.append(problem)
        partner[role] = dict(pairing.pairs)
        stream_sync.append(
            StreamSync(
                role,
                chosen[role],
                int(stamps[role].size),
                pairing.depth_unpaired,
                pairing.worst_gap_ns / 1e6,
                pairing.mean_gap_ns / 1e6,
            )
        )

    primary = "depth" if "depth" in chosen else reference
    camera_frame = cameras[primary].frame_id or chosen[primary]
    world_frame, has_odometry, chain = _world(path, io, index, camera_frame, odom_topic, warnings)
    jump = index.tf.jump_problem(chain) if has_odometry else None
    if jump is not None:
        child, jump_message = jump
        by_odometry = index.odom_frames is not None and index.odom_frames[1] == child
        raise TransformError(path, jump_message, odom_topic if by_odometry else None)
    colour, depth = cameras.get("colour"), cameras.get("depth")
    depth_to_rgb = (
        _depth_to_rgb(index.tf, colour, depth, warnings)
        if colour is not None and depth is not None
        else Pose.identity()
    )
    # Each other camera's pose relative to the primary one (static extrinsics from tf).
    extrinsics: dict[str, Pose] = {}
    for role, cam in cameras.items():
        if role != primary:
            extrinsics[role] = _extrinsics(index.tf, cameras[primary], cam, role, warnings)

    tol = int(io.max_pose_extrapolation_ms * 1e6)
    plan: list[_FramePlan] = []
    no_pose = 0
    ref_stamps = stamps[reference]
    for r in range(ref_stamps.size):
        if not all(r in partner[role] for role in partner):
            continue
        stamp = int(ref_stamps[r])
        kept = {reference: r, **{role: partner[role][r] for role in partner}}
        if has_odometry:
            try:
                pose = index.tf.lookup(world_frame, camera_frame, stamp, tol)
            except TransformLookupError:
                no_pose += 1
                continue
        else:
            pose = OPTICAL_TO_BODY
        poses = {primary: pose}
        for role, ext in extrinsics.items():
            poses[role] = pose.compose(ext)
        plan.append(
            _FramePlan(
                stamp,
                {role: int(ordinals[role][i]) for role, i in kept.items()},  # topic positions
                {role: int(stamps[role][i]) for role, i in kept.items()},
                poses,
            )
        )
    if not plan and partner and not problems and all(partner.values()) and not no_pose:
        problem = SyncProblem("no frame has every stream within the sync gap")
        if not unpaired_ok:
            raise SyncError(path, problem.message)
        problems.append(problem)
    if not plan and skipped and not problems:
        raise DecodeError(path, f"no usable frame left: {skip_note}")
    if not plan and not problems:
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
            gt = groundtruth.from_objects(f"{path}:{gt_topic}", index.gt_objects, index.gt_frames)
        except GroundTruthError as err:  # bad ground truth (exit 5), not a bad recording
            raise GroundTruthError(path, err.message, gt_topic) from err

    ref_sync = StreamSync(
        reference,
        chosen[reference],
        int(ref_stamps.size),
        int(ref_stamps.size) - len(plan) - no_pose,
        0.0,
        0.0,
    )
    sync = SyncStats(
        reference=reference,
        streams=(ref_sync, *stream_sync),
        frames=len(plan),
        no_pose_dropped=no_pose,
        max_gap_ms=io.max_sync_gap_ms,
        problems=tuple(problems),
    )
    dropped = [f"{s.dropped} {s.role}" for s in sync.streams if s.dropped]
    if dropped:
        warnings.append(f"unpaired messages dropped: {', '.join(dropped)}")
    info = RecordingInfo(
        path=str(path),
        container=kind,
        duration_s=duration_s,
        topics=topics,
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


def _skip_wrong_sizes(
    index: _Index, sel: SelectedTopics, cameras: Mapping[str, CameraModel]
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


def _neighbour_gaps_ns(a: NDArray[np.int64], b: NDArray[np.int64]) -> NDArray[np.int64]:
    """The offsets of each a_i to its neighbours in b on either side (both sorted, non-empty)."""
    j = np.searchsorted(b, a)
    before, after = j > 0, j < b.size
    return np.concatenate([a[before] - b[j[before] - 1], b[j[after]] - a[after]]).astype(np.int64)


def _unpaired(
    io: IoConfig,
    reference: str,
    role: str,
    chosen: Mapping[str, str],
    stamps: Mapping[str, NDArray[np.int64]],
) -> SyncProblem:
    """Why ``role`` pairs with no ``reference`` message, and the sync gap that would pair them.

    That gap is the smallest at which as many messages pair as at any gap: the
    candidates :func:`pair_nearest` weighs are every stamp's neighbours in the other
    stream, and the pairs it keeps only grow with the gap, so a bisection over those
    neighbours' offsets finds it.
    """
    ref, other = stamps[reference], stamps[role]
    counts = f"({chosen[reference]}: {ref.size} messages, {chosen[role]}: {other.size})"
    head = f"{reference} and {role} do not pair: no pair within {io.max_sync_gap_ms} ms {counts}"
    if ref.size == 0 or other.size == 0:
        return SyncProblem(f"{head}; a stream has no message", role, chosen[role])
    gaps = np.unique(
        np.concatenate([_neighbour_gaps_ns(ref, other), _neighbour_gaps_ns(other, ref)])
    )

    def pairs_within(gap_ns: int) -> int:
        return len(pair_nearest(ref, other, gap_ns).pairs)

    most = pairs_within(int(gaps[-1]))
    lo, hi = 0, gaps.size - 1  # the first gap at which ``most`` pair is in gaps[lo:hi + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if pairs_within(int(gaps[mid])) == most:
            hi = mid
        else:
            lo = mid + 1
    smallest, needed = float(gaps[0]) / 1e6, float(gaps[lo]) / 1e6
    accept = math.ceil(needed + 1)
    setting = f"--set {SyncProblem.option}={accept}"
    return SyncProblem(
        f"{head}; the smallest offset is {smallest:.1f} ms, and as many as can pair do within "
        f"{needed:.1f} ms: accept them with {setting} (pairs {most} of {ref.size} "
        f"{reference} messages)",
        role,
        chosen[role],
        smallest,
        needed,
        accept_with=setting,
        pairs_accepted=most,
    )


def _rate(stamps: list[int] | None) -> float | None:
    if not stamps or len(stamps) < 2:
        return None
    span = (max(stamps) - min(stamps)) / 1e9
    return (len(stamps) - 1) / span if span > 0 else None


def _index_pass(path: Path, src: MessageSource, sel: SelectedTopics, io: IoConfig) -> _Index:
    index = _Index()
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
            image = msg.image if hasattr(msg, "f") else msg  # a DisparityImage's image
            problem = integrity.image_problem(image)
            if problem is not None:
                index.skips.add(topic, problem)
                continue
            index.stamps.setdefault(topic, []).append(_stamp_of(msg))
            index.ordinals.setdefault(topic, []).append(ordinal)
            if not hasattr(image, "format"):
                index.sizes.setdefault(topic, []).append((int(image.width), int(image.height)))
            continue
        index.log_stamps.setdefault(topic, []).append(log_ns)
        if topic in infos:
            problem = integrity.camera_info_problem(msg)
            if problem is not None:
                index.skips.add(topic, problem)
            else:
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
        elif topic == sel.joint_states and odometer is not None and io.wheels is not None:
            w = io.wheels
            try:
                v_L, v_R = wheels.wheel_speeds(msg, w.left_joint, w.right_joint, w.radius_m)
                pose = odometer.add(_stamp_of(msg), v_L, v_R).pose()
            except ValueError as err:
                raise DecodeError(path, str(err), topic) from err
            index.odom_frames = (w.odom_frame, w.base_frame)
            _add_tf(path, index.tf, w.odom_frame, w.base_frame, _stamp_of(msg), pose, False, topic)
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
        elif topic == provenance.PROVENANCE_TOPIC:
            if index.provenance is None:
                try:
                    index.provenance = provenance.decode(str(msg.data))
                except ValueError as err:
                    index.skips.add(topic, str(err))
        elif topic == sel.ground_truth:
            frame = index.gt_messages
            index.gt_messages += 1
            index.gt_frames.append((frame, _stamp_of(msg)))
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


def _cameras(
    path: Path,
    sel: SelectedTopics,
    index: _Index,
    first: Mapping[str, Any],
    warnings: list[str],
) -> dict[str, CameraModel]:
    """Each stream's camera model from its CameraInfo.

    A depth image without CameraInfo of its own that has the colour image's frame id
    and size is registered to it (``depth_registered`` topics): it takes the colour
    camera's model (:attr:`SelectedTopics.registration`, also when the method reads no
    colour images), with a warning.
    """
    cameras: dict[str, CameraModel] = {}
    order = sorted(sel.streams, key=lambda r: r in sel.infos, reverse=True)  # own info first
    for role in order:
        topic = sel.streams[role]
        info_topic = sel.infos.get(role)
        msg = index.first_msgs.get(info_topic) if info_topic else None
        if msg is None and info_topic is not None and info_topic in index.skips.counts:
            raise DecodeError(
                path,
                f"no usable CameraInfo: all {index.skips.counts[info_topic]} messages are "
                f"damaged ({index.skips.first[info_topic]})",
                info_topic,
            )
        if msg is None:
            colour = _registered_camera(path, sel, index, first, cameras, warnings)
            img = first[topic]
            left = cameras.get("left")
            if role_kind(role) == "disparity" and left is not None:
                inner = img.image
                if (int(inner.width), int(inner.height)) != (left.width, left.height):
                    raise TopicError(
                        path,
                        f"disparity image is {inner.width}x{inner.height} but the left camera "
                        f"is {left.width}x{left.height} (give --topic disparity_info=/name)",
                        topic,
                    )
                cameras[role] = left  # a DisparityImage is in the left camera's frame
                continue
            frame_id = img.header.frame_id.lstrip("/")
            if (
                role_kind(role) == "depth"
                and colour is not None
                and frame_id == colour.frame_id
                and (
                    hasattr(img, "format")
                    or (int(img.width), int(img.height)) == (colour.width, colour.height)
                )
            ):
                warnings.append(
                    f"{topic} has no CameraInfo of its own: registered to the colour image "
                    f"({sel.registration[1] if sel.registration else None}), whose camera "
                    "model it takes"
                )
                cameras[role] = colour
                continue
            raise TopicError(
                path,
                f"no CameraInfo for this image topic (choose it with --topic {role}_info=/name)",
                topic,
            )
        cameras[role] = _camera(path, info_topic, msg, first[topic], topic, warnings)
    return {role: cameras[role] for role in sel.streams}


def _registered_camera(
    path: Path,
    sel: SelectedTopics,
    index: _Index,
    first: Mapping[str, Any],
    cameras: Mapping[str, CameraModel],
    warnings: list[str],
) -> CameraModel | None:
    """The model of the colour camera of :attr:`SelectedTopics.registration`, if usable."""
    if sel.registration is None:
        return None
    if "colour" in cameras:  # read by the method: its model, from the same CameraInfo
        return cameras["colour"]
    topic, info_topic = sel.registration
    msg = index.first_msgs.get(info_topic)
    return None if msg is None else _camera(path, info_topic, msg, first[topic], topic, warnings)


def _camera(
    path: Path, info_topic: str | None, msg: Any, first: Any, topic: str, warnings: list[str]
) -> CameraModel:
    """The camera model of ``topic`` from its CameraInfo ``msg``; what of the distortion is
    not applied goes to ``warnings``."""
    first = first.image if hasattr(first, "f") else first  # a DisparityImage's image
    rectified = is_rectified(topic)
    try:
        camera = camera_model_from_info(msg, rectified)
    except ValueError as err:
        raise DecodeError(path, f"bad CameraInfo: {err}", info_topic) from err
    if not camera.frame_id:
        camera = replace(camera, frame_id=first.header.frame_id.lstrip("/"))
    notes = []
    if rectified and any(msg.D if hasattr(msg, "D") else msg.d):
        notes.append(
            f"{topic} is rectified: the {camera.distortion_model} distortion in {info_topic} "
            "describes the raw image and is not applied (intrinsics from its P, where set)"
        )
    problem = camera.distortion_problem()
    if problem is not None:
        notes.append(f"{info_topic}: {problem}")
    warnings.extend(n for n in notes if n not in warnings)  # once per camera
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
