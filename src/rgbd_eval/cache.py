"""On-disk cache of detections, keyed by recording content and detector config.

Detections are a pure function of (recording, io config, detector config: its
``name`` included), so a sweep over tracker parameters runs detection once per sequence.
Entries are pickles written atomically; a corrupt or foreign entry is a miss.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
from pathlib import Path

from rgbd_eval import __version__
from rgbd_eval.config import RunConfig
from rgbd_eval.pipeline import SequenceDetections

#: Bump when the Detection layout or the detector's behaviour changes incompatibly.
CACHE_FORMAT = 2


def default_cache_dir() -> Path:
    """``$RGBD_EVAL_CACHE`` or ``.cache/rgbd-eval`` under the working directory."""
    return Path(os.environ.get("RGBD_EVAL_CACHE", ".cache/rgbd-eval"))


def detection_key(recording_digest: str, config: RunConfig) -> str:
    """The cache key: what the detections depend on, and nothing else."""
    payload = {
        "format": CACHE_FORMAT,
        "tool": __version__,
        "recording": recording_digest,
        "io": config.io.model_dump(mode="json"),
        "detector": config.detector.model_dump(mode="json"),
    }
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


class DetectionCache:
    """Load and store :class:`SequenceDetections` by key."""

    def __init__(self, root: Path | None = None) -> None:
        self.root = Path(root) if root is not None else default_cache_dir()
        self.hits = 0
        self.misses = 0

    def _path(self, key: str) -> Path:
        return self.root / "detections" / f"{key}.pkl"

    def load(self, key: str) -> SequenceDetections | None:
        path = self._path(key)
        try:
            with path.open("rb") as handle:
                value = pickle.load(handle)
        except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError):
            self.misses += 1
            return None
        if not isinstance(value, SequenceDetections):
            self.misses += 1
            return None
        self.hits += 1
        return value

    def store(self, key: str, detections: SequenceDetections) -> None:
        path = self._path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
        with tmp.open("wb") as handle:
            pickle.dump(detections, handle, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, path)
