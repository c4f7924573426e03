"""Every bad input of the corpus gives its documented exit code with one error line.

The classes are those of issue 21: no traceback, no silent score from corrupt data,
the documented code, no hang (non-regular files are refused before they are opened),
one line, and no partial output or temporary leftovers.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.fuzz.cli import leftovers, run_cli
from tests.fuzz.corpus import Case, all_cases

CASES = all_cases()


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_bad_input_gets_its_documented_code_and_one_line(
    case: Case, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = case.build(tmp_path)
    before = {p for p in tmp_path.rglob("*")}
    result = run_cli(args, capsys)
    assert result.code == case.code, (result.code, result.stderr[-2000:])
    assert "Traceback" not in result.stderr
    if case.code != 0:
        assert len(result.error_lines) == 1, result.stderr
        assert result.error_lines[0].startswith("error: ")
        assert case.message.lower() in result.error_lines[0].lower()
        # Nothing new in the folder: no partial output, no temporary files.
        assert {p for p in tmp_path.rglob("*")} == before
    assert leftovers(tmp_path) == []
