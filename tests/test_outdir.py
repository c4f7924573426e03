"""Outputs: staged before the work, published whole, never replacing what we did not write."""

from __future__ import annotations

import json
import os
import re
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from rgbd_eval.atomic import write_text
from rgbd_eval.errors import OutputError
from rgbd_eval.outdir import MANIFEST, OutputFolder, check_output_file, remove_stale


def _publish(
    target: Path,
    files: dict[str, str],
    force: bool = False,
    command: str = "run",
    marker: str = "report.json",
) -> None:
    with OutputFolder(target, marker, force, command=command) as folder:
        for name, text in files.items():
            (folder.staging / name).write_text(text)
        folder.commit()


def _listed(folder: Path) -> dict[str, list[str]]:
    """What the manifest of ``folder`` says each command wrote."""
    data = json.loads((folder / MANIFEST).read_text())
    return {owner: sorted(files) for owner, files in data["files"].items()}


def test_rerun_replaces_only_our_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    _publish(out, {"report.json": "1", "a.tracks.csv": "old", "b.tracks.csv": "old"})
    (out / "compare.md").write_text("the user's")  # as the README's CI example does
    _publish(out, {"report.json": "2", "a.tracks.csv": "new"})
    assert (out / "compare.md").read_text() == "the user's"
    assert (out / "report.json").read_text() == "2"
    assert (out / "a.tracks.csv").read_text() == "new"
    assert not (out / "b.tracks.csv").exists()  # ours, from the previous run: removed
    assert _listed(out) == {"run": ["a.tracks.csv", "report.json"]}
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
        check_output_file(tmp_path, "compare")
    with pytest.raises(OutputError, match="too long"):
        OutputFolder(tmp_path / ("o" * 300), "report.json").prepare()
    with pytest.raises(OutputError, match="too long"):
        check_output_file(tmp_path / ("o" * 300), "compare")


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


def test_each_command_replaces_and_removes_only_its_own_files(tmp_path: Path) -> None:
    out = tmp_path / "res"
    _publish(out, {"sweep.json": "s", "sweep.csv": "s"}, command="sweep", marker="sweep.json")
    _publish(out, {"report.json": "1", "a.tracks.csv": "a"})  # run into the sweep's folder
    _publish(out, {"report.json": "2"})  # run again: its a.tracks.csv is stale, sweep's kept
    assert sorted(p.name for p in out.iterdir() if p.name != MANIFEST) == [
        "report.json",
        "sweep.csv",
        "sweep.json",
    ]
    assert _listed(out) == {"run": ["report.json"], "sweep": ["sweep.csv", "sweep.json"]}
    for force in (False, True):  # score writes report.json too: run's is never replaced
        with pytest.raises(OutputError, match="written by `rgbd-eval run`"):
            _publish(out, {"report.json": "score"}, force=force, command="score")
    assert (out / "report.json").read_text() == "2"
    # The sweep's own re-run replaces its files and removes its stale one, not run's.
    _publish(out, {"sweep.json": "s2"}, command="sweep", marker="sweep.json")
    assert {p.name for p in out.iterdir()} == {MANIFEST, "report.json", "sweep.json"}


def test_a_file_edited_since_we_wrote_it_is_neither_replaced_nor_removed(tmp_path: Path) -> None:
    out = tmp_path / "out"
    _publish(out, {"report.json": "1", "report.md": "ours", "a.tracks.csv": "a"})
    (out / "report.md").write_text("the user's notes")
    with pytest.raises(OutputError, match="changed since `rgbd-eval run` wrote it"):
        _publish(out, {"report.json": "2", "report.md": "new"})
    assert (out / "report.md").read_text() == "the user's notes"
    (out / "a.tracks.csv").write_text("edited")
    _publish(out, {"report.json": "3"})  # both are stale now: the edited ones stay, unlisted
    assert (out / "report.md").read_text() == "the user's notes"
    assert (out / "a.tracks.csv").read_text() == "edited"
    assert _listed(out) == {"run": ["report.json"]}


@pytest.mark.parametrize("name", ["report.json", "report.md", "b.tracks.csv"])
def test_force_never_replaces_a_users_file(tmp_path: Path, name: str) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / name).write_text("the user's")
    with pytest.raises(OutputError, match="add --force"):  # a report.json does not make it ours
        _publish(out, {"report.json": "1", "report.md": "m", "b.tracks.csv": "b"})
    with pytest.raises(OutputError, match=f"{re.escape(name)}: exists and was not written by"):
        _publish(out, {"report.json": "1", "report.md": "m", "b.tracks.csv": "b"}, force=True)
    assert [p.name for p in out.iterdir()] == [name]
    assert (out / name).read_text() == "the user's"
    assert [p.name for p in tmp_path.iterdir()] == ["mine"]  # no staging left


def test_a_folder_named_early_is_refused_before_the_work(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.md").write_text("the user's")
    folder = OutputFolder(out, "report.json", True, command="run", names=["report.md"])
    with pytest.raises(OutputError, match=r"report\.md: exists and was not written"):
        folder.prepare()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_symbolic_link_to_a_folder_is_written_through(tmp_path: Path) -> None:
    (tmp_path / "real").mkdir()
    (tmp_path / "out").symlink_to("real")
    _publish(tmp_path / "out", {"report.json": "1"})
    assert (tmp_path / "out").is_symlink()
    assert (tmp_path / "real" / "report.json").read_text() == "1"
    _publish(tmp_path / "out", {"report.json": "2"})  # again: the folder is ours now
    assert (tmp_path / "real" / "report.json").read_text() == "2"
    (tmp_path / "dangling").symlink_to("nowhere")
    with pytest.raises(OutputError, match="symbolic link"):
        OutputFolder(tmp_path / "dangling", "report.json").prepare()


def test_a_version_1_manifest_still_lets_its_command_replace_its_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    for name in ("report.json", "a.tracks.csv", "compare.md"):
        (out / name).write_text("old")
    (out / MANIFEST).write_text(json.dumps({"files": ["a.tracks.csv", "report.json"]}))
    _publish(out, {"report.json": "new"})
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "compare.md", "report.json"]
    assert _listed(out) == {"run": ["report.json"]}


@pytest.mark.parametrize("content", [b"{not json", b'{"files": 3}', b"[" * 100_000, None])
def test_a_manifest_we_cannot_read_stops_every_write_there(
    tmp_path: Path, content: bytes | None
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    if content is None:
        os.mkfifo(out / MANIFEST)  # never opened (it would block)
    else:
        (out / MANIFEST).write_bytes(content)
    with pytest.raises(OutputError, match="not rgbd-eval's record"):
        _publish(out, {"report.json": "1"}, force=True)
    with pytest.raises(OutputError, match="not rgbd-eval's record"):
        write_text(out / "cmp.md", "x", "compare")
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST]


def test_single_files_replace_only_what_their_command_wrote(tmp_path: Path) -> None:
    cmp = tmp_path / "cmp.md"
    write_text(cmp, "1", "compare")
    write_text(cmp, "2", "compare")  # its own file: replaced
    assert cmp.read_text() == "2"
    with pytest.raises(OutputError, match="written by `rgbd-eval compare`"):
        write_text(cmp, "bench", "bench")
    with pytest.raises(OutputError, match="written by `rgbd-eval compare`"):
        check_output_file(cmp, "bench")
    (tmp_path / "notes.md").write_text("the user's")
    with pytest.raises(OutputError, match="not written by `rgbd-eval compare`"):
        check_output_file(tmp_path / "notes.md", "compare")
    with pytest.raises(OutputError, match="not written by `rgbd-eval compare`"):
        write_text(tmp_path / "notes.md", "x", "compare")
    assert (tmp_path / "notes.md").read_text() == "the user's"
    cmp.write_text("edited")
    with pytest.raises(OutputError, match="changed since"):
        write_text(cmp, "3", "compare")
    assert _listed(tmp_path) == {"compare": ["cmp.md"]}
    assert not [p for p in tmp_path.iterdir() if ".tmp-" in p.name]


def test_an_input_is_never_an_output(tmp_path: Path) -> None:
    report = tmp_path / "report.json"
    report.write_text("{}")
    (tmp_path / "link.json").symlink_to("report.json")
    for target in (report, tmp_path / "link.json"):
        with pytest.raises(OutputError, match="input"):
            check_output_file(target, "compare", [report])


def test_pipes_links_and_devices_are_never_replaced(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe")
    (tmp_path / "link").symlink_to("/dev/null")
    targets = {"pipe": "named pipe", "link": "symbolic link"}
    try:
        os.mknod(tmp_path / "full", stat.S_IFCHR | 0o666, os.makedev(1, 7))
        targets["full"] = "device"
    except PermissionError:
        pass  # no CAP_MKNOD: the device case is left out
    for name, kind in targets.items():
        with pytest.raises(OutputError, match=kind):
            check_output_file(tmp_path / name, "compare")
        for owner in ("compare", None):
            with pytest.raises(OutputError, match=kind):
                write_text(tmp_path / name, "x", owner)
    assert stat.S_ISFIFO(os.lstat(tmp_path / "pipe").st_mode)
    assert (tmp_path / "link").is_symlink()
    if "full" in targets:
        assert stat.S_ISCHR(os.lstat(tmp_path / "full").st_mode)
