"""``rgbd-eval inspect``: what a recording holds and how the reader will use it."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from rgbd_eval.cli.common import (
    SCHEMA_VERSION,
    ConfigOption,
    SetOption,
    TopicOption,
    console,
    handle_errors,
    jsonable,
    topic_overrides,
)
from rgbd_eval.config import IoConfig, load_config
from rgbd_eval.io.groundtruth import GroundTruth, load_ground_truth
from rgbd_eval.io.recording import RecordingInfo, open_recording
from rgbd_eval.io.streams import ALL_STREAMS
from rgbd_eval.plugins import StreamSpec


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


def inspect_data(
    path: Path,
    io: IoConfig,
    gt_path: Path | None = None,
    streams: Sequence[StreamSpec] = ALL_STREAMS,
) -> dict[str, Any]:
    """Everything ``inspect`` reports, as a JSON-ready dict.

    Streams that do not pair are findings (``recording.sync.problems``), not an error:
    the rest of the recording is still described.
    """
    rec = open_recording(path, io, streams, unpaired_ok=True)
    info: RecordingInfo = rec.info
    if len(rec):
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
    sel = info["selected"]
    roles = {t: r for r, t in sel["streams"].items()}
    roles.update({t: f"{r}_info" for r, t in sel["infos"].items()})
    for role in ("odometry", "ground_truth"):
        if sel[role]:
            roles[sel[role]] = role
    for t in sel["tf"]:
        roles[t] = "tf"
    for t in info["topics"]:
        rate = f"{t['rate_hz']:.2f}" if t["rate_hz"] else "-"
        table.add_row(t["name"], t["msgtype"], str(t["count"]), rate, roles.get(t["name"], ""))
    console.print(table)
    s = info["sync"]
    console.print(
        f"sync: {s['frames']} frames on the {s['reference']} stamps, "
        f"{s['no_pose_dropped']} dropped without pose (largest gap accepted {s['max_gap_ms']:.1f} ms)"
    )
    unpaired = {p["role"]: p for p in s["problems"] if p["role"]}
    for st in s["streams"]:
        if st["role"] == s["reference"]:
            gap = ""
        elif (p := unpaired.get(st["role"])) is not None and p["smallest_gap_ms"] is not None:
            gap = f", none paired (smallest offset {p['smallest_gap_ms']:.1f} ms)"
        elif st["role"] in unpaired:
            gap = ", none paired"
        else:
            gap = f", worst gap {st['worst_gap_ms']:.2f} ms, mean {st['mean_gap_ms']:.2f} ms"
        console.print(f"  {st['role']}: {st['messages']} messages, {st['dropped']} dropped{gap}")
    for p in s["problems"]:
        console.print(f"[red]{escape(p['message'])}[/]", soft_wrap=True)
    if s["problems"]:
        console.print(
            "run refuses this recording until the streams pair (no frame: images not decoded)"
        )
    for role, c in info["cameras"].items():
        lens = f", {c['distortion_model']} distortion" if any(c["distortion"]) else ""
        console.print(
            f"{role} camera: {c['width']}x{c['height']} fx={c['fx']:.1f} fy={c['fy']:.1f} "
            f"cx={c['cx']:.1f} cy={c['cy']:.1f} frame {c['frame_id']!r}{lens}"
        )
    if info["has_odometry"]:
        console.print("tf chain: " + " -> ".join(info["tf_chain"]))
    else:
        console.print(
            f"tf chain: none (no odometry; world = camera frame {info['camera_frame']!r})"
        )
    for sk in info.get("skipped", ()):
        console.print(
            f"skipped {sk['topic']}: {sk['count']} of {sk['total']} messages damaged "
            f"(first: {sk['first_problem']})"
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
    topics: TopicOption = None,
    method: Annotated[
        str | None,
        typer.Option(help="choose the streams this method reads (default: every stream found)"),
    ] = None,
    config_file: ConfigOption = None,
    overrides: SetOption = None,
) -> None:
    """Topics, rates, chosen streams, sync quality, tf chain and ground truth of a recording."""
    from rgbd_eval.plugins import detector_spec, streams_of, tracker_spec

    sets = [*(overrides or []), *topic_overrides(topics)]
    config = load_config(config_file, sets, method=method or (None if config_file else "basso2012"))
    streams = (
        streams_of(detector_spec(config.detector.name), tracker_spec(config.tracker.name))
        if method or config_file
        else ALL_STREAMS
    )
    data = inspect_data(path, config.io, gt, streams)
    if json_out:
        typer.echo(json.dumps(data, indent=2))
    else:
        _print_human(data)
