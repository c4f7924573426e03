"""The task graph a sweep submits (no cluster: a client that records its submissions)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rgbd_eval.chunked import ChunkPlan
from rgbd_eval.config import RunConfig, load_config
from rgbd_eval.engine import worker_environ
from rgbd_eval.sweep import (
    _advance,
    _detect_chunk,
    _join,
    _score,
    _submit,
    _submit_chunks,
    _submit_points,
    _track,
)


@dataclass(frozen=True)
class Submitted:
    """A stand-in future: what was submitted, under which key."""

    func: Any
    args: tuple[Any, ...]
    key: str


@dataclass
class RecordingClient:
    """The one client method the graph builders call."""

    calls: list[tuple[Submitted, dict[str, Any]]] = field(default_factory=list)

    scattered: list[tuple[Any, dict[str, Any]]] = field(default_factory=list)

    def submit(self, func: Any, *args: Any, key: str, **options: Any) -> Submitted:
        future = Submitted(func, args, key)
        self.calls.append((future, options))
        return future

    def scatter(self, data: Any, **options: Any) -> Submitted:
        self.scattered.append((data, options))
        return Submitted(self.scatter, (data,), f"scattered-{len(self.scattered)}")


def config() -> RunConfig:
    return load_config(method="basso2012")


def test_chunk_0_needs_no_advance_and_each_chunk_its_link() -> None:
    client = RecordingClient()
    opened = Submitted(print, (), "_prepare-x")
    plan = ChunkPlan(3, 1, 0.28)
    slots = ["tcp://a:1", "tcp://b:1", "tcp://c:1"]
    joined: Any = _submit_chunks(client, Path("r.mcap"), opened, config(), plan, None, slots)  # type: ignore[arg-type]
    futures = [f for f, _ in client.calls]
    # Submission order: the advance chain (2 links), the 3 chunks, the join.
    assert [f.func for f in futures] == [_advance] * 2 + [_detect_chunk] * 3 + [_join]
    adv0, adv1, chunk0, chunk1, chunk2, join = futures
    # _advance(opened, config, plan, k, state) and _detect_chunk(opened, config, plan, k, state)
    assert adv0.args[3:] == (0, None) and adv1.args[3:] == (1, adv0)
    assert chunk0.args[3:] == (0, None)  # ready as soon as the recording is open
    assert chunk1.args[3:] == (1, adv0) and chunk2.args[3:] == (2, adv1)
    assert all(f.args[0] is opened for f in futures[:5])
    assert all(f.args[1] == config() for f in futures[:5])
    assert all(f.args[2] == plan for f in futures[:5])
    assert join is joined and join.args[4:] == (chunk0, chunk1, chunk2)
    # Keys name the task and its chunk; every submission starts its own priority generation.
    assert [f.key.rsplit("-", 1)[0] for f in futures[:5]] == [
        "_advance-0",
        "_advance-1",
        "_detect_chunk-0",
        "_detect_chunk-1",
        "_detect_chunk-2",
    ]
    assert len({f.key for f in futures}) == 6
    # Placement, loose: the advance chain on the first slot (the prepare task's), chunk k on
    # slot k + 1, so chunk 0 starts at once elsewhere and the last chunk follows the chain.
    loose = {"fifo_timeout": 0, "allow_other_workers": True}
    options = [o for _, o in client.calls]
    assert options[:5] == [
        {**loose, "workers": ["tcp://a:1"]},
        {**loose, "workers": ["tcp://a:1"]},
        {**loose, "workers": ["tcp://b:1"]},
        {**loose, "workers": ["tcp://c:1"]},
        {**loose, "workers": ["tcp://a:1"]},
    ]
    assert options[5] == {"fifo_timeout": 0}  # the join: wherever its inputs are


def test_chunks_without_known_workers_are_not_placed() -> None:
    client = RecordingClient()
    plan = ChunkPlan(2, 1, 0.28)
    _submit_chunks(
        client, Path("r.mcap"), Submitted(print, (), "p"), config(), plan, None, [None, None]
    )  # type: ignore[arg-type]
    assert all(options == {"fifo_timeout": 0} for _, options in client.calls)


def test_submit_keys_without_an_index() -> None:
    client = RecordingClient()
    future: Any = _submit(client, _join, 1, 2)  # type: ignore[arg-type]
    assert future.key.startswith("_join-") and len(future.key) == len("_join-") + 32
    assert future.args == (1, 2)


def test_worker_environment_keeps_thread_limits_not_the_trim_threshold() -> None:
    dask_default = {"MALLOC_TRIM_THRESHOLD_": 65536, "OMP_NUM_THREADS": 1}
    assert worker_environ(dask_default) == {"OMP_NUM_THREADS": 1}
    assert worker_environ({}) == {}


def test_track_tasks_alternate_over_the_group_slots() -> None:
    client = RecordingClient()
    prepared = Submitted(print, (), "_stored-x")
    cfg = config()
    points = [(10 + j, cfg) for j in range(5)]
    scores: Any = _submit_points(client, prepared, points, ["tcp://a:1", "tcp://b:1"])  # type: ignore[arg-type]
    futures = [f for f, _ in client.calls]
    # All 5 track tasks first, then the 5 score tasks, each scoring its own track.
    assert [f.func for f in futures] == [_track] * 5 + [_score] * 5
    tracks = futures[:5]
    assert [f.key.rsplit("-", 1)[0] for f in tracks] == [f"_track-{i}" for i in range(10, 15)]
    assert list(scores) == list(range(10, 15))
    assert [scores[i].args[:2] for i in range(10, 15)] == [(prepared, t) for t in tracks]
    options = [o for _, o in client.calls]
    # Tracks on a b a b a; the scores where Dask puts them (with their tracks, or the input).
    assert "".join(o["workers"][0][len("tcp://")] for o in options[:5]) == "ababa"
    assert all(o["allow_other_workers"] for o in options[:5])
    assert all(o == {"fifo_timeout": 0} for o in options[5:])


def test_track_and_score_tasks_without_slots_are_not_placed() -> None:
    client = RecordingClient()
    _submit_points(client, Submitted(print, (), "p"), [(0, config()), (1, config())], [])  # type: ignore[arg-type]
    assert all(options == {"fifo_timeout": 0} for _, options in client.calls)
