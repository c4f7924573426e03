"""Atomic file output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path
from typing import Any

from rgbd_eval.errors import OutputError
from rgbd_eval.outdir import remove_stale, staging_name


def write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` so that ``path`` is either absent, the old file, or the complete new one."""
    path = Path(path)
    tmp = path.with_name(staging_name(path.name))
    try:
        if path.is_dir():
            raise IsADirectoryError(21, "is a folder")
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(path.parent, path.name)
        tmp.write_bytes(data)
        os.replace(tmp, path)
    except OSError as err:
        raise OutputError(path, f"cannot write ({err.strerror})") from err
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)


def write_text(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) atomically, as :func:`write_bytes`."""
    write_bytes(path, text.encode("utf-8"))


def write_json(path: Path, data: Any) -> None:
    """Atomically write ``data`` as indented JSON (NaN is not allowed: use None)."""
    write_text(path, json.dumps(data, indent=2, sort_keys=False, allow_nan=False) + "\n")
