"""Outputs that appear complete or not at all, and never replace what we did not write.

The rule, for every command: an output path is written only when it is absent, or when it
is a regular file that the same command wrote there and that is unchanged since. Folders,
device nodes, named pipes, sockets and symbolic links are never replaced; nor is a file
another command wrote, nor one the user made or edited. What each command wrote into a
folder is recorded in that folder's manifest (:data:`MANIFEST`): per command, each file's
size and sha256. A command replaces, and removes as stale, only files its own section
lists and that still match it; ``--force`` lets a command add its files to a folder it
did not write, never replace a file there.

Output folders (``run``, ``score``, ``sweep``, ``reproduce``) are written into a staging
folder beside the target, created before any work runs (so an unwritable ``--out`` fails
first, not after the pipeline), with the user's umask. On success:

- a missing target is replaced by the staging folder in one rename;
- into an existing folder (empty, one we wrote, or any with ``force``; a symbolic link to
  a folder is written through) every file is checked first, then our old marker goes, so
  an interrupted update never leaves an old report beside new tables, our stale files
  go, our files move in, the marker last, then the manifest;
- any other non-empty folder is refused unless ``force``.

Single files (``compare --markdown``, ``bench --html``, ``synth`` recordings, sidecars and
previews, ``import``) are checked with :func:`check_output_file` before the work and
published with :func:`publish_file`, recorded in their folder's manifest likewise.

Staging names are ``.<target>.tmp-<pid>-<random>``; ones left by a killed process (its
pid no longer runs) are removed the next time the target is written.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import secrets
import shutil
import stat
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType

from rgbd_eval.errors import OutputError
from rgbd_eval.files import file_kind, read_bytes

#: Hidden file listing what each command wrote into a folder.
MANIFEST = ".rgbd-eval-files.json"
MANIFEST_VERSION = 2
#: Where a manifest of version 1 (a list of names, no command) puts its files.
LEGACY = "rgbd-eval"
_MAX_MANIFEST_BYTES = 16 << 20

#: Errors of a full or read-only disk (too large a file: RLIMIT_FSIZE, a filesystem's limit).
_DISK_FULL = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS}

#: What we wrote: (size in bytes, sha256 hex); None for a version-1 manifest's names.
Record = tuple[int, str] | None


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


def lstat_output(path: Path) -> os.stat_result | None:
    """``lstat`` of an output path; None when it (or its parent) does not exist.

    Any other failure (a name too long, a folder we may not search) is an OutputError.
    """
    try:
        return os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as err:
        raise OutputError(path, f"cannot use this path ({err.strerror})") from err


def file_record(path: Path) -> tuple[int, str]:
    """(size, sha256) of the regular file ``path``; OSError for anything else.

    Opened without following a link and without blocking, then checked, so that a
    named pipe swapped in meanwhile is refused rather than waited on.
    """
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as handle:
        st = os.fstat(handle.fileno())
        if not stat.S_ISREG(st.st_mode):
            raise OSError(errno.EINVAL, f"{file_kind(st.st_mode)}, not a regular file")
        digest = hashlib.file_digest(handle, "sha256").hexdigest()
    return st.st_size, digest


@dataclass
class Manifest:
    """The record of a folder: what each command wrote, and whether it is an output folder."""

    output_folder: bool = False
    owners: dict[str, dict[str, Record]] = field(default_factory=dict)

    def files_of(self, owner: str, marker: str | None = None) -> dict[str, Record]:
        """The files ``owner`` wrote; a version-1 manifest's are its if they hold ``marker``."""
        own = dict(self.owners.get(owner, {}))
        legacy = self.owners.get(LEGACY, {})
        if marker is not None and marker in legacy:
            own.update(legacy)
        return own

    def owner_of(self, name: str) -> str | None:
        """The command that wrote ``name``, if any."""
        return next((o for o, files in self.owners.items() if name in files), None)

    def set_files(self, owner: str, files: Mapping[str, Record], marker: str | None) -> None:
        """Record ``files`` as all that ``owner`` wrote (claiming the legacy list as above)."""
        if marker is not None and marker in self.owners.get(LEGACY, {}):
            del self.owners[LEGACY]
        self.owners[owner] = dict(files)
        if not files:
            del self.owners[owner]

    def to_json(self) -> str:
        owners = {
            owner: {
                n: None if r is None else {"size": r[0], "sha256": r[1]} for n, r in files.items()
            }
            for owner, files in sorted(self.owners.items())
        }
        data = {"version": MANIFEST_VERSION, "output_folder": self.output_folder, "files": owners}
        return json.dumps(data, indent=1, sort_keys=True) + "\n"


def _not_ours(path: Path) -> OutputError:
    return OutputError(
        path,
        "is not rgbd-eval's record of the files it wrote (unreadable or edited); "
        "nothing is written beside it: remove it, or choose another output",
    )


def _parse_record(value: object) -> Record:
    if value is None:
        return None
    if isinstance(value, dict):
        size, digest = value.get("size"), value.get("sha256")
        if isinstance(size, int) and isinstance(digest, str) and len(digest) == 64:
            return size, digest
    raise ValueError("bad record")


def _safe_name(name: object) -> bool:
    return isinstance(name, str) and "/" not in name and name not in ("", ".", "..", MANIFEST)


def load_manifest(folder: Path) -> Manifest:
    """The manifest of ``folder`` (empty when there is none); OutputError when it is not ours."""
    path = folder / MANIFEST
    st = lstat_output(path)
    if st is None:
        return Manifest()
    if not stat.S_ISREG(st.st_mode):
        raise _not_ours(path)
    try:
        data = json.loads(read_bytes(path, lambda m: OutputError(path, m), "", _MAX_MANIFEST_BYTES))
        files = data["files"] if isinstance(data, dict) else None
        if isinstance(files, list):  # version 1: the names an output folder's command wrote
            names = {n for n in files if _safe_name(n)}
            return Manifest(True, {LEGACY: dict.fromkeys(names)} if names else {})
        if data.get("version") != MANIFEST_VERSION or not isinstance(files, dict):
            raise ValueError("not a manifest")
        owners = {
            str(owner): {n: _parse_record(r) for n, r in listed.items() if _safe_name(n)}
            for owner, listed in files.items()
            if isinstance(listed, dict)
        }
        return Manifest(bool(data.get("output_folder")), owners)
    except (OutputError, ValueError, KeyError, TypeError, AttributeError, RecursionError) as err:
        raise _not_ours(path) from err


def _save_manifest(folder: Path, manifest: Manifest) -> None:
    """Replace the manifest of ``folder`` (checked by :func:`load_manifest`) atomically."""
    path = folder / MANIFEST
    tmp = folder / staging_name(MANIFEST)
    try:
        tmp.write_text(manifest.to_json(), encoding="utf-8")
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)


@contextlib.contextmanager
def _locked(folder: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``folder`` while its files and manifest change, so that two
    commands writing into one folder do not lose each other's records (none where the
    filesystem has no locks: the manifest is still replaced atomically)."""
    try:
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        fd = -1
    try:
        if fd >= 0:
            with contextlib.suppress(OSError):
                fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        if fd >= 0:
            os.close(fd)


def _refuse_unless_ours(
    path: Path, owner: str, files: Mapping[str, Record], manifest: Manifest
) -> None:
    """OutputError unless ``path`` is absent or a regular file ``owner`` wrote, unchanged."""
    st = lstat_output(path)
    if st is None:
        return
    if stat.S_ISDIR(st.st_mode):
        raise OutputError(path, "is a folder; not replaced (its content would be lost)")
    if not stat.S_ISREG(st.st_mode):
        raise OutputError(path, f"is {file_kind(st.st_mode)}, not a regular file; not replaced")
    how = "remove or rename it, or choose another output"
    if path.name not in files:
        other = manifest.owner_of(path.name)
        if other is not None and other != LEGACY:
            raise OutputError(
                path, f"was written by `rgbd-eval {other}`; `{owner}` does not replace it ({how})"
            )
        raise OutputError(
            path, f"exists and was not written by `rgbd-eval {owner}`; not replaced ({how})"
        )
    if not _unchanged(path, files[path.name]):
        raise OutputError(
            path, f"was changed since `rgbd-eval {owner}` wrote it; not replaced ({how})"
        )


def _unchanged(path: Path, record: Record) -> bool:
    """Whether the regular file ``path`` still holds what ``record`` says we wrote."""
    if record is None:  # a version-1 manifest's name: no content to check
        return True
    try:
        if os.lstat(path).st_size != record[0]:
            return False
        return file_record(path) == record
    except OSError:
        return False


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output_file(path: Path, owner: str, inputs: Iterable[Path] = ()) -> None:
    """OutputError unless ``owner`` (a command) may write the file ``path``: it is absent, or a
    regular file that command wrote and that is unchanged, and it is none of ``inputs``.

    Called before the work; creates the parent folder.
    """
    path = Path(path)
    st = lstat_output(path)
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise OutputError(path, "is a folder; name a file (its content would be lost)")
    if st is not None and any(_same_file(path, i) for i in inputs):
        raise OutputError(path, "is an input of this command; not replaced (name another file)")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(path, f"cannot create its parent folder ({err.strerror})") from err
    if not os.access(path.parent, os.W_OK):
        raise OutputError(path, "its folder is not writable")
    manifest = load_manifest(path.parent)
    _refuse_unless_ours(path, owner, manifest.files_of(owner), manifest)


def publish_file(tmp: Path, path: Path, owner: str) -> None:
    """Move the finished file ``tmp`` to ``path`` when ``owner`` may replace what is there
    (see :func:`check_output_file`), and record it in the folder's manifest.

    ``tmp`` is removed in any case; OutputError when ``path`` is not ours or cannot be written.
    """
    path = Path(path)
    folder = path.parent
    try:
        with _locked(folder):
            manifest = load_manifest(folder)
            files = manifest.files_of(owner)
            _refuse_unless_ours(path, owner, files, manifest)
            files[path.name] = file_record(tmp)
            os.replace(tmp, path)
            manifest.set_files(owner, files, None)
            _save_manifest(folder, manifest)
    except OSError as err:
        raise OutputError(path, f"cannot write ({err.strerror or err})") from err
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)


class OutputFolder:
    """Stage a command's output files and publish them into ``target`` (see the module doc).

    ``command`` names the writer in the manifest (default: ``marker``); ``names`` are files
    the command will write, checked against what is there already when it is prepared.
    """

    def __init__(
        self,
        target: Path,
        marker: str,
        force: bool = False,
        *,
        command: str | None = None,
        names: Iterable[str] = (),
    ) -> None:
        self.target = Path(target)
        self.marker = marker
        self.force = force
        self.owner = command or marker
        self.names = [marker, *names]
        self._staging: Path | None = None
        self._place = self.target  # where files go: the folder a symbolic link points to

    @property
    def staging(self) -> Path:
        """The folder to write into (after :meth:`prepare`)."""
        if self._staging is None:
            raise OutputError(self.target, "output folder used before it was prepared")
        return self._staging

    def _resolve(self) -> os.stat_result | None:
        """The target's ``stat`` (None: absent); a symbolic link to a folder is followed."""
        target = self.target
        st = lstat_output(target)
        if st is not None and stat.S_ISLNK(st.st_mode):
            try:
                st = os.stat(target)
                self._place = target.resolve(strict=True)
            except OSError as err:
                raise OutputError(
                    target,
                    f"is a symbolic link to nothing usable ({err.strerror}); choose another --out",
                ) from err
        return st

    def prepare(self) -> Path:
        """Check the target and create the staging folder; OutputError when it cannot be written."""
        target = self.target
        st = self._resolve()
        place = self._place
        if st is not None:
            if not stat.S_ISDIR(st.st_mode):
                raise OutputError(target, "exists and is not a folder; choose another --out")
            manifest = load_manifest(place)
            try:
                entries = [p.name for p in place.iterdir() if p.name != MANIFEST]
            except OSError as err:
                raise OutputError(target, f"cannot list it ({err.strerror})") from err
            foreign = [n for n in entries if manifest.owner_of(n) is None]
            if foreign and not manifest.output_folder and not self.force:
                raise OutputError(
                    target,
                    "exists, is not empty and was not written by rgbd-eval; choose another "
                    "--out or add --force to add our files to it (yours are kept)",
                )
            files = manifest.files_of(self.owner, self.marker)
            for name in self.names:
                _refuse_unless_ours(place / name, self.owner, files, manifest)
        parent = place.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise OutputError(target, f"cannot create its parent folder ({err.strerror})") from err
        remove_stale(parent, place.name)
        staging = parent / staging_name(place.name)
        # known before it exists: a signal that arrives just after mkdir (its handler raises)
        # still finds it to discard
        self._staging = staging
        try:
            staging.mkdir(mode=0o777)  # the umask applies, unlike tempfile.mkdtemp's 0700
        except OSError as err:
            self._staging = None
            raise OutputError(target, f"cannot write beside it ({err.strerror})") from err
        return staging

    def discard(self) -> None:
        """Remove the staging folder (after a failure)."""
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)
            self._staging = None

    def commit(self) -> None:
        """Publish the staged files (see the module docstring)."""
        staging = self.staging
        place = self._place
        try:
            records: dict[str, Record] = {
                p.name: file_record(p) for p in sorted(staging.iterdir()) if p.name != MANIFEST
            }
            if lstat_output(place) is None:
                manifest = Manifest(True)
                manifest.set_files(self.owner, records, self.marker)
                (staging / MANIFEST).write_text(manifest.to_json(), encoding="utf-8")
                os.replace(staging, place)
            else:
                with _locked(place):
                    self._merge(staging, place, records)
                shutil.rmtree(staging, ignore_errors=True)
        except OutputError:
            self.discard()
            raise
        except OSError as err:
            self.discard()
            raise OutputError(self.target, f"cannot publish the output ({err.strerror})") from err
        self._staging = None

    def _merge(self, staging: Path, place: Path, records: dict[str, Record]) -> None:
        manifest = load_manifest(place)
        old = manifest.files_of(self.owner, self.marker)
        for name in records:  # all checked before anything moves
            _refuse_unless_ours(place / name, self.owner, old, manifest)
        marker = place / self.marker
        if self.marker in old and _unchanged(marker, old[self.marker]):
            marker.unlink(missing_ok=True)
        for name in sorted(set(old) - set(records)):  # ours from before, unless edited since
            stale = place / name
            st = lstat_output(stale)
            if st is not None and stat.S_ISREG(st.st_mode) and _unchanged(stale, old[name]):
                stale.unlink()
        for name in [n for n in records if n != self.marker] + [self.marker]:
            if (staging / name).exists():
                os.replace(staging / name, place / name)
        manifest.output_folder = True
        manifest.set_files(self.owner, records, self.marker)
        _save_manifest(place, manifest)

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
        if isinstance(exc, OSError) and exc.errno in _DISK_FULL:
            # Only writing fails so; the outputs are written in the staging folder.
            raise OutputError(self.target, f"cannot write ({exc.strerror})") from exc
