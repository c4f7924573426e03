"""Score a tracker's recorded output against ground truth (``rgbd-eval score``), no pipeline.

One sequence is a pair (tracker output, ground truth), read by
:mod:`rgbd_eval.io.tracks` and put on one timeline; the report has the layout of
``rgbd-eval run``'s ``report.json`` (so ``compare`` reads both), with per-sequence
``events.csv`` files.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rgbd_eval import __version__
from rgbd_eval.config import EvaluationConfig, Gating
from rgbd_eval.errors import ScoringError
from rgbd_eval.files import file_digest
from rgbd_eval.io.tracks import Aligned, Benchmark, align, load_gt, load_tracks
from rgbd_eval.machine import machine_info
from rgbd_eval.metrics import SequenceScores, evaluate_sequence, summarize, total
from rgbd_eval.outdir import OutputFolder
from rgbd_eval.report import analysis as analysis_report
from rgbd_eval.report.run import (
    COLUMNS,
    MATCHING,
    REPORT_SCHEMA_VERSION,
    events_csv,
    format_value,
    library_versions,
)

if TYPE_CHECKING:
    from rgbd_eval.report.analysis import Analysis


@dataclass(frozen=True)
class ScoredSequence:
    """One scored sequence: its inputs, the aligned frames and the scores."""

    name: str
    tracks_path: Path
    gt_path: Path
    aligned: Aligned
    scores: SequenceScores
    warnings: tuple[str, ...]


def score_sequence(
    name: str,
    tracks_path: Path,
    gt_path: Path,
    config: EvaluationConfig,
    max_gap_ns: int,
    benchmark: Benchmark = Benchmark.AUTO,
    topic: str | None = None,
    world_frame: str | None = None,
) -> ScoredSequence:
    """Read, align and score one sequence; ScoringError when nothing can be compared.

    ``topic`` and ``world_frame`` apply to tracks recorded in a bag.
    """
    gt, length = load_gt(gt_path, benchmark)
    tracks = load_tracks(tracks_path, topic, world_frame)
    aligned = align(gt, tracks, max_gap_ns, length)
    if tracks.frames and aligned.unmatched_track_frames == len(tracks.frames) and gt.frames:
        raise ScoringError(
            f"{tracks_path}: none of its {len(tracks.frames)} frames matches an annotated "
            f"frame of {gt_path} (by stamp within {max_gap_ns / 1e6:g} ms)"
        )
    warnings = []
    if aligned.unmatched_track_frames:
        warnings.append(
            f"{aligned.unmatched_track_frames} of {len(tracks.frames)} tracker frames match no "
            "annotated frame and are not scored"
        )
    scores = evaluate_sequence(aligned.gt, aligned.tracks, config)
    return ScoredSequence(name, tracks_path, gt_path, aligned, scores, tuple(warnings))


def _motp_text(gating: Gating) -> str:
    if gating is Gating.IOU:
        return "mean IoU of matches (higher is better)"
    return "mean ground-plane distance of matches in metres (lower is better)"


def report_dict(
    sequences: Sequence[ScoredSequence], config: EvaluationConfig, max_gap_ns: int
) -> dict[str, Any]:
    """The content of ``report.json`` (the layout of ``rgbd-eval run``'s report)."""
    overall = total(s.scores.counts for s in sequences) if sequences else None
    return {
        "schema_version": REPORT_SCHEMA_VERSION,
        "tool": {"name": "rgbd-eval", "version": __version__},
        "libraries": library_versions(),
        "machine": machine_info(),
        "method": "external tracker output",
        "evaluation": {
            "gating": config.gating.value,
            "threshold": config.effective_threshold(),
            "motp": _motp_text(config.gating),
            "convention": config.convention.value,
            "matching": MATCHING[config.convention],
        },
        "config": {
            "evaluation": config.model_dump(mode="json"),
            "max_sync_gap_ms": max_gap_ns / 1e6,
        },
        "sequences": [
            {
                "name": s.name,
                "path": str(s.tracks_path),
                "ground_truth": {"source": str(s.gt_path)},
                # compare checks that both reports scored the same data: the ground truth.
                "sha256": file_digest(s.gt_path),
                "tracks_sha256": file_digest(s.tracks_path),
                "frames": len(s.aligned.gt),
                "warnings": list(s.warnings),
                "scored": True,
                "counts": s.scores.counts.to_dict(),
                "metrics": s.scores.summary(),
            }
            for s in sequences
        ],
        "overall": None
        if overall is None
        else {"counts": overall.to_dict(), "metrics": summarize(overall)},
    }


def table_rows(sequences: Sequence[ScoredSequence], gating: Gating) -> list[list[str]]:
    """One row per sequence, then 'overall' for several (cells as in ``run``'s table)."""
    rows = [
        [
            s.name,
            str(len(s.aligned.gt)),
            *[format_value(s.scores.summary(), k, kind, gating) for k, _, kind in COLUMNS],
        ]
        for s in sequences
    ]
    if len(sequences) > 1:
        summary = summarize(total(s.scores.counts for s in sequences))
        frames = sum(len(s.aligned.gt) for s in sequences)
        cells = [format_value(summary, k, kind, gating) for k, _, kind in COLUMNS]
        rows.append(["overall", str(frames), *cells])
    return rows


def write_report(
    folder: OutputFolder,
    sequences: Sequence[ScoredSequence],
    config: EvaluationConfig,
    max_gap_ns: int,
    also: Callable[[Path, dict[str, Any]], None] | None = None,
    analysis: Analysis | None = None,
) -> dict[str, Any]:
    """Write report.json, report.md and one events.csv per sequence into ``folder``'s
    staging folder (prepared before the inputs were read, as ``run`` does), then publish it;
    the caller's ``with folder`` discards the staging folder when this fails.

    ``also(folder, report)`` writes further outputs (the HTML page) into the staged folder;
    ``analysis`` adds breakdowns, intervals, the curve and the ``<name>.frames.npz`` files.
    """
    from rgbd_eval.report.run import sequence_summaries, table_header

    report = report_dict(sequences, config, max_gap_ns)
    if analysis is not None:
        analysis_report.annotate(report, analysis)
    header = table_header()
    lines = [
        "# rgbd-eval score",
        "",
        f"Gating: {config.gating.value} (threshold {config.effective_threshold()}); "
        f"MOTP is the {_motp_text(config.gating)}.",
        f"Convention: {MATCHING[config.convention]}.",
        "",
        "| " + " | ".join(header) + " |",
        "|" + "|".join("---" for _ in header) + "|",
        *("| " + " | ".join(row) + " |" for row in table_rows(sequences, config.gating)),
        "",
        *(f"- {s.name}: warning: {w}" for s in sequences for w in s.warnings),
        *(analysis_report.markdown(analysis, sequence_summaries(report)) if analysis else []),
    ]
    tmp = folder.staging
    for s in sequences:
        (tmp / f"{s.name}.events.csv").write_text(
            events_csv(s.scores.frames, s.aligned.stamps_ns, s.aligned.frame_numbers),
            encoding="utf-8",
        )
    if analysis is not None:
        for name, data in analysis_report.frames_files(analysis).values():
            (tmp / name).write_bytes(data)
    (tmp / "report.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    (tmp / "report.json").write_text(
        json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8"
    )
    if also is not None:
        also(tmp, report)
    folder.commit()
    return report
