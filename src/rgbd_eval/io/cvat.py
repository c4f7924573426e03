"""CVAT's track exports: "CVAT for video 1.1" XML and "MOT 1.1" text, read and written exactly.

CVAT for video 1.1 (CVAT's ``xml_format`` page; ``cvat/apps/dataset_manager/formats/cvat.py``
writes it)::

    <annotations>
      <version>1.1</version>
      <meta><task>                          (<job> for a job's export)
        <size>4</size> <start_frame>10</start_frame> <stop_frame>19</stop_frame>
        <frame_filter>step=3</frame_filter>      (empty: every frame)
        <original_size><width>640</width><height>480</height></original_size> ...
      </task></meta>
      <track id="0" label="person" source="manual">
        <box frame="10" outside="0" occluded="1" keyframe="1" xtl="3.00" ytl="4.00"
             xbr="10.00" ybr="5.00" z_order="0">
          <attribute name="...">value</attribute>
        </box> ...
      </track> ...
    </annotations>

A box's ``frame`` is the task's frame number (``start_frame + i * step`` for the i-th frame of
the task). Between two boxes of a track that is not ``outside`` at the first, CVAT interpolates
linearly (``cvat/apps/dataset_manager/annotation.py``, ``get_interpolated_shapes``: the corners
``p0 + (p1 - p0) * (f - f0) / (f1 - f0)``; ``occluded`` and the attributes of the earlier box);
after the last box, unless it is ``outside``, the box stays to the end of the task. An
``outside`` box ends the track's visible stretch: the object is absent from that frame to
the next box. CVAT exports a box for every frame of a track (``keyframe="1"`` on the ones an
annotator placed); files with keyframes only (our pre-annotations, hand-written ones) are
interpolated here the same way.

MOT 1.1 (CVAT's ``format-mot`` page; datumaro's ``mot_seq_gt`` writes it): ``gt/gt.txt`` with
rows ``frame_id,track_id,x,y,w,h,not_ignored,class_id,visibility`` (frames from 1, the task's
i-th frame is ``i + 1``; ``class_id`` indexes ``gt/labels.txt``, one label per line, from 1;
MOTChallenge's own classes without that file), visibility 0 for CVAT's ``occluded``. A
track's frames need not be consecutive: as CVAT's importer does, a gap ends the visible
stretch (``outside`` on the frame after) and the track ends after its last row.
"""

from __future__ import annotations

import csv
import io
import math
import re
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from xml.sax.saxutils import XMLGenerator
from xml.sax.xmlreader import AttributesImpl

from rgbd_eval.errors import GroundTruthError
from rgbd_eval.files import MAX_TEXT_BYTES, check_input, decode_text, read_bytes

#: The label of people in our tasks (CVAT's label name; ``--label`` chooses another).
PERSON = "person"
#: MOTChallenge's classes, for a ``gt.txt`` without ``labels.txt`` (class id = index + 1).
MOT_LABELS = (
    "pedestrian",
    "person on vehicle",
    "car",
    "bicycle",
    "motorbike",
    "non motorized vehicle",
    "static person",
    "distractor",
    "occluder",
    "occluder on the ground",
    "occluder full",
    "reflection",
)
#: Shapes a CVAT track may hold besides boxes (such tracks are not people's boxes: skipped).
OTHER_SHAPES = ("polygon", "polyline", "points", "cuboid", "skeleton", "ellipse", "mask")
#: The XML files in a CVAT for video export (``annotations.xml``) and MOT's ground truth.
XML_NAME = "annotations.xml"
MOT_GT = "gt/gt.txt"
MOT_LABELS_NAME = "labels.txt"
#: Members of a zip that are read (bytes), at most: a whole export is one XML or two texts.
_MAX_MEMBER_BYTES = MAX_TEXT_BYTES
_STEP = re.compile(r"^\s*step\s*=\s*(\d+)\s*$")


@dataclass(frozen=True)
class CvatTask:
    """The task (or job) an export belongs to: its frames and its image size.

    The task's frames are ``range(start_frame, stop_frame + 1, step)``, ``size`` of them.
    """

    size: int
    start_frame: int = 0
    stop_frame: int = -1
    step: int = 1
    width: int | None = None
    height: int | None = None
    name: str = ""
    labels: tuple[str, ...] = (PERSON,)

    def __post_init__(self) -> None:
        if self.stop_frame < 0:  # the default: the task's frames from start_frame on
            object.__setattr__(self, "stop_frame", self.start_frame + (self.size - 1) * self.step)

    @property
    def frames(self) -> range:
        return range(self.start_frame, self.stop_frame + 1, self.step)

    @property
    def frame_filter(self) -> str:
        """CVAT's ``frame_filter``: empty for every frame, ``step=N`` otherwise."""
        return "" if self.step == 1 else f"step={self.step}"


@dataclass(frozen=True)
class CvatBox:
    """One ``<box>`` of a track: corners in pixels (top left, bottom right) and flags."""

    frame: int
    xtl: float
    ytl: float
    xbr: float
    ybr: float
    outside: bool = False
    occluded: bool = False
    keyframe: bool = True
    z_order: int = 0
    attributes: tuple[tuple[str, str], ...] = ()

    def attribute(self, name: str) -> str | None:
        return next((v for n, v in self.attributes if n == name), None)


@dataclass(frozen=True)
class CvatTrack:
    """One ``<track>`` of boxes."""

    track_id: int
    label: str
    boxes: tuple[CvatBox, ...]
    source: str = "manual"


@dataclass(frozen=True)
class CvatAnnotations:
    """What an export holds: the task (None for MOT text, which has none), box tracks, and the
    tracks of other shapes that were left out (per shape kind)."""

    source: str
    task: CvatTask | None
    tracks: tuple[CvatTrack, ...]
    other_shapes: Mapping[str, int] = field(default_factory=dict)
    kind: str = "CVAT for video 1.1"


# ----------------------------------------------------------------------------- interpolation


def _interpolated(box0: CvatBox, box1: CvatBox, frame: int) -> CvatBox:
    """CVAT's ``simple_interpolation`` of a rectangle at ``frame`` between two boxes."""
    offset = (frame - box0.frame) / (box1.frame - box0.frame)
    xtl, ytl, xbr, ybr = (
        a + (b - a) * offset
        for a, b in zip(
            (box0.xtl, box0.ytl, box0.xbr, box0.ybr),
            (box1.xtl, box1.ytl, box1.xbr, box1.ybr),
            strict=True,
        )
    )
    return replace(box0, frame=frame, xtl=xtl, ytl=ytl, xbr=xbr, ybr=ybr, keyframe=False)


def _with_attributes_of(box: CvatBox, previous: CvatBox) -> CvatBox:
    """``box`` with the attributes of ``previous`` it lacks (CVAT propagates them)."""
    names = {n for n, _ in box.attributes}
    missing = tuple((n, v) for n, v in previous.attributes if n not in names)
    return replace(box, attributes=box.attributes + missing) if missing else box


def visible_boxes(track: CvatTrack, frames: Sequence[int]) -> dict[int, CvatBox]:
    """The track's box on each of ``frames`` (ascending) where it is visible, as CVAT shows it.

    Listed boxes as they are; between two listed boxes, the first not ``outside``, linear
    interpolation; after the last listed box, if not ``outside``, that box to the end of
    ``frames``; nothing before the first box, at ``outside`` boxes, and from an ``outside``
    box to the next one.
    """
    boxes = sorted(track.boxes, key=lambda b: b.frame)
    out: dict[int, CvatBox] = {}
    if not boxes:
        return out
    wanted = [f for f in frames if f >= boxes[0].frame]
    previous: CvatBox | None = None
    position = 0  # index into `wanted`
    for box in boxes:
        if previous is not None:
            box = _with_attributes_of(box, previous)
        while position < len(wanted) and wanted[position] < box.frame:
            if previous is not None and not previous.outside:
                out[wanted[position]] = _interpolated(previous, box, wanted[position])
            position += 1
        if position < len(wanted) and wanted[position] == box.frame:
            if not box.outside:
                out[box.frame] = box
            position += 1
        previous = box
    if previous is not None and not previous.outside:
        for frame in wanted[position:]:
            out[frame] = replace(previous, frame=frame, keyframe=False)
    return out


# ----------------------------------------------------------------------------- reading


def _error(source: str) -> Callable[[str], GroundTruthError]:
    return lambda message: GroundTruthError(source, message)


def _int(text: str | None, what: str, error: Callable[[str], GroundTruthError]) -> int:
    try:
        return int((text or "").strip())
    except ValueError:
        raise error(f"{what} {text!r} is not an integer") from None


def _flag(value: str | None, what: str, error: Callable[[str], GroundTruthError]) -> bool:
    """CVAT writes flags as ``0``/``1``; a missing one is 0."""
    text = (value or "0").strip().lower()
    if text in ("0", "false"):
        return False
    if text in ("1", "true"):
        return True
    raise error(f"{what}={value!r}: expected 0 or 1")


def _number(value: str | None, what: str, error: Callable[[str], GroundTruthError]) -> float:
    try:
        number = float((value or "").strip())
    except ValueError:
        raise error(f"{what}={value!r} is not a number") from None
    if not math.isfinite(number):
        raise error(f"{what}={value!r} is not finite")
    return number


def _task(meta: ET.Element | None, error: Callable[[str], GroundTruthError]) -> CvatTask:
    if meta is None:
        raise error("<meta> is missing: not a CVAT export")
    project = meta.find("project")
    if project is not None and meta.find("task") is None:
        tasks = project.findall("tasks/task")
        if len(tasks) != 1:
            raise error(
                f"a project export with {len(tasks)} tasks: export the task of this recording"
            )
        element: ET.Element | None = tasks[0]
    else:
        element = meta.find("task")
        if element is None:
            element = meta.find("job")
    if element is None:
        raise error("<meta> has no <task> (or <job>): not a CVAT for video export")
    size = _int(element.findtext("size"), "<size>", error)
    if size < 1:
        raise error(f"<size> {size}: the task has no frames")
    start = _int(element.findtext("start_frame") or "0", "<start_frame>", error)
    step_text = element.findtext("frame_filter") or ""
    step = 1
    if step_text.strip():
        match = _STEP.match(step_text)
        if match is None or int(match.group(1)) < 1:
            raise error(f"<frame_filter> {step_text!r}: expected empty or step=N")
        step = int(match.group(1))
    stop_text = element.findtext("stop_frame")
    stop = (
        _int(stop_text, "<stop_frame>", error)
        if stop_text and stop_text.strip()
        else start + (size - 1) * step
    )
    if start < 0 or stop < start:
        raise error(f"<start_frame> {start} and <stop_frame> {stop} give no frames")
    count = len(range(start, stop + 1, step))
    if count != size:
        raise error(
            f"<size> {size}, but frames {start} to {stop} every {step} are {count}: "
            "the file contradicts itself"
        )
    width = height = None
    original = element.find("original_size")
    if original is not None:
        width = _int(original.findtext("width"), "<original_size><width>", error)
        height = _int(original.findtext("height"), "<original_size><height>", error)
        if width < 1 or height < 1:
            raise error(f"<original_size> {width}x{height} is not an image size")
    labels = tuple(
        (label.findtext("name") or "").strip() for label in element.findall("labels/label")
    )
    return CvatTask(size, start, stop, step, width, height, element.findtext("name") or "", labels)


def _box(element: ET.Element, error: Callable[[str], GroundTruthError]) -> CvatBox:
    a = element.attrib
    if "frame" not in a:
        raise error("a <box> has no frame")
    frame = _int(a["frame"], "frame", error)
    where = f"frame {frame}"

    def err(message: str) -> GroundTruthError:
        return error(f"{where}: {message}")

    xtl, ytl, xbr, ybr = (_number(a.get(k), k, err) for k in ("xtl", "ytl", "xbr", "ybr"))
    box = CvatBox(
        frame=frame,
        xtl=xtl,
        ytl=ytl,
        xbr=xbr,
        ybr=ybr,
        outside=_flag(a.get("outside"), "outside", err),
        occluded=_flag(a.get("occluded"), "occluded", err),
        keyframe=_flag(a.get("keyframe", "1"), "keyframe", err),
        z_order=_int(a.get("z_order", "0"), "z_order", err),
        attributes=tuple(
            (attr.get("name", ""), (attr.text or "").strip())
            for attr in element.findall("attribute")
        ),
    )
    if not box.outside and (box.xbr <= box.xtl or box.ybr <= box.ytl):
        raise err(f"box ({xtl}, {ytl})-({xbr}, {ybr}) has no area")
    return box


def _check_frames(
    track: CvatTrack, task: CvatTask, error: Callable[[str], GroundTruthError]
) -> None:
    """Every box on a frame of the task (a closing ``outside`` box may follow the last one)."""
    seen: set[int] = set()
    for box in track.boxes:
        if box.frame in seen:
            raise error(f"track {track.track_id}: frame {box.frame} has two boxes")
        seen.add(box.frame)
        on_grid = box.frame >= task.start_frame and (box.frame - task.start_frame) % task.step == 0
        after = box.frame > task.stop_frame
        if not on_grid or (after and not box.outside):
            raise error(
                f"track {track.track_id}: frame {box.frame} is not a frame of the task "
                f"({task.start_frame} to {task.stop_frame} every {task.step}; another task's "
                "annotations?)"
            )


def parse_cvat_xml(text: str, source: str) -> CvatAnnotations:
    """A CVAT for video 1.1 export; :class:`GroundTruthError` naming ``source`` otherwise."""
    error = _error(source)
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise error("an XML document type (<!DOCTYPE>) is not part of a CVAT export")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise error(f"not well-formed XML ({err})") from err
    if root.tag != "annotations":
        raise error(f"root element <{root.tag}>: expected <annotations> (a CVAT XML export)")
    version = (root.findtext("version") or "").strip()
    if version != "1.1":
        raise error(f"<version> {version or 'missing'}: expected CVAT for video 1.1")
    if root.find("image") is not None:
        raise error(
            "per-image boxes (CVAT for images 1.1): export the task as 'CVAT for video 1.1'"
        )
    task = _task(root.find("meta"), error)
    tracks: list[CvatTrack] = []
    other: dict[str, int] = {}
    ids: set[int] = set()
    for element in root.findall("track"):
        track_id = _int(element.get("id"), "<track> id", error)
        if track_id in ids:
            raise error(f"track id {track_id} is used by two tracks")
        ids.add(track_id)
        label = element.get("label")
        if label is None:
            raise error(f"track {track_id} has no label")
        kinds = {child.tag for child in element if child.tag in OTHER_SHAPES}
        if kinds:
            for kind in kinds:
                other[kind] = other.get(kind, 0) + 1
            continue

        def track_error(message: str, track_id: int = track_id) -> GroundTruthError:
            return error(f"track {track_id}: {message}")

        boxes = tuple(_box(child, track_error) for child in element.findall("box"))
        track = CvatTrack(track_id, label, boxes, element.get("source", "manual"))
        _check_frames(track, task, error)
        tracks.append(track)
    return CvatAnnotations(source, task, tuple(tracks), other)


def _mot_labels(text: str | None) -> tuple[str, ...]:
    if text is None:
        return MOT_LABELS
    return tuple(line.strip() for line in text.splitlines() if line.strip())


def parse_mot(gt_text: str, labels_text: str | None, source: str) -> CvatAnnotations:
    """CVAT's MOT 1.1 ``gt.txt`` (with ``labels.txt`` when given), frames numbered from 0.

    As CVAT's importer: rows with track id -1 or 0 are boxes of no track (refused here: ground
    truth needs identities); a visibility of 0 is CVAT's ``occluded``; ``not_ignored`` 0 sets
    the attribute ``ignored``; a gap in a track's frames and the frame after its last row are
    ``outside``.
    """
    error = _error(source)
    labels = _mot_labels(labels_text)
    rows: dict[int, dict[int, CvatBox]] = {}
    track_labels: dict[int, str] = {}
    no_track = 0
    for number, row in enumerate(csv.reader(io.StringIO(gt_text)), start=1):
        if not row or not "".join(row).strip():
            continue

        def line_error(message: str, number: int = number) -> GroundTruthError:
            return error(f"line {number}: {message}")

        if len(row) < 6:
            raise line_error(
                f"{len(row)} fields; expected frame,id,x,y,w,h[,flag,class,visibility]"
            )
        frame = _int(row[0], "frame", line_error) - 1
        if frame < 0:
            raise line_error(f"frame {frame + 1}: MOT frames count from 1")
        track_id = _int(row[1], "track id", line_error)
        x, y, w, h = (_number(v, k, line_error) for v, k in zip(row[2:6], "xywh", strict=True))
        if w <= 0 or h <= 0:
            raise line_error(f"box {w}x{h} has no area")
        not_ignored = _number(row[6], "not_ignored", line_error) if len(row) > 6 else 1.0
        class_id = _int(row[7], "class_id", line_error) if len(row) > 7 and row[7].strip() else 1
        visibility = _number(row[8], "visibility", line_error) if len(row) > 8 else 1.0
        if not 0.0 <= visibility <= 1.0:
            raise line_error(f"visibility {visibility} outside [0, 1]")
        if track_id <= 0:
            no_track += 1
            continue
        if not 1 <= class_id <= len(labels):
            raise line_error(f"class {class_id}: the labels are 1 to {len(labels)}")
        label = labels[class_id - 1]
        if track_labels.setdefault(track_id, label) != label:
            raise line_error(f"track {track_id} changes its label to {label!r}")
        attributes: tuple[tuple[str, str], ...] = (("visibility", repr(visibility)),)
        if not_ignored == 0:
            attributes += (("ignored", "true"),)
        box = CvatBox(frame, x, y, x + w, y + h, occluded=visibility <= 0.0, attributes=attributes)
        per_frame = rows.setdefault(track_id, {})
        if frame in per_frame:
            raise line_error(f"track {track_id} has two boxes in frame {frame + 1}")
        per_frame[frame] = box
    if no_track:
        raise error(
            f"{no_track} boxes have no track id (-1 or 0): ground truth needs identities; "
            "draw people as tracks in CVAT"
        )
    tracks = []
    for track_id in sorted(rows):
        frames = sorted(rows[track_id])
        boxes: list[CvatBox] = []
        for i, frame in enumerate(frames):
            box = rows[track_id][frame]
            boxes.append(box)
            following = frames[i + 1] if i + 1 < len(frames) else None
            if following is None or following > frame + 1:
                boxes.append(replace(box, frame=frame + 1, outside=True))
        tracks.append(CvatTrack(track_id, track_labels[track_id], tuple(boxes)))
    return CvatAnnotations(source, None, tuple(tracks), {}, kind="MOT 1.1")


def _zip_member(archive: zipfile.ZipFile, name: str, source: str) -> str | None:
    """A member's text (its name with or without one leading folder), or None when absent."""
    error = _error(source)
    members = [
        i for i in archive.infolist() if i.filename == name or i.filename.endswith("/" + name)
    ]
    if not members:
        return None
    info = min(members, key=lambda i: i.filename.count("/"))
    if info.file_size > _MAX_MEMBER_BYTES:
        raise error(f"{info.filename} is {info.file_size} bytes, more than the limit")
    try:
        data = archive.read(info)
    except (zipfile.BadZipFile, OSError, ValueError) as err:
        raise error(f"cannot read {info.filename} from the zip ({err})") from err
    return decode_text(data, error, info.filename)


def _text(path: Path) -> str:
    error = _error(str(path))
    return decode_text(read_bytes(path, error, "annotations"), error, "annotations")


def load_cvat(path: Path) -> CvatAnnotations:
    """A CVAT export: the zip CVAT downloads, its ``annotations.xml`` or ``gt/gt.txt``, or a
    folder holding either (format from the content)."""
    path = Path(path)
    source = str(path)
    error = _error(source)
    if not path.exists():
        raise error("not found")
    check_input(path, error, "annotations", allow_dir=True)
    if path.is_dir():
        if (path / XML_NAME).is_file():
            return parse_cvat_xml(_text(path / XML_NAME), str(path / XML_NAME))
        gt = path / MOT_GT
        if gt.is_file():
            return parse_mot(_text(gt), _labels_beside(gt), str(gt))
        raise error(f"folder holds neither {XML_NAME} (CVAT for video 1.1) nor {MOT_GT} (MOT 1.1)")
    if zipfile.is_zipfile(path):
        try:
            with zipfile.ZipFile(path) as archive:
                xml = _zip_member(archive, XML_NAME, source)
                if xml is not None:
                    return parse_cvat_xml(xml, source)
                gt_text = _zip_member(archive, MOT_GT, source)
                if gt_text is not None:
                    labels = _zip_member(archive, MOT_LABELS_NAME, source)
                    return parse_mot(gt_text, labels, source)
        except zipfile.BadZipFile as err:
            raise error(f"not a readable zip ({err})") from err
        raise error(f"zip holds neither {XML_NAME} (CVAT for video 1.1) nor {MOT_GT} (MOT 1.1)")
    text = _text(path)
    if text.lstrip().startswith("<"):
        return parse_cvat_xml(text, source)
    return parse_mot(text, _labels_beside(path), source)


def _labels_beside(gt: Path) -> str | None:
    """``labels.txt`` beside ``gt.txt`` (CVAT) or in its parent folder (older datumaro)."""
    for candidate in (gt.parent / MOT_LABELS_NAME, gt.parent.parent / MOT_LABELS_NAME):
        if candidate.is_file():
            return _text(candidate)
    return None


# ----------------------------------------------------------------------------- writing


def _coord(value: float) -> str:
    return f"{value:.2f}"  # CVAT's own precision


def cvat_xml(task: CvatTask, tracks: Iterable[CvatTrack]) -> str:
    """CVAT for video 1.1 XML, laid out as CVAT's exporter lays it out (same writer, same
    element order, coordinates with 2 decimals)."""
    buffer = io.StringIO()
    gen = XMLGenerator(buffer, "utf-8")
    level = 0

    def indent() -> None:
        gen.ignorableWhitespace("\n" + "  " * level)

    def element(name: str, text: str = "", attrs: Mapping[str, str] | None = None) -> None:
        indent()
        gen.startElement(name, AttributesImpl(dict(attrs or {})))
        gen.characters(text)
        gen.endElement(name)

    def open_(name: str, attrs: Mapping[str, str] | None = None) -> None:
        nonlocal level
        indent()
        gen.startElement(name, AttributesImpl(dict(attrs or {})))
        level += 1

    def close(name: str) -> None:
        nonlocal level
        level -= 1
        indent()
        gen.endElement(name)

    gen.startDocument()
    gen.startElement("annotations", AttributesImpl({}))
    level = 1
    element("version", "1.1")
    open_("meta")
    open_("task")
    element("id", "0")
    element("name", task.name)
    element("size", str(task.size))
    element("mode", "interpolation")
    element("overlap", "0")
    element("bugtracker")
    element("start_frame", str(task.start_frame))
    element("stop_frame", str(task.stop_frame))
    element("frame_filter", task.frame_filter)
    open_("labels")
    for label in task.labels:
        open_("label")
        element("name", label)
        element("attributes")
        close("label")
    close("labels")
    open_("segments")
    open_("segment")
    element("id", "0")
    element("start", "0")
    element("stop", str(task.size - 1))
    element("url")
    close("segment")
    close("segments")
    if task.width is not None and task.height is not None:
        open_("original_size")
        element("width", str(task.width))
        element("height", str(task.height))
        close("original_size")
    close("task")
    close("meta")
    for track in tracks:
        open_("track", {"id": str(track.track_id), "label": track.label, "source": track.source})
        for box in sorted(track.boxes, key=lambda b: b.frame):
            attrs = {
                "frame": str(box.frame),
                "outside": str(int(box.outside)),
                "occluded": str(int(box.occluded)),
                "keyframe": str(int(box.keyframe)),
                "xtl": _coord(box.xtl),
                "ytl": _coord(box.ytl),
                "xbr": _coord(box.xbr),
                "ybr": _coord(box.ybr),
                "z_order": str(box.z_order),
            }
            open_("box", attrs)
            for name, value in box.attributes:
                element("attribute", value, {"name": name})
            close("box")
        close("track")
    level = 0
    indent()
    gen.endElement("annotations")
    gen.endDocument()
    return buffer.getvalue() + "\n"
