"""``rgbd-eval import``: a dataset's own folder layout to a recording plus ground truth.

Formats: ``epfl-rgbd`` (EPFL-LAB, EPFL-CORRIDOR; :mod:`rgbd_eval.io.epfl_rgbd`). KTP needs no
import: its ROS bags are read as they are and its ground-truth text by ``--gt``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from rgbd_eval.cli.common import advance_callback, console, handle_errors, progress_bar
from rgbd_eval.errors import ConfigError, GroundTruthError, InputError
from rgbd_eval.outdir import check_output_file
from rgbd_eval.types import CameraModel, Pose

FORMATS = ("epfl-rgbd",)
#: World up in a camera's optical frame (y points down) for the floor search; the floor's
#: normal may lean from it by the dmtbs default of 30 deg (EPFL cameras look down 5-15 deg).
_OPTICAL_UP = np.array([0.0, -1.0, 0.0])


def _numbers(text: str, option: str, count: tuple[int, ...]) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError as err:
        raise ConfigError(
            f"{option} {text!r}: expected {count[0]} comma-separated numbers"
        ) from err
    if len(values) not in count or not all(math.isfinite(v) for v in values):
        raise ConfigError(f"{option} {text!r}: expected {count[0]} comma-separated finite numbers")
    return values


def _camera(intrinsics: str | None) -> CameraModel:
    from rgbd_eval.io.epfl_rgbd import EPFL_KINECT2

    if intrinsics is None:
        return EPFL_KINECT2
    values = _numbers(intrinsics, "--intrinsics", (4, 6))
    width, height = (values[4], values[5]) if len(values) == 6 else (512.0, 424.0)
    if width != int(width) or height != int(height):
        raise ConfigError(f"--intrinsics {intrinsics!r}: width and height must be integers")
    try:
        fx, fy, cx, cy = values[:4]
        return CameraModel(int(width), int(height), fx, fy, cx, cy)
    except ValueError as err:
        raise ConfigError(f"--intrinsics {intrinsics!r}: {err}") from err


def _camera_pose(floor: str, first_depth: Path, camera: CameraModel) -> Pose | None:
    """The camera in the floor-aligned world (x forward along the floor, z up), or None."""
    from rgbd_eval.detect.calibration import floor_frame, floor_from_depth
    from rgbd_eval.io.epfl_rgbd import read_depth
    from rgbd_eval.methods.dmtbs.detector import DmtbsDetectorConfig

    if floor == "none":
        return None
    forward = np.array([0.0, 0.0, 1.0])
    if floor == "first-frame":
        defaults = DmtbsDetectorConfig()
        try:
            plane = floor_from_depth(
                read_depth(first_depth),
                camera,
                _OPTICAL_UP,
                defaults.floor_band_m,
                defaults.floor_max_tilt_deg,
            )
        except ValueError as err:
            raise InputError(first_depth, f"{err}; give --floor a,b,c,d or --floor none") from err
        return floor_frame(plane, forward)
    plane = np.asarray(_numbers(floor, "--floor", (4,)))
    try:
        return floor_frame(plane, forward)
    except ValueError as err:
        raise ConfigError(f"--floor {floor!r}: {err}") from err


def _height_and_pitch(world_T_optical: Pose) -> tuple[float, float]:
    """The camera's height above the floor (m) and how far its axis points down (deg)."""
    axis = world_T_optical.rotation_matrix()[:, 2]  # the optical z (viewing) axis in the world
    down = math.degrees(math.asin(max(-1.0, min(1.0, -float(axis[2])))))
    return float(world_T_optical.translation[2]), down


@handle_errors
def import_(
    fmt: Annotated[str, typer.Argument(metavar="FORMAT", help="dataset layout: epfl-rgbd")],
    source: Annotated[
        Path, typer.Argument(help="sequence folder, e.g. epfl_lab/20140804_160621_00")
    ],
    out: Annotated[Path, typer.Option("-o", "--out", help="output recording (.mcap or .bag)")],
    annotations: Annotated[
        Path | None,
        typer.Option(help="ground_truth_image_plane.yaml (default: beside the sequence folder)"),
    ] = None,
    no_gt: Annotated[bool, typer.Option("--no-gt", help="write no ground truth")] = False,
    floor: Annotated[
        str,
        typer.Option(
            help="the world frame's floor: first-frame (RANSAC on the first depth image), "
            "a,b,c,d (plane in the camera's optical frame, metres), or none (camera frame, "
            "boxes without world positions)"
        ),
    ] = "first-frame",
    fps: Annotated[
        float, typer.Option(help="frame rate for the stamps (the folders carry none)")
    ] = 30.0,
    intrinsics: Annotated[
        str | None,
        typer.Option(help="fx,fy,cx,cy[,width,height] instead of the dataset's Kinect v2 values"),
    ] = None,
    no_rgb: Annotated[bool, typer.Option("--no-rgb", help="write depth only")] = False,
    frames: Annotated[int | None, typer.Option(help="convert only the first N frames")] = None,
) -> None:
    """Convert a dataset sequence folder to .mcap/.bag (depth, colour, CameraInfo, tf) + <name>.gt.csv."""
    from rgbd_eval.io.epfl_rgbd import (
        FPS_RANGE,
        OWNER,
        annotation_path,
        import_sequence,
        scan_sequence,
    )

    if fmt not in FORMATS:
        raise ConfigError(f"format {fmt!r}: expected one of {', '.join(FORMATS)}")
    if out.suffix not in (".mcap", ".bag"):
        raise ConfigError(f"--out {out}: name a .mcap or .bag recording")
    if not FPS_RANGE[0] <= fps <= FPS_RANGE[1]:  # also refuses nan
        raise ConfigError(f"--fps {fps}: must be within {FPS_RANGE[0]:g}..{FPS_RANGE[1]:g} Hz")
    if frames is not None and frames < 1:
        raise ConfigError(f"--frames {frames}: must be at least 1")
    if no_gt and annotations is not None:
        raise ConfigError("--no-gt and --annotations contradict each other")
    # The recording and its sidecar replace only files `import` wrote (a user's annotations
    # named <name>.gt.csv beside it are never replaced); checked before any work.
    check_output_file(out, OWNER)
    if not no_gt:
        check_output_file(out.with_name(f"{out.stem}.gt.csv"), OWNER)
    camera = _camera(intrinsics)
    sequence = scan_sequence(source)
    if not no_gt and annotations is None:
        annotations = annotation_path(sequence)
        if annotations is None:
            raise GroundTruthError(
                source.parent / "ground_truth_image_plane.yaml",
                "not found beside the sequence folder; give --annotations FILE or --no-gt",
            )
    world_T_optical = _camera_pose(floor, sequence.frames[0].depth, camera)
    with progress_bar() as bar:
        task = bar.add_task(sequence.tag, total=None)
        summary = import_sequence(
            sequence,
            out,
            annotations=annotations,
            camera=camera,
            fps=fps,
            world_T_optical=world_T_optical,
            with_rgb=not no_rgb,
            max_frames=frames,
            progress=advance_callback(bar, task),
        )
        bar.remove_task(task)
    gt = (
        f" + {summary.ground_truth_csv.name} ({summary.boxes} boxes in "
        f"{summary.annotated_frames} annotated frames, {summary.positions} with a world position)"
        if summary.ground_truth_csv is not None
        else ""
    )
    console.print(f"{summary.recording} ({summary.frames} frames){gt}")
    if world_T_optical is not None:
        height, down = _height_and_pitch(world_T_optical)
        console.print(f"camera {height:.2f} m above the floor, looking {down:.1f} deg down")
