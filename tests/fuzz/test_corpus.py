"""Every bad input of the corpus gives its documented exit code with one error line.

The classes are those of issues 21 and 28: no traceback, no silent score from corrupt data,
the documented code, no hang (non-regular files are refused before they are opened),
one line, no partial output or temporary leftovers, and no file of the user's replaced.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.fuzz.cli import file_size_limit, leftovers, run_cli, run_isolated
from tests.fuzz.corpus import Case, all_cases

CASES = all_cases()


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_bad_input_gets_its_documented_code_and_one_line(
    case: Case, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = case.build(tmp_path)
    before = {p for p in tmp_path.rglob("*")}
    if case.isolated:
        result = run_isolated(args, tmp_path, case.max_file_bytes)
    else:
        with file_size_limit(case.max_file_bytes):
            result = run_cli(args, capsys)
    assert result.code == case.code, (result.code, result.stderr[-2000:])
    assert "Traceback" not in result.stderr
    if case.code != 0:
        assert len(result.error_lines) == 1, result.stderr
        assert result.error_lines[0].startswith("error: ")
        assert case.message.lower() in result.error_lines[0].lower()
        # Nothing new in the folder: no partial output, no temporary files.
        assert {p for p in tmp_path.rglob("*")} == before
    else:  # success: stderr holds warnings at most (each one line)
        assert all(line.startswith("warning: ") for line in result.error_lines), result.stderr
        assert case.message.lower() in result.stderr.lower()
    assert leftovers(tmp_path) == []
    if case.check is not None:
        case.check(tmp_path)
