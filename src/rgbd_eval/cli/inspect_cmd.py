"""``rgbd-eval inspect``: what a recording holds and how the reader will use it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from rgbd_eval.cli.common import SCHEMA_VERSION, console, handle_errors, jsonable
from rgbd_eval.config import IoConfig
from rgbd_eval.errors import ConfigError
from rgbd_eval.io.groundtruth import GroundTruth, load_ground_truth
from rgbd_eval.io.reader import RecordingInfo, open_recording


def sidecar_for(path: Path) -> Path | None:
    """``<name>.gt.csv`` beside a recording, if present."""
    stem = path.name[: -len(path.suffix)] if path.suffix in (".bag", ".mcap", ".db3") else path.name
    candidate = path.with_name(f"{stem}.gt.csv")
    return candidate if candidate.exists() else None


def gt_summary(gt: GroundTruth | None, source: str | None) -> dict[str, Any] | None:
    if gt is None:
        return None
    return {
        "source": source,
        "frames": len(gt.frames),
        "objects": gt.num_objects,
        "ids": sorted(gt.ids),
        "boxes": gt.has_boxes,
        "world_positions": gt.has_world,
        "ignored": sum(o.ignore for _, _, objs in gt.frames for o in objs),
    }


def inspect_data(path: Path, io: IoConfig, gt_path: Path | None = None) -> dict[str, Any]:
    """Everything ``inspect`` reports, as a JSON-ready dict."""
    rec = open_recording(path, io)
    info: RecordingInfo = rec.info
    next(iter(rec.frames()))  # decode one frame: encodings and image sizes are checked here
    sidecar = gt_path or sidecar_for(path)
    data: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "recording": jsonable(info)}
    gts = []
    if rec.ground_truth_topic is not None:
        gts.append(gt_summary(rec.ground_truth_topic, f"topic {info.selected.ground_truth}"))
    if sidecar is not None:
        gts.append(gt_summary(load_ground_truth(sidecar), str(sidecar)))
    data["ground_truth"] = gts
    return data


def _print_human(data: dict[str, Any]) -> None:
    info = data["recording"]
    console.print(
        f"[bold]{info['path']}[/]  ({info['container']}, {info['duration_s']:.2f} s, "
        f"{info['num_frames']} synchronised frames)"
    )
    table = Table(title="topics", title_justify="left")
    for col in ("topic", "type", "messages", "rate (Hz)", "used as"):
        numeric = col in ("messages", "rate (Hz)")
        table.add_column(
            col, justify="right" if numeric else "left", overflow="fold", no_wrap=numeric
        )
    roles = {v: k for k, v in info["selected"].items() if isinstance(v, str)}
    for t in info["selected"]["tf"]:
        roles[t] = "tf"
    for t in info["topics"]:
        rate = f"{t['rate_hz']:.2f}" if t["rate_hz"] else "-"
        table.add_row(t["name"], t["msgtype"], str(t["count"]), rate, roles.get(t["name"], ""))
    console.print(table)
    s = info["sync"]
    console.print(
        f"sync: {s['paired']} pairs of {s['rgb_messages']} RGB / {s['depth_messages']} depth; dropped "
        f"{s['rgb_dropped']} RGB, {s['depth_dropped']} depth, {s['no_pose_dropped']} without pose; "
        f"worst gap {s['worst_gap_ms']:.2f} ms (max {s['max_gap_ms']:.1f}), mean {s['mean_gap_ms']:.2f} ms"
    )
    for name in ("rgb_camera", "depth_camera"):
        c = info[name]
        console.print(
            f"{name}: {c['width']}x{c['height']} fx={c['fx']:.1f} fy={c['fy']:.1f} "
            f"cx={c['cx']:.1f} cy={c['cy']:.1f} frame {c['frame_id']!r}"
        )
    if info["has_odometry"]:
        console.print("tf chain: " + " -> ".join(info["tf_chain"]))
    else:
        console.print(
            f"tf chain: none (no odometry; world = camera frame {info['camera_frame']!r})"
        )
    for w in info["warnings"]:
        console.print(f"[yellow]warning:[/] {w}")
    if not data["ground_truth"]:
        console.print("ground truth: none found (topic or <name>.gt.csv sidecar)")
    for g in data["ground_truth"]:
        console.print(
            f"ground truth ({g['source']}): {g['frames']} frames, {g['objects']} objects, "
            f"{len(g['ids'])} ids, {g['ignored']} ignored, boxes={g['boxes']}, world={g['world_positions']}"
        )


@handle_errors
def inspect(
    path: Annotated[Path, typer.Argument(help="a .bag, .mcap, .db3 or ROS2 bag folder")],
    json_out: Annotated[
        bool, typer.Option("--json", help="machine-readable JSON on stdout")
    ] = False,
    gt: Annotated[Path | None, typer.Option("--gt", help="ground-truth file (CSV or KTP)")] = None,
    rgb_topic: Annotated[str | None, typer.Option(help="RGB image topic")] = None,
    depth_topic: Annotated[str | None, typer.Option(help="depth image topic")] = None,
    odom_topic: Annotated[str | None, typer.Option(help="odometry topic")] = None,
    max_sync_gap_ms: Annotated[float, typer.Option(help="largest RGB/depth stamp gap")] = 20.0,
) -> None:
    """Topics, rates, chosen streams, sync quality, tf chain and ground truth of a recording."""
    try:
        io = IoConfig(
            rgb_topic=rgb_topic,
            depth_topic=depth_topic,
            odom_topic=odom_topic,
            max_sync_gap_ms=max_sync_gap_ms,
        )
    except ValueError as err:
        raise ConfigError(" ".join(str(err).split())) from err
    data = inspect_data(path, io, gt)
    if json_out:
        typer.echo(json.dumps(data, indent=2))
    else:
        _print_human(data)
