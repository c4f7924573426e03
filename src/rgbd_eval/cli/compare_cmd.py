"""``rgbd-eval compare``: gate regressions between two reports (exit 1 on regression)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from rgbd_eval.atomic import write_text
from rgbd_eval.cli.common import console, handle_errors, one_line
from rgbd_eval.outdir import check_output_file


@handle_errors
def compare(
    baseline: Annotated[Path, typer.Argument(help="baseline report.json (or its run folder)")],
    current: Annotated[Path, typer.Argument(help="current report.json (or its run folder)")],
    tolerance: Annotated[
        list[str] | None,
        typer.Option("--tolerance", help="METRIC=VALUE allowed worsening, repeatable"),
    ] = None,
    markdown_file: Annotated[
        Path | None, typer.Option("--markdown", help="also write the table as Markdown")
    ] = None,
    all_rows: Annotated[bool, typer.Option("--all", help="show unchanged metrics too")] = False,
    html_file: Annotated[
        Path | None, typer.Option("--html", help="also write the deltas as an HTML page")
    ] = None,
    significance: Annotated[
        bool,
        typer.Option(
            "--significance",
            help="a metric regresses when worse beyond its 95% paired-bootstrap interval "
            "(instead of its tolerance; needs the reports' <name>.frames.npz)",
        ),
    ] = False,
) -> None:
    """Per sequence and overall, what got better and what got worse; exit 1 on regression."""
    from rgbd_eval.compare import (  # heavy (report -> metrics -> motmetrics/pandas): only here
        HEADER,
        Status,
        compare_reports,
        load_report,
        markdown,
        parse_tolerances,
        table_rows,
    )
    from rgbd_eval.significance import paired_intervals

    tolerances = parse_tolerances(tolerance or [])  # bad arguments fail before any file is read
    inputs = [baseline, baseline / "report.json", current, current / "report.json"]
    for output in (markdown_file, html_file):
        if output is not None:  # before the reports are read; never one of them
            check_output_file(output, "compare", inputs)
    base_report, cur_report = load_report(baseline), load_report(current)
    intervals, missing = paired_intervals(baseline, base_report, current, cur_report)
    comparison = compare_reports(base_report, cur_report, tolerances, intervals, significance)
    if significance:  # where there is no interval, say so: those metrics keep their tolerance
        comparison = replace(comparison, notes=(*comparison.notes, *missing))
    table = Table(title=f"{baseline} -> {current}", title_justify="left")
    for i, head in enumerate(HEADER):
        table.add_column(head, justify="left" if i < 2 else "right")
    styles = {
        Status.REGRESSED.value: "bold red",
        Status.WORSE.value: "yellow",
        Status.BETTER.value: "green",
    }
    rows = table_rows(comparison, changed_only=not all_rows)
    for row in rows:
        table.add_row(*row, style=styles.get(row[-1]))
    if rows:
        console.print(table)
    for change in comparison.config_changes:
        console.print(f"config: {change}")
    for note in comparison.notes:
        if note in missing:  # how the gate works, with the table: not a problem of the input
            console.print(f"note: {one_line(note)}", markup=False, highlight=False)
        else:
            typer.echo(f"note: {one_line(note)}", err=True)
    if markdown_file is not None:
        write_text(markdown_file, markdown(comparison), "compare")
    if html_file is not None:
        from rgbd_eval.report.html.pages import compare_page

        write_text(html_file, compare_page(comparison, str(baseline), str(current)), "compare")
    if comparison.regressions:
        lost = [d for d in comparison.regressions if d.status is Status.MISSING]
        worse = [d for d in comparison.regressions if d.status is Status.REGRESSED]
        reasons = []
        if worse:
            names = ", ".join(f"{d.sequence}/{d.metric}" for d in worse)
            reasons.append(f"{len(worse)} regression(s) beyond {comparison.gate}: {names}")
        if lost:
            names = ", ".join(f"{d.sequence}/{d.metric}" for d in lost)
            reasons.append(f"{len(lost)} metric(s) scored in the baseline but missing now: {names}")
        typer.echo(f"error: {one_line('; '.join(reasons))}", err=True)
        raise typer.Exit(1)
    console.print(f"no regression beyond {comparison.gate}")
