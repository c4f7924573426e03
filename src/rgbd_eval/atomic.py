"""Atomic file output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import contextlib
import json
import os
import stat
from pathlib import Path
from typing import Any

from rgbd_eval.errors import OutputError
from rgbd_eval.files import file_kind
from rgbd_eval.outdir import lstat_output, publish_file, remove_stale, staging_name


def write_bytes(path: Path, data: bytes, owner: str | None = None) -> None:
    """Write ``data`` so that ``path`` is either absent, the old file, or the complete new one.

    With ``owner`` (the command writing it, e.g. ``"compare"``) the file is an output the
    user named: it replaces only a file that command wrote, unchanged since, and is
    recorded as written by it (:func:`~rgbd_eval.outdir.publish_file`). Without, ``path``
    is in a folder of ours (a staging folder); either way nothing but a regular file is
    replaced: never a folder, a device, a named pipe or a symbolic link.
    """
    path = Path(path)
    tmp = path.with_name(staging_name(path.name))
    try:
        st = lstat_output(path)
        if st is not None and stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError(21, "is a folder")
        if st is not None and not stat.S_ISREG(st.st_mode):
            raise OutputError(path, f"is {file_kind(st.st_mode)}, not a regular file; not replaced")
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(path.parent, path.name)
        tmp.write_bytes(data)
        if owner is None:
            os.replace(tmp, path)
        else:
            publish_file(tmp, path, owner)
    except OSError as err:
        raise OutputError(path, f"cannot write ({err.strerror or err})") from err
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)


def write_text(path: Path, text: str, owner: str | None = None) -> None:
    """Write ``text`` (UTF-8) atomically, as :func:`write_bytes`."""
    write_bytes(path, text.encode("utf-8"), owner)


def write_json(path: Path, data: Any, owner: str | None = None) -> None:
    """Atomically write ``data`` as indented JSON (NaN is not allowed: use None)."""
    text = json.dumps(data, indent=2, sort_keys=False, allow_nan=False) + "\n"
    write_text(path, text, owner)
