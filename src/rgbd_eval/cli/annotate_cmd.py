"""``rgbd-eval annotate export|import``: ground truth made in CVAT (:mod:`rgbd_eval.annotate`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from rgbd_eval.cli.common import (
    ConfigOption,
    SetOption,
    TopicOption,
    advance_callback,
    console,
    handle_errors,
    progress_bar,
    topic_overrides,
)
from rgbd_eval.config import load_config

annotate = typer.Typer(
    name="annotate",
    help="Ground truth with CVAT: export a task to annotate, import CVAT's export back.",
    no_args_is_help=False,  # a missing subcommand is one error line (exit 2), as elsewhere
    add_completion=False,
    pretty_exceptions_enable=False,
)

EveryOption = Annotated[
    int | None,
    typer.Option(min=1, help="recording frames per task frame (export: default 1)"),
]


@annotate.command("export")
@handle_errors
def export(
    recording: Annotated[Path, typer.Argument(help="the recording to annotate")],
    out: Annotated[Path, typer.Option("-o", "--out", help="task folder to write")],
    method: Annotated[
        str | None,
        typer.Option(help="method whose tracks pre-annotate the task (default: basso2012)"),
    ] = None,
    tracks: Annotated[
        Path | None,
        typer.Option(
            help="pre-annotate with this tracker output instead (e.g. a run's tracks.csv)"
        ),
    ] = None,
    every: EveryOption = None,
    config_file: ConfigOption = None,
    overrides: SetOption = None,
    topics: TopicOption = None,
    force: Annotated[
        bool,
        typer.Option(help="write into a non-empty --out folder we did not write (keeps its files)"),
    ] = False,
) -> None:
    """Write a CVAT task: every Nth colour frame (images.zip), pre-annotations, README.txt."""
    from rgbd_eval.annotate import export_task

    sets = [*(overrides or []), *topic_overrides(topics)]
    config = load_config(config_file, sets, method=method or (None if config_file else "basso2012"))
    with progress_bar() as bar:
        task = bar.add_task(recording.name, total=None)
        summary = export_task(
            recording,
            out,
            config,
            every=every or 1,
            tracks_file=tracks,
            force=force,
            progress=advance_callback(bar, task),
        )
    console.print(
        f"{summary.folder}: {summary.images} frames (every {summary.every}.), "
        f"{summary.tracks} tracks ({summary.boxes} boxes) of {summary.source}; "
        f"see {summary.folder / 'README.txt'}"
    )


@annotate.command("import")
@handle_errors
def import_(
    annotations: Annotated[
        Path,
        typer.Argument(
            metavar="CVAT_EXPORT",
            help="CVAT's export: its zip, annotations.xml (CVAT for video 1.1) or gt/gt.txt (MOT 1.1)",
        ),
    ],
    recording: Annotated[Path, typer.Option(help="the recording the task was made from")],
    out: Annotated[
        Path | None,
        typer.Option("-o", "--out", help="sidecar CSV to write (default: <name>.gt.csv beside it)"),
    ] = None,
    every: EveryOption = None,
    label: Annotated[str | None, typer.Option(help="the label of people (default: person)")] = None,
    other_labels: Annotated[
        str, typer.Option(help="tracks of other labels: ignore or refuse")
    ] = "ignore",
    config_file: ConfigOption = None,
    overrides: SetOption = None,
    topics: TopicOption = None,
) -> None:
    """Read CVAT's export into a ground-truth CSV, with world positions from depth and tf."""
    from rgbd_eval.annotate import OtherLabels, import_annotations
    from rgbd_eval.pipeline import sequence_name

    try:
        others = OtherLabels(other_labels)
    except ValueError:
        raise typer.BadParameter(
            f"{other_labels!r}: expected ignore or refuse", param_hint="'--other-labels'"
        ) from None
    sets = [*(overrides or []), *topic_overrides(topics)]
    config = load_config(config_file, sets, method=None if config_file else "basso2012")
    target = out or recording.with_name(f"{sequence_name(recording)}.gt.csv")
    with progress_bar() as bar:
        task = bar.add_task(recording.name, total=None)
        summary = import_annotations(
            annotations,
            recording,
            target,
            config,
            every=every,
            label=label,
            others=others,
            progress=advance_callback(bar, task),
        )
    skipped = ", ".join(f"{n} {what}" for what, n in sorted(summary.skipped.items()))
    depth = (
        f"{summary.positions} with a world position"
        if summary.has_depth
        else "no depth in the recording: boxes only (metric gating will refuse it)"
    )
    if summary.unplaced is not None:
        frame, track = summary.unplaced
        depth += (
            f" (none for frame {frame} id {track} and {summary.boxes - summary.positions - 1} "
            "more: no single surface in the torso; metric gating refuses them unless ignored)"
        )
    console.print(
        f"{summary.output}: {summary.tracks} tracks, {summary.boxes} boxes on "
        f"{summary.frames} frames ({summary.kind}, task frame k = recording frame "
        f"{summary.every} x k), {depth}" + (f"; left out: {skipped}" if skipped else "")
    )
