"""Safe reading of user-named input files: regular files only, bounded, UTF-8 (BOM allowed).

A named pipe blocks ``open`` forever and a link to ``/dev/zero`` never ends, so
every input path is checked with ``stat`` before it is opened. Text is decoded as
UTF-8, with the byte-order mark that spreadsheet programs write skipped. YAML is
parsed with duplicate keys refused and aliases bounded (an alias "bomb" expands
exponentially). Every failure is the caller's own error class, one line.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

from rgbd_eval.errors import RgbdEvalError

#: Builds the caller's error from a message (e.g. ``lambda m: GroundTruthError(path, m)``).
ErrorFactory = Callable[[str], RgbdEvalError]

#: Largest text input read whole (ground truth, configs, reports): 256 MiB.
MAX_TEXT_BYTES = 256 << 20
#: Most values a YAML document may expand to through aliases (configs hold a few hundred).
MAX_YAML_VALUES = 100_000


def file_kind(mode: int) -> str:
    """What a non-regular file is, for messages: "a named pipe", "a device", ..."""
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISDIR(mode):
        return "a folder"
    return "not a regular file"


def check_input(
    path: Path, error: ErrorFactory, what: str = "file", allow_dir: bool = False
) -> os.stat_result:
    """``stat`` of ``path`` (links followed); the caller's error unless a regular file (or folder).

    ``what`` names the input in messages ("cannot read config (...)").
    """
    try:
        st = os.stat(path)
    except OSError as err:
        raise error(f"cannot read {what} ({err.strerror})") from err
    if stat.S_ISDIR(st.st_mode):
        if allow_dir:
            return st
        raise error(f"cannot read {what} (it is a folder)")
    if not stat.S_ISREG(st.st_mode):
        raise error(f"cannot read {what} (it is {file_kind(st.st_mode)}, not a regular file)")
    return st


def read_bytes(
    path: Path, error: ErrorFactory, what: str = "file", limit: int = MAX_TEXT_BYTES
) -> bytes:
    """The whole content of a regular file no larger than ``limit`` bytes."""
    st = check_input(path, error, what)
    if st.st_size > limit:
        raise error(f"{what} is {st.st_size} bytes, more than the {limit}-byte limit")
    try:
        with open(path, "rb") as handle:
            data = handle.read(limit + 1)
    except OSError as err:
        raise error(f"cannot read {what} ({err.strerror})") from err
    if len(data) > limit:  # grew while reading
        raise error(f"{what} is more than the {limit}-byte limit")
    return data


def decode_text(data: bytes, error: ErrorFactory, what: str = "file") -> str:
    """UTF-8 text, a leading byte-order mark skipped; the error names the first bad byte."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        bad = data[err.start : err.start + 1].hex()
        raise error(
            f"{what} is not UTF-8 text (byte 0x{bad} at offset {err.start}); save it as UTF-8"
        ) from err


def read_text(
    path: Path, error: ErrorFactory, what: str = "file", limit: int = MAX_TEXT_BYTES
) -> str:
    """A regular, bounded UTF-8 text file (BOM allowed)."""
    return decode_text(read_bytes(path, error, what, limit), error, what)


class _StrictLoader(yaml.SafeLoader):
    """``SafeLoader`` that refuses a key given twice in one mapping."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:  # unhashable key: SafeLoader reports it
                break
            if duplicate:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark
                )
            seen.add(key)
        return super().construct_mapping(node, deep)


def _expanded_size(value: Any, limit: int) -> int:
    """Number of values in ``value`` counting shared (aliased) parts each time; stops past limit."""
    count = 0
    stack = [value]
    while stack and count <= limit:
        item = stack.pop()
        count += 1
        if isinstance(item, dict):
            stack.extend(item.keys())
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
    return count


def parse_yaml(text: str, error: ErrorFactory, limit: int = MAX_YAML_VALUES) -> Any:
    """Parse YAML text: duplicate keys and alias bombs are errors; messages kept short.

    ``limit`` bounds the values after alias expansion (data files such as a dataset's
    annotations hold more than any configuration).
    """
    try:
        data = yaml.load(text, Loader=_StrictLoader)  # a SafeLoader subclass
    except yaml.YAMLError as err:
        message = " ".join(str(err).split())
        raise error(f"not valid YAML ({message[:300]})") from err
    if _expanded_size(data, limit) > limit:
        raise error(f"YAML expands to more than {limit} values through aliases")
    return data
