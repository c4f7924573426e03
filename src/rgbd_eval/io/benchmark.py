"""Read throughput: decoded frames per second against the floor of raw message reading."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader as Ros1Reader

from rgbd_eval.config import IoConfig
from rgbd_eval.io.recording import open_recording
from rgbd_eval.io.streams import RGBD_STREAMS
from rgbd_eval.plugins import StreamSpec


@dataclass(frozen=True)
class ReadTimings:
    """Seconds spent on one recording, and the frame count."""

    frames: int
    index_s: float
    frames_s: float
    raw_floor_s: float
    raw_floor_reader: str

    @property
    def fps(self) -> float:
        return self.frames / (self.index_s + self.frames_s)

    @property
    def floor_fps(self) -> float:
        return self.frames / self.raw_floor_s


def _raw_floor(path: Path, topics: set[str]) -> tuple[float, str]:
    """Time to iterate the image topics' raw bytes with the lowest-level reader available."""
    start = time.perf_counter()
    if path.suffix == ".mcap":
        with path.open("rb") as handle:
            for _ in make_reader(handle).iter_messages(topics=list(topics)):
                pass
        return time.perf_counter() - start, "mcap.reader"
    if path.suffix == ".bag":
        with Ros1Reader(path) as reader:
            conns = [c for c in reader.connections if c.topic in topics]
            for _ in reader.messages(connections=conns):
                pass
        return time.perf_counter() - start, "rosbags.rosbag1.Reader"
    with AnyReader([path]) as any_reader:
        conns = [c for c in any_reader.connections if c.topic in topics]
        for _ in any_reader.messages(connections=conns):
            pass
    return time.perf_counter() - start, "rosbags AnyReader"


def time_read(
    path: Path, io: IoConfig | None = None, streams: Sequence[StreamSpec] = RGBD_STREAMS
) -> ReadTimings:
    """Index + decode every frame of ``path``, and the raw floor for the same image topics."""
    path = Path(path)
    start = time.perf_counter()
    rec = open_recording(path, io, streams)
    index_s = time.perf_counter() - start
    start = time.perf_counter()
    n = sum(1 for _ in rec.frames())
    frames_s = time.perf_counter() - start
    floor_s, floor_reader = _raw_floor(path, set(rec.info.selected.streams.values()))
    return ReadTimings(n, index_s, frames_s, floor_s, floor_reader)
