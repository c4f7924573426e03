"""Track and score tasks read a recording's detections from the shared cache (sweep._stored)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval import sweep
from rgbd_eval.cache import DetectionCache
from rgbd_eval.errors import CacheError
from rgbd_eval.pipeline import GroundTruthMatch
from rgbd_eval.sweep import _detections_of, _Failed, _Prepared, _Stored, _stored
from tests.test_cache import KEY, same, sample

GT = GroundTruthMatch("gt.csv", [[], [], []], 0, 3)


def prepared() -> _Prepared:
    return _Prepared(Path("r.mcap"), KEY, sample(), GT, 1.0, False, ())


@pytest.fixture(autouse=True)
def _no_local_detections(monkeypatch: pytest.MonkeyPatch) -> None:
    # Each test starts as a worker that has made or loaded nothing.
    monkeypatch.setattr(sweep, "_LOCAL_DETECTIONS", {})


def test_stored_entry_travels_without_its_detections(tmp_path: Path) -> None:
    DetectionCache(tmp_path).store(KEY, sample())
    handle = _stored(prepared(), tmp_path)
    assert handle == _Stored(Path("r.mcap"), KEY, tmp_path, GT)
    # A worker that did not make them loads them, checksummed, once.
    loaded = _detections_of(handle)
    assert same(loaded, sample())
    assert _detections_of(handle) is loaded


def test_unstored_detections_and_failures_pass_as_they_are(tmp_path: Path) -> None:
    p = prepared()
    assert _stored(p, tmp_path) is p  # nothing in the cache (it could not be written)
    assert _detections_of(p) is p.detections
    failed = _Failed("bad input", 3)
    assert _stored(failed, tmp_path) is failed


def test_an_entry_that_breaks_after_it_was_stored_is_a_cache_error(tmp_path: Path) -> None:
    cache = DetectionCache(tmp_path)
    cache.store(KEY, sample())
    handle = _stored(prepared(), tmp_path)
    blob = bytearray(cache.path(KEY).read_bytes())
    blob[-1] ^= 0xFF  # a flipped bit in the payload: the checksum fails
    cache.path(KEY).write_bytes(bytes(blob))
    with pytest.raises(CacheError, match="cannot be read back"):
        _detections_of(handle)
    cache.path(KEY).unlink()
    with pytest.raises(CacheError, match="it is gone"):
        _detections_of(handle)


def test_a_worker_keeps_the_last_two_recordings_detections() -> None:
    for key in ("a", "b", "c"):
        sweep._keep_local(key, sample())
    assert list(sweep._LOCAL_DETECTIONS) == ["b", "c"]
    sweep._keep_local("b", sample())  # used again: now the most recent
    assert list(sweep._LOCAL_DETECTIONS) == ["c", "b"]
