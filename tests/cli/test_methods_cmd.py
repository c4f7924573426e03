"""``rgbd-eval methods``: the printed text, square brackets included."""

from __future__ import annotations

from typer.testing import CliRunner

from rgbd_eval.cli.main import app

runner = CliRunner()


def test_methods_print_every_stream_with_its_optional_mark() -> None:
    result = runner.invoke(app, ["methods"])
    assert result.exit_code == 0, result.output
    rows = {}
    for line in result.output.splitlines():
        cells = [c.strip() for c in line.strip("│ ").split("│")]
        if len(cells) == 6 and cells[0]:
            rows[cells[0]] = cells
    assert rows["satake2009"][1] == "left, [right], [disparity]"
    assert rows["cielniak2010"][1] == "thermal, colour"
    assert rows["dmtbs"][1] == "depth..."
    assert rows["basso2012"][1] == "colour, depth"


def test_methods_help_keeps_its_square_brackets() -> None:
    result = runner.invoke(app, ["methods", "--help"])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.replace("│", " ").split())
    assert "List the methods: streams read ([optional], ... = one or more)" in text
