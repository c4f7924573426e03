"""Person boxes recorded beside the images: a detection topic in the bag, or a MOTChallenge det.txt.

Seed 001's dataset (IV) ships its YOLO detections this way; evaluating a tracker on recorded
detections needs no detector at all. Supported:

- ``vision_msgs/Detection2DArray`` (ROS1 1.x: integer ``id`` per hypothesis; ROS2 4.x:
  string ``class_id``), box = ``bbox`` centre and size;
- ``darknet_ros_msgs/BoundingBoxes`` (``Class`` name, ``probability``, pixel corners), stamped
  with ``image_header`` (the image's stamp) when it is set, else ``header``;
- a MOTChallenge ``det.txt``: ``frame, id, left, top, width, height, conf[, x, y, z]``, frames
  numbered from 1 in image order.

A hypothesis counts as a person when its class label (the ROS1 integer id written in
decimal) is one of ``classes``; an empty ``classes`` accepts every box. Messages are matched
to images by nearest stamp within ``max_gap_ns``; an image with no message within the gap
has no detections (darknet_ros publishes nothing on an image without detections).
"""

from __future__ import annotations

import bisect
import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rgbd_eval.detect.person2d import ColourImage, PersonBox
from rgbd_eval.errors import InputError
from rgbd_eval.files import read_text
from rgbd_eval.io.messages import BOUNDING_BOXES_TYPE, DETECTION2D_ARRAY_TYPE
from rgbd_eval.io.source import READ_ERRORS, open_source
from rgbd_eval.types import Box2D

SUPPORTED_TYPES = (DETECTION2D_ARRAY_TYPE, BOUNDING_BOXES_TYPE)


@dataclass(frozen=True)
class RecordedParams:
    """Which recorded boxes are people, and how far apart stamps may be."""

    classes: tuple[str, ...] = ("person", "0")
    min_score: float = 0.0
    max_gap_ns: int = 5_000_000


def _stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _accept(label: str, score: float, params: RecordedParams) -> bool:
    return (not params.classes or label in params.classes) and score >= params.min_score


def boxes_from_message(msg: Any, msgtype: str, params: RecordedParams) -> list[PersonBox]:
    """The person boxes of one deserialised detection message."""
    out: list[PersonBox] = []
    if msgtype == BOUNDING_BOXES_TYPE:
        for bb in msg.bounding_boxes:
            if _accept(str(bb.Class), float(bb.probability), params):
                box = Box2D(
                    float(bb.xmin),
                    float(bb.ymin),
                    float(bb.xmax - bb.xmin),
                    float(bb.ymax - bb.ymin),
                )
                out.append(PersonBox(box, float(bb.probability)))
        return out
    for det in msg.detections:
        centre = det.bbox.center
        cx, cy = (
            (centre.position.x, centre.position.y)
            if hasattr(centre, "position")
            else (centre.x, centre.y)
        )
        w, h = float(det.bbox.size_x), float(det.bbox.size_y)
        best: tuple[float, str] | None = None
        for hyp in det.results:
            if hasattr(hyp, "hypothesis"):
                label, score = str(hyp.hypothesis.class_id), float(hyp.hypothesis.score)
            else:
                label, score = str(hyp.id), float(hyp.score)
            if _accept(label, score, params) and (best is None or score > best[0]):
                best = (score, label)
        if best is None and not det.results and not params.classes:
            best = (1.0, "")
        if best is not None and w > 0 and h > 0:
            out.append(PersonBox(Box2D(float(cx) - w / 2, float(cy) - h / 2, w, h), best[0]))
    return out


class RecordedDetector:
    """:class:`~rgbd_eval.detect.person2d.PersonDetector2D` replaying recorded boxes."""

    def __init__(
        self,
        by_stamp: dict[int, list[PersonBox]] | None = None,
        by_frame: dict[int, list[PersonBox]] | None = None,
        params: RecordedParams | None = None,
    ) -> None:
        self.params = params or RecordedParams()
        self._by_stamp = by_stamp or {}
        self._stamps = sorted(self._by_stamp)
        self._by_frame = by_frame

    @classmethod
    def from_topic(
        cls, path: Path, topic: str, params: RecordedParams | None = None
    ) -> RecordedDetector:
        """All messages of ``topic`` in the recording at ``path``, keyed by stamp."""
        params = params or RecordedParams()
        by_stamp: dict[int, list[PersonBox]] = {}
        try:
            with open_source(path) as source:
                conn = source.topics.get(topic)
                if conn is None:
                    raise InputError(path, "no such topic in the recording", topic)
                if conn.msgtype not in SUPPORTED_TYPES:
                    raise InputError(
                        path,
                        f"type {conn.msgtype}, expected one of {', '.join(SUPPORTED_TYPES)}",
                        topic,
                    )
                for _, log_ns, raw in source.messages({topic}):
                    msg = source.deserialize(raw, conn.msgtype)
                    stamp = _stamp_ns(msg.header)
                    if conn.msgtype == BOUNDING_BOXES_TYPE and _stamp_ns(msg.image_header) > 0:
                        stamp = _stamp_ns(msg.image_header)
                    if stamp == 0:
                        stamp = log_ns
                    by_stamp.setdefault(stamp, []).extend(
                        boxes_from_message(msg, conn.msgtype, params)
                    )
        except READ_ERRORS as err:
            raise InputError(path, f"cannot read detections: {err}", topic) from err
        return cls(by_stamp=by_stamp, params=params)

    @classmethod
    def from_det_txt(cls, path: Path, params: RecordedParams | None = None) -> RecordedDetector:
        """A MOTChallenge ``det.txt`` (frames from 1)."""
        params = params or RecordedParams()
        by_frame: dict[int, list[PersonBox]] = {}
        # A regular, bounded UTF-8 file (a pipe would block, Latin-1 raised UnicodeDecodeError).
        text = read_text(path, lambda m: InputError(path, m), "detections")
        try:
            for line_no, row in enumerate(csv.reader(text.splitlines()), start=1):
                if not row or not "".join(row).strip():
                    continue
                if len(row) < 7:
                    raise InputError(path, f"line {line_no}: {len(row)} fields, expected >= 7")
                try:
                    frame = int(float(row[0]))
                    left, top, w, h, conf = (float(v) for v in row[2:7])
                except ValueError as err:
                    raise InputError(path, f"line {line_no}: not a number ({err})") from err
                if frame < 1:
                    raise InputError(path, f"line {line_no}: frame {frame} < 1")
                if w > 0 and h > 0 and conf >= params.min_score:
                    by_frame.setdefault(frame, []).append(PersonBox(Box2D(left, top, w, h), conf))
        except csv.Error as err:
            raise InputError(path, f"not CSV text ({err})") from err
        return cls(by_frame=by_frame, params=params)

    def detect(self, image: ColourImage) -> list[PersonBox]:
        by_frame = self._by_frame
        boxes = (
            by_frame.get(image.index + 1, [])
            if by_frame is not None
            else self._nearest(image.stamp_ns)
        )
        return sorted(boxes, key=lambda b: -b.score)

    def _nearest(self, stamp_ns: int) -> list[PersonBox]:
        if not self._stamps:
            return []
        i = bisect.bisect_left(self._stamps, stamp_ns)
        candidates = [
            s
            for s in (
                self._stamps[i - 1] if i > 0 else None,
                self._stamps[i] if i < len(self._stamps) else None,
            )
            if s is not None
        ]
        best = min(candidates, key=lambda s: (abs(s - stamp_ns), s))
        if abs(best - stamp_ns) > self.params.max_gap_ns:
            return []
        return list(self._by_stamp[best])
