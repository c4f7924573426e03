"""A corpus of bad inputs, rebuilt in a temporary folder for each test.

Each :class:`Case` names a failure class of issue 21 (TRACEBACK, SILENT, WRONG-CODE,
HANG, MULTILINE, LEFTOVER), builds its inputs with the project's own writers (or by
corrupting what they wrote), and states the documented exit code the CLI must give.
The cases of issue 28 (sizes taken from inputs before allocating, values taken on
trust) follow the others.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import stat
import struct
import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.images import encode_depth_raw
from rgbd_eval.io.messages import CAMERA_INFO_TYPE, IMAGE_TYPE
from rgbd_eval.io.writer import DEPTH_INFO_TOPIC, Container, RecordingWriter
from rgbd_eval.types import OPTICAL_TO_BODY, Box2D, CameraModel, GroundTruthObject, Pose
from tests.fuzz.cli import run_isolated
from tests.io.conftest import (
    BASE_TO_CAMERA,
    DEPTH_CAM,
    DEPTH_OFFSET,
    PERIOD,
    RGB_CAM,
    T0,
    Spec,
    depth_image,
    odom_pose,
    rgb_image,
    write_recording,
)

GT_HEADER = "frame,stamp_ns,id,bb_left,bb_top,bb_width,bb_height,x,y,z,visibility\n"
FRAMES = 4


@dataclass(frozen=True)
class Case:
    """One bad input: how to build it, the command line, the documented exit code."""

    name: str
    kind: str  # the failure class it reproduces
    build: Callable[[Path], list[str]]  # writes inputs under the folder, returns CLI arguments
    code: int
    message: str = ""  # a fragment the one-line error must contain
    #: Checks after the command (e.g. that the user's files are untouched); raises on failure.
    check: Callable[[Path], None] | None = None
    #: Run in a fresh interpreter: stderr as a user sees it, Dask's own logging included.
    isolated: bool = False
    #: RLIMIT_FSIZE of the command: a write past it fails (EFBIG) as on a full disk.
    max_file_bytes: int | None = None


# ----------------------------------------------------------------------------- recordings


def good_recording(root: Path, name: str = "rec.mcap", container: Container = "mcap") -> Path:
    """A valid 4-frame recording (with its ground-truth topic)."""
    path = root / name
    if not path.exists():
        write_recording(path, container, Spec(n=FRAMES))
    return path


def write_rig(w: RecordingWriter, odom: Callable[[int], Pose] = odom_pose) -> None:
    """The test rig's static tf and 50 Hz odometry ``odom(stamp)`` over FRAMES frames."""
    w.write_static_transform(T0, "base_link", "camera_link", BASE_TO_CAMERA)
    w.write_static_transform(T0, "camera_link", "camera_rgb_optical_frame", OPTICAL_TO_BODY)
    w.write_static_transform(T0, "camera_link", "camera_depth_optical_frame", DEPTH_OFFSET)
    for k in range(FRAMES * 2 + 4):
        s = T0 - 20_000_000 + k * 20_000_000
        w.write_odometry(s, "odom", "base_link", odom(s))


def odd_recording(
    path: Path,
    container: Container = "ros1",
    odom: Callable[[int], Pose] = odom_pose,
    depth: Callable[[int], np.ndarray] = depth_image,
    rgb_cam: CameraModel = RGB_CAM,
    depth_cam: CameraModel = DEPTH_CAM,
) -> Path:
    """A 4-frame recording whose odometry, depth or image size is replaced."""
    with RecordingWriter(path, container) as w:
        write_rig(w, odom)
        for i in range(FRAMES):
            stamp = T0 + i * PERIOD
            rgb = rgb_image(i)[: rgb_cam.height, : rgb_cam.width]
            w.write_rgb(stamp, np.ascontiguousarray(rgb), rgb_cam)
            w.write_depth(
                stamp + 2_000_000, depth(i)[: depth_cam.height, : depth_cam.width], depth_cam
            )
    return path


#: Where :func:`damaged_ros1` writes its depth images (16UC1, as the writer's default).
DAMAGED_DEPTH_TOPIC = "/camera/depth/image_raw"


def damaged_ros1(
    path: Path,
    damaged: Callable[[int], bool],
    image: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
    info: Callable[[Any], Any] | None = None,
    cut: int = 0,
) -> Path:
    """A 4-frame ROS1 bag (odometry, ground truth) whose depth frames ``i`` with
    ``damaged(i)`` are altered: ``image`` rewrites the Image fields, ``info`` the
    CameraInfo message, ``cut`` drops that many bytes from the serialised Image."""
    with RecordingWriter(path, "ros1") as w:
        write_rig(w)
        for i, obj in enumerate(ground_truth_objects()):
            stamp = T0 + i * PERIOD
            w.write_rgb(stamp, rgb_image(i), RGB_CAM)
            fields = encode_depth_raw(depth_image(i), "16UC1")
            if damaged(i) and image is not None:
                fields = image(fields)
            header = w.header(stamp + 2_000_000, DEPTH_CAM.frame_id, DAMAGED_DEPTH_TOPIC)
            msg = w._t(IMAGE_TYPE)(header=header, **fields)
            if damaged(i) and cut:
                raw = bytes(w.store.serialize_ros1(msg, IMAGE_TYPE))[:-cut]
                w._writer.write(w._connection(DAMAGED_DEPTH_TOPIC, IMAGE_TYPE), stamp, raw)
            else:
                w.write_message(DAMAGED_DEPTH_TOPIC, IMAGE_TYPE, stamp, msg)
            cam_info = w.camera_info(stamp, DEPTH_CAM, DEPTH_INFO_TOPIC)
            if damaged(i) and info is not None:
                cam_info = info(cam_info)
            w.write_message(DEPTH_INFO_TOPIC, CAMERA_INFO_TYPE, stamp, cam_info)
            w.write_ground_truth(stamp, "odom", [obj])
    return path


def half_data(fields: dict[str, Any]) -> dict[str, Any]:
    """An Image whose payload lost its second half (data shorter than step * height)."""
    return {**fields, "data": fields["data"][: fields["data"].size // 2]}


def short_step(fields: dict[str, Any]) -> dict[str, Any]:
    """An Image whose step is one byte less than a row (width * 2 bytes for 16UC1)."""
    return {**fields, "step": fields["step"] - 1}


def zero_k(msg: Any) -> Any:
    """A CameraInfo with K all zero (an uncalibrated driver)."""
    return dataclasses.replace(msg, K=np.zeros(9))


def flip_byte(path: Path, offset: int) -> None:
    """Invert the bits of one byte of ``path``."""
    with path.open("r+b") as handle:
        handle.seek(offset)
        value = handle.read(1)[0]
        handle.seek(offset)
        handle.write(bytes([value ^ 0xFF]))


def mcap_chunk_data_offset(path: Path) -> int:
    """Offset of the middle of the first chunk's compressed records (MCAP spec, Chunk)."""
    data = path.read_bytes()
    pos = 8  # magic
    while pos < len(data):
        opcode, length = struct.unpack_from("<BQ", data, pos)
        if opcode == 0x06:  # Chunk: start 8, end 8, uncompressed size 8, crc 4, compression
            body = pos + 9
            clen = int(struct.unpack_from("<I", data, body + 28)[0])
            records_at = body + 32 + clen + 8  # after compression string and records length
            rlen = int(struct.unpack_from("<Q", data, body + 32 + clen)[0])
            return records_at + rlen // 2
        pos += 9 + length
    raise ValueError("no chunk")


def mcap_summary_offset(path: Path) -> int:
    """Offset of a byte inside the summary section (from the footer)."""
    data = path.read_bytes()
    footer = len(data) - 8 - 29
    summary_start = int(struct.unpack_from("<Q", data, footer + 9)[0])
    return summary_start + 20


def without_statistics(source: Path, target: Path) -> Path:
    """``source`` rewritten with the same records but no Statistics record in its summary."""
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer

    with source.open("rb") as fin, target.open("wb") as fout:
        reader = make_reader(fin)
        writer = Writer(fout, compression=CompressionType.ZSTD, use_statistics=False)
        writer.start(profile="ros2", library="test")
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        for schema, channel, message in reader.iter_messages():
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = writer.register_schema(
                    schema.name, schema.encoding, schema.data
                )
            if channel.id not in channels:
                channels[channel.id] = writer.register_channel(
                    channel.topic, channel.message_encoding, schemas.get(channel.schema_id, 0)
                )
            writer.add_message(
                channels[channel.id], message.log_time, message.data, message.publish_time
            )
        writer.finish()
    return target


def _nan_quat(stamp: int) -> Pose:
    p = odom_pose(stamp)
    return Pose(p.translation, (0.0, 0.0, float("nan"), 1.0)) if stamp > T0 else p


def _zero_quat(stamp: int) -> Pose:
    p = odom_pose(stamp)
    return Pose(p.translation, (0.0, 0.0, 0.0, 0.0)) if stamp > T0 else p


def _inf_pos(stamp: int) -> Pose:
    p = odom_pose(stamp)
    return Pose((float("inf"), 0.0, 0.0), p.rotation) if stamp > T0 else p


def _all_nan_depth(i: int) -> np.ndarray:
    return np.full((DEPTH_CAM.height, DEPTH_CAM.width), np.nan, dtype=np.float32)


def _all_zero_depth(i: int) -> np.ndarray:
    return np.zeros((DEPTH_CAM.height, DEPTH_CAM.width), dtype=np.float32)


def _recording_cases() -> list[Case]:
    def flipped_chunk(root: Path) -> list[str]:
        rec = root / "flip_chunk.mcap"
        write_recording(rec, "mcap", Spec(n=FRAMES))
        flip_byte(rec, mcap_chunk_data_offset(rec))
        return ["run", str(rec), "--out", str(root / "out")]

    def flipped_summary(root: Path) -> list[str]:
        rec = root / "flip_summary.mcap"
        write_recording(rec, "mcap", Spec(n=FRAMES))
        flip_byte(rec, mcap_summary_offset(rec))
        return ["run", str(rec), "--out", str(root / "out")]

    def empty_mcap(root: Path) -> list[str]:
        (root / "empty.mcap").write_bytes(b"")
        return ["run", str(root / "empty.mcap"), "--out", str(root / "out")]

    def fifo(suffix: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            os.mkfifo(root / f"pipe{suffix}")
            return ["inspect", str(root / f"pipe{suffix}")]

        return build

    def devzero(root: Path) -> list[str]:
        (root / "zero.bag").symlink_to("/dev/zero")
        return ["inspect", str(root / "zero.bag")]

    def zero_filled(root: Path) -> list[str]:
        with (root / "zeros.bag").open("wb") as handle:  # sparse: 300 MB of zeros, no disk
            handle.truncate(300 << 20)
        return ["run", str(root / "zeros.bag"), "--out", str(root / "out")]

    def odd(name: str, **kwargs: object) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            rec = odd_recording(root / f"{name}.bag", **kwargs)  # type: ignore[arg-type]
            return ["run", str(rec), "--out", str(root / "out")]

        return build

    tiny = CameraModel(1, 1, 1.0, 1.0, 0.0, 0.0, (0.0,) * 5, "camera_rgb_optical_frame")
    tiny_depth = CameraModel(1, 1, 1.0, 1.0, 0.0, 0.0, (0.0,) * 5, "camera_depth_optical_frame")
    return [
        Case("flip_chunk_mcap", "SILENT", flipped_chunk, 3, "crc"),
        Case("flip_summary_mcap", "SILENT", flipped_summary, 3, "summary section CRC"),
        Case("empty_mcap", "MISLEADING", empty_mcap, 3, "0 bytes"),
        Case("fifo_mcap", "HANG", fifo(".mcap"), 3, "named pipe"),
        Case("fifo_bag", "HANG", fifo(".bag"), 3, "named pipe"),
        Case("devzero_bag", "HANG", devzero, 3, "device"),
        Case("zero_filled_bag", "HANG", zero_filled, 3, "not a ROS1 bag"),
        Case("odom_nan_quat", "SILENT", odd("odom_nan_quat", odom=_nan_quat), 3, "/odom"),
        Case("odom_zero_quat", "TRACEBACK", odd("odom_zero_quat", odom=_zero_quat), 3, "norm 0"),
        Case("odom_inf_pos", "SILENT", odd("odom_inf_pos", odom=_inf_pos), 3, "not finite"),
        Case("depth_all_nan", "SILENT", odd("depth_nan", depth=_all_nan_depth), 3, "no depth"),
        Case("depth_all_zero", "SILENT", odd("depth_zero", depth=_all_zero_depth), 3, "no depth"),
        Case(
            "image_1x1",
            "SILENT",
            odd("img_1x1", rgb_cam=tiny, depth_cam=tiny_depth),
            3,
            "smaller than",
        ),
    ]


# ----------------------------------------------------------------------------- ground truth


def _gt_case(name: str, text: bytes, code: int, message: str, suffix: str = ".csv") -> Case:
    def build(root: Path) -> list[str]:
        gt = root / f"{name}{suffix}"
        gt.write_bytes(text)
        return ["run", str(good_recording(root)), "--gt", str(gt), "--out", str(root / "out")]

    return Case(f"gt_{name}", "GROUND-TRUTH", build, code, message)


def _gt_cases() -> list[Case]:
    row = "0,0,1,10,5,8,30,2.0,0.1,0.9,1\n"
    stamp = T0 / 1e9

    def fifo(root: Path) -> list[str]:
        os.mkfifo(root / "pipe.csv")
        return ["run", str(good_recording(root)), "--gt", str(root / "pipe.csv")]

    return [
        Case("gt_fifo", "HANG", fifo, 5, "named pipe"),
        _gt_case("short_row", (GT_HEADER + "0,0,1,10\n").encode(), 5, "fewer fields"),
        _gt_case("long_row", (GT_HEADER + row.strip() + ",1,2,3\n").encode(), 5, "more fields"),
        _gt_case("latin1", (GT_HEADER + "# caf\xe9\n").encode("latin-1"), 5, "not UTF-8"),
        _gt_case("binary", bytes(range(256)) * 4, 5, "not UTF-8"),
        _gt_case("nan_box", (GT_HEADER + "0,0,1,10,5,nan,30,,,,1\n").encode(), 5, "finite"),
        _gt_case("inf_box", (GT_HEADER + "0,0,1,10,5,inf,30,,,,1\n").encode(), 5, "finite"),
        _gt_case("inf_xyz", (GT_HEADER + "0,0,1,10,5,8,30,inf,0.1,0.9,1\n").encode(), 5, "finite"),
        _gt_case("part_box", (GT_HEADER + "0,0,1,10,,8,30,,,,1\n").encode(), 5, "partly"),
        _gt_case("huge_id", (GT_HEADER + f"0,0,{2**60},10,5,8,30,,,,1\n").encode(), 5, "2**53"),
        _gt_case("header_only", GT_HEADER.encode(), 5, "no annotated object"),
        _gt_case("ktp_nan", f"nan: 1 10 5 8 30\n{stamp}: 1 1 1 1 1\n".encode(), 5, "stamp", ".txt"),
        _gt_case("ktp_inf_value", f"{stamp}: 1 10 5 inf 30\n".encode(), 5, "not finite", ".txt"),
        _gt_case("ktp_neg_box", f"{stamp}: 1 10 10 -50 -100\n".encode(), 5, "negative", ".txt"),
    ]


# ----------------------------------------------------------------------------- configs


def _cfg_case(name: str, text: bytes, code: int, message: str) -> Case:
    def build(root: Path) -> list[str]:
        cfg = root / f"{name}.yaml"
        cfg.write_bytes(text)
        rec = good_recording(root)
        return ["run", str(rec), "--config", str(cfg), "--out", str(root / "out")]

    return Case(f"cfg_{name}", "CONFIG", build, code, message)


def _set_case(name: str, sets: list[str], code: int, message: str, kind: str = "TRACEBACK") -> Case:
    def build(root: Path) -> list[str]:
        extra = [a for s in sets for a in ("--set", s)]
        return ["run", str(good_recording(root)), *extra, "--out", str(root / "out")]

    return Case(f"set_{name}", kind, build, code, message)


_BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
    for p, c in zip("abcdefgh", "bcdefghi", strict=True)
)


def _config_cases() -> list[Case]:
    def fifo(root: Path) -> list[str]:
        os.mkfifo(root / "pipe.yaml")
        return ["run", str(good_recording(root)), "--config", str(root / "pipe.yaml")]

    return [
        _cfg_case(
            "dup_keys", b"tracker:\n  min_confidence: -1\n  min_confidence: 0\n", 4, "duplicate"
        ),
        _cfg_case("latin1", "tracker: {min_confidence: caf\xe9}\n".encode("latin-1"), 4, "UTF-8"),
        _cfg_case("nan", b"tracker:\n  min_confidence: .nan\n", 4, "finite"),
        _cfg_case("bom", b"\xef\xbb\xbftracker:\n  min_confidence: 0\n", 0, ""),
        _cfg_case("alias_bomb", _BOMB.encode(), 4, "aliases"),
        Case("cfg_fifo", "HANG", fifo, 4, "named pipe"),
        _set_case("nan_minconf", ["tracker.min_confidence=.nan"], 4, "--set"),
        _set_case("inf_maxdist", ["detector.max_distance=.inf"], 4, "finite"),
        _set_case("rate_tiny", ["tracker.reference_rate_hz=1e-300"], 4, "reference_rate_hz"),
        _set_case(
            "plane_zero",
            ["detector.ground_mode=plane", "detector.ground_plane=[0,0,0,0]"],
            4,
            "normal",
        ),
        _set_case(
            "points_collinear",
            ["detector.ground_mode=points", "detector.ground_points=[[0,0,1],[0,0,2],[0,0,3]]"],
            4,
            "collinear",
        ),
        _set_case(
            "pixels_outside",
            ["detector.ground_mode=points", "detector.ground_pixels=[[1,1],[99999,0],[0,2]]"],
            4,
            "off the",
            "SILENT",
        ),
        _set_case(
            "threshold_inf", ["evaluation.gating=metric", "evaluation.threshold=.inf"], 4, ""
        ),
        Case(  # a detector/tracker check was blamed on methods/pinto2022/method.yaml alone
            "set_reid_units",
            "MISLEADING",
            lambda root: [
                "run",
                str(good_recording(root)),
                "--method",
                "pinto2022",
                "--set",
                "detector.reid.backend=mobilenet",
                "--out",
                str(root / "out"),
            ],
            4,
            "with --set detector.reid.backend=mobilenet",
        ),
    ]


# ----------------------------------------------------------------------------- usage


def _usage_cases() -> list[Case]:
    def args(*a: str) -> Callable[[Path], list[str]]:
        return lambda root: list(a)

    return [
        Case("usage_bad_number", "MULTILINE", args("run", "--threshold", "abc"), 2, "--threshold"),
        Case("usage_unknown_option", "MULTILINE", args("run", "--bogus"), 2, "--bogus"),
        Case("usage_no_command", "MULTILINE", args(), 2, "no command"),
        Case("usage_bad_command", "MULTILINE", args("frobnicate"), 2, "frobnicate"),
    ]


# ----------------------------------------------------------------------------- outputs


def _output_cases() -> list[Case]:
    def out_is_file(root: Path) -> list[str]:
        (root / "file.txt").write_text("mine\n")
        return ["run", str(good_recording(root)), "--out", str(root / "file.txt")]

    def out_parent_is_file(root: Path) -> list[str]:
        (root / "afile").write_text("mine\n")
        return ["run", str(good_recording(root)), "--out", str(root / "afile" / "sub")]

    def out_proc(root: Path) -> list[str]:
        return ["run", str(good_recording(root)), "--out", "/proc/rgbd_eval_out"]

    def foreign(root: Path) -> list[str]:
        (root / "out").mkdir()
        (root / "out" / "notes.txt").write_text("mine\n")
        return ["run", str(good_recording(root)), "--out", str(root / "out")]

    def synth_into_folder(root: Path) -> list[str]:
        (root / "data").mkdir()
        (root / "data" / "notes.txt").write_text("mine\n")
        return ["synth", "demo", "--frames", "1", "-o", str(root / "data")]

    def preview_bad_dir(root: Path) -> list[str]:
        (root / "afile").write_text("mine\n")
        return ["synth", "demo", "--frames", "1", "--preview", str(root / "afile" / "p.png")]

    return [
        Case("out_is_file", "TRACEBACK", out_is_file, 7, "not a folder"),
        Case("out_parent_is_file", "TRACEBACK", out_parent_is_file, 7, "cannot create"),
        Case("out_proc", "TRACEBACK", out_proc, 7, ""),
        Case("out_foreign_folder", "DATA-LOSS", foreign, 7, "--force"),
        Case("synth_into_folder", "DATA-LOSS", synth_into_folder, 7, "folder"),
        Case("synth_preview_bad_dir", "TRACEBACK", preview_bad_dir, 7, ""),
    ]


# ----------------------------------------------------------------------------- compare


def report(
    metrics: Mapping[str, object] | None, name: str = "rec", **extra: object
) -> dict[str, object]:
    """A minimal valid report with one sequence."""
    data: dict[str, object] = {
        "schema_version": 1,
        "evaluation": {"gating": "iou", "threshold": 0.5},
        "config": {},
        "sequences": [{"name": name, "sha256": "0" * 64, "metrics": metrics}],
        "overall": None,
    }
    data.update(extra)
    return data


BASE_METRICS = {"mota": 0.7, "motp": 0.8, "idf1": 0.75, "fp_rate": 0.1, "fn_rate": 0.2}


def _cmp_case(
    name: str,
    current: object,
    code: int,
    message: str,
    raw: bytes | None = None,
    extra: tuple[str, ...] = (),
) -> Case:
    def build(root: Path) -> list[str]:
        (root / "base.json").write_text(json.dumps(report(BASE_METRICS)))
        cur = root / f"{name}.json"
        cur.write_bytes(raw if raw is not None else json.dumps(current).encode())
        return ["compare", str(root / "base.json"), str(cur), *extra]

    return Case(f"cmp_{name}", "COMPARE", build, code, message)


def _compare_cases() -> list[Case]:
    seq_str = report(BASE_METRICS)
    seq_str["sequences"] = ["rec"]
    no_name = report(BASE_METRICS)
    no_name["sequences"] = [{"metrics": BASE_METRICS}]
    no_eval = report(BASE_METRICS)
    del no_eval["evaluation"]
    lower = dict(BASE_METRICS, mota=0.5)

    def markdown_dir(root: Path) -> list[str]:
        (root / "base.json").write_text(json.dumps(report(BASE_METRICS)))
        (root / "md").mkdir()
        return [
            "compare",
            str(root / "base.json"),
            str(root / "base.json"),
            "--markdown",
            str(root / "md"),
        ]

    return [
        _cmp_case("schema_only", {"schema_version": 1}, 2, "evaluation"),
        _cmp_case("metrics_str", report({**BASE_METRICS, "mota": "high"}), 2, "not a number"),
        _cmp_case("no_name", no_name, 2, "name"),
        _cmp_case("seq_str", seq_str, 2, "name"),
        _cmp_case("no_eval", no_eval, 2, "evaluation"),
        _cmp_case(
            "nan",
            None,
            2,
            "NaN",
            raw=json.dumps(report(BASE_METRICS)).replace("0.7", "NaN").encode(),
        ),
        _cmp_case(
            "latin1", None, 2, "UTF-8", raw=json.dumps(report(BASE_METRICS)).encode() + b"\xe9"
        ),
        _cmp_case("unscored_current", report(None), 1, "missing now"),
        _cmp_case("mota_null", report({**BASE_METRICS, "mota": None}), 1, "rec/mota"),
        _cmp_case("metrics_empty", report({}), 1, "missing now"),
        _cmp_case("regressed", report(lower), 1, "1 regression(s) beyond tolerance: rec/mota"),
        _cmp_case("tolerance_nan", report(lower), 2, "finite", extra=("--tolerance", "mota=nan")),
        Case("cmp_markdown_dir", "TRACEBACK", markdown_dir, 7, "folder"),
    ]


def _other_command_cases() -> list[Case]:
    def with_bad_sidecar(root: Path) -> Path:
        rec = good_recording(root)
        (root / "rec.gt.csv").write_text(GT_HEADER + "0,0,1,10\n")  # a short row
        return rec

    def run_sidecar(root: Path) -> list[str]:
        return ["run", str(with_bad_sidecar(root)), "--out", str(root / "out")]

    def two_point_sweep(rec: Path, root: Path) -> list[str]:
        """A sweep of min_confidence over -1 and 0 on ``rec``, two jobs."""
        grid = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec)]
        return [*grid, "--jobs", "2", "--out", str(root / "out")]

    def sweep_sidecar(root: Path) -> list[str]:
        return two_point_sweep(with_bad_sidecar(root), root)

    def sweep_corrupt(root: Path) -> list[str]:
        rec = root / "flip.mcap"
        write_recording(rec, "mcap", Spec(n=FRAMES))
        flip_byte(rec, mcap_chunk_data_offset(rec))
        return two_point_sweep(rec, root)

    def sweep_nan(root: Path) -> list[str]:
        rec = good_recording(root)
        return [
            "sweep",
            "tracker.min_confidence",
            "-1",
            ".nan",
            "--dataset",
            str(rec),
            "--out",
            str(root / "out"),
        ]

    def inspect_bad_gt(root: Path) -> list[str]:
        (root / "short.csv").write_text(GT_HEADER + "0,0,1,10\n")
        return ["inspect", str(good_recording(root)), "--gt", str(root / "short.csv")]

    def zero_quat(command: str, *extra: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            rec = odd_recording(root / "zq.bag", odom=_zero_quat)
            return [command, str(rec), *extra]

        return build

    return [
        Case("run_sidecar_short_row", "TRACEBACK", run_sidecar, 5, "fewer fields"),
        Case("sweep_sidecar_short_row", "TRACEBACK", sweep_sidecar, 5, "fewer fields"),
        Case("sweep_nan_value", "TRACEBACK", sweep_nan, 4, "finite"),
        Case("sweep_corrupt_in_worker", "SILENT", sweep_corrupt, 3, "crc"),
        Case("inspect_bad_gt", "TRACEBACK", inspect_bad_gt, 5, "fewer fields"),
        Case("inspect_json_zero_quat", "TRACEBACK", zero_quat("inspect", "--json"), 3, "norm 0"),
        Case("bench_zero_quat", "TRACEBACK", zero_quat("bench", "--repeat", "1"), 3, "norm 0"),
    ]


def _damage_cases() -> list[Case]:
    """ROS1 bags carry no checksum: damaged messages are checked, skipped and counted;
    with nothing usable left the recording is refused (exit 3)."""

    def bag(name: str, **kwargs: Any) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            rec = damaged_ros1(root / f"{name}.bag", lambda i: True, **kwargs)
            return ["run", str(rec), "--out", str(root / "out")]

        return build

    def inspect_all_k_zero(root: Path) -> list[str]:
        rec = damaged_ros1(root / "kzero.bag", lambda i: True, info=zero_k)
        return ["inspect", str(rec), "--json"]

    return [
        Case("ros1_truncated_payload", "SILENT", bag("half", image=half_data), 3, "data holds"),
        Case("ros1_wrong_step", "SILENT", bag("step", image=short_step), 3, "step 63"),
        Case("ros1_cut_message", "TRACEBACK", bag("cut", cut=100), 3, "no usable message"),
        Case("ros1_camera_info_k_zero", "SILENT", bag("kzero", info=zero_k), 3, "K is all zero"),
        Case("inspect_camera_info_k_zero", "SILENT", inspect_all_k_zero, 3, "K is all zero"),
    ]


# MOTChallenge text: frame,id,x,y,w,h,conf,x,y,z (tracks) and frame,id,x,y,w,h,consider,class,vis.
MOT_TRACKS = "1,7,0,0,10,10,-1,-1,-1,-1\n2,7,0,0,10,10,-1,-1,-1,-1\n"
MOT_GT = "1,1,0,0,10,10,1,1,1.0\n2,1,0,0,10,10,1,1,1.0\n"


def _score_cases() -> list[Case]:
    """``score`` checks its output folder before it reads anything, as ``run`` does."""

    def score_into(
        prepare: Callable[[Path], Path], broken_input: bool = False
    ) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            (root / "tracks.txt").write_text("1,7,0,0\n" if broken_input else MOT_TRACKS)
            (root / "gt.txt").write_text(MOT_GT)
            out = prepare(root)
            return [
                "score",
                str(root / "tracks.txt"),
                "--gt",
                str(root / "gt.txt"),
                "--out",
                str(out),
            ]

        return build

    def a_file(root: Path) -> Path:
        (root / "file.txt").write_text("mine\n")
        return root / "file.txt"

    def foreign(root: Path) -> Path:
        (root / "out").mkdir()
        (root / "out" / "notes.txt").write_text("mine\n")
        return root / "out"

    def tracks_file(name: str, data: bytes) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            (root / name).write_bytes(data)
            (root / "gt.txt").write_text(MOT_GT)
            return [
                "score",
                str(root / name),
                "--gt",
                str(root / "gt.txt"),
                "--out",
                str(root / "o"),
            ]

        return build

    def tracks_fifo(root: Path) -> list[str]:
        os.mkfifo(root / "tracks.txt")
        (root / "gt.txt").write_text(MOT_GT)
        return ["score", str(root / "tracks.txt"), "--gt", str(root / "gt.txt")]

    header = b"frame,id,bb_left,bb_top,bb_width,bb_height,x,y,z,stamp_ns\n"
    return [
        Case(
            "score_tracks_csv_short_row",
            "TRACEBACK",
            tracks_file("t.csv", header + b"1,7,0,0\n"),
            3,
            "fewer fields",
        ),
        Case(
            "score_tracks_csv_bad_frame",
            "TRACEBACK",
            tracks_file("t.csv", header + b"x,7,0,0,10,10,1,1,1,0\n"),
            3,
            "line 2",
        ),
        Case(
            "score_tracks_csv_conf_nan",  # a NaN confidence would be dropped at every threshold
            "SILENT",
            tracks_file(
                "t.csv", header.replace(b",x,", b",conf,x,") + b"1,7,0,0,10,10,nan,1,1,1,0\n"
            ),
            3,
            "confidence nan is not finite",
        ),
        Case("score_tracks_fifo", "HANG", tracks_fifo, 3, "named pipe"),
        Case("score_out_is_file", "TRACEBACK", score_into(a_file), 7, "not a folder"),
        Case("score_out_foreign_folder", "DATA-LOSS", score_into(foreign), 7, "--force"),
        # The output problem is found first: the broken tracks file is never read.
        Case("score_out_before_input", "ORDER", score_into(a_file, True), 7, "not a folder"),
        Case("score_bad_tracks", "ORDER", score_into(lambda r: r / "out", True), 3, "lacks"),
    ]


def _model_and_cache_cases() -> list[Case]:
    def run_naming_file(
        name: str, data: bytes | None, method: str, *overrides: str
    ) -> Callable[[Path], list[str]]:
        """``run --method method`` with ``--set`` overrides naming ``root/name`` as ``{path}``:
        a file holding ``data``, or a named pipe when ``data`` is None."""

        def build(root: Path) -> list[str]:
            path = root / name
            if data is None:
                os.mkfifo(path)
            else:
                path.write_bytes(data)
            sets = [arg for o in overrides for arg in ("--set", o.format(path=path))]
            head = ["run", str(good_recording(root)), "--method", method]
            return [*head, *sets, "--out", str(root / "out")]

        return build

    not_a_model = run_naming_file(
        "model.onnx",
        b"not an onnx model\n" * 10,
        "pinto2022",
        "detector.person.backend=onnx",
        "detector.person.model={path}",
    )

    def det_txt(data: bytes | None) -> Callable[[Path], list[str]]:
        recorded = ("detector.person.backend=recorded", "detector.person.source={path}")
        return run_naming_file("det.txt", data, "pinto2022", *recorded)

    def calibration(data: bytes | None) -> Callable[[Path], list[str]]:
        return run_naming_file("calib.yaml", data, "dmtbs", "detector.calibration={path}")

    def reproduce_into_file(option: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            (root / "file.txt").write_text("mine\n")
            # Refused before any scenario is generated (that takes minutes).
            return ["reproduce", "basso2012", option, str(root / "file.txt")]

        return build

    latin = "1,-1,0,0,10,10,0.9\n# caf\xe9\n".encode("latin-1")
    return [
        Case("reproduce_data_is_file", "TRACEBACK", reproduce_into_file("--data"), 7, "--data"),
        Case("reproduce_out_is_file", "LATE", reproduce_into_file("--out"), 7, "not a folder"),
        Case("onnx_model_not_a_model", "TRACEBACK", not_a_model, 4, "cannot be loaded"),
        Case("det_txt_latin1", "TRACEBACK", det_txt(latin), 3, "not UTF-8"),
        Case("det_txt_fifo", "HANG", det_txt(None), 3, "named pipe"),
        Case(
            "calibration_latin1",
            "TRACEBACK",
            calibration("a: caf\xe9\n".encode("latin-1")),
            4,
            "not UTF-8",
        ),
        Case("calibration_fifo", "HANG", calibration(None), 4, "named pipe"),
        Case(
            "calibration_dup_key",
            "SILENT",
            calibration(b"cameras: {}\ncameras: {}\n"),
            4,
            "duplicate",
        ),
    ]


# ----------------------------------------------------------------------------- issue 28


def mine(root: Path, *names: str) -> None:
    """Files the user made, each holding ``the user's <name>``."""
    for name in names:
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(f"the user's {name}\n")


def kept(*names: str) -> Callable[[Path], None]:
    """A check that the user's files of :func:`mine` are still there, unchanged."""

    def check(root: Path) -> None:
        for name in names:
            assert (root / name).read_text() == f"the user's {name}\n", name

    return check


def device(path: Path, minor: int) -> Path:
    """A private copy of a memory device: /dev/null (minor 3) or /dev/full (minor 7)."""
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, minor))
    except PermissionError:
        pytest.skip("creating a device node needs CAP_MKNOD")
    return path


def still_a_device(name: str) -> Callable[[Path], None]:
    def check(root: Path) -> None:
        assert stat.S_ISCHR(os.lstat(root / name).st_mode), f"{name} was replaced"

    return check


def two_point_sweep(rec: Path, out: Path, *extra: str, cluster: str = "local:1") -> list[str]:
    """A sweep of min_confidence over -1 and 0 on ``rec`` (one in-process worker)."""
    grid = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec)]
    return [*grid, "--cluster", cluster, "--out", str(out), *extra]


def sweep_records(folder: Path) -> list[dict[str, object]]:
    """A sweep's records without their timings."""
    data = json.loads((folder / "sweep.json").read_text())
    return [{k: v for k, v in r.items() if "second" not in k} for r in data["records"]]


def _ownership_cases() -> list[Case]:
    """Outputs replace nothing but a regular file the same command wrote (issue 28)."""

    def cmp_reports(root: Path) -> tuple[Path, Path]:
        (root / "base1").mkdir()
        (root / "base1" / "report.json").write_text(json.dumps(report(BASE_METRICS)))
        (root / "cur.json").write_text(json.dumps(report(BASE_METRICS)))
        return root / "base1" / "report.json", root / "cur.json"

    def compare_onto(option: str, target: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            base, cur = cmp_reports(root)
            return ["compare", str(base), str(cur), option, str(root / target)]

        return build

    def compare_into_device(minor: int) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            base, cur = cmp_reports(root)
            return ["compare", str(base), str(cur), "--markdown", str(device(root / "DEV", minor))]

        return build

    def bench_into_full(root: Path) -> list[str]:
        rec = good_recording(root)
        html = str(device(root / "DEV", 7))
        return ["bench", str(rec), "--repeat", "1", "--all-cores", "--html", html]

    def preview_into_full(root: Path) -> list[str]:
        return ["synth", "demo", "--frames", "1", "--preview", str(device(root / "DEV", 7))]

    def run_into_users(*names: str, force: bool = False) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            mine(root, *(f"out/{n}" for n in names))
            args = ["run", str(good_recording(root)), "--out", str(root / "out")]
            return [*args, "--force"] if force else args

        return build

    def score_into_users(*names: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            mine(root, *(f"out/{n}" for n in names))
            (root / "t.txt").write_text(MOT_TRACKS)
            (root / "g.txt").write_text(MOT_GT)
            args = ["score", str(root / "t.txt"), "--gt", str(root / "g.txt")]
            return [*args, "--out", str(root / "out"), "--force"]

        return build

    def run_into_sweep_folder(root: Path) -> list[str]:
        rec = good_recording(root)
        first = run_isolated(two_point_sweep(rec, root / "res"), root)
        assert first.code == 0, first.stderr
        return ["run", str(rec), "--out", str(root / "res")]

    def sweep_kept(root: Path) -> None:
        names = {p.name for p in (root / "res").iterdir()}
        assert {"sweep.csv", "sweep.json", "sweep.html", "sweep.png", "report.json"} <= names
        assert len(sweep_records(root / "res")) == 2

    def score_into_run_folder(root: Path) -> list[str]:
        first = run_isolated(["run", str(good_recording(root)), "--out", str(root / "res")], root)
        assert first.code == 0, first.stderr
        (root / "t.txt").write_text(MOT_TRACKS)
        (root / "g.txt").write_text(MOT_GT)
        return [
            "score",
            str(root / "t.txt"),
            "--gt",
            str(root / "g.txt"),
            "--out",
            str(root / "res"),
        ]

    def run_kept(root: Path) -> None:
        names = {p.name for p in (root / "res").iterdir()}
        assert {"rec.tracks.csv", "rec.detections.csv", "rec.birdseye.png"} <= names
        assert json.loads((root / "res" / "report.json").read_text())["sequences"][0]["frames"]

    def import_over_sidecar(root: Path) -> list[str]:
        from tests.io.epfl_folder import write_sequence

        folder = write_sequence(root, [(4.0, 0.0)])
        mine(root, "x.gt.csv")
        return ["import", "epfl-rgbd", str(folder), "-o", str(root / "x.mcap")]

    def synth_over_sidecar(root: Path) -> list[str]:
        mine(root, "rig.bag", "rig.gt.csv")  # the user's recording and its annotations
        return ["synth", "demo", "--frames", "1", "-o", str(root / "rig.mcap")]

    return [
        Case(
            "bench_html_dev_full", "DATALOSS", bench_into_full, 7, "device", still_a_device("DEV")
        ),
        Case(
            "cmp_html_onto_current",
            "DATALOSS",
            compare_onto("--html", "cur.json"),
            7,
            "input",
            lambda root: json.loads((root / "cur.json").read_text()),
        ),
        Case("cmp_markdown_dev_full", "DATALOSS", compare_into_device(7), 7, "device"),
        Case("cmp_markdown_dev_null_private", "DATALOSS", compare_into_device(3), 7, "device"),
        Case(
            "cmp_markdown_onto_baseline",
            "DATALOSS",
            compare_onto("--markdown", "base1/report.json"),
            7,
            "input",
            lambda root: json.loads((root / "base1" / "report.json").read_text()),
        ),
        Case("synth_preview_dev_full", "DATALOSS", preview_into_full, 7, "device"),
        Case(
            "out_force_user_report_md",
            "DATALOSS",
            run_into_users("report.md", "notes.txt", force=True),
            7,
            "report.md",
            kept("out/report.md", "out/notes.txt"),
        ),
        Case(
            "out_force_user_report_html",
            "DATALOSS",
            run_into_users("report.html", force=True),
            7,
            "report.html",
            kept("out/report.html"),
        ),
        Case(
            "out_user_report_json_no_manifest",
            "DATALOSS",
            run_into_users("report.json"),
            7,
            "--force",
            kept("out/report.json"),
        ),
        Case(
            "out_force_user_tracks_csv",
            "DATALOSS",
            run_into_users("rec.tracks.csv", force=True),
            7,
            "rec.tracks.csv",
            kept("out/rec.tracks.csv"),
        ),
        Case(
            "out_force_user_frames_npz",
            "DATALOSS",
            run_into_users("rec.frames.npz", force=True),
            7,
            "rec.frames.npz",
            kept("out/rec.frames.npz"),
        ),
        Case(
            "out_force_score_user_frames_npz",
            "DATALOSS",
            score_into_users("t.frames.npz"),
            7,
            "t.frames.npz",
            kept("out/t.frames.npz"),
        ),
        Case(
            "out_run_into_sweep_folder",
            "DATALOSS",
            run_into_sweep_folder,
            0,
            check=sweep_kept,
            isolated=True,
        ),
        Case(
            "out_score_into_run_folder",
            "DATALOSS",
            score_into_run_folder,
            7,
            "written by `rgbd-eval run`",
            run_kept,
            isolated=True,
        ),
        Case(
            "import_over_users_sidecar",
            "DATALOSS",
            import_over_sidecar,
            7,
            "x.gt.csv",
            kept("x.gt.csv"),
        ),
        Case(
            "synth_new_mcap_over_users_sidecar",
            "DATALOSS",
            synth_over_sidecar,
            7,
            "rig.gt.csv",
            kept("rig.bag", "rig.gt.csv"),
        ),
    ]


def _path_and_disk_cases() -> list[Case]:
    def javascript_video(root: Path) -> list[str]:
        rec = good_recording(root, "javascript:alert(document.domain).mcap")
        return ["run", str(rec), "--video", "--out", str(root / "out")]

    def relative_link(root: Path) -> None:
        page = (root / "out" / "report.html").read_text()
        assert 'href="javascript:' not in page
        assert 'href="./javascript%3Aalert%28document.domain%29.overlay.mp4"' in page

    def long_out(root: Path) -> list[str]:
        return ["run", str(good_recording(root)), "--out", str(root / ("o" * 300))]

    def synth_on_full_disk(root: Path) -> list[str]:
        (root / "full").mkdir()
        return ["synth", "demo", "--frames", "5", "-o", str(root / "full" / "x.mcap")]

    def run_on_full_disk(root: Path) -> list[str]:
        return ["run", str(good_recording(root)), "--out", str(root / "out")]

    def out_symlink(root: Path) -> list[str]:
        (root / "real").mkdir()
        (root / "out").symlink_to("real")
        return ["run", str(good_recording(root)), "--out", str(root / "out")]

    def written_through_the_link(root: Path) -> None:
        assert (root / "out").is_symlink()
        assert json.loads((root / "real" / "report.json").read_text())["sequences"]

    return [
        Case(
            "html_video_link_javascript",
            "INJECTION",
            javascript_video,
            0,
            check=relative_link,
        ),
        Case("out_name_300_chars", "TRACEBACK", long_out, 7, "too long"),
        Case(
            "full_synth",
            "TRACEBACK",
            synth_on_full_disk,
            7,
            "cannot write",
            isolated=True,
            max_file_bytes=100_000,
        ),
        Case(
            "full_run",
            "TRACEBACK",
            run_on_full_disk,
            7,
            "cannot write",
            isolated=True,
            max_file_bytes=20_000,
        ),
        Case(
            "out_symlink_to_empty_dir",
            "WRONG-CODE",
            out_symlink,
            0,
            check=written_through_the_link,
        ),
    ]


# Sizes taken from an input are bounded before anything is allocated; values a reader
# used to take on trust are checked (ground truth: exit 5, wherever it comes from).

GT_HEADER_IGNORE = GT_HEADER.rstrip("\n") + ",ignore\n"
#: Ten years past T0: a stamp no recording frame is near.
FAR_FUTURE_NS = 10 * 365 * 86_400 * 10**9


def gt_topic_recording(
    path: Path,
    people: Callable[[int], list[GroundTruthObject]] | None = None,
    stamp: Callable[[int], int] | None = None,
) -> Path:
    """A 4-frame MCAP recording whose ground-truth topic holds ``people(i)`` in frame ``i``
    (default: one person), stamped ``stamp(i)`` (default: the frame's stamp)."""
    objects = ground_truth_objects()
    with RecordingWriter(path, "mcap") as w:
        write_rig(w)
        for i in range(FRAMES):
            frame_stamp = T0 + i * PERIOD
            w.write_rgb(frame_stamp, rgb_image(i), RGB_CAM)
            w.write_depth(frame_stamp + 2_000_000, depth_image(i), DEPTH_CAM)
            gt_stamp = stamp(i) if stamp is not None else frame_stamp
            w.write_ground_truth(gt_stamp, "odom", people(i) if people else [objects[i]])
    return path


def _first_frame(*objects: GroundTruthObject) -> Callable[[int], list[GroundTruthObject]]:
    """Frame 0 holds ``objects``, the others one person each."""
    rest = ground_truth_objects()
    return lambda i: list(objects) if i == 0 else [rest[i]]


def _gt_value_cases() -> list[Case]:
    row = "0,0,1,10,5,8,30,2.0,0.1,0.9,1"

    def gt_rows(rows: list[str], header: str = GT_HEADER) -> bytes:
        return (header + "".join(f"{r}\n" for r in rows)).encode()

    def by_index(i: int) -> str:  # person 7 in frame i, no stamps: matched by frame index
        return f"{i},0,7,{10 + i},5,8,30,2.0,{0.1 * i},0.9,1"

    def by_stamp(i: int, offset: int = 0) -> str:
        return f"{i},{T0 + i * PERIOD + offset},7,{10 + i},5,8,30,2.0,{0.1 * i},0.9,1"

    hour = 3600 * 10**9

    def topic(
        people: Callable[[int], list[GroundTruthObject]], *extra: str
    ) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            rec = gt_topic_recording(root / "gt.mcap", people)
            return ["run", str(rec), *extra, "--out", str(root / "out")]

        return build

    def folder_of_recordings(root: Path) -> list[str]:
        (root / "f").mkdir()
        good_recording(root / "f", "a.mcap")
        good_recording(root / "f", "b.mcap")
        (root / "base.gt.csv").write_bytes(gt_rows([row]))
        return [
            "run",
            str(root / "f"),
            "--gt",
            str(root / "base.gt.csv"),
            "--out",
            str(root / "out"),
        ]

    def far_future(root: Path) -> list[str]:
        stamps = lambda i: T0 + i * PERIOD + (FAR_FUTURE_NS if i == 1 else 0)  # noqa: E731
        rec = gt_topic_recording(root / "fut1.mcap", stamp=stamps)
        return ["run", str(rec), "--out", str(root / "out")]

    inf_box = GroundTruthObject(0, T0, 1, Box2D(0.0, 133.8, math.inf, 284.4), None)
    nan_left = GroundTruthObject(0, T0, 1, Box2D(math.nan, 133.8, 0.617, 284.4), None)
    nan_y = GroundTruthObject(0, T0, 1, None, (4.0, math.nan, 0.9))
    person = GroundTruthObject(0, T0, 1, Box2D(10.0, 5.0, 8.0, 30.0), (2.0, 0.0, 0.9))
    ignore = GT_HEADER_IGNORE
    return [
        _gt_case("ignore_2", gt_rows([f"{row},2"], ignore), 5, "ignore '2' is not 0, 1"),
        _gt_case("ignore_no", gt_rows([f"{row},no"], ignore), 5, "ignore 'no' is not"),
        _gt_case("ignore_FALSE_upper", gt_rows([f"{row},FALSE"], ignore), 0, ""),
        _gt_case("box_negative_zero", gt_rows(["0,0,1,10,5,-0,30,2.0,0.1,0.9,1"]), 5, "negative"),
        _gt_case("box_zero_height", gt_rows(["0,0,1,10,5,8,0,,,,1"]), 5, "empty"),
        _gt_case("box_1e300", gt_rows(["0,0,1,1e300,5,8,30,2.0,0.1,0.9,1"]), 5, "beyond"),
        _gt_case("xyz_1e30", gt_rows(["0,0,1,10,5,8,30,1e30,0.1,0.9,1"]), 5, "beyond"),
        _gt_case("frame_negative", gt_rows(["-1,0,1,10,5,8,30,,,,1"]), 5, "frame number -1"),
        _gt_case("stamp_2e19", gt_rows(["0,20000000000000000000,1,10,5,8,30,,,,1"]), 5, "stamp"),
        _gt_case("only_empty_frames", gt_rows(["0,0,,,,,,,,,", "1,0,,,,,,,,,"]), 5, "no annotated"),
        # Frames outside the annotated span are not scored (a warning says how many).
        _gt_case("only_first_2_frames", gt_rows([by_index(0), by_index(1)]), 0, ""),
        _gt_case(
            "stamps_one_hour_gap",
            gt_rows([by_stamp(0), by_stamp(1), by_stamp(2, hour), by_stamp(3, hour)]),
            0,
            "",
        ),
        Case("gt_for_folder_of_recordings", "WRONG-CODE", folder_of_recordings, 5, "single"),
        Case("gttopic_inf_box", "WRONG-CODE", topic(_first_frame(inf_box)), 5, "finite"),
        Case(
            "gttopic_nan_box_left",
            "WRONG-CODE",
            topic(_first_frame(nan_left)),
            5,
            "finite",
        ),
        Case(
            "gttopic_nan_y_only_metric",
            "WRONG-CODE",
            topic(_first_frame(nan_y), "--gating", "metric"),
            5,
            "[/ground_truth]: frame 0, id 1: position",
        ),
        Case(
            "gttopic_duplicate_ids",
            "WRONG-CODE",
            topic(_first_frame(person, person)),
            5,
            "id 1 appears twice in frame 0",
        ),
        Case("rec_stamps_one_far_future", "SILENT", far_future, 0, ""),
    ]


def _score_mot(
    gt: bytes | str,
    tracks: bytes | str = MOT_TRACKS,
    *extra: str,
    seqinfo: str | None = None,
) -> Callable[[Path], list[str]]:
    """``score t.txt --gt gt.txt`` on MOTChallenge text (with a seqinfo.ini beside it)."""

    def build(root: Path) -> list[str]:
        for name, data in (("t.txt", tracks), ("gt.txt", gt)):
            (root / name).write_bytes(data.encode() if isinstance(data, str) else data)
        if seqinfo is not None:
            (root / "seqinfo.ini").write_text(seqinfo)
        gt_path, tracks_path = str(root / "gt.txt"), str(root / "t.txt")
        return ["score", tracks_path, "--gt", gt_path, *extra, "--out", str(root / "o")]

    return build


def _mot_value_cases() -> list[Case]:
    mot15 = "1,1,0,0,10,10,1,-1,-1,-1\n2,1,0,0,10,10,1,-1,-1,-1\n"
    return [
        Case("score_gt_binary", "WRONG-CODE", _score_mot(bytes(range(256)) * 4), 5, "not UTF-8"),
        Case("score_gt_nan_box", "WRONG-CODE", _score_mot("1,1,nan,0,10,10,1,1,1\n"), 5, "finite"),
        Case(
            "score_gt_negative_box",
            "WRONG-CODE",
            _score_mot("1,1,103,60,-40,100,1,1,1\n"),
            5,
            "negative",
        ),
        Case("score_gt_empty_file", "SILENT", _score_mot(""), 5, "no annotated object"),
        Case(
            "score_gt_frame_fractional",
            "SILENT",
            _score_mot("1.5,1,0,0,10,10,1,1,1\n2,1,0,0,10,10,1,1,1\n"),
            5,
            "frame 1.5 is not a whole number",
        ),
        Case(
            "score_tracks_frame_fractional",
            "SILENT",
            _score_mot(MOT_GT, "1.5,7,0,0,10,10,-1,-1,-1,-1\n"),
            3,
            "frame 1.5 is not a whole number",
        ),
        Case(
            "score_gt_frame_huge_1e8",
            "TRACEBACK",
            _score_mot(MOT_GT + "100000000,1,0,0,10,10,1,1,1\n"),
            5,
            "frame 1e+08",
        ),
        Case(
            "score_gt_frames_far_apart",
            "TRACEBACK",
            _score_mot(MOT_GT + "5000000,1,0,0,10,10,1,1,1\n"),
            5,
            "span more than the 100000 frames",
        ),
        Case(
            "score_tracks_frame_huge_2e9",
            "TRACEBACK",
            _score_mot(MOT_GT, MOT_TRACKS + "2000000000,7,0,0,10,10,-1,-1,-1,-1\n"),
            3,
            "frame 2e+09",
        ),
        Case(
            "score_tracks_box_1e300",
            "TRACEBACK",
            _score_mot(MOT_GT, "1,7,1e300,0,10,10,-1,-1,-1,-1\n"),
            3,
            "beyond",
        ),
        Case(
            "score_seqinfo_length_1e9",
            "TRACEBACK",
            _score_mot(MOT_GT, seqinfo="[Sequence]\nname=x\nseqLength=1000000000\n"),
            5,
            "seqLength 1000000000 outside",
        ),
        Case(
            "score_tracks_beyond_seqlength",
            "SILENT",
            _score_mot(
                MOT_GT,
                MOT_TRACKS + "9,7,0,0,10,10,-1,-1,-1,-1\n",
                seqinfo="[Sequence]\nseqLength=2\n",
            ),
            3,
            "frame 9 outside 1..2",
        ),
        Case(
            "score_benchmark_mot17_on_mot15",
            "SILENT",
            _score_mot(mot15, MOT_TRACKS, "--benchmark", "mot17"),
            5,
            "not a MOTChallenge class",
        ),
        Case(
            "score_gt_nothing_scored",
            "SILENT",
            _score_mot("1,1,0,0,10,10,1,7,1\n2,1,0,0,10,10,0,1,1\n"),
            5,
            "no row is scored",
        ),
    ]


def _cluster_and_cache_cases() -> list[Case]:
    def reproduce(*extra: str) -> Callable[[Path], list[str]]:
        """``reproduce basso2012`` with ``extra`` options ({root} is the case's folder)."""

        def build(root: Path) -> list[str]:
            mine(root, "f")
            data, out = str(root / "d"), str(root / "o")
            options = [e.format(root=root) for e in extra]
            return ["reproduce", "basso2012", *options, "--data", data, "--out", out]

        return build

    def cluster(address: str) -> Callable[[Path], list[str]]:
        return lambda root: two_point_sweep(good_recording(root), root / "out", cluster=address)

    def folder_with_a_broken_recording(root: Path) -> list[str]:
        (root / "set").mkdir()
        good = good_recording(root / "set", "a.mcap")
        (root / "set" / "bad.mcap").write_bytes(good.read_bytes()[:20_000])
        return ["run", str(root / "set"), "--cluster", "local:1", "--out", str(root / "out")]

    def cache_entry(damage: Callable[[Path], None], *mode: str) -> Callable[[Path], list[str]]:
        """A sweep into s1 with a cache, its entry damaged, then the same sweep into s2."""

        def build(root: Path) -> list[str]:
            rec = good_recording(root)
            extra = ("--cache", str(root / "cache"), *mode)
            first = run_isolated(two_point_sweep(rec, root / "s1", *extra), root)
            assert first.code == 0, first.stderr
            (entry,) = (root / "cache").rglob("*.det")
            damage(entry)
            return two_point_sweep(rec, root / "s2", *extra)

        return build

    def fifo(entry: Path) -> None:
        entry.unlink()
        os.mkfifo(entry)

    def dev_zero(entry: Path) -> None:
        entry.unlink()
        entry.symlink_to("/dev/zero")

    def flip_a_float(entry: Path) -> None:
        flip_byte(entry, entry.stat().st_size // 2)

    def same_records(root: Path) -> None:
        assert sweep_records(root / "s1") == sweep_records(root / "s2")
        assert len(sweep_records(root / "s2")) == 2

    return [
        Case("reproduce_cache_is_file", "HANG", reproduce("--cache", "{root}/f"), 7, "cache"),
        Case("reproduce_cluster_bogus", "HANG", reproduce("--cluster", "mars://x"), 4, "--cluster"),
        Case("cluster_tls_127_0_0_1_1", "TRACEBACK", cluster("tls://127.0.0.1:1"), 8, "tls"),
        Case("cluster_ucx_127_0_0_1_1", "TRACEBACK", cluster("ucx://127.0.0.1:1"), 8, "ucx"),
        Case(
            "multi_folder_one_broken",
            "MULTILINE",
            folder_with_a_broken_recording,
            3,
            "bad.mcap",
            isolated=True,
        ),
        Case(
            "cache_client_mode_float",
            "MULTILINE",
            cache_entry(flip_a_float, "--cache-mode", "client"),
            0,
            "checksum mismatch",
            same_records,
            isolated=True,
        ),
        Case(
            "cache_fifo_entry",
            "HANG",
            cache_entry(fifo),
            0,
            "named pipe",
            same_records,
            isolated=True,
        ),
        Case(
            "cache_devzero_entry",
            "TRACEBACK",
            cache_entry(dev_zero),
            0,
            "device",
            same_records,
            isolated=True,
        ),
    ]


def _nesting_and_size_cases() -> list[Case]:
    deep_block = "".join("  " * i + "a:\n" for i in range(2000)) + "  " * 2000 + "b: 1\n"
    deep_flow = "tracker: " + "{a: " * 2000 + "1" + "}" * 2000 + "\n"
    bomb = (
        "tracker.min_confidence={a: &a [1,1,1,1,1,1,1,1,1], "
        + ", ".join(
            f"{c}: &{c} [{', '.join([f'*{p}'] * 9)}]"
            for p, c in zip("abcdefgh", "bcdefghi", strict=True)
        )
        + "}"
    )
    deep_report = json.dumps(report(BASE_METRICS))[:-1] + ', "config": '
    deep_report += '{"a": ' * 500 + "1" + "}" * 500 + "}"
    deep_json = b'{"schema_version": 1, "x": ' + b"[" * 100_000 + b"]" * 100_000 + b"}"

    def method_set(method: str, *sets: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            extra = [a for s in sets for a in ("--set", s)]
            rec = str(good_recording(root))
            return ["run", rec, "--method", method, *extra, "--out", str(root / "out")]

        return build

    def sweep_grid(root: Path) -> list[str]:
        a = ",".join(str(-k / 1000) for k in range(1000))
        b = ",".join(str(1 + k / 100) for k in range(1000))
        rec = str(good_recording(root))
        params = ["--param", f"tracker.min_confidence={a}"]
        params += ["--param", f"tracker.acceleration_variance={b}"]
        return ["sweep", *params, "--dataset", rec, "--out", str(root / "out")]

    return [
        _cfg_case("deep_nesting_2k", deep_block.encode(), 4, "nests deeper than 100"),
        _cfg_case("deep_nesting_mapping", deep_flow.encode(), 4, "nests deeper than 100"),
        _set_case("alias_bomb_9", [bomb], 4, "aliases"),
        _set_case(
            "deep_nesting", ["tracker.min_confidence=" + "[" * 5000 + "]" * 5000], 4, "deeper"
        ),
        _cfg_case("voxel_1e-9", b"detector:\n  voxel_size: 1.0e-9\n", 4, "0.01 <= voxel_size"),
        _set_case("voxel_1e-12", ["detector.voxel_size=1e-12"], 4, "0.01 <= voxel_size <= 0.5"),
        _cfg_case(
            "weak_classifiers_1e9",
            b"tracker:\n  weak_classifiers: 1000000000\n",
            4,
            "weak_classifiers <= 2500",
        ),
        _set_case("selectors_1e9", ["tracker.selectors=1000000000"], 4, "selectors <= 500"),
        Case(
            "set_reid_input_1e9",
            "TRACEBACK",
            method_set("pinto2022", "detector.reid.input_width=1000000000"),
            4,
            "input_width <= 2048",
        ),
        Case(
            "set_dmtbs_closing_1e9",
            "TRACEBACK",
            method_set("dmtbs", "detector.closing_radius_m=1e9"),
            4,
            "closing_radius_m <= 1.0",
        ),
        Case("sweep_grid_1e6_points", "TRACEBACK", sweep_grid, 4, "1000000 points"),
        _cmp_case(
            "number_1e400",
            None,
            2,
            "too large",
            raw=json.dumps(report(BASE_METRICS)).replace("0.7", "1e400").encode(),
        ),
        _cmp_case("deep_nesting", None, 2, "nested too deeply", raw=deep_json),
        _cmp_case("deep_config", None, 2, "deeper than 100", raw=deep_report.encode()),
    ]


def _teleport(stamp: int) -> Pose:
    p = odom_pose(stamp)
    hop = ((stamp - T0) // 20_000_000) % 2  # every other odometry message 5 m away
    return Pose((p.translation[0] + 5.0 * hop, *p.translation[1:]), p.rotation)


def _jump_1km(stamp: int) -> Pose:
    p = odom_pose(stamp)
    return Pose((p.translation[0] + 1000.0, *p.translation[1:]), p.rotation) if stamp > T0 else p


def _position_1e30(stamp: int) -> Pose:
    p = odom_pose(stamp)
    return Pose((1e30, 0.0, 0.0), p.rotation) if stamp > T0 else p


def _all_max_depth(i: int) -> np.ndarray:
    return np.full((DEPTH_CAM.height, DEPTH_CAM.width), 65.535, dtype=np.float32)


def _tiny_focal(msg: Any) -> Any:
    K = np.array(msg.K, dtype=np.float64)
    K[0] = 1e-300
    return dataclasses.replace(msg, K=K)


def png_claiming(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width`` x ``height`` RGB pixels, with almost no data."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(b"\x00" * 64))
        + chunk(b"IEND", b"")
    )


def _png_bomb_recording(path: Path) -> Path:
    """A ROS1 bag whose colour images are PNGs claiming 30000 x 30000 pixels (2.7 GB)."""
    from unittest import mock

    from rgbd_eval.io import images
    from rgbd_eval.io.writer import StreamOptions

    def bomb(rgb: np.ndarray, quality: int = 90) -> dict[str, Any]:
        return {"format": "png", "data": np.frombuffer(png_claiming(30000, 30000), np.uint8)}

    with mock.patch.object(images, "encode_color_jpeg", bomb):
        return write_recording(path, "ros1", Spec(n=FRAMES, options=StreamOptions("jpeg")))


def _recording_value_cases() -> list[Case]:
    def run(rec: Callable[[Path], Path], *extra: str) -> Callable[[Path], list[str]]:
        return lambda root: ["run", str(rec(root)), *extra, "--out", str(root / "out")]

    def odd(name: str, **kwargs: Any) -> Callable[[Path], Path]:
        return lambda root: odd_recording(root / f"{name}.bag", **kwargs)

    def damaged(name: str, **kwargs: Any) -> Callable[[Path], Path]:
        return lambda root: damaged_ros1(root / f"{name}.bag", lambda i: True, **kwargs)

    def bigendian(fields: dict[str, Any]) -> dict[str, Any]:
        return {**fields, "is_bigendian": 1}  # the bytes stay little-endian

    def ros2(damage: Callable[[Path], None]) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            bag = write_recording(root / "r2", "ros2-sqlite3", Spec(n=FRAMES))
            damage(bag)
            return ["run", str(bag), "--out", str(root / "out")]

        return build

    def fifo_for(pattern: str) -> Callable[[Path], None]:
        def damage(bag: Path) -> None:
            target = next(bag.glob(pattern))
            target.unlink()
            os.mkfifo(target)

        return damage

    def metadata_bomb(bag: Path) -> None:
        (bag / "metadata.yaml").write_text(_BOMB)

    return [
        Case("img_depth_all_max", "SILENT", run(odd("dmax", depth=_all_max_depth)), 3, "plausible"),
        Case(
            "img_depth_bigendian_flag",
            "SILENT",
            run(damaged("bigend", image=bigendian)),
            3,
            "is_bigendian",
        ),
        Case(
            "img_info_focal_1e-300",
            "SILENT",
            run(damaged("tinyf", info=_tiny_focal)),
            3,
            "field of view",
        ),
        Case(
            "rec_odom_jump_1km", "SILENT", run(odd("jump", odom=_jump_1km)), 3, "faster than 20 m/s"
        ),
        Case(
            "rec_odom_jump_1km_metric",
            "SILENT",
            run(odd("jumpm", odom=_jump_1km), "--gating", "metric"),
            3,
            "1e+03 m in",
        ),
        Case(
            "rec_odom_teleport_every_other",
            "SILENT",
            run(odd("tele", odom=_teleport)),
            3,
            "[/odom]: odom->base_link moves",
        ),
        Case("rec_odom_1e30", "TRACEBACK", run(odd("huge", odom=_position_1e30)), 3, "beyond"),
        Case(
            "img_png_bomb",
            "TRACEBACK",
            run(lambda root: _png_bomb_recording(root / "bomb.bag")),
            3,
            "declares 30000x30000 pixels",
        ),
        Case("r2sql_metadata_fifo", "HANG", ros2(fifo_for("metadata.yaml")), 3, "named pipe"),
        Case("r2sql_db3_is_fifo", "HANG", ros2(fifo_for("*.db3")), 3, "named pipe"),
        Case("r2sql_metadata_alias_bomb", "TRACEBACK", ros2(metadata_bomb), 3, "aliases"),
    ]


def _import_cases() -> list[Case]:
    from tests.io.epfl_folder import write_sequence

    def import_fps(fps: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            folder = write_sequence(root, [None])
            out = str(root / "x.mcap")
            return ["import", "epfl-rgbd", str(folder), "-o", out, "--fps", fps]

        return build

    return [
        Case("import_fps_1e-300", "TRACEBACK", import_fps("1e-300"), 4, "--fps 1e-300"),
        Case("import_fps_1e300", "TRACEBACK", import_fps("1e300"), 4, "0.1..1000"),
    ]


def _annotate_and_view_cases() -> list[Case]:
    """CVAT exports that are not, or not of this recording; runs `view` cannot show (issue 34)."""

    def cvat(box: str = 'xtl="2.00" ytl="3.00" xbr="12.00" ybr="40.00"', size: int = FRAMES) -> str:
        return (
            '<?xml version="1.0" encoding="utf-8"?>\n<annotations><version>1.1</version>'
            f"<meta><task><size>{size}</size><original_size><width>64</width><height>48"
            '</height></original_size></task></meta><track id="0" label="person">'
            f'<box frame="0" outside="0" occluded="0" keyframe="1" {box} z_order="0"/>'
            "</track></annotations>\n"
        )

    def importing(name: str, text: str) -> Callable[[Path], list[str]]:
        def build(root: Path) -> list[str]:
            (root / name).write_text(text)
            rec, out = good_recording(root), str(root / "imported.gt.csv")
            return ["annotate", "import", str(root / name), "--recording", str(rec), "-o", out]

        return build

    def view_score_report(root: Path) -> list[str]:
        (root / "score").mkdir()
        (root / "score" / "report.json").write_text('{"config": {}, "sequences": [{"name": "x"}]}')
        return ["view", str(root / "score")]

    def export_to_file(root: Path) -> list[str]:
        (root / "task").write_text("mine")
        return ["annotate", "export", str(good_recording(root)), "-o", str(root / "task")]

    return [
        Case(
            "cvat_box_outside",
            "TRACEBACK",
            importing("a.xml", cvat('xtl="50" ytl="3" xbr="90" ybr="40"')),
            5,
            "reaches outside the 64x48 image",
        ),
        Case(
            "cvat_other_task_size",
            "SILENT",
            importing("a.xml", cvat(size=9)),
            5,
            "which no --every gives",
        ),
        Case(
            "cvat_not_xml",
            "TRACEBACK",
            importing("a.xml", "<annotations><version>"),
            5,
            "not well-formed",
        ),
        Case(
            "cvat_mot_without_every",
            "WRONG-CODE",
            importing("gt.txt", "1,1,2,3,10,37,1,1,1\n"),
            4,
            "give --every",
        ),
        Case(
            "view_no_report",
            "TRACEBACK",
            lambda root: ["view", str(root)],
            3,
            "holds no report.json",
        ),
        Case(
            "view_score_report", "TRACEBACK", view_score_report, 3, "written by `rgbd-eval score`"
        ),
        Case("annotate_export_to_a_file", "TRACEBACK", export_to_file, 7, "not a folder"),
    ]


def all_cases() -> list[Case]:
    """Every case of the corpus."""
    return [
        *_recording_cases(),
        *_gt_cases(),
        *_config_cases(),
        *_usage_cases(),
        *_output_cases(),
        *_compare_cases(),
        *_other_command_cases(),
        *_damage_cases(),
        *_score_cases(),
        *_model_and_cache_cases(),
        *_ownership_cases(),
        *_path_and_disk_cases(),
        *_cluster_and_cache_cases(),
        *_gt_value_cases(),
        *_mot_value_cases(),
        *_nesting_and_size_cases(),
        *_recording_value_cases(),
        *_import_cases(),
        *_annotate_and_view_cases(),
    ]


def ground_truth_objects(n: int = FRAMES) -> list[GroundTruthObject]:
    """One person per frame with box and world position (for scored runs)."""
    return [
        GroundTruthObject(
            i, T0 + i * PERIOD, 7, Box2D(10.0 + i, 5.0, 8.0, 30.0), (2.0, 0.1 * i, 0.9)
        )
        for i in range(n)
    ]


__all__ = ["Case", "all_cases", "flip_byte", "good_recording", "ground_truth_objects", "write_csv"]
