"""The detection cache: exact round trip, checksums, corrupt or foreign entries, a bad folder."""

from __future__ import annotations

import hashlib
import io
import os
import threading
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.cache import DetectionCache, decode, detection_key, encode
from rgbd_eval.config import load_config
from rgbd_eval.errors import CacheError
from rgbd_eval.pipeline import SequenceDetections
from rgbd_eval.types import Box2D, Box3D, Detection

KEY = "ab" + "0" * 62


def sample() -> SequenceDetections:
    """Three frames: two detections (one with every optional field), none, one bare."""
    full = Detection(
        position=(2.0, -0.1, 0.9),
        height=1.78,
        confidence=-0.3125,
        box2d=Box2D(10.5, 5.0, 8.0, 30.0),
        box3d=Box3D((1.8, -0.3, 0.0), (2.2, 0.1, 1.78)),
        distance=2.0000000000000004,  # the last bit must survive
        occluded=True,
        appearance=np.arange(8, dtype=np.float32) / 7,
    )
    square = Detection(
        (1.0, 1.0, 1.0), 1.5, 0.25, Box2D(0, 0, 1, 1), appearance=np.eye(2, dtype=np.float32)
    )
    bare = Detection((3.0, 0.5, 0.8), 1.6, -1.0, Box2D(1.0, 2.0, 3.0, 4.0))
    return SequenceDetections(
        stamps_ns=(1_000, 2_000, 3_000),
        detections=((full, square), (), (bare,)),
        seconds={"read": 0.5, "detect": 1.25},
    )


def same(a: SequenceDetections, b: SequenceDetections) -> bool:
    """Field-by-field equality (Detection compares by identity: it holds an array)."""
    if (a.stamps_ns, a.seconds, len(a.detections)) != (b.stamps_ns, b.seconds, len(b.detections)):
        return False
    for fa, fb in zip(a.detections, b.detections, strict=True):
        if len(fa) != len(fb):
            return False
        for da, db in zip(fa, fb, strict=True):
            fields = ("position", "height", "confidence", "box2d", "box3d", "distance", "occluded")
            if any(getattr(da, f) != getattr(db, f) for f in fields):
                return False
            pa, pb = da.appearance, db.appearance
            if (pa is None) != (pb is None):
                return False
            if (
                pa is not None
                and pb is not None
                and (pa.dtype != pb.dtype or not np.array_equal(pa, pb))
            ):
                return False
    return True


def test_round_trip_is_exact() -> None:
    value = sample()
    back = decode(KEY, encode(KEY, value))
    assert same(back, value)
    assert [len(f) for f in back.detections] == [2, 0, 1]
    assert back.detections[0][1].appearance is not None
    assert back.detections[0][1].appearance.shape == (2, 2)
    assert back.detections[2][0].box3d is None and back.detections[2][0].appearance is None
    # Encoding is deterministic: the same detections give the same bytes.
    assert encode(KEY, value) == encode(KEY, back)
    empty = SequenceDetections((), (), {})
    assert same(decode(KEY, encode(KEY, empty)), empty)


def test_store_then_load(tmp_path: Path) -> None:
    cache = DetectionCache(tmp_path / "c")
    assert cache.load(KEY) is None  # absent: a plain miss, no warning
    cache.store(KEY, sample())
    assert cache.path(KEY) == tmp_path / "c" / "detections" / "ab" / f"{KEY}.det"
    loaded = cache.load(KEY)
    assert loaded is not None and same(loaded, sample())
    assert [p.name for p in cache.path(KEY).parent.iterdir()] == [f"{KEY}.det"]  # no temp left


def _payload_offset(blob: bytes) -> int:
    return blob.index(b"\n", blob.index(b"\n") + 1) + 1  # after the magic and the digest lines


def test_a_float_changed_on_disk_is_a_miss_with_a_warning(tmp_path: Path) -> None:
    cache = DetectionCache(tmp_path)
    cache.store(KEY, sample())
    path = cache.path(KEY)
    blob = path.read_bytes()
    # The case: a position moved by +3 m, same length on disk. x = 2.0 is stored as the
    # little-endian float64 00..00 40; 5.0 is 00..14 40: one byte differs.
    old, new = np.float64(2.0).tobytes(), np.float64(5.0).tobytes()
    assert blob.count(old) >= 1
    path.write_bytes(blob.replace(old, new, 1))
    with pytest.warns(UserWarning, match="checksum mismatch, recomputing"):
        assert cache.load(KEY) is None
    # A single flipped bit anywhere in the payload is caught the same way.
    flipped = bytearray(blob)
    flipped[_payload_offset(blob) + 100] ^= 0x01
    path.write_bytes(bytes(flipped))
    with pytest.warns(UserWarning, match="checksum mismatch"):
        assert cache.load(KEY) is None


@pytest.mark.parametrize(
    ("mangle", "reason"),
    [
        (lambda b: b[: len(b) // 2], "checksum mismatch"),  # truncated by a crash
        (lambda b: b"", "not a detection cache entry"),
        (lambda b: b"\x80\x04\x95 a pickle from format 1", "not a detection cache entry"),
        (lambda b: b.replace(b"detections 2", b"detections 9", 1), "not a detection cache entry"),
    ],
)
def test_damaged_entries_are_misses(tmp_path: Path, mangle: object, reason: str) -> None:
    cache = DetectionCache(tmp_path)
    cache.store(KEY, sample())
    path = cache.path(KEY)
    path.write_bytes(mangle(path.read_bytes()))  # type: ignore[operator]
    with pytest.warns(UserWarning, match=reason):
        assert cache.load(KEY) is None


@pytest.mark.parametrize(
    ("make", "reason"),
    [
        (os.mkfifo, "named pipe"),  # opening it would block for ever
        (lambda p: p.symlink_to("/dev/zero"), "device"),  # reading it would never end
        (lambda p: p.mkdir(), "folder"),
    ],
)
def test_an_entry_that_is_not_a_regular_file_is_never_opened_nor_replaced(
    tmp_path: Path, make: object, reason: str
) -> None:
    cache = DetectionCache(tmp_path)
    path = cache.path(KEY)
    path.parent.mkdir(parents=True)
    make(path)  # type: ignore[operator]
    with pytest.warns(UserWarning, match=f"{reason}.*recomputing .it is not replaced: remove it"):
        assert cache.load(KEY) is None
    before = os.lstat(path)
    cache.store(KEY, sample())  # left as it is: not a file we wrote
    after = os.lstat(path)
    assert (before.st_mode, before.st_ino) == (after.st_mode, after.st_ino)
    assert not cache.has(KEY)
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary file left


def test_an_entry_larger_than_the_bound_is_not_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cache = DetectionCache(tmp_path)
    cache.store(KEY, sample())
    monkeypatch.setattr("rgbd_eval.cache.MAX_ENTRY_BYTES", 100)
    with pytest.warns(UserWarning, match="more than the 100-byte limit, recomputing$"):
        assert cache.load(KEY) is None


def test_a_digest_memo_that_is_a_named_pipe_is_not_opened(tmp_path: Path) -> None:
    recording = tmp_path / "rec.mcap"
    recording.write_bytes(b"abc")
    cache = DetectionCache(tmp_path / "cache")
    memo = cache._memo(recording)
    memo.parent.mkdir(parents=True)
    os.mkfifo(memo)
    assert cache.known_digest(recording) is None
    assert cache.digest(recording) == hashlib.sha256(b"abc").hexdigest()
    assert os.path.exists(memo) and not memo.is_file()  # left alone


def test_checksummed_garbage_and_foreign_keys_are_misses(tmp_path: Path) -> None:
    cache = DetectionCache(tmp_path)
    blob = encode(KEY, sample())
    head = blob[: blob.index(b"\n") + 1]
    # A payload that is not an npz, with a matching checksum: unreadable, not a traceback.
    junk = b"\xff" * 64
    cache.path(KEY).parent.mkdir(parents=True)
    cache.path(KEY).write_bytes(head + hashlib.sha256(junk).hexdigest().encode() + b"\n" + junk)
    with pytest.warns(UserWarning, match="unreadable payload"):
        assert cache.load(KEY) is None
    # An intact entry renamed to another key is refused: the key is inside the checksum.
    other = "ab" + "1" * 62
    cache.path(other).write_bytes(blob)
    with pytest.warns(UserWarning, match="another key"):
        assert cache.load(other) is None
    # An npz whose arrays disagree in length.
    arrays = dict(np.load(io.BytesIO(blob[_payload_offset(blob) :])))
    arrays["per_frame"] = np.array([5, 0, 1])
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    payload = buf.getvalue()
    cache.path(KEY).write_bytes(
        head + hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload
    )
    with pytest.warns(UserWarning, match="inconsistent array shapes"):
        assert cache.load(KEY) is None


def test_cache_folder_that_is_a_file(tmp_path: Path) -> None:
    target = tmp_path / "cache"
    target.write_text("not a folder")
    with pytest.raises(CacheError, match="is a file, not a detection cache folder"):
        DetectionCache(target)
    # A file where the entry's sub-folder should be: a one-line CacheError on store.
    root = tmp_path / "ok"
    (root / "detections").mkdir(parents=True)
    (root / "detections" / "ab").write_text("in the way")
    with pytest.raises(CacheError, match="cannot write"):
        DetectionCache(root).store(KEY, sample())


def test_concurrent_writers_leave_one_complete_entry(tmp_path: Path) -> None:
    cache = DetectionCache(tmp_path)
    value = sample()
    threads = [threading.Thread(target=cache.store, args=(KEY, value)) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    loaded = cache.load(KEY)
    assert loaded is not None and same(loaded, value)
    assert len(list(cache.path(KEY).parent.iterdir())) == 1


def test_recording_digest_is_memoised_by_file_identity(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    recording = tmp_path / "rec.mcap"
    recording.write_bytes(b"abc")
    cache = DetectionCache(tmp_path / "cache")
    # sha256("abc"), the FIPS 180-2 example.
    abc = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    assert cache.digest(recording) == abc
    memos = list((tmp_path / "cache" / "digests").iterdir())
    assert len(memos) == 1 and memos[0].read_text() == abc + "\n"

    # A second call reads the memo, not the recording.
    def no_hashing(path: Path) -> str:
        raise AssertionError(f"{path} hashed again")

    monkeypatch.setattr("rgbd_eval.cache.file_digest", no_hashing)
    assert cache.digest(recording) == abc
    monkeypatch.undo()
    # Rewritten (size and ctime change): hashed again; sha256("abcd").
    recording.write_bytes(b"abcd")
    assert cache.digest(recording) == hashlib.sha256(b"abcd").hexdigest()
    # A memo that does not hold a digest is recomputed and rewritten.
    for memo in (tmp_path / "cache" / "digests").iterdir():
        memo.write_text("not a digest\n")
    assert cache.digest(recording) == hashlib.sha256(b"abcd").hexdigest()
    texts = {m.read_text() for m in (tmp_path / "cache" / "digests").iterdir()}
    # The memo of the old content ("abc") is still junk: nothing looked it up.
    assert texts == {"not a digest\n", hashlib.sha256(b"abcd").hexdigest() + "\n"}


def test_known_digest_reads_only_the_memo(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    recording = tmp_path / "rec.mcap"
    recording.write_bytes(b"abc")
    cache = DetectionCache(tmp_path / "cache")

    def no_hashing(path: Path) -> str:
        raise AssertionError(f"{path} hashed")

    monkeypatch.setattr("rgbd_eval.cache.file_digest", no_hashing)
    assert cache.known_digest(recording) is None  # no memo yet, and nothing hashed
    assert cache.known_digest(tmp_path / "missing.mcap") is None
    monkeypatch.undo()
    digest = cache.digest(recording)
    assert cache.known_digest(recording) == digest
    recording.write_bytes(b"abcd")  # other files now: the old memo does not apply
    assert cache.known_digest(recording) is None


def test_digest_of_a_missing_recording_is_an_os_error(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        DetectionCache(tmp_path / "cache").digest(tmp_path / "missing.mcap")


def test_key_follows_the_contents_of_files_the_detector_reads(tmp_path: Path) -> None:
    # A model replaced in place keeps its path; the cached detections of the old model
    # must not be reused, so the key hashes the file (and a byte-equal copy elsewhere
    # still differs by its path, which is part of the config).
    model = tmp_path / "person.onnx"
    model.write_bytes(b"model one")
    config = load_config(
        method="pinto2022",
        overrides=["detector.person.backend=onnx", f"detector.person.model={model}"],
    )
    first = detection_key("0" * 64, config)
    assert detection_key("0" * 64, config) == first  # deterministic
    model.write_bytes(b"model two")
    os.utime(model, ns=(1, 1))  # a new stat identity, as any rewrite gives
    second = detection_key("0" * 64, config)
    assert second != first
    model.write_bytes(b"model one")
    os.utime(model, ns=(2, 2))
    assert detection_key("0" * 64, config) == first  # the contents, not the history
