"""Raw message access to a recording, behind one small interface.

Lone ``.mcap`` files are read with ``mcap.reader`` and the typestore's
``deserialize_cdr`` (2-4x faster than ``rosbags``' AnyReader on zstd chunks);
everything else (ROS1 bags, ROS2 folders, ``.db3``) goes through AnyReader.
"""

from __future__ import annotations

import sqlite3
import struct
import zlib
from collections.abc import Iterator
from contextlib import AbstractContextManager
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from types import TracebackType
from typing import IO, Any

import apsw
import zstandard
from mcap.exceptions import McapError
from mcap.reader import McapReader, make_reader
from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.rosbag1 import ReaderError as Ros1ReaderError
from rosbags.rosbag2 import ReaderError as Ros2ReaderError
from rosbags.serde import SerdeError
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import TypesysError
from rosbags.typesys.store import Typestore

from rgbd_eval.errors import InputError
from rgbd_eval.files import check_folder, parse_yaml, read_text
from rgbd_eval.io.messages import typestore

#: Exceptions the underlying readers raise on broken files; the reader maps them to InputError.
READ_ERRORS: tuple[type[BaseException], ...] = (
    AnyReaderError,
    Ros1ReaderError,
    Ros2ReaderError,
    SerdeError,
    TypesysError,
    McapError,
    OSError,
    struct.error,
    EOFError,
    ValueError,  # includes mcap's CRCValidationError
    zstandard.ZstdError,  # a corrupt zstd chunk (MCAP, ROS2 mcap storage)
    apsw.Error,  # a corrupt ROS2 sqlite3 database
    sqlite3.Error,
)

#: Exceptions of deserialising one message whose bytes do not match its definition
#: (rosbags wraps struct/unicode/size errors in SerdeError; an unknown type is ValueError).
MESSAGE_ERRORS: tuple[type[BaseException], ...] = (SerdeError, ValueError)


@dataclass(frozen=True)
class TopicConnection:
    """A topic with its message type and message count."""

    topic: str
    msgtype: str
    count: int


class MessageSource(AbstractContextManager["MessageSource"]):
    """Iterate raw messages of chosen topics in log-time order, and deserialise them."""

    ros1: bool = False
    topics: dict[str, TopicConnection]
    start_ns: int = 0
    end_ns: int = 0

    def messages(
        self, topics: set[str], start_ns: int | None = None
    ) -> Iterator[tuple[str, int, bytes | memoryview]]:
        """``(topic, log_time_ns, raw)`` for the given topics (from log time ``start_ns`` on:
        the container's index skips what comes before, undecompressed)."""
        raise NotImplementedError

    def deserialize(self, raw: bytes | memoryview, msgtype: str) -> Any:
        raise NotImplementedError

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        """Release the file."""


class AnyReaderSource(MessageSource):
    """ROS1 bags, ROS2 bag folders and ``.db3`` files via ``rosbags.highlevel.AnyReader``."""

    def __init__(self, path: Path) -> None:
        self.ros1 = path.suffix == ".bag"
        if path.is_file():
            check_magic(path)
        self._reader = AnyReader([path], default_typestore=typestore(1 if self.ros1 else 2))
        self._reader.open()
        self._conns = {c.topic: c for c in self._reader.connections}
        self.topics = {
            c.topic: TopicConnection(c.topic, c.msgtype, c.msgcount)
            for c in self._reader.connections
        }
        if self._conns:
            self.start_ns, self.end_ns = self._reader.start_time, self._reader.end_time

    def messages(
        self, topics: set[str], start_ns: int | None = None
    ) -> Iterator[tuple[str, int, bytes | memoryview]]:
        conns = [c for t, c in self._conns.items() if t in topics]
        if not conns:
            return
        try:
            for conn, log_ns, raw in self._reader.messages(connections=conns, start=start_ns):
                yield conn.topic, log_ns, raw
        except (AssertionError, KeyError) as err:
            # rosbags' ROS1 reader asserts that a message record's time equals its index
            # entry's, and looks its connection id up in a dict: a flipped byte in either
            # was an AssertionError or KeyError traceback.
            raise Ros1ReaderError("index and message record disagree: the bag is corrupt") from err

    def deserialize(self, raw: bytes | memoryview, msgtype: str) -> Any:
        try:
            return self._reader.deserialize(bytes(raw), msgtype)
        except KeyError as err:  # a damaged type table names a type the typestore lacks
            raise ValueError(f"message type {msgtype!r} has no definition") from err
        except AnyReaderError as err:  # AnyReader wraps the SerdeError of one message
            raise SerdeError(str(err)) from err

    def close(self) -> None:
        self._reader.close()


class McapSource(MessageSource):
    """A lone ``.mcap`` file (ROS2 CDR messages with ``ros2msg`` schemas)."""

    def __init__(self, path: Path) -> None:
        self._handle: IO[bytes] = path.open("rb")
        try:
            verify_summary_crc(self._handle)
            # Chunk CRCs are checked whenever a chunk is decompressed: in the index pass
            # and again in the frame pass (each opens its own source).
            self._reader: McapReader = make_reader(self._handle, validate_crcs=True)
            summary = self._reader.get_summary()
            if summary is None:
                raise McapError("no summary section (file truncated or written without an index)")
            if summary.statistics is not None:
                counts = dict(summary.statistics.channel_message_counts)
            else:  # no statistics record: count in one extra pass over the chunks
                counts = {}
                for _, channel, _ in self._reader.iter_messages():
                    counts[channel.id] = counts.get(channel.id, 0) + 1
        except BaseException:
            self._handle.close()
            raise
        self.topics = {}
        schemas: dict[str, bytes] = {}  # empty text: not ros2msg (e.g. ros2idl)
        for cid, channel in summary.channels.items():
            schema = summary.schemas.get(channel.schema_id)
            if schema is None or channel.message_encoding != "cdr":
                continue
            schemas[schema.name] = schema.data if schema.encoding == "ros2msg" else b""
            self.topics[channel.topic] = TopicConnection(
                channel.topic, schema.name, int(counts.get(cid, 0))
            )
        self.store = _schema_store(tuple(sorted(schemas.items())))
        if summary.statistics is not None:
            self.start_ns = summary.statistics.message_start_time
            self.end_ns = summary.statistics.message_end_time
        elif summary.chunk_indexes:
            self.start_ns = min(c.message_start_time for c in summary.chunk_indexes)
            self.end_ns = max(c.message_end_time for c in summary.chunk_indexes)

    def messages(
        self, topics: set[str], start_ns: int | None = None
    ) -> Iterator[tuple[str, int, bytes | memoryview]]:
        wanted = [t for t in topics if t in self.topics]
        if not wanted:
            return
        for _, channel, message in self._reader.iter_messages(topics=wanted, starting_at=start_ns):
            yield channel.topic, message.log_time, message.data

    def deserialize(self, raw: bytes | memoryview, msgtype: str) -> Any:
        try:
            return self.store.deserialize_cdr(raw, msgtype)
        except KeyError as err:
            raise ValueError(f"message type {msgtype!r} has no definition") from err

    def close(self) -> None:
        self._handle.close()


#: File signatures by suffix. rosbags reads a ROS1 bag's first line with an unbounded
#: ``readline``: a zero-filled file was read whole (300 MB -> 700 MB of memory) before
#: its magic was refused, so the first bytes are checked here first.
_MAGICS = {".bag": b"#ROSBAG V2.0\n", ".db3": b"SQLite format 3\x00"}


def check_magic(path: Path) -> None:
    """ValueError unless a ``.bag``/``.db3`` file starts with its format's signature."""
    magic = _MAGICS.get(path.suffix)
    if magic is None:
        return
    with path.open("rb") as handle:
        head = handle.read(len(magic))
    if head != magic:
        kind = "ROS1 bag v2.0" if path.suffix == ".bag" else "SQLite database"
        raise ValueError(f"not a {kind} (the file does not start with {magic!r})")


#: Magic (8 bytes) + footer record (opcode 1, length 8, summary_start 8,
#: summary_offset_start 8, summary_crc 4) + magic: the smallest MCAP file.
_MAGIC_SIZE = 8
_FOOTER_SIZE = 1 + 8 + 8 + 8 + 4
MIN_MCAP_BYTES = 2 * _MAGIC_SIZE + _FOOTER_SIZE


def verify_summary_crc(handle: IO[bytes]) -> None:
    """McapError unless the file is long enough and its summary section matches the footer CRC.

    The CRC (when not 0) covers the summary section up to and including the footer's
    ``summary_offset_start`` (MCAP specification, Footer); ``mcap.reader`` checks
    only chunk CRCs, so a flipped byte in an index or the statistics went unnoticed.
    """
    size = handle.seek(0, 2)
    if size < MIN_MCAP_BYTES:
        raise McapError(f"file is {size} bytes, shorter than the smallest MCAP file")
    footer_at = size - _MAGIC_SIZE - _FOOTER_SIZE
    handle.seek(footer_at)
    footer = handle.read(_FOOTER_SIZE)
    opcode, length, summary_start, _, summary_crc = struct.unpack("<BQQQI", footer)
    if opcode != 0x02 or length != 20:
        raise McapError("no MCAP footer at the end of the file (truncated?)")
    if summary_crc == 0 or summary_start == 0:
        handle.seek(0)
        return
    if not 0 < summary_start <= footer_at:
        raise McapError(f"footer points the summary to byte {summary_start}, outside the file")
    handle.seek(summary_start)
    crc = 0
    remaining = footer_at + _FOOTER_SIZE - 4 - summary_start
    while remaining > 0:
        block = handle.read(min(remaining, 1 << 20))
        if not block:
            break
        crc = zlib.crc32(block, crc)
        remaining -= len(block)
    handle.seek(0)
    if crc != summary_crc:
        raise McapError(
            f"summary section CRC mismatch (footer {summary_crc:#010x}, computed {crc:#010x}): "
            "the file is corrupt"
        )


@lru_cache(maxsize=8)
def _schema_store(schemas: tuple[tuple[str, bytes], ...]) -> Typestore:
    """A typestore of just the file's ``ros2msg`` schemas (with their dependencies).

    Registering a whole distribution's types builds hundreds of classes (~0.1-0.2 s),
    more than decoding a short recording; a file's handful takes ~20 ms, and the
    index and frame passes (and sweeps) of one file share it through the cache.
    When a schema is not ``ros2msg`` or does not parse, all of ROS2 Humble's types
    are registered too (deserialising a type found in neither fails, naming it).
    """
    store = get_typestore(Stores.EMPTY)
    for name, data in schemas:
        try:
            types = get_types_from_msg(data.decode(), name) if data else {}
        except (TypesysError, UnicodeDecodeError):
            types = {}
        if name not in types:
            types = dict(typestore(2).fielddefs)
        store.register({k: v for k, v in types.items() if k not in store.fielddefs})
    return store


#: Largest ROS2 ``metadata.yaml`` read (a long bag's lists a few thousand files).
MAX_METADATA_BYTES = 16 << 20


def check_bag_folder(path: Path) -> None:
    """InputError unless a ROS2 bag folder holds only regular files and folders (a named
    pipe as ``metadata.yaml`` or ``.db3`` blocked the reader forever) and its
    ``metadata.yaml`` is bounded, non-bomb YAML (rosbags parses it without bounds)."""

    def error(message: str) -> InputError:
        return InputError(path, message)

    check_folder(path, error, "ROS2 bag folder")
    metadata = path / "metadata.yaml"
    if metadata.exists():
        text = read_text(metadata, error, "metadata.yaml", MAX_METADATA_BYTES)
        parse_yaml(text, lambda m: error(f"metadata.yaml: {m}"))


def open_source(path: Path) -> MessageSource:
    """The fastest source for ``path`` (see the module docstring)."""
    if path.suffix == ".mcap" and path.is_file():
        return McapSource(path)
    if path.is_dir():
        check_bag_folder(path)
    return AnyReaderSource(path)
