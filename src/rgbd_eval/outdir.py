"""Output folders that appear complete or not at all, and never lose a user's files.

Outputs are written into a staging folder beside the target, created before any
work runs (so an unwritable ``--out`` fails first, not after the pipeline), with
the user's umask. On success:

- a missing or empty target is replaced by the staging folder in one rename;
- a target we wrote before (it holds our manifest or ``marker`` file) keeps every
  file we did not write: the old marker goes first, so an interrupted update never
  leaves an old report beside new tables, then our files move in, the marker last;
- any other non-empty folder is refused unless ``force``, which adds our files to it.

Staging folders are named ``.<target>.tmp-<pid>-<random>``; ones left by a killed
process (its pid no longer runs) are removed the next time the target is written.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
from pathlib import Path
from types import TracebackType

from rgbd_eval.errors import OutputError

#: Hidden file listing what we wrote into a folder.
MANIFEST = ".rgbd-eval-files.json"


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    return True


def remove_stale(parent: Path, name: str) -> list[Path]:
    """Remove ``.<name>.tmp-<pid>-*`` staging entries in ``parent`` whose process is gone."""
    removed: list[Path] = []
    prefix = f".{name}.tmp-"
    try:
        entries = list(parent.iterdir())
    except OSError:
        return removed
    for entry in entries:
        if not entry.name.startswith(prefix):
            continue
        pid_text = entry.name[len(prefix) :].split("-", 1)[0]
        if not pid_text.isdigit() or _pid_alive(int(pid_text)):
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
        else:
            entry.unlink(missing_ok=True)
        removed.append(entry)
    return removed


def staging_name(name: str) -> str:
    """A fresh staging name for ``name``: ``.<name>.tmp-<pid>-<random>``."""
    return f".{name}.tmp-{os.getpid()}-{secrets.token_hex(4)}"


def _read_manifest(folder: Path) -> set[str]:
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    files = data.get("files") if isinstance(data, dict) else None
    if not isinstance(files, list):
        return set()
    return {f for f in files if isinstance(f, str) and "/" not in f and f not in ("", ".", "..")}


def check_output_file(path: Path) -> None:
    """OutputError unless ``path`` can be written as a file (its parent is created)."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(path, "is a folder; name a file (its content would be lost)")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(path, f"cannot create its parent folder ({err.strerror})") from err
    if not os.access(path.parent, os.W_OK):
        raise OutputError(path, "its folder is not writable")


class OutputFolder:
    """Stage a command's output files and publish them into ``target`` (see the module doc)."""

    def __init__(self, target: Path, marker: str, force: bool = False) -> None:
        self.target = Path(target)
        self.marker = marker
        self.force = force
        self._staging: Path | None = None

    @property
    def staging(self) -> Path:
        """The folder to write into (after :meth:`prepare`)."""
        if self._staging is None:
            raise OutputError(self.target, "output folder used before it was prepared")
        return self._staging

    def _ours(self) -> bool:
        return (self.target / MANIFEST).is_file() or (self.target / self.marker).is_file()

    def prepare(self) -> Path:
        """Check the target and create the staging folder; OutputError when it cannot be written."""
        target = self.target
        if target.exists() or target.is_symlink():
            if not target.is_dir():
                raise OutputError(target, "exists and is not a folder; choose another --out")
            if any(target.iterdir()) and not self._ours() and not self.force:
                raise OutputError(
                    target,
                    "exists, is not empty and was not written by rgbd-eval; choose another "
                    "--out or add --force to add our files to it (yours are kept)",
                )
        parent = target.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise OutputError(target, f"cannot create its parent folder ({err.strerror})") from err
        remove_stale(parent, target.name)
        staging = parent / staging_name(target.name)
        try:
            staging.mkdir(mode=0o777)  # the umask applies, unlike tempfile.mkdtemp's 0700
        except OSError as err:
            raise OutputError(target, f"cannot write beside it ({err.strerror})") from err
        self._staging = staging
        return staging

    def discard(self) -> None:
        """Remove the staging folder (after a failure)."""
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)
            self._staging = None

    def commit(self) -> None:
        """Publish the staged files (see the module docstring)."""
        staging = self.staging
        new = sorted(p.name for p in staging.iterdir())
        (staging / MANIFEST).write_text(json.dumps({"files": new}) + "\n", encoding="utf-8")
        target = self.target
        try:
            if not target.exists() or (target.is_dir() and not any(target.iterdir())):
                os.replace(staging, target)
            else:
                self._merge(staging, target, new)
                shutil.rmtree(staging, ignore_errors=True)
        except OSError as err:
            self.discard()
            raise OutputError(target, f"cannot publish the output ({err.strerror})") from err
        self._staging = None

    def _merge(self, staging: Path, target: Path, new: list[str]) -> None:
        old = _read_manifest(target)
        (target / self.marker).unlink(missing_ok=True)
        for name in sorted(old - set(new) - {self.marker}):
            stale = target / name
            if stale.is_file() and not stale.is_symlink():
                stale.unlink()
        for name in [n for n in new if n != self.marker] + [self.marker, MANIFEST]:
            if (staging / name).exists():
                if (target / name).is_dir() and not (target / name).is_symlink():
                    raise IsADirectoryError(21, "a folder has the name of an output file", name)
                os.replace(staging / name, target / name)

    def __enter__(self) -> OutputFolder:
        if self._staging is None:
            self.prepare()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is not None or self._staging is not None:
            self.discard()  # failed, or left without commit: nothing published
