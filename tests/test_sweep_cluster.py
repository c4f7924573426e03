"""Sweeps on a local Dask cluster of two worker processes: determinism, a killed worker,
a corrupted cache entry, a failing recording."""

from __future__ import annotations

import json
import os
import pickle
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from rgbd_eval.cache import DetectionCache, detection_key
from rgbd_eval.chunked import ChunkPlan
from rgbd_eval.cli.main import app
from rgbd_eval.config import RunConfig, load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.engine import ClusterSpec, connect
from rgbd_eval.files import file_digest
from rgbd_eval.sim import load_scenario, synthesize
from rgbd_eval.sweep import (
    CacheMode,
    SweepParam,
    SweepResult,
    expand_grid,
    point_configs,
    run_sweep,
)

pytestmark = pytest.mark.slow  # a 2-process cluster and two synthesized scenes: ~1 min in all

VALUES = (-2.0, -0.5, 0.5)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Two short demo scenes (three people crossing): 12 and 10 frames."""
    folder = tmp_path_factory.mktemp("recs")
    scenario = load_scenario(scenarios_dir() / "demo.yaml")
    return [
        synthesize(scenario, folder / f"demo{n}.mcap", max_frames=n).recording for n in (12, 10)
    ]


@pytest.fixture(scope="module")
def client2() -> Iterator[Any]:
    with connect(ClusterSpec(None, 2)) as client:
        yield client


def grid_and_configs() -> tuple[list[dict[str, Any]], list[RunConfig]]:
    base = load_config(method="basso2012").model_dump(mode="json")
    grid = expand_grid([SweepParam("tracker.min_confidence", VALUES)])
    return grid, point_configs(base, [], grid)


def records(result: SweepResult) -> list[tuple[Any, ...]]:
    """Everything of a record but its timing."""
    return [(r.point, r.sequence, r.counts) for r in result.records]


@pytest.fixture(scope="module")
def reference(recordings: list[Path], tmp_path_factory: pytest.TempPathFactory) -> SweepResult:
    """The sweep on local:1 (one in-process worker), fresh cache."""
    grid, configs = grid_and_configs()
    cache = tmp_path_factory.mktemp("cache1")
    result = run_sweep(recordings, grid, configs, cache_root=cache)
    assert (result.cache_hits, result.cache_misses, result.failures) == (0, 2, ())
    # Not a vacuous comparison: people are matched, and the points differ.
    assert sum(r.counts.num_matches for r in result.records) > 0
    return result


def test_two_workers_equal_one_bit_for_bit(
    recordings: list[Path], reference: SweepResult, client2: Any, tmp_path: Path
) -> None:
    grid, configs = grid_and_configs()
    # Cold cache (detections computed on the workers), then warm (loaded from entries).
    cold = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path)
    warm = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path)
    assert (cold.cache_misses, warm.cache_hits) == (2, 2)
    assert records(cold) == records(reference)
    assert records(warm) == records(reference)
    # The client-side cache mode (workers share no disk) gives the same records too: cold (the
    # fresh detections come back and this process stores them), then warm (sent to workers).
    own = tmp_path / "client-side"
    for expected_hits in (0, 2):
        client_mode = run_sweep(
            recordings, grid, configs, client2, cache_root=own, cache_mode=CacheMode.CLIENT
        )
        assert client_mode.cache_hits == expected_hits
        assert records(client_mode) == records(reference)
    assert len(list((own / "detections").rglob("*.det"))) == 2
    # Counts hold floats (IoU sums): compare their exact JSON too, not only ==.
    dump = [json.dumps(r.counts.__dict__, sort_keys=True, default=str) for r in cold.records]
    assert dump == [
        json.dumps(r.counts.__dict__, sort_keys=True, default=str) for r in reference.records
    ]


@pytest.mark.parametrize("plan", [ChunkPlan(3, 3), ChunkPlan(2, 3, 0.5)])
def test_detection_in_chunks_equals_one_pass(
    recordings: list[Path], reference: SweepResult, client2: Any, tmp_path: Path, plan: ChunkPlan
) -> None:
    """Each recording detected in 3 chunks of 3 or more frames (12 -> 4+4+4, 10 -> 3+3+4), or
    in 2 unequal ones (advance cost 0.5: 1 : 0.5, so 12 -> 8+4 and 10 -> int(10/1.5) = 6,
    then 4) on the two workers: the same detections in the cache entries, the same records."""
    grid, configs = grid_and_configs()
    cold = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path, chunks=plan)
    warm = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path, chunks=plan)
    assert (cold.cache_misses, warm.cache_hits, cold.failures) == (2, 2, ())
    assert records(cold) == records(reference) and records(warm) == records(reference)
    # Against one pass on local:1 (one worker: no chunks); the entries differ only in the
    # stage seconds they record.
    one = tmp_path / "one-pass"
    run_sweep(recordings, grid, configs, cache_root=one)
    for entry in (tmp_path / "detections").rglob("*.det"):
        twin = one / entry.relative_to(tmp_path)
        a, b = (DetectionCache(root).load(entry.stem) for root in (tmp_path, one))
        assert twin.exists() and a is not None and b is not None
        assert a.stamps_ns == b.stamps_ns
        assert pickle.dumps(a.detections) == pickle.dumps(b.detections)


def test_default_split_of_one_recording(
    recordings: list[Path], reference: SweepResult, client2: Any, tmp_path: Path
) -> None:
    """One recording on two workers takes the default split graph (advance, chunks, join;
    12 frames hold one chunk of the 60-frame minimum, the second is empty): the same records
    as local:1's. The workers run without Dask's malloc setting."""
    grid, configs = grid_and_configs()
    one = run_sweep(recordings[:1], grid, configs, client2, cache_root=tmp_path)
    name = one.records[0].sequence
    assert one.cache_misses == 1
    assert records(one) == [r for r in records(reference) if r[1] == name]
    assert set(client2.run(os.environ.get, "MALLOC_TRIM_THRESHOLD_").values()) == {None}


def test_a_warm_sweep_submits_no_chunks_and_a_corrupt_entry_is_detected_in_one_pass(
    recordings: list[Path], reference: SweepResult, client2: Any, tmp_path: Path
) -> None:
    """The client finds the entries by the memoised digests: a warm sweep submits no chunk
    tasks. An entry that fails its checksum is still recomputed (by the prepare task, in
    one pass), with the same records."""
    from distributed import get_task_stream

    grid, configs = grid_and_configs()
    plan = ChunkPlan(3, 3)
    with get_task_stream(client2) as cold_ts:
        cold = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path, chunks=plan)
    with get_task_stream(client2) as warm_ts:
        warm = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path, chunks=plan)

    def chunk_tasks(stream: Any) -> int:
        return sum(str(t["key"]).startswith("_detect_chunk") for t in stream.data)

    assert (cold.cache_misses, warm.cache_hits) == (2, 2)
    assert chunk_tasks(cold_ts) == 6 and chunk_tasks(warm_ts) == 0  # 3 chunks x 2 recordings
    entry = DetectionCache(tmp_path).path(detection_key(file_digest(recordings[0]), configs[0]))
    blob = bytearray(entry.read_bytes())
    blob[len(blob) // 2] ^= 0x04
    entry.write_bytes(bytes(blob))
    again = run_sweep(recordings, grid, configs, client2, cache_root=tmp_path, chunks=plan)
    assert (again.cache_hits, again.cache_misses) == (1, 1)
    assert any("checksum mismatch" in w for w in again.warnings)
    assert records(cold) == records(warm) == records(again) == records(reference)


def test_a_bad_recording_fails_alike_in_chunks(client2: Any, tmp_path: Path) -> None:
    bad = tmp_path / "broken.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n" + b"\x00" * 64)  # magic, then nothing readable
    grid, configs = grid_and_configs()
    whole, split = (
        run_sweep([bad], grid, configs, client2, cache_root=tmp_path, chunks=ChunkPlan(n, 1))
        for n in (1, 3)
    )
    assert split.records == () and len(split.failures) == len(VALUES)
    assert split.failures == whole.failures and split.failures[0].exit_code == 3


def test_worker_killed_mid_sweep_is_replaced_and_the_sweep_completes(
    recordings: list[Path], reference: SweepResult, client2: Any, tmp_path: Path
) -> None:
    grid, configs = grid_and_configs()
    before = client2.run(os.getpid)
    killed: list[int] = []

    def kill_a_busy_worker(stage: str, done: int, total: int) -> None:
        if killed:
            return
        busy = [w for w, keys in client2.processing().items() if keys]
        if busy:  # SIGKILL the worker while the scheduler has a task running on it
            pid = before[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    result = run_sweep(
        recordings, grid, configs, client2, cache_root=tmp_path, progress=kill_a_busy_worker
    )
    assert killed, "no task was running when the first task completed"
    assert result.failures == ()
    assert records(result) == records(reference)
    client2.wait_for_workers(2, timeout=60)  # the nanny restarts the killed worker
    assert killed[0] not in client2.run(os.getpid).values()


def test_corrupted_cache_entry_is_detected_and_recomputed(
    recordings: list[Path], reference: SweepResult, tmp_path: Path
) -> None:
    grid, configs = grid_and_configs()
    first = run_sweep(recordings, grid, configs, cache_root=tmp_path)
    entry = DetectionCache(tmp_path).path(detection_key(file_digest(recordings[0]), configs[0]))
    blob = bytearray(entry.read_bytes())
    blob[len(blob) // 2] ^= 0x04  # one flipped bit in the payload
    entry.write_bytes(bytes(blob))
    second = run_sweep(recordings, grid, configs, cache_root=tmp_path)
    assert (second.cache_hits, second.cache_misses) == (1, 1)
    assert len(second.warnings) == 1 and "checksum mismatch, recomputing" in second.warnings[0]
    assert records(second) == records(first) == records(reference)
    assert DetectionCache(tmp_path).load(entry.stem) is not None  # rewritten intact
    third = run_sweep(recordings, grid, configs, cache_root=tmp_path)
    assert (third.cache_hits, third.warnings) == (2, ())


def test_a_bad_recording_fails_its_points_and_the_others_complete(
    recordings: list[Path], reference: SweepResult, tmp_path: Path
) -> None:
    bad = tmp_path / "broken.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n" + b"\x00" * 64)  # magic, then nothing readable
    args = ["sweep", "tracker.min_confidence", *map(str, VALUES), "--cluster", "local:1"]
    for path in (recordings[0], bad):
        args += ["--dataset", str(path)]
    out = tmp_path / "out"
    result = CliRunner().invoke(app, [*args, "--cache", str(tmp_path / "c"), "--out", str(out)])
    # Exit code of the failure (3: bad input recording); one line counts the failures and
    # names the first in grid order.
    assert result.exit_code == 3, result.output
    error = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(error) == 1 and error[0].startswith("error: 3 of 6 sweep point(s) failed")
    assert f"first: tracker.min_confidence={VALUES[0]} on broken:" in error[0]
    report = json.loads((out / "sweep.json").read_text())
    assert [
        (f["tracker.min_confidence"], f["sequence"], f["exit_code"]) for f in report["failures"]
    ] == [(v, "broken", 3) for v in VALUES]
    assert all("broken.mcap" in f["error"] for f in report["failures"])
    good = [(r["tracker.min_confidence"], r["num_matches"]) for r in report["records"]]
    want = [
        (r.point["tracker.min_confidence"], r.counts.num_matches)
        for r in reference.records
        if r.sequence == recordings[0].stem
    ]
    assert good == want and len(good) == len(VALUES)
    # When every point fails there is nothing to report: one error line, no output folder.
    alone = [*args[: args.index("--dataset")], "--dataset", str(bad), "--out", str(tmp_path / "o2")]
    result = CliRunner().invoke(app, alone)
    assert result.exit_code == 3
    error = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(error) == 1 and error[0].startswith("error: 3 of 3 sweep point(s) failed; first:")
    assert not (tmp_path / "o2").exists()


def test_run_over_a_folder_on_two_workers(tmp_path: Path, client2: Any) -> None:
    from rgbd_eval.engine import map_ordered
    from rgbd_eval.pipeline import run_sequence
    from tests.io.conftest import Spec, write_recording

    data = tmp_path / "data"
    paths = [write_recording(data / "a.mcap", "mcap", Spec(n=3))]
    paths.append(write_recording(data / "b.bag", "ros1", Spec(n=2)))
    config = load_config(method="basso2012")
    remote = map_ordered(client2, run_sequence, [(p, config, None) for p in paths])
    local = [run_sequence(p, config) for p in paths]
    assert [r.name for r in remote] == ["a", "b"]
    assert [r.scores.counts for r in remote if r.scores] == [
        r.scores.counts for r in local if r.scores
    ]
    # An error raised on a worker process comes back as the same one-line error and exit code.
    (data / "c.mcap").write_bytes(b"not a recording")
    out = tmp_path / "o"
    result = CliRunner().invoke(app, ["run", str(data), "--out", str(out), "--cluster", "local:2"])
    assert result.exit_code == 3, result.output
    assert result.output.startswith(f"error: {data / 'c.mcap'}") and result.output.count("\n") == 1
    assert not out.exists()
