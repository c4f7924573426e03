"""Content-addressed on-disk cache of detections, safe to share between processes and machines.

Detections are a pure function of (recording, io config, detector config: its
``name`` included, and the contents of the files it names, such as a model), so
a sweep over tracker parameters runs detection once per sequence. The key is the
sha256 of exactly those inputs (:func:`detection_key`).

An entry is one file, ``detections/<key[:2]>/<key>.det``: a magic line, the
sha256 of the payload in hex, a newline, then the payload, an uncompressed
``.npz`` of flat arrays (no pickle, ``allow_pickle=False`` on read) whose
``meta`` member is UTF-8 JSON. Entries are written to a unique temporary file
beside the target and renamed into place, so concurrent writers of the same key
(two workers, two machines on a network filesystem) leave one complete entry.
An entry whose checksum, layout or key does not match is a miss: it is
recomputed and overwritten, with a warning; it is never trusted. Only regular files
are read, no larger than :data:`MAX_ENTRY_BYTES`, and only regular files are replaced:
a named pipe or a link to a device in the cache is a miss with a warning, left alone.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import io
import json
import os
import stat
import uuid
import warnings
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import __version__
from rgbd_eval.config import RunConfig
from rgbd_eval.errors import CacheError
from rgbd_eval.files import file_digest, read_bytes
from rgbd_eval.pipeline import SequenceDetections
from rgbd_eval.types import Box2D, Box3D, Detection

#: Bump when the Detection layout or the detector's behaviour changes incompatibly.
CACHE_FORMAT = 3  # 3: checksummed npz entries (1 and 2 were pickles)
_MAGIC = b"rgbd-eval detections 2\n"
_DIGEST_LEN = 64  # hex sha256
#: Largest entry read (4 GiB): a sequence's detections with appearance vectors take
#: tens of MB; a larger file is not one we wrote, and is not loaded into memory.
MAX_ENTRY_BYTES = 4 << 30


class CacheWarning(UserWarning):
    """A cache entry was unreadable or did not match its checksum, and is recomputed."""


def default_cache_dir() -> Path:
    """``$RGBD_EVAL_CACHE`` or ``.cache/rgbd-eval`` under the working directory."""
    return Path(os.environ.get("RGBD_EVAL_CACHE", ".cache/rgbd-eval"))


def _paths(value: object, where: str = "detector") -> Iterator[tuple[str, Path]]:
    """Every path-valued setting in a dumped config, with its dotted key."""
    if isinstance(value, Path):
        yield where, value
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _paths(v, f"{where}.{k}")
    elif isinstance(value, list | tuple):
        for i, v in enumerate(value):
            yield from _paths(v, f"{where}.{i}")


@functools.lru_cache(maxsize=64)
def _file_sha256(path: Path, size: int, mtime_ns: int, inode: int) -> str:
    """sha256 of a file the detector reads, memoised per process by its stat identity."""
    return file_digest(path)


def _detector_files(config: RunConfig) -> dict[str, str]:
    """sha256 of each file the detector's settings name (models, recorded detections).

    Detections depend on a model's contents, not on its path: a file replaced in place
    must not reuse the old entries. A path that does not name a readable file is left
    to the detector to refuse.
    """
    out: dict[str, str] = {}
    for key, path in _paths(config.detector.model_dump(mode="python")):
        try:
            st = path.stat()
            if stat.S_ISREG(st.st_mode):
                out[key] = _file_sha256(path.resolve(), st.st_size, st.st_mtime_ns, st.st_ino)
        except OSError:
            continue
    return out


def detector_inputs(config: RunConfig) -> str:
    """What detections depend on besides the recording, as canonical JSON."""
    payload = {
        "format": CACHE_FORMAT,
        "tool": __version__,
        "io": config.io.model_dump(mode="json"),
        "detector": config.detector.model_dump(mode="json"),
        "files": _detector_files(config),
    }
    return json.dumps(payload, sort_keys=True)


def detection_key(recording_digest: str, config: RunConfig) -> str:
    """The cache key: what the detections depend on, and nothing else."""
    payload = {**json.loads(detector_inputs(config)), "recording": recording_digest}
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


class _CorruptEntryError(Exception):
    """Internal: why an entry was rejected (becomes a warning and a miss)."""


def encode(key: str, value: SequenceDetections) -> bytes:
    """The entry file's bytes: magic, sha256 of the payload, payload (see the module docstring)."""
    dets = [d for frame in value.detections for d in frame]
    n = len(dets)
    apps = [None if d.appearance is None else np.asarray(d.appearance) for d in dets]
    ndim = max([1, *(a.ndim for a in apps if a is not None)])
    shapes = np.full((n, ndim), -1, dtype=np.int64)
    for i, a in enumerate(apps):
        if a is not None:
            shapes[i, : a.ndim] = a.shape
    flat = [a.astype(np.float32).ravel() for a in apps if a is not None]
    arrays: dict[str, NDArray[Any]] = {
        "stamps_ns": np.asarray(value.stamps_ns, dtype=np.int64),
        "per_frame": np.asarray([len(f) for f in value.detections], dtype=np.int64),
        "position": np.asarray([d.position for d in dets], dtype=np.float64).reshape(n, 3),
        "scalars": np.asarray(
            [(d.height, d.confidence, d.distance) for d in dets], dtype=np.float64
        ).reshape(n, 3),
        "box2d": np.asarray([d.box2d.as_tuple() for d in dets], dtype=np.float64).reshape(n, 4),
        "box3d": np.asarray(
            [
                (*d.box3d.min_corner, *d.box3d.max_corner) if d.box3d else (np.nan,) * 6
                for d in dets
            ],
            dtype=np.float64,
        ).reshape(n, 6),
        "flags": np.asarray(
            [(d.box3d is not None, d.occluded) for d in dets], dtype=np.bool_
        ).reshape(n, 2),
        "appearance_shape": shapes,
        "appearance": np.concatenate(flat) if flat else np.zeros(0, dtype=np.float32),
        "meta": np.frombuffer(
            json.dumps({"key": key, "seconds": value.seconds}, sort_keys=True).encode(),
            dtype=np.uint8,
        ),
    }
    buf = io.BytesIO()
    np.savez(buf, **arrays)  # type: ignore[arg-type]  # numpy's stub types **kwds too narrowly
    payload = buf.getvalue()
    return _MAGIC + hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload


def decode(key: str, blob: bytes) -> SequenceDetections:
    """Inverse of :func:`encode`; raises ``_CorruptEntryError`` on any mismatch."""
    head = len(_MAGIC) + _DIGEST_LEN + 1
    if len(blob) < head or not blob.startswith(_MAGIC) or blob[head - 1 : head] != b"\n":
        raise _CorruptEntryError("not a detection cache entry of this format")
    payload = blob[head:]
    if hashlib.sha256(payload).hexdigest().encode() != blob[len(_MAGIC) : head - 1]:
        raise _CorruptEntryError("checksum mismatch")
    try:
        with np.load(io.BytesIO(payload), allow_pickle=False) as npz:
            a = {name: npz[name] for name in npz.files}
        meta = json.loads(a["meta"].tobytes().decode("utf-8"))
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, UnicodeDecodeError) as err:
        raise _CorruptEntryError(f"unreadable payload ({type(err).__name__})") from err
    if not isinstance(meta, dict) or meta.get("key") != key:
        raise _CorruptEntryError("entry belongs to another key")
    return _unpack(a, meta)


def _unpack(a: dict[str, NDArray[Any]], meta: dict[str, Any]) -> SequenceDetections:
    per_frame = a["per_frame"]
    n = int(per_frame.sum()) if per_frame.size else 0
    shapes = a["appearance_shape"]
    sizes = [int(np.prod(s[s >= 0])) if s[0] >= 0 else 0 for s in shapes]
    expected = {
        "position": (n, 3),
        "scalars": (n, 3),
        "box2d": (n, 4),
        "box3d": (n, 6),
        "flags": (n, 2),
        "appearance": (sum(sizes),),
    }
    if (
        per_frame.shape != a["stamps_ns"].shape
        or (per_frame < 0).any()
        or shapes.ndim != 2
        or shapes.shape[0] != n
        or any(a[k].shape != shape for k, shape in expected.items())
        or not isinstance(meta.get("seconds"), dict)
    ):
        raise _CorruptEntryError("inconsistent array shapes")
    position, scalars, box2d = a["position"].tolist(), a["scalars"].tolist(), a["box2d"].tolist()
    box3d, flags, app = a["box3d"].tolist(), a["flags"].tolist(), a["appearance"]
    dets: list[Detection] = []
    offset = 0
    for i in range(n):
        shape = tuple(int(x) for x in shapes[i] if x >= 0)
        appearance = None
        if shapes[i][0] >= 0:
            appearance = app[offset : offset + sizes[i]].reshape(shape).copy()
            offset += sizes[i]
        height, confidence, distance = scalars[i]
        has_box3d, occluded = flags[i]
        dets.append(
            Detection(
                position=_xyz(position[i]),
                height=height,
                confidence=confidence,
                box2d=Box2D(*box2d[i]),
                box3d=Box3D(_xyz(box3d[i][:3]), _xyz(box3d[i][3:])) if has_box3d else None,
                distance=distance,
                occluded=bool(occluded),
                appearance=appearance,
            )
        )
    frames, start = [], 0
    for count in per_frame.tolist():
        frames.append(tuple(dets[start : start + count]))
        start += count
    return SequenceDetections(
        stamps_ns=tuple(a["stamps_ns"].tolist()),
        detections=tuple(frames),
        seconds={str(k): float(v) for k, v in meta["seconds"].items()},
    )


def _xyz(values: list[float]) -> tuple[float, float, float]:
    return (values[0], values[1], values[2])


def _stat_identity(path: Path) -> list[list[Any]]:
    """What identifies a recording's bytes without reading them: per file, its path,
    size, mtime_ns, ctime_ns, inode and device."""
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    out = []
    for f in files:
        st = f.stat()
        out.append([str(f), st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino, st.st_dev])
    return out


def _replaceable(path: Path) -> bool:
    """Whether ``path`` is absent or a regular file (not a link, pipe, device or folder)."""
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except (FileNotFoundError, NotADirectoryError):  # absent (writing it may still fail)
        return True
    except OSError:
        return False


class DetectionCache:
    """Load and store :class:`SequenceDetections` by key under ``root``."""

    def __init__(self, root: Path | None = None) -> None:
        self.root = Path(root) if root is not None else default_cache_dir()
        if self.root.exists() and not self.root.is_dir():
            raise CacheError(self.root, "is a file, not a detection cache folder")

    def _memo(self, recording: Path) -> Path:
        """Where the digest of ``recording``'s current files is memoised; OSError if unreadable."""
        identity = json.dumps(_stat_identity(recording.resolve())).encode()
        return self.root / "digests" / f"{hashlib.sha256(identity).hexdigest()}.sha256"

    @staticmethod
    def _read_memo(memo: Path) -> str | None:
        """The digest a memo holds, or None when it is missing or does not hold one (a memo
        that is not a small regular file is not opened)."""
        with contextlib.suppress(CacheError, UnicodeDecodeError):
            text = read_bytes(memo, lambda m: CacheError(memo, m), "memo", 256).decode("ascii")
            if len(text.strip()) == _DIGEST_LEN and all(
                c in "0123456789abcdef" for c in text.strip()
            ):
                return text.strip()
        return None

    def known_digest(self, recording: Path) -> str | None:
        """The memoised digest of ``recording`` (see :meth:`digest`), or None when there is
        no valid memo for its current files; never reads the recording itself."""
        try:
            memo = self._memo(recording)
        except OSError:
            return None
        return self._read_memo(memo)

    def digest(self, recording: Path) -> str:
        """The recording's :func:`~rgbd_eval.files.file_digest`, memoised under ``digests/``
        by the files' (path, size, mtime_ns, ctime_ns, inode, device): a warm sweep does
        not read every recording again. A memo that does not parse is recomputed; OSError
        when the recording cannot be read."""
        recording = recording.resolve()
        memo = self._memo(recording)
        known = self._read_memo(memo)
        if known is not None:
            return known
        digest = file_digest(recording)
        if not _replaceable(memo):
            return digest
        tmp = memo.with_name(f".{memo.name}.tmp-{os.getpid()}-{uuid.uuid4().hex[:8]}")
        try:  # a memo that cannot be written costs a re-hash next time, nothing else
            memo.parent.mkdir(parents=True, exist_ok=True)
            tmp.write_text(digest + "\n", encoding="ascii")
            os.replace(tmp, memo)
        except OSError:
            with contextlib.suppress(OSError):
                tmp.unlink()
        return digest

    def path(self, key: str) -> Path:
        """Where the entry of ``key`` lives."""
        return self.root / "detections" / key[:2] / f"{key}.det"

    def has(self, key: str) -> bool:
        """Whether an entry of ``key`` is present (not checked: :meth:`load` verifies)."""
        return self.path(key).is_file()

    def load(self, key: str) -> SequenceDetections | None:
        """The entry of ``key``; None when absent or rejected (a rejection warns).

        Only a regular file of at most :data:`MAX_ENTRY_BYTES` is opened: a named pipe
        would block, a link to ``/dev/zero`` never end.
        """
        path = self.path(key)
        if not os.path.lexists(path):
            return None
        try:
            blob = read_bytes(path, lambda m: CacheError(path, m), "it", MAX_ENTRY_BYTES)
        except CacheError as err:
            if not os.path.lexists(path):  # removed meanwhile
                return None
            kept = "" if _replaceable(path) else " (it is not replaced: remove it)"
            warnings.warn(
                f"detection cache entry {path}: {str(err).removeprefix(f'{path}: ')}, "
                f"recomputing{kept}",
                CacheWarning,
                stacklevel=2,
            )
            return None
        try:
            return decode(key, blob)
        except _CorruptEntryError as bad:
            warnings.warn(
                f"detection cache entry {path}: {bad}, recomputing", CacheWarning, stacklevel=2
            )
            return None

    def store(self, key: str, detections: SequenceDetections) -> None:
        """Write the entry of ``key`` atomically (unique temporary file, then rename); an
        entry path that holds anything but a regular file is left as it is (not stored)."""
        path = self.path(key)
        if not _replaceable(path):
            return
        tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}-{uuid.uuid4().hex[:8]}")
        blob = encode(key, detections)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp.write_bytes(blob)
            os.replace(tmp, path)
        except OSError as err:
            with contextlib.suppress(OSError):
                tmp.unlink()
            raise CacheError(
                path, f"cannot write this detection cache entry ({err.strerror or err})"
            ) from err
