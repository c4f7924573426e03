"""``compare``'s paired bootstrap: the 95 % interval of each change, from the reports' tables.

Each report's sequences name their per-frame table (``frames_file``: ``<name>.frames.npz``
beside ``report.json``, with its sha256). Per sequence one set of block-bootstrap frame
weights (:mod:`rgbd_eval.metrics.bootstrap`; its block length the larger of the two tables'
own, its seed :data:`~rgbd_eval.metrics.bootstrap.DEFAULT_SEED`) is applied to both tables, so
a replicate's change is the current metric minus the baseline's on the same frames; the
overall row sums the sequences' replicates. A report without its tables (written before
them, or the files removed) gives no interval: a note says so, and ``compare`` gates on the
fixed tolerance.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rgbd_eval.compare import DEFAULT_TOLERANCES
from rgbd_eval.errors import CompareInputError
from rgbd_eval.metrics import bootstrap as boot
from rgbd_eval.metrics.frames import FrameTable

#: The largest per-frame table ``compare`` reads.
MAX_TABLE_BYTES = 1 << 30


def _frames_table(folder: Path, record: Mapping[str, Any], source: str) -> FrameTable | None:
    """A sequence's per-frame table beside its report (None when the report names none or
    the file is gone); CompareInputError when it is not the file the report names."""
    from rgbd_eval.files import read_bytes

    named = record.get("frames_file")
    if not isinstance(named, Mapping):
        return None
    name, digest = named.get("name"), named.get("sha256")
    if not isinstance(name, str) or Path(name).name != name or name.startswith("."):
        raise CompareInputError(f"{source}: sequence {record['name']!r}: bad frames_file {name!r}")
    path = folder / name
    if not path.exists():
        return None

    def error(message: str) -> CompareInputError:
        return CompareInputError(f"{path}: {message}")

    data = read_bytes(path, error, "frames table", MAX_TABLE_BYTES)
    if hashlib.sha256(data).hexdigest() != digest:
        raise error("changed since the report was written (sha256 differs)")
    try:
        return FrameTable.load(data)
    except ValueError as err:
        raise error(str(err)) from err


def _tables(path: Path, report: Mapping[str, Any]) -> dict[str, FrameTable | None]:
    folder = path if path.is_dir() else path.parent
    return {s["name"]: _frames_table(folder, s, str(path)) for s in report["sequences"]}


def paired_intervals(
    baseline_path: Path,
    baseline: Mapping[str, Any],
    current_path: Path,
    current: Mapping[str, Any],
    replicates: int = boot.DEFAULT_REPLICATES,
    seed: int = boot.DEFAULT_SEED,
) -> tuple[dict[tuple[str, str], tuple[float, float]], list[str]]:
    """The 95 % interval of every change, by sequence and overall, and notes on what has none.

    Paired block bootstrap: per sequence one set of frame weights (its block length the
    larger of the two tables' own) is applied to both reports' tables; a replicate's change
    is the current metric minus the baseline's on the same frames. The overall row sums the
    sequences' replicates, as the reports' intervals do.
    """
    base_tables, cur_tables = _tables(baseline_path, baseline), _tables(current_path, current)
    out: dict[tuple[str, str], tuple[float, float]] = {}
    notes = []
    pairs: list[tuple[boot.Replicates, boot.Replicates]] = []
    names = sorted(base_tables)
    for name in names:
        base, cur = base_tables.get(name), cur_tables.get(name)
        missing = [label for label, t in (("baseline", base), ("current", cur)) if t is None]
        if base is None or cur is None:
            notes.append(
                f"sequence {name!r}: no intervals ({' and '.join(missing)} report without its "
                f"{name}.frames.npz); gated on the fixed tolerance"
            )
            continue
        if base.num_frames != cur.num_frames:
            notes.append(
                f"sequence {name!r}: no intervals ({base.num_frames} frames against "
                f"{cur.num_frames}); gated on the fixed tolerance"
            )
            continue
        block = max(
            boot.block_length(boot.frame_errors(base)), boot.block_length(boot.frame_errors(cur))
        )
        pair = boot.paired_replicates((base, cur), name, block, replicates, seed)
        pairs.append(pair)
        out.update(_change_intervals(name, *pair))
    if len(names) > 1 and len(pairs) == len(names):
        out.update(
            _change_intervals(
                "overall",
                boot.total_replicates([a for a, _ in pairs]),
                boot.total_replicates([b for _, b in pairs]),
            )
        )
    elif len(names) > 1:
        notes.append("overall: no intervals (a sequence has none); gated on the fixed tolerance")
    return out, notes


def _change_intervals(
    name: str, base: boot.Replicates, cur: boot.Replicates
) -> dict[tuple[str, str], tuple[float, float]]:
    before, after = boot.replicate_metrics(base), boot.replicate_metrics(cur)
    out = {}
    for metric in before:
        if metric not in DEFAULT_TOLERANCES:
            continue
        interval = boot.interval(after[metric] - before[metric])
        if interval is not None:
            out[name, metric] = interval
    return out
