"""Named datasets: the synthetic thesis scenarios and the demo, by name or path."""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.config import config_dir, data_home
from rgbd_eval.errors import InputError


def datasets_dir() -> Path:
    return data_home()


def scenarios_dir() -> Path:
    return config_dir() / "scenarios"


def known_names() -> list[str]:
    """Names accepted by ``--dataset``: scenario file stems, also as ``thesis-<stem with ->``."""
    return sorted(p.stem for p in scenarios_dir().glob("*.yaml"))


def scenario_name(name_or_path: str) -> str:
    """``thesis-moving-complex`` -> ``moving_complex``; other names unchanged."""
    return name_or_path.removeprefix("thesis-").replace("-", "_")


def dataset_folder(name: str) -> Path:
    """The demo lives in ``datasets/``, the thesis scenarios in ``datasets/generated/``."""
    return datasets_dir() if name == "demo" else datasets_dir() / "generated"


def resolve(name_or_path: str) -> Path:
    """A path as is; a name (``moving_complex`` or ``thesis-moving-complex``) under ``datasets/``."""
    path = Path(name_or_path)
    if path.exists():
        return path
    stem = scenario_name(name_or_path)
    if stem in known_names():
        folder = dataset_folder(stem)
        for suffix in (".mcap", ".bag"):
            if (folder / f"{stem}{suffix}").exists():
                return folder / f"{stem}{suffix}"
        raise InputError(
            folder / f"{stem}.mcap",
            f"dataset {name_or_path!r} is not generated yet; run `make datasets`",
        )
    known = ", ".join(known_names()) or "none"
    raise InputError(path, f"no such file, and not a dataset name (known: {known})")
