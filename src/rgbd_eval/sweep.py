"""Parameter sweeps: expand a grid, detect once per (sequence, detector config), track and score each point.

Work runs as Dask tasks (:mod:`rgbd_eval.engine`). A *prepare* task loads (or
computes and stores) the detections of one sequence for one distinct detector
config of the grid, and aligns the ground truth with them; a *track* task
tracks one (grid point, sequence) from its prepare task's result, which the
scheduler hands from worker to worker, and a *score* task scores those tracks.
Tasks return records to the client; workers write nothing but cache entries. With fewer
recordings than workers, a miss is detected in frame chunks on several workers
(:mod:`rgbd_eval.chunked`): the prepare task opens the recording, a chain of
*advance* tasks hands each *chunk* task its detector state, a *join* task
assembles and stores the detections, and the track tasks start from the join.

A task that fails on bad input returns its error instead of raising, so the
other points complete and the failure is reported with its grid point. A
worker that dies mid-task is replaced and the task re-run elsewhere; a task
that kills every worker it runs on becomes a failure of its points.

Results do not depend on the number of workers or on completion order: the
records are assembled in grid order, and tracking always starts from the
detections as the cache encodes them (a fresh detection is round-tripped
through :func:`rgbd_eval.cache.encode` first), so a cache hit and a miss
track the very same numbers. A tracker that reads frames (``needs_frame``) gets
them by reading the recording again in its track task; the others replay the
detections alone.
"""

from __future__ import annotations

import enum
import itertools
import math
import threading
import time
import uuid
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rgbd_eval.cache import (
    CacheWarning,
    DetectionCache,
    decode,
    detection_key,
    detector_inputs,
    encode,
)
from rgbd_eval.chunked import (
    Chunk,
    ChunkPlan,
    advance,
    advance_cost,
    detect_chunk,
    join,
    resumable,
)
from rgbd_eval.components import needs_frame
from rgbd_eval.config import RunConfig, build_config, parse_overrides
from rgbd_eval.engine import ClusterSpec, connect, killed_worker_message
from rgbd_eval.errors import (
    CacheError,
    ClusterError,
    ConfigError,
    InputError,
    RgbdEvalError,
    ScoringError,
)
from rgbd_eval.files import file_digest
from rgbd_eval.io.groundtruth import GroundTruth
from rgbd_eval.io.recording import Recording
from rgbd_eval.metrics import Counts, summarize, total
from rgbd_eval.pipeline import (
    GroundTruthMatch,
    SequenceDetections,
    detect_sequence,
    ground_truth_file,
    match_ground_truth,
    open_for,
    score_sequence,
    sequence_name,
    track_sequence,
)
from rgbd_eval.plugins import load_plugins
from rgbd_eval.types import TrackOutput

if TYPE_CHECKING:
    from distributed import Client, Future

Point = dict[str, Any]


@dataclass(frozen=True)
class SweepParam:
    """One swept key and its values."""

    key: str
    values: tuple[Any, ...]


def parse_param(spec: str) -> SweepParam:
    """``tracker.min_confidence=-1,-0.5,0`` -> SweepParam (values parsed as YAML scalars)."""
    key, sep, raw = spec.partition("=")
    if not sep or not key.strip() or not raw.strip():
        raise ConfigError(
            f"--param {spec!r}: expected NAME=V1,V2,... e.g. tracker.min_confidence=-1,0"
        )
    values = tuple(v for _, v in parse_overrides(f"{key}={item}" for item in raw.split(",")))
    return SweepParam(key.strip(), values)


#: Most grid points a sweep may have: each is validated, then run on every recording, and
#: the product of a few long value lists grows fast (1000 x 1000 exhausted memory).
MAX_GRID_POINTS = 10_000


def expand_grid(params: Sequence[SweepParam]) -> list[Point]:
    """The Cartesian product of the parameters' values, first parameter slowest.

    ConfigError beyond :data:`MAX_GRID_POINTS` points (counted before any is built).
    """
    keys = [p.key for p in params]
    if len(set(keys)) != len(keys):
        raise ConfigError(f"a parameter is swept twice: {', '.join(keys)}")
    if any(not p.values for p in params):
        raise ConfigError("every swept parameter needs at least one value")
    size = math.prod(len(p.values) for p in params)
    if size > MAX_GRID_POINTS:
        counts = " x ".join(f"{len(p.values)} {p.key}" for p in params)
        raise ConfigError(
            f"the grid has {size} points ({counts}), more than the {MAX_GRID_POINTS} a sweep "
            "may have; sweep fewer values"
        )
    return [
        dict(zip(keys, combo, strict=True))
        for combo in itertools.product(*(p.values for p in params))
    ]


def point_configs(
    base: Mapping[str, Any], overrides: Iterable[tuple[str, Any]], grid: Sequence[Point]
) -> list[RunConfig]:
    """Validate every grid point before anything runs; a bad point names itself."""
    fixed = list(overrides)
    configs = []
    for point in grid:
        label = ", ".join(f"{k}={v}" for k, v in point.items())
        configs.append(build_config(base, [*fixed, *point.items()], source=f"sweep point {label}"))
    return configs


class CacheMode(enum.Enum):
    """Who reads and writes the detection cache folder."""

    #: Workers load and store entries themselves: the folder is on a disk every worker sees
    #: under the same path (local cluster, or a network filesystem).
    SHARED = "shared"
    #: Only the client touches the folder: hits are sent to workers with their tasks, fresh
    #: detections come back to the client, which stores them (workers share no disk).
    CLIENT = "client"


@dataclass(frozen=True)
class SweepRecord:
    """The scores of one sequence at one grid point."""

    point: Point
    sequence: str
    counts: Counts
    seconds: float


@dataclass(frozen=True)
class SweepFailure:
    """A (grid point, sequence) that could not be scored, with the one-line error."""

    point: Point
    sequence: str
    error: str
    exit_code: int


@dataclass(frozen=True)
class SweepResult:
    params: tuple[str, ...]
    grid: tuple[Point, ...]
    records: tuple[SweepRecord, ...]
    #: Task seconds summed over prepare (detect or load) and track+score tasks.
    detect_seconds: float
    track_seconds: float
    cache_hits: int
    cache_misses: int
    #: The (grid point, sequence) tasks that failed, in grid order.
    failures: tuple[SweepFailure, ...] = ()
    #: Cache entries rejected (checksum, layout) and recomputed, one line each.
    warnings: tuple[str, ...] = ()

    def overall(self) -> list[tuple[Point, Counts]]:
        """Per grid point, the counts summed over sequences (failed ones left out)."""
        out = []
        for point in self.grid:
            counts = [r.counts for r in self.records if r.point == point]
            out.append((point, total(counts)))
        return out

    def rows(self) -> list[dict[str, Any]]:
        """Flat records (one per sequence and point, plus 'overall' rows) for CSV/JSON."""
        rows = []
        for r in self.records:
            rows.append(
                {**r.point, "sequence": r.sequence, **summarize(r.counts), "seconds": r.seconds}
            )
        if len({r.sequence for r in self.records}) > 1:
            for point, counts in self.overall():
                rows.append({**point, "sequence": "overall", **summarize(counts), "seconds": None})
        return rows


@dataclass(frozen=True)
class _Failed:
    """A task's error, returned rather than raised so that the other tasks go on."""

    error: str
    exit_code: int


@dataclass(frozen=True)
class _Prepared:
    """Prepare-task output for one sequence and one detector config."""

    path: Path
    key: str
    detections: SequenceDetections
    ground_truth: GroundTruthMatch
    seconds: float
    hit: bool
    rejected: tuple[str, ...]


@dataclass(frozen=True)
class _Stored:
    """A prepare result whose detections are in the shared cache, without them: what the
    track and score tasks receive, so that a worker loads the entry (checksummed) instead of
    receiving the detections from the worker that made them (:func:`_stored`)."""

    path: Path
    key: str
    cache_root: Path
    ground_truth: GroundTruthMatch


#: Detections a worker process made or loaded, by cache key: the last few, so that the
#: track tasks of one recording read its cache entry once per worker (see :func:`_stored`).
_LOCAL_DETECTIONS: dict[str, SequenceDetections] = {}
_LOCAL_KEEP = 2
#: A worker may run tasks in several threads (a remote worker started with several).
_LOCAL_LOCK = threading.Lock()


def _keep_local(key: str, detections: SequenceDetections) -> None:
    with _LOCAL_LOCK:
        _LOCAL_DETECTIONS.pop(key, None)
        _LOCAL_DETECTIONS[key] = detections
        while len(_LOCAL_DETECTIONS) > _LOCAL_KEEP:
            del _LOCAL_DETECTIONS[next(iter(_LOCAL_DETECTIONS))]


@dataclass(frozen=True)
class _Opened:
    """A cache miss to detect in chunks: the recording, opened once for its chunk tasks."""

    key: str
    recording: Recording
    ground_truth: GroundTruth
    seconds: float
    rejected: tuple[str, ...]


@dataclass(frozen=True)
class _Brief:
    """What the client needs of a prepare task (not the detections, unless it stores them)."""

    seconds: float
    hit: bool
    rejected: tuple[str, ...]
    failed: _Failed | None


def _failed(err: RgbdEvalError) -> _Failed:
    return _Failed(" ".join(str(err).split()), err.exit_code)


def _prepare(
    path: Path,
    digest: str | None,
    config: RunConfig,
    gt_path: Path | None,
    cache_root: Path | None,
    cached: SequenceDetections | None,
    chunked: bool = False,
) -> _Prepared | _Opened | _Failed:
    """Detections (cache, ``cached`` from the client, or fresh) and aligned ground truth.

    ``digest`` is the recording's :func:`file_digest`, computed (or found in the cache's
    digest memo) here when None. With ``chunked``, a miss returns the opened recording
    for :func:`_advance`, :func:`_detect_chunk` and :func:`_join` instead of detecting.
    """
    start = time.perf_counter()
    try:
        cache = DetectionCache(cache_root) if cache_root is not None else None
        try:
            if digest is None:
                digest = cache.digest(path) if cache is not None else file_digest(path)
            key = detection_key(digest, config)
        except OSError as err:
            raise InputError(path, f"cannot read ({err.strerror or err})") from err
        detections = cached
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", CacheWarning)
            if detections is None and cache is not None:
                detections = cache.load(key)
        rejected = tuple(str(w.message) for w in caught if issubclass(w.category, CacheWarning))
        hit = detections is not None
        gt = ground_truth_file(path, gt_path)
        if detections is None or gt is None:
            # The index pass reads every image message: only when detecting or for a ground-truth topic.
            recording = open_for(path, config)
            if gt is None:
                gt = recording.ground_truth_topic
            if gt is None:
                raise ScoringError(
                    f"{path}: a sweep needs ground truth (topic, <name>.gt.csv sidecar or --gt)"
                )
            if detections is None and chunked:
                return _Opened(key, recording, gt, time.perf_counter() - start, rejected)
            if detections is None:
                # Tracked in its encoded form, so that a later cache hit tracks the same numbers.
                detections = decode(key, encode(key, detect_sequence(recording, config)))
                if cache is not None:
                    cache.store(key, detections)
        matched = match_ground_truth(gt, detections.stamps_ns, config)
    except RgbdEvalError as err:
        return _failed(err)
    if cache_root is not None:  # only track tasks handed a _Stored record read the memo
        _keep_local(key, detections)
    return _Prepared(path, key, detections, matched, time.perf_counter() - start, hit, rejected)


#: A chunk task's input state: the detector's carried state (None: fresh), or why there is none.
_State = object


def _advance(
    opened: _Prepared | _Opened | _Failed,
    config: RunConfig,
    plan: ChunkPlan,
    k: int,
    state: _State,
) -> _State:
    """The detector's state after chunk ``k`` (nothing to do unless ``opened`` is a miss)."""
    if not isinstance(opened, _Opened) or isinstance(state, _Failed):
        return state
    try:
        return advance(opened.recording, config, plan.spans(len(opened.recording))[k], state)
    except RgbdEvalError as err:
        return _failed(err)


def _detect_chunk(
    opened: _Prepared | _Opened | _Failed,
    config: RunConfig,
    plan: ChunkPlan,
    k: int,
    state: _State,
) -> tuple[Chunk, float] | _Failed | None:
    """Detections of chunk ``k`` from ``state``, and the task's seconds (None on a hit)."""
    if not isinstance(opened, _Opened):
        return None
    if isinstance(state, _Failed):
        return state
    start = time.perf_counter()
    try:
        span = plan.spans(len(opened.recording))[k]
        chunk = detect_chunk(opened.recording, config, span, state)
    except RgbdEvalError as err:
        return _failed(err)
    return chunk, time.perf_counter() - start


def _join(
    path: Path,
    opened: _Prepared | _Opened | _Failed,
    config: RunConfig,
    cache_root: Path | None,
    *parts: tuple[Chunk, float] | _Failed | None,
) -> _Prepared | _Failed:
    """The prepare result of a chunked detection: the chunks joined, stored, and aligned."""
    if not isinstance(opened, _Opened):
        return opened
    start = time.perf_counter()
    try:
        for part in parts:  # the first failing chunk in frame order, as one pass would fail
            if isinstance(part, _Failed):
                return part
        chunks = [p for p in parts if isinstance(p, tuple)]
        joined = join(opened.recording, [c for c, _ in chunks])
        key = opened.key
        detections = decode(key, encode(key, joined))
        if cache_root is not None:
            DetectionCache(cache_root).store(key, detections)
        matched = match_ground_truth(opened.ground_truth, detections.stamps_ns, config)
    except RgbdEvalError as err:
        return _failed(err)
    seconds = opened.seconds + sum(t for _, t in chunks) + time.perf_counter() - start
    if cache_root is not None:
        _keep_local(key, detections)
    return _Prepared(path, key, detections, matched, seconds, False, opened.rejected)


def _stored(prepared: _Prepared | _Failed, cache_root: Path) -> _Prepared | _Stored | _Failed:
    """``prepared`` without its detections when they are in the shared cache, else as is.

    Runs where ``prepared`` is. The track tasks then depend on this small record alone, so
    the scheduler places them freely and no worker receives 4.4 MB of detections from
    another (0.1-0.35 s on moving_complex, while the sender computes, and traffic that
    grows with the cluster); each worker loads the entry once instead (0.04 s).
    """
    if not isinstance(prepared, _Prepared):
        return prepared
    if not DetectionCache(cache_root).has(prepared.key):
        return prepared  # not stored (it could not be written): the detections travel
    return _Stored(prepared.path, prepared.key, cache_root, prepared.ground_truth)


def _detections_of(prepared: _Prepared | _Stored) -> SequenceDetections:
    """The detections of a prepare result, loaded from the shared cache when not at hand."""
    if isinstance(prepared, _Prepared):
        return prepared.detections
    with _LOCAL_LOCK:
        local = _LOCAL_DETECTIONS.get(prepared.key)
    if local is not None:
        return local
    cache = DetectionCache(prepared.cache_root)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CacheWarning)
        loaded = cache.load(prepared.key)
    if loaded is None:
        why = "; ".join(str(w.message) for w in caught) or "it is gone"
        raise CacheError(
            cache.path(prepared.key),
            f"the detection cache entry written moments ago cannot be read back ({why})",
        )
    _keep_local(prepared.key, loaded)
    return loaded


def _brief(prepared: _Prepared | _Failed) -> _Brief:
    if isinstance(prepared, _Failed):
        return _Brief(0.0, False, (), prepared)
    return _Brief(prepared.seconds, prepared.hit, prepared.rejected, None)


#: One grid point's tracks on one sequence, and the track task's seconds.
_Tracked = tuple[tuple[tuple[TrackOutput, ...], ...], float]


def _track(prepared: _Prepared | _Stored | _Failed, config: RunConfig) -> _Tracked | _Failed:
    """Track one grid point on one sequence (scored by :func:`_score`, a task of its own)."""
    if isinstance(prepared, _Failed):
        return prepared
    start = time.perf_counter()
    try:
        detections = _detections_of(prepared)
        # A tracker that reads frames replays them from the recording, read again.
        recording = open_for(prepared.path, config) if needs_frame(config) else None
        tracks = track_sequence(detections, config, recording)
    except RgbdEvalError as err:
        return _failed(err)
    return tracks, time.perf_counter() - start


def _score(
    prepared: _Prepared | _Stored | _Failed, tracked: _Tracked | _Failed, config: RunConfig
) -> tuple[Counts, float] | _Failed:
    """Score one grid point's tracks; the seconds are the track and score tasks' together."""
    if isinstance(prepared, _Failed):
        return prepared
    if isinstance(tracked, _Failed):
        return tracked
    tracks, track_seconds = tracked
    start = time.perf_counter()
    try:
        scores = score_sequence(prepared.ground_truth, tracks, config)
    except RgbdEvalError as err:
        return _failed(err)
    return scores.counts, track_seconds + time.perf_counter() - start


def _worker_slots(client: Client) -> list[str]:
    """The cluster's task slots: each worker's address once per thread, in address order."""
    workers = client.scheduler_info().get("workers", {})
    return [a for a, w in sorted(workers.items()) for _ in range(int(w.get("nthreads", 1)))]


def _submit_chunks(
    client: Client,
    path: Path,
    opened: Future[Any],
    config: RunConfig,
    plan: ChunkPlan,
    cache_root: Path | None,
    slots: Sequence[str | None],
) -> Future[Any]:
    """The chunk tasks of one recording's detection; returns the future of their join.

    The advance chain (each link the state after one more chunk) is submitted first,
    so it runs ahead of the chunk detections that wait on it. ``slots``: the group's
    workers, one per chunk; the first also ran the prepare task (see :func:`run_sweep`).
    """
    states: list[Any] = [None]
    for k in range(plan.chunks - 1):
        states.append(
            _submit(client, _advance, opened, config, plan, k, states[-1], index=k, on=slots[0])
        )
    # Where each chunk runs is stated, loosely (a lost worker's tasks still run elsewhere):
    # the advance chain stays on the prepare task's worker, which then detects the last
    # (shortest) chunk; chunk k < K-1 goes to slot k+1, so chunk 0 starts as soon as the
    # recording is open. Left to itself, Dask places a task on a worker that holds one of
    # its inputs: chunk 0 then queued behind the advance pass on the prepare task's worker
    # in 3 of 11 idle runs of bench/dask_scaling.py, starting 0.6-1.0 s late, or the chunk
    # after the advance pass went to the other worker and waited for its state.
    parts = [
        _submit(
            client,
            _detect_chunk,
            opened,
            config,
            plan,
            k,
            states[k],
            index=k,
            on=slots[(k + 1) % plan.chunks],
        )
        for k in range(plan.chunks)
    ]
    return _submit(client, _join, path, opened, config, cache_root, *parts)


def _submit_points(
    client: Client,
    prepared: Future[Any],
    points: Sequence[tuple[int, RunConfig]],
    slots: Sequence[str | None],
) -> dict[int, Future[Any]]:
    """The track and score tasks of one group's ``points`` (unit index, config): the score
    task's future of each unit.

    Tracking and scoring are separate tasks (about 0.35 and 0.17 s on moving_complex):
    2 x 9 tasks of uneven size fill two workers more evenly than 9 equal ones. The track
    tasks are submitted first, so a worker tracks before it scores, and the client keeps
    no reference to them: their tracks are freed once scored.

    ``slots``: the group's own workers (several when there are fewer groups than
    workers). Track ``j`` is placed on slot ``j`` (mod the count), loosely. Left to itself,
    Dask queues the track tasks at the scheduler (root-ish: many tasks on one small input)
    and each worker scored its finished tracks before it was sent the next: on
    moving_complex one worker ended on a track and its score (0.5 s) while the other idled.
    A score task goes where Dask puts it, on a worker holding its track or the prepare
    result: placed on the other slot as well, its tracks (230 KB) had to be copied, 0.1-0.2
    s each while the sender computed, and the sweep was slower (9 repetitions: cold 1.60x
    against 1.69x, warm 1.73x against 1.84x). With no ``slots``, every task goes where Dask
    puts it (many groups keep every worker busy, and the queue keeps few detections loaded).
    """

    on = [slots[j % len(slots)] if slots else None for j in range(len(points))]
    tracks = [
        _submit(client, _track, prepared, config, index=i, on=on[j])
        for j, (i, config) in enumerate(points)
    ]
    return {
        i: _submit(client, _score, prepared, track, config, index=i)
        for (i, config), track in zip(points, tracks, strict=True)
    }


def _submit(
    client: Client,
    func: Callable[..., Any],
    *args: Any,
    index: int | None = None,
    on: str | None = None,
) -> Future[Any]:
    """``client.submit(func, *args)``, run in submission order among ready tasks.

    Dask gives every task submitted within ``fifo_timeout`` (100 ms by default) of the
    previous one the same priority, so a burst of submissions runs in no set order; 0
    starts a new priority generation with each call. The key names ``func`` and ``index``
    (chunk, or unit of the sweep), which the task stream then shows. ``on``: the worker
    the task should run on, if it is alive and free (a loose restriction).
    """
    tag = f"-{index}" if index is not None else ""
    key = f"{func.__name__}{tag}-{uuid.uuid4().hex}"
    if on is None:
        return client.submit(func, *args, key=key, fifo_timeout=0)
    return client.submit(
        func, *args, key=key, fifo_timeout=0, workers=[on], allow_other_workers=True
    )


def _outcome(future: Future[Any]) -> Any:
    """A task's result; a task that killed every worker it ran on becomes a failure."""
    from distributed import KilledWorker

    try:
        return future.result()
    except KilledWorker as err:
        return _Failed(killed_worker_message(err), ClusterError.exit_code)


def warm_up() -> None:
    """Prepare a new worker process (:func:`rgbd_eval.engine.connect`): running this function
    there imports this module, the task code, and it loads every registered method (measured
    here: 0.9 CPU s to import the sweep's modules, 0.85 s the methods)."""
    load_plugins()


def run_sweep(
    recordings: Sequence[Path],
    grid: Sequence[Point],
    configs: Sequence[RunConfig],
    client: Client | None = None,
    cache_root: Path | None = None,
    gt_path: Path | None = None,
    progress: Callable[[str, int, int], None] | None = None,
    cache_mode: CacheMode = CacheMode.SHARED,
    chunks: ChunkPlan | None = None,
) -> SweepResult:
    """Run every grid point on every recording (see the module docstring).

    Without ``client``, a local cluster of one in-process worker runs the sweep.
    ``progress(stage, done, total)`` is called as tasks complete, stage
    ``"detect"`` or ``"track+score"``. ``chunks``: how a recording's detection is split
    (:mod:`rgbd_eval.chunked`); by default into as many chunks as there are workers per
    (recording, detector config), so one recording still keeps every worker busy, of
    lengths balanced by the detector's ``advance_cost``.
    """
    if client is None:
        with connect(ClusterSpec(None, 1)) as own:
            return run_sweep(
                recordings, grid, configs, own, cache_root, gt_path, progress, cache_mode, chunks
            )
    from distributed import as_completed

    cache = DetectionCache(cache_root)
    root = cache.root.resolve()  # workers may not share the client's working directory
    client_side = cache_mode is CacheMode.CLIENT
    # The client hashes the recordings only when it reads the cache itself; otherwise each
    # prepare task hashes its recording on a worker, in parallel. Either way the digest is
    # memoised in the cache folder, so a warm sweep reads no recording.
    digests = {p: cache.digest(p) for p in recordings} if client_side else {}
    units = [
        (point, cfg, path) for point, cfg in zip(grid, configs, strict=True) for path in recordings
    ]
    # One prepare task per (recording, distinct detector inputs), the track tasks that use it
    # submitted right after it: the scheduler runs earlier submissions first, so a
    # recording's detections are tracked, then released, before many more are loaded.
    groups: dict[tuple[Path, str], list[int]] = {}
    for i, (_, cfg, path) in enumerate(units):
        groups.setdefault((path, detector_inputs(cfg)), []).append(i)
    slots = _worker_slots(client)
    slots_per_group = max(1, len(slots) // max(1, len(groups)))
    prepared: dict[tuple[Path, str], Future[Any]] = {}
    briefs: dict[tuple[Path, str], Future[Any]] = {}
    tracked: dict[int, Future[Any]] = {}  # the score task of each unit
    rejected: list[str] = []
    for g, (group, members) in enumerate(groups.items()):
        path, cfg = group[0], units[members[0]][1]
        cached = None
        if client_side:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", CacheWarning)
                cached = cache.load(detection_key(digests[path], cfg))
            rejected += [str(w.message) for w in caught if issubclass(w.category, CacheWarning)]
        plan = chunks or ChunkPlan(slots_per_group)
        split = plan.chunks > 1 and cached is None and resumable(cfg)
        if split and not client_side:
            # A warm sweep needs no chunk tasks: they would only wait for the opened
            # recording and pass. Looked up by the memoised digest alone (no hashing); an
            # entry that then fails its checksum is detected in one pass by the prepare task.
            known = cache.known_digest(path)
            split = known is None or not cache.has(detection_key(known, cfg))
        if split and chunks is None:
            # Chunks shorter where they wait longer for the detector's state.
            plan = replace(plan, advance_cost=advance_cost(cfg))
        gt = gt_path.resolve() if gt_path is not None else None
        cache_at = None if client_side else root
        # A split group's tasks are placed on its own slots (wrapping round when there are
        # more groups than slots can split, which only happens with an explicit plan).
        mine: list[str | None] = [
            slots[(g * plan.chunks + k) % len(slots)] if slots else None for k in range(plan.chunks)
        ]
        prep = _submit(
            client,
            _prepare,
            path.resolve(),
            digests.get(path),
            cfg,
            gt,
            cache_at,
            client.scatter(cached) if cached is not None else None,
            split,
            on=mine[0] if split else None,
        )
        if split:
            prep = _submit_chunks(client, path.resolve(), prep, cfg, plan, cache_at, mine)
        briefs[group] = _submit(client, _brief, prep)
        # With a shared cache, track and score tasks take the detections from it.
        use = prep if cache_at is None else _submit(client, _stored, prep, cache_at)
        points = [(i, units[i][1]) for i in members]
        tracked |= _submit_points(client, use, points, mine if len(mine) > 1 else [])
        if client_side:
            # Kept to fetch fresh detections. Otherwise the client holds no reference, so
            # the scheduler frees the detections once this group's track tasks are done.
            prepared[group] = prep
    stage = {f.key: "detect" for f in briefs.values()}
    stage |= {f.key: "track+score" for f in tracked.values()}
    totals = {"detect": len(briefs), "track+score": len(tracked)}
    done = dict.fromkeys(totals, 0)
    try:
        for future in as_completed([*briefs.values(), *tracked.values()], loop=client.loop):
            name = stage[future.key]
            done[name] += 1
            if progress:
                progress(name, done[name], totals[name])
        brief = {k: _outcome(f) for k, f in briefs.items()}
        outcomes = [_outcome(tracked[i]) for i in range(len(units))]
        if client_side:  # fresh detections come back here to be stored
            for group, b in brief.items():
                if isinstance(b, _Brief) and b.failed is None and not b.hit:
                    fresh = prepared[group].result()
                    cache.store(fresh.key, fresh.detections)
    finally:
        # Only the last tasks of each chain are cancelled (the scheduler then releases what
        # they needed). Cancelling a prepare task would cancel its track tasks too, which
        # no client holds, and trips an assertion in Dask's scheduler (a traceback on
        # stderr after a successful client-mode sweep); the prepare futures are released.
        client.cancel([*briefs.values(), *tracked.values()])
        for future in prepared.values():
            future.release()
    records, failures = [], []
    for (point, _, path), out in zip(units, outcomes, strict=True):
        if isinstance(out, _Failed):
            failures.append(
                SweepFailure(dict(point), sequence_name(path), out.error, out.exit_code)
            )
        else:
            counts, seconds = out
            records.append(SweepRecord(dict(point), sequence_name(path), counts, seconds))
    ok = [b for b in brief.values() if isinstance(b, _Brief) and b.failed is None]
    hits = sum(b.hit for b in ok)
    return SweepResult(
        params=tuple(grid[0].keys()) if grid else (),
        grid=tuple(dict(p) for p in grid),
        records=tuple(records),
        failures=tuple(failures),
        detect_seconds=sum(b.seconds for b in ok),
        track_seconds=sum(r.seconds for r in records),
        cache_hits=hits,
        cache_misses=len(ok) - hits,
        warnings=(*rejected, *(w for b in ok for w in b.rejected)),
    )
