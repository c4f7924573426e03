"""Output folders: staged before the work, published whole, never deleting the user's files."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rgbd_eval.errors import OutputError
from rgbd_eval.outdir import MANIFEST, OutputFolder, check_output_file, remove_stale


def _publish(target: Path, files: dict[str, str], force: bool = False) -> None:
    with OutputFolder(target, "report.json", force) as folder:
        for name, text in files.items():
            (folder.staging / name).write_text(text)
        folder.commit()


def test_rerun_replaces_only_our_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    _publish(out, {"report.json": "1", "a.tracks.csv": "old", "b.tracks.csv": "old"})
    (out / "compare.md").write_text("the user's")  # as the README's CI example does
    _publish(out, {"report.json": "2", "a.tracks.csv": "new"})
    assert (out / "compare.md").read_text() == "the user's"
    assert (out / "report.json").read_text() == "2"
    assert (out / "a.tracks.csv").read_text() == "new"
    assert not (out / "b.tracks.csv").exists()  # ours, from the previous run: removed
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["files"] == ["a.tracks.csv", "report.json"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging left


def test_foreign_folder_is_refused_unless_forced(tmp_path: Path) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("keep me")
    with pytest.raises(OutputError, match="--force"):
        OutputFolder(out, "report.json").prepare()
    _publish(out, {"report.json": "1"}, force=True)
    assert (out / "thesis.tex").read_text() == "keep me"
    assert (out / "report.json").read_text() == "1"


def test_failure_publishes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt), OutputFolder(out, "report.json") as folder:
        (folder.staging / "report.json").write_text("partial")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []


def test_folders_follow_the_umask(tmp_path: Path) -> None:
    old = os.umask(0o022)
    try:
        _publish(tmp_path / "out", {"report.json": "1"})
    finally:
        os.umask(old)
    # mkdtemp gave 0700; with umask 022 a folder is 0777 & ~022 = 0755.
    assert (tmp_path / "out").stat().st_mode & 0o777 == 0o755


def test_unwritable_targets_fail_before_any_work(tmp_path: Path) -> None:
    (tmp_path / "file.txt").write_text("x")
    with pytest.raises(OutputError, match="not a folder"):
        OutputFolder(tmp_path / "file.txt", "report.json").prepare()
    with pytest.raises(OutputError, match="cannot create its parent"):
        OutputFolder(tmp_path / "file.txt" / "sub", "report.json").prepare()
    with pytest.raises(OutputError, match="is a folder"):
        check_output_file(tmp_path)


def _dead_pid() -> int:
    proc = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    return int(proc.stdout)


def test_stale_staging_of_a_dead_process_is_removed(tmp_path: Path) -> None:
    dead = tmp_path / f".out.tmp-{_dead_pid()}-abcd"
    dead.mkdir()
    (dead / "report.json").write_text("half")
    alive = tmp_path / f".out.tmp-{os.getpid()}-beef"  # this process: still running
    alive.mkdir()
    other = tmp_path / ".other.tmp-1-abcd"  # another target's: not ours to judge here
    other.mkdir()
    assert remove_stale(tmp_path, "out") == [dead]
    assert alive.exists() and other.exists() and not dead.exists()
