"""Reports of runs: JSON for machines, Markdown and terminal tables for people, CSVs.

A run's output folder is written under a temporary name and renamed when
complete, so a failed run never leaves a half-written ``report.json`` that a
later ``compare`` could mistake for a result.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Sequence
from dataclasses import asdict
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rgbd_eval import __version__
from rgbd_eval.config import Convention, Gating, RunConfig, config_to_dict
from rgbd_eval.files import file_digest
from rgbd_eval.machine import machine_info
from rgbd_eval.metrics import Counts, FrameEvents, Summary, summarize, total
from rgbd_eval.outdir import OutputFolder
from rgbd_eval.pipeline import SequenceResult
from rgbd_eval.report import analysis as analysis_report

if TYPE_CHECKING:
    from rgbd_eval.report.analysis import Analysis

REPORT_SCHEMA_VERSION = 1
#: The file that marks a run folder as ours (and that ``compare`` reads).
REPORT_FILE = "report.json"
_LIBRARIES = (
    "numpy",
    "scipy",
    "opencv-python-headless",
    "open3d-cpu",
    "open3d",
    "rosbags",
    "mcap",
    "pydantic",
)

#: Table columns in the order of the thesis' Tables 7.2-7.6: (key, header, kind).
COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("motp", "MOTP", "motp"),
    ("mota", "MOTA", "pct"),
    ("fp_rate", "FP", "pct"),
    ("fn_rate", "FN", "pct"),
    ("id_switches", "ID Sw.", "int"),
    ("main_tr", "Main Tr.", "pct"),
    ("all_tr", "All Tr.", "pct"),
    ("idf1", "IDF1", "pct"),
    ("hota", "HOTA", "pct"),
    ("mt", "MT", "int"),
    ("pt", "PT", "int"),
    ("ml", "ML", "int"),
    ("fragmentations", "Frag.", "int"),
    ("recall_errors", "Rec. err.", "int"),
)

#: Shares whose count is shown beside them (``3.2% (41)``): the count's key in a summary.
COUNT_OF = {"fp_rate": "fp", "fn_rate": "fn"}

#: How each convention matches, for the report header.
MATCHING = {
    Convention.MOTCHALLENGE: "motchallenge (devkit/TrackEval): a previous match is kept only "
    "from the previous frame; MT means tracked in more than 80% of frames",
    Convention.MOTMETRICS: "motmetrics 1.4: a previous match is kept while it stays within "
    "the gate, however long ago; MT means tracked in 80% of frames or more",
}


def library_versions() -> dict[str, str]:
    out = {}
    for name in _LIBRARIES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return out


def format_value(summary: Summary | None, key: str, kind: str, gating: Gating) -> str:
    """One table cell: percentages as in the thesis (FP and FN with their counts,
    :data:`COUNT_OF`), MOTP as % (IoU) or metres."""
    if summary is None or summary.get(key) is None:
        return "-"
    value = summary[key]
    assert value is not None
    if kind == "pct" and (count := summary.get(COUNT_OF.get(key, ""))) is not None:
        return f"{100.0 * float(value):.1f}% ({int(count)})"
    if kind == "pct" or (kind == "motp" and gating is Gating.IOU):
        return f"{100.0 * float(value):.1f}%"
    if kind == "motp":
        return f"{float(value):.3f} m"
    return str(int(value))


def overall_counts(results: Sequence[SequenceResult]) -> Counts | None:
    scored = [r.scores.counts for r in results if r.scores is not None]
    return total(scored) if scored else None


def table_rows(results: Sequence[SequenceResult], gating: Gating) -> list[list[str]]:
    """Rows of the terminal/Markdown table: one per sequence, then 'overall' for several."""
    rows = []
    for r in results:
        summary = r.scores.summary() if r.scores is not None else None
        cells = [format_value(summary, k, kind, gating) for k, _, kind in COLUMNS]
        rows.append([r.name, str(r.info.num_frames), *cells])
    overall = overall_counts(results)
    if len(results) > 1 and overall is not None:
        summary = summarize(overall)
        rows.append(
            [
                "overall",
                str(sum(r.info.num_frames for r in results)),
                *[format_value(summary, k, kind, gating) for k, _, kind in COLUMNS],
            ]
        )
    return rows


def table_header() -> list[str]:
    return ["sequence", "frames", *(h for _, h, _ in COLUMNS)]


def markdown_table(results: Sequence[SequenceResult], gating: Gating) -> str:
    header = table_header()
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in table_rows(results, gating)]
    return "\n".join(lines) + "\n"


def run_notes(results: Sequence[SequenceResult], warnings: bool = True) -> list[str]:
    """What a reader must know besides the table: unscored sequences and (unless
    ``warnings`` is False) the warnings of :func:`run_warnings`."""
    notes = []
    for r in results:
        if r.scores is None:
            notes.append(
                f"{r.name}: no ground truth found, nothing scored "
                f"({sum(len(d) for d in r.detections.detections)} detections and the tracks written)"
            )
        if warnings:
            notes += run_warnings([r])
    return notes


def run_warnings(results: Sequence[SequenceResult]) -> list[str]:
    """``<name>: warning: ...`` for each warning of each sequence (reader, detector, ground
    truth)."""
    return [f"{r.name}: warning: {w}" for r in results for w in sequence_warnings(r)]


def sequence_warnings(r: SequenceResult) -> list[str]:
    """The reader's warnings, then the ground truth's (frames matched or left unscored)."""
    gt = r.ground_truth.warnings if r.ground_truth is not None else ()
    return [*r.info.warnings, *gt]


def sequence_record(r: SequenceResult, digest: str) -> dict[str, Any]:
    info = r.info
    gt = r.ground_truth
    return {
        "name": r.name,
        "path": r.path,
        "sha256": digest,
        "frames": info.num_frames,
        "has_odometry": info.has_odometry,
        "world_frame": info.world_frame,
        "sync": asdict(info.sync),
        "warnings": sequence_warnings(r),
        "provenance": None if info.provenance is None else dict(info.provenance),
        "skipped_messages": [asdict(s) for s in info.skipped],  # damaged, per topic
        "ground_truth": None
        if gt is None
        else {
            "source": gt.source,
            "annotated_frames": gt.annotated_frames,
            "unmatched_frames": gt.unmatched_frames,
            # recording frames outside the annotated span (first..last matched frame)
            "unscored_frames": gt.unscored_frames,
            "scored_span": list(gt.span) if gt.span is not None else None,
        },
        "scored": r.scores is not None,
        "counts": None if r.scores is None else r.scores.counts.to_dict(),
        "metrics": None if r.scores is None else r.scores.summary(),
        "detections": sum(len(d) for d in r.detections.detections),
        "seconds": {k: round(v, 6) for k, v in r.seconds.items()},
    }


def report_dict(
    results: Sequence[SequenceResult], config: RunConfig, digests: Sequence[str]
) -> dict[str, Any]:
    """The content of ``report.json``."""
    overall = overall_counts(results)
    gating = config.evaluation.gating
    return {
        "schema_version": REPORT_SCHEMA_VERSION,
        "tool": {"name": "rgbd-eval", "version": __version__},
        "libraries": library_versions(),
        "machine": machine_info(),
        "method": config.method,
        "evaluation": {
            "gating": gating.value,
            "threshold": config.evaluation.effective_threshold(),
            "motp": "mean IoU of matches (higher is better)"
            if gating is Gating.IOU
            else "mean ground-plane distance of matches in metres (lower is better)",
            "convention": config.evaluation.convention.value,
            "matching": MATCHING[config.evaluation.convention],
        },
        "config": config_to_dict(config),
        "sequences": [sequence_record(r, d) for r, d in zip(results, digests, strict=True)],
        "overall": None
        if overall is None
        else {"counts": overall.to_dict(), "metrics": summarize(overall)},
    }


def sequence_summaries(report: dict[str, Any]) -> dict[str, Any]:
    """Each sequence's metrics, and the overall row's, by name (for the analysis tables)."""
    out = {s["name"]: s["metrics"] for s in report["sequences"]}
    if report.get("overall") is not None:
        out["overall"] = report["overall"]["metrics"]
    return out


def _csv(rows: Sequence[Sequence[Any]], header: Sequence[str]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return buf.getvalue()


def _num(v: float) -> str:
    return f"{v:.4f}"


def detections_csv(r: SequenceResult) -> str:
    header = [
        "frame",
        "stamp_ns",
        "x",
        "y",
        "z",
        "height",
        "bb_left",
        "bb_top",
        "bb_width",
        "bb_height",
        "confidence",
        "occluded",
        "distance",
    ]
    rows = []
    for i, (stamp, dets) in enumerate(
        zip(r.detections.stamps_ns, r.detections.detections, strict=True)
    ):
        for d in dets:
            rows.append(
                [
                    i,
                    stamp,
                    *map(_num, d.position),
                    _num(d.height),
                    *map(_num, d.box2d.as_tuple()),
                    _num(d.confidence),
                    int(d.occluded),
                    _num(d.distance),
                ]
            )
    return _csv(rows, header)


def tracks_csv(r: SequenceResult) -> str:
    """MOTChallenge-style rows (frame, id, box, conf, x, y, z) plus stamp, height, visibility,
    status; ``conf`` is the track's confidence, empty where the tracker gives none."""
    header = [
        "frame",
        "id",
        "bb_left",
        "bb_top",
        "bb_width",
        "bb_height",
        "conf",
        "x",
        "y",
        "z",
        "stamp_ns",
        "height",
        "visibility",
        "status",
    ]
    rows = []
    for i, (stamp, tracks) in enumerate(zip(r.detections.stamps_ns, r.tracks, strict=True)):
        for t in tracks:
            box = [_num(v) for v in t.box2d.as_tuple()] if t.box2d is not None else ["", "", "", ""]
            rows.append(
                [
                    i,
                    t.track_id,
                    *box,
                    "" if t.confidence is None else _num(t.confidence),
                    _num(t.x),
                    _num(t.y),
                    _num(t.height / 2),
                    stamp,
                    _num(t.height),
                    t.visibility.name.lower(),
                    t.status.value,
                ]
            )
    return _csv(rows, header)


EVENTS_HEADER = ("frame", "stamp_ns", "event", "gt_id", "track_id", "similarity", "recall_error")


def events_csv(
    frames: Sequence[FrameEvents],
    stamps_ns: Sequence[int],
    frame_numbers: Sequence[int] | None = None,
) -> str:
    """Per-frame scoring events: one row per match/switch, miss, false positive, ignored object.

    ``similarity`` is the IoU (IoU gating) or the distance in metres (metric gating) of a
    match; ``switch`` rows are matches that are id switches. ``frame`` is the frame index,
    or the input's own frame number (MOTChallenge counts from 1) where given.
    """
    # Every field is a whole number, a fixed word or a formatted float: the lines are what
    # csv.writer makes of them (nothing to quote), joined without its per-row cost.
    lines = [",".join(EVENTS_HEADER)]
    numbers = frame_numbers if frame_numbers is not None else [e.frame for e in frames]
    for events, stamp, f in zip(frames, stamps_ns, numbers, strict=True):
        at = f"{f},{stamp},"
        lines += [
            f"{at}{'switch' if m.id_switch else 'match'},{m.gt_id},{m.track_id},"
            f"{m.similarity:.6f},{int(m.recall_error)}"
            for m in events.matches
        ]
        lines += [f"{at}miss,{g},,," for g in events.misses]
        lines += [f"{at}fp,,{t},," for t in events.false_positives]
        lines += [f"{at}ignored_gt,{g},,," for g in events.ignored_gt]
        lines += [f"{at}ignored_track,,{t},," for t in events.ignored_tracks]
    lines.append("")
    return "\n".join(lines)


def write_run(
    out: Path | OutputFolder,
    results: Sequence[SequenceResult],
    config: RunConfig,
    also: Callable[[Path, dict[str, Any]], None] | None = None,
    analysis: Analysis | None = None,
) -> dict[str, Any]:
    """Write every output of a run into ``out`` (published when complete); return the report.

    ``out`` is a folder path, or an :class:`OutputFolder` prepared before the pipeline ran.
    ``also(folder, report)`` writes further outputs (the HTML page and its plots) into the
    staged folder. ``analysis`` (:func:`rgbd_eval.report.analysis.analyse`) adds the breakdowns,
    intervals and curve to the report, and a ``<name>.frames.npz`` per scored sequence.
    """
    import json

    digests = [file_digest(Path(r.path)) for r in results]
    report = report_dict(results, config, digests)
    if analysis is not None:
        analysis_report.annotate(report, analysis)
    folder = out if isinstance(out, OutputFolder) else OutputFolder(out, REPORT_FILE, command="run")
    with folder:
        tmp = folder.staging
        for r in results:
            (tmp / f"{r.name}.detections.csv").write_text(detections_csv(r), encoding="utf-8")
            (tmp / f"{r.name}.tracks.csv").write_text(tracks_csv(r), encoding="utf-8")
            if r.scores is not None:
                (tmp / f"{r.name}.events.csv").write_text(
                    events_csv(r.scores.frames, r.detections.stamps_ns), encoding="utf-8"
                )
        if analysis is not None:
            for name, data in analysis_report.frames_files(analysis).values():
                (tmp / name).write_bytes(data)
        md = [
            f"# rgbd-eval run: {config.method}",
            "",
            f"Gating: {report['evaluation']['gating']} (threshold {report['evaluation']['threshold']}); "
            f"MOTP is the {report['evaluation']['motp']}.",
            f"Convention: {report['evaluation']['matching']}.",
            "",
        ]
        if any(r.scores is not None for r in results):
            md.append(markdown_table(results, config.evaluation.gating))
        md += [f"- {note}" for note in run_notes(results)]
        if analysis is not None:
            md += analysis_report.markdown(analysis, sequence_summaries(report))
        (tmp / "report.md").write_text("\n".join(md) + "\n", encoding="utf-8")
        (tmp / REPORT_FILE).write_text(
            json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8"
        )
        if also is not None:
            also(tmp, report)
        folder.commit()
    return report
