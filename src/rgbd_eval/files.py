"""Safe reading of user-named input files: regular files only, bounded, UTF-8 (BOM allowed).

A named pipe blocks ``open`` forever and a link to ``/dev/zero`` never ends, so
every input path is checked with ``stat`` before it is opened. Text is decoded as
UTF-8, with the byte-order mark that spreadsheet programs write skipped. YAML is
parsed with duplicate keys refused, aliases bounded (an alias "bomb" expands
exponentially) and nesting bounded (PyYAML and ``json`` recurse once per level: a
document 2,000 levels deep was a RecursionError). A folder input (a ROS2 bag) may
hold only regular files and folders. Every failure is the caller's own error class,
one line.
"""

from __future__ import annotations

import hashlib
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
#: Deepest nesting of mappings and lists in a YAML or JSON input (configs and reports
#: nest fewer than 10 levels; Python's recursion limit is 1000).
MAX_NESTING = 100


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


def check_folder(path: Path, error: ErrorFactory, what: str = "folder") -> None:
    """The caller's error unless every entry of folder ``path`` is a regular file or folder.

    A reader that opens a folder's files by name (a ROS2 bag's ``metadata.yaml`` and
    storage files) would block on a named pipe there; nothing is opened here.
    """
    try:
        entries = sorted(os.scandir(path), key=lambda e: e.name)
    except OSError as err:
        raise error(f"cannot read {what} ({err.strerror})") from err
    for entry in entries:
        try:
            mode = os.stat(entry.path).st_mode  # links followed, as the reader's open would
        except OSError as err:
            raise error(f"cannot read {what} entry {entry.name} ({err.strerror})") from err
        if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
            raise error(
                f"{what} entry {entry.name} is {file_kind(mode)}, not a regular file (not opened)"
            )


def too_deep(value: Any, limit: int = MAX_NESTING) -> bool:
    """Whether parsed data (dicts and lists) nests deeper than ``limit`` levels (no recursion)."""
    stack: list[tuple[Any, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            if depth >= limit:
                return True
            children = item.values() if isinstance(item, dict) else item
            stack.extend((child, depth + 1) for child in children)
    return False


class YamlLimitError(ValueError):
    """A YAML text is valid but too big once expanded, or nested too deeply."""


def _yaml_depth_problem(text: str, limit: int) -> str | None:
    """Why ``text`` nests too deeply (None when it does not); yaml.YAMLError on bad syntax.

    Walks the parser's events, which PyYAML produces without recursion (the composer
    and constructor recurse once per level).
    """
    depth = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, yaml.events.CollectionStartEvent):
            depth += 1
            if depth > limit:
                return f"YAML nests deeper than {limit} levels"
        elif isinstance(event, yaml.events.CollectionEndEvent):
            depth -= 1
    return None


def load_yaml_bounded(text: str, limit: int = MAX_YAML_VALUES, max_depth: int = MAX_NESTING) -> Any:
    """YAML text parsed with duplicate keys refused; yaml.YAMLError on bad syntax,
    :class:`YamlLimitError` when it nests deeper than ``max_depth`` or expands to more
    than ``limit`` values through aliases."""
    problem = _yaml_depth_problem(text, max_depth)
    if problem is not None:
        raise YamlLimitError(problem)
    data = yaml.load(text, Loader=_StrictLoader)  # a SafeLoader subclass
    if _expanded_size(data, limit) > limit:
        raise YamlLimitError(f"YAML expands to more than {limit} values through aliases")
    return data


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
    """Parse YAML text: duplicate keys, alias bombs and deep nesting are errors; messages
    kept short.

    ``limit`` bounds the values after alias expansion (data files such as a dataset's
    annotations hold more than any configuration).
    """
    try:
        return load_yaml_bounded(text, limit)
    except YamlLimitError as err:
        raise error(str(err)) from err
    except yaml.YAMLError as err:
        message = " ".join(str(err).split())
        raise error(f"not valid YAML ({message[:300]})") from err


def file_digest(path: Path) -> str:
    """sha256 of a file, or of a folder's files (names and contents, sorted)."""
    h = hashlib.sha256()
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    for f in files:
        if path.is_dir():
            h.update(str(f.relative_to(path)).encode())
        with f.open("rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                h.update(block)
    return h.hexdigest()
