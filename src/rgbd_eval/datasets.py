"""Named datasets: the synthetic thesis scenarios and the demo, by name or path."""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.config import repo_root
from rgbd_eval.errors import InputError


def datasets_dir() -> Path:
    return repo_root() / "datasets"


def scenarios_dir() -> Path:
    return repo_root() / "configs" / "scenarios"


def known_names() -> list[str]:
    """Names accepted by ``--dataset``: scenario file stems, also as ``thesis-<stem with ->``."""
    return sorted(p.stem for p in scenarios_dir().glob("*.yaml"))


def resolve(name_or_path: str) -> Path:
    """A path as is; a name (``moving_complex`` or ``thesis-moving-complex``) under ``datasets/``."""
    path = Path(name_or_path)
    if path.exists():
        return path
    stem = name_or_path.removeprefix("thesis-").replace("-", "_")
    if stem in known_names():
        candidate = datasets_dir() / f"{stem}.mcap"
        if candidate.exists():
            return candidate
        raise InputError(
            candidate, f"dataset {name_or_path!r} is not generated yet; run `make datasets`"
        )
    known = ", ".join(known_names()) or "none"
    raise InputError(path, f"no such file, and not a dataset name (known: {known})")
