"""``rgbd-eval methods``: each method, the streams it reads, its paper and its default gating."""

from __future__ import annotations

import json
from typing import Annotated, Any

import typer
from rich.table import Table
from rich.text import Text

from rgbd_eval.cli.common import SCHEMA_VERSION, console, handle_errors


def methods_data() -> list[dict[str, Any]]:
    """One record per registered method (JSON-ready)."""
    from rgbd_eval.plugins import (
        detector_spec,
        known,
        method_spec,
        streams_of,
        tracker_spec,
    )

    papers = set(known("papers"))
    out = []
    for name in known("methods"):
        m = method_spec(name)
        det, trk = detector_spec(m.detector), tracker_spec(m.tracker)
        out.append(
            {
                "method": name,
                "title": m.title,
                "seed": m.seed,
                "detector": det.name,
                "tracker": trk.name,
                "streams": [
                    {"role": s.role, "required": s.required, "multiple": s.multiple}
                    for s in streams_of(det, trk)
                ],
                "tracker_reads_frames": trk.needs_frame,
                "gating": m.gating,
                "reproduce": name in papers,
            }
        )
    return out


def _streams(streams: list[dict[str, Any]]) -> str:
    """``colour, [depth]``: the roles read, ``[optional]``, ``depth...`` for one or more."""
    parts = []
    for s in streams:
        text = s["role"] + ("..." if s["multiple"] else "")
        parts.append(text if s["required"] else f"[{text}]")
    return ", ".join(parts)


@handle_errors
def methods(
    json_out: Annotated[bool, typer.Option("--json", help="machine-readable JSON")] = False,
) -> None:
    r"""List the methods: streams read (\[optional], ... = one or more), paper, default gating."""
    data = methods_data()
    if json_out:
        typer.echo(json.dumps({"schema_version": SCHEMA_VERSION, "methods": data}, indent=2))
        return
    table = Table(title="methods", title_justify="left")
    for col in ("method", "streams", "detector + tracker", "gating", "reproduce", "paper"):
        # method and streams stay on one line; the cells are plain text, not rich markup
        table.add_column(col, overflow="fold", no_wrap=col in ("method", "streams"))
    for m in data:
        cells = (
            m["method"],
            _streams(m["streams"]),
            f"{m['detector']} + {m['tracker']}"
            + (" (reads frames)" if m["tracker_reads_frames"] else ""),
            m["gating"],
            "yes" if m["reproduce"] else "-",
            f"seed {m['seed']}: {m['title']}" if m["seed"] else m["title"],
        )
        table.add_row(*map(Text, cells))
    console.print(table)
