"""Parameter sweeps: expand a grid, detect once per (sequence, detector config), track and score each point.

Work runs in two phases. Phase 1 computes (or loads from the cache) the
detections of every sequence for every distinct detector config of the grid;
phase 2 tracks and scores every (sequence, grid point). A tracker that reads
frames (``needs_frame``) gets them by reading the recording again in phase 2;
the others replay the cached detections alone. Both phases run in
``jobs`` processes (inline when ``jobs == 1``). Results are records, never
parsed from printed text.
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rgbd_eval.cache import DetectionCache, detection_key
from rgbd_eval.config import RunConfig, build_config, parse_overrides
from rgbd_eval.errors import ConfigError, ScoringError
from rgbd_eval.metrics import Counts, summarize, total
from rgbd_eval.pipeline import (
    GroundTruthMatch,
    detect_sequence,
    ground_truth_file,
    match_ground_truth,
    open_for,
    score_sequence,
    sequence_name,
    track_sequence,
)
from rgbd_eval.report import file_digest
from rgbd_eval.track.protocol import needs_frame

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


def expand_grid(params: Sequence[SweepParam]) -> list[Point]:
    """The Cartesian product of the parameters' values, first parameter slowest."""
    keys = [p.key for p in params]
    if len(set(keys)) != len(keys):
        raise ConfigError(f"a parameter is swept twice: {', '.join(keys)}")
    if any(not p.values for p in params):
        raise ConfigError("every swept parameter needs at least one value")
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


@dataclass(frozen=True)
class SweepRecord:
    """The scores of one sequence at one grid point."""

    point: Point
    sequence: str
    counts: Counts
    seconds: float


@dataclass(frozen=True)
class SweepResult:
    params: tuple[str, ...]
    grid: tuple[Point, ...]
    records: tuple[SweepRecord, ...]
    detect_seconds: float
    track_seconds: float
    cache_hits: int
    cache_misses: int

    def overall(self) -> list[tuple[Point, Counts]]:
        """Per grid point, the counts summed over sequences."""
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
class _Prepared:
    """Phase-1 output for one sequence and one detector config."""

    path: Path
    key: str
    ground_truth: GroundTruthMatch
    seconds: float
    hit: bool


def _detect_job(
    path: Path, digest: str, config: RunConfig, gt_path: Path | None, cache_root: Path
) -> _Prepared:
    start = time.perf_counter()
    cache = DetectionCache(cache_root)
    key = detection_key(digest, config)
    gt = ground_truth_file(path, gt_path)
    detections = cache.load(key)
    hit = detections is not None
    if detections is None or gt is None:
        # The index pass reads every image message: only when detecting or for a ground-truth topic.
        recording = open_for(path, config)
        if gt is None:
            gt = recording.ground_truth_topic
        if gt is None:
            raise ScoringError(
                f"{path}: a sweep needs ground truth (topic, <name>.gt.csv sidecar or --gt)"
            )
        if detections is None:
            detections = detect_sequence(recording, config)
            cache.store(key, detections)
    matched = match_ground_truth(gt, detections.stamps_ns, config)
    return _Prepared(path, key, matched, time.perf_counter() - start, hit)


def _track_job(prepared: _Prepared, config: RunConfig, cache_root: Path) -> tuple[Counts, float]:
    start = time.perf_counter()
    detections = DetectionCache(cache_root).load(prepared.key)
    if detections is None:
        raise ConfigError(f"detection cache entry {prepared.key} vanished during the sweep")
    # A tracker that reads frames replays them from the recording, read again.
    recording = open_for(prepared.path, config) if needs_frame(config) else None
    tracks = track_sequence(detections, config, recording)
    scores = score_sequence(prepared.ground_truth, tracks, config)
    return scores.counts, time.perf_counter() - start


def run_sweep(
    recordings: Sequence[Path],
    grid: Sequence[Point],
    configs: Sequence[RunConfig],
    jobs: int = 1,
    cache_root: Path | None = None,
    gt_path: Path | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> SweepResult:
    """Run every grid point on every recording (see the module docstring)."""
    if jobs < 1:
        raise ConfigError(f"--jobs {jobs}: must be at least 1")
    cache = DetectionCache(cache_root)
    root = cache.root
    digests = {p: file_digest(p) for p in recordings}
    # Phase 1: one detection pass per (recording, distinct detector config).
    det_jobs: dict[tuple[Path, str], RunConfig] = {}
    for config in configs:
        for path in recordings:
            det_jobs.setdefault((path, detection_key(digests[path], config)), config)
    start = time.perf_counter()
    prepared: dict[tuple[Path, str], _Prepared] = {}
    items = list(det_jobs.items())
    args = [(path, digests[path], cfg, gt_path, root) for (path, _), cfg in items]
    for done, result in enumerate(_map(_detect_job, args, jobs), start=1):
        prepared[(result.path, result.key)] = result
        if progress:
            progress("detect", done, len(items))
    detect_s = time.perf_counter() - start
    # Phase 2: track and score each (grid point, recording).
    start = time.perf_counter()
    units = [
        (point, cfg, path) for point, cfg in zip(grid, configs, strict=True) for path in recordings
    ]
    track_args = [
        (prepared[(path, detection_key(digests[path], cfg))], cfg, root) for _, cfg, path in units
    ]
    records = []
    for done, ((point, _, path), (counts, seconds)) in enumerate(
        zip(units, _map(_track_job, track_args, jobs), strict=True), start=1
    ):
        records.append(SweepRecord(dict(point), sequence_name(path), counts, seconds))
        if progress:
            progress("track+score", done, len(units))
    track_s = time.perf_counter() - start
    hits = sum(p.hit for p in prepared.values())
    return SweepResult(
        params=tuple(grid[0].keys()) if grid else (),
        grid=tuple(dict(p) for p in grid),
        records=tuple(records),
        detect_seconds=detect_s,
        track_seconds=track_s,
        cache_hits=hits,
        cache_misses=len(prepared) - hits,
    )


def default_jobs() -> int:
    """Worker processes when none are asked for: one per CPU this process may use."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def _map(func: Callable[..., Any], args: list[tuple[Any, ...]], jobs: int) -> Iterable[Any]:
    """``func(*a)`` for each ``a``, in order; in ``jobs`` processes when jobs > 1."""
    if jobs == 1 or len(args) <= 1:
        for a in args:
            yield func(*a)
        return
    with ProcessPoolExecutor(max_workers=min(jobs, len(args))) as pool:
        futures = [pool.submit(func, *a) for a in args]
        for future in futures:
            yield future.result()
