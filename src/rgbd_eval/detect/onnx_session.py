"""Opening ONNX model files with onnxruntime on the CPU, with the package's own errors."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rgbd_eval.errors import ConfigError

#: Where the models shipped with the package live (see models/README.md).
MODELS_DIR = Path(__file__).resolve().parents[1] / "models"


def builtin_model(name: str) -> Path:
    """Path of a model file shipped with the package; :class:`ConfigError` if it is missing."""
    path = MODELS_DIR / name
    if not path.is_file():
        raise ConfigError(f"built-in model {name} is missing from {MODELS_DIR}")
    return path


#: onnxruntime's own exception classes (they derive from Exception directly).
_ORT_ERROR_NAMES = (
    "Fail",
    "InvalidArgument",
    "NoSuchFile",
    "NoModel",
    "EngineError",
    "RuntimeException",
    "InvalidProtobuf",
    "ModelLoaded",
    "NotImplemented",
    "InvalidGraph",
    "EPFail",
)


def onnxruntime_errors() -> tuple[type[BaseException], ...]:
    """The exception classes onnxruntime raises on bad models and failed runs."""
    from onnxruntime.capi import onnxruntime_pybind11_state as state

    found = [getattr(state, name, None) for name in _ORT_ERROR_NAMES]
    return (RuntimeError, ValueError, *(c for c in found if isinstance(c, type)))


def open_session(path: Path, threads: int = 1) -> Any:
    """An onnxruntime CPU session for ``path`` using ``threads`` intra-op threads.

    Returns ``onnxruntime.InferenceSession`` (typed ``Any``: onnxruntime ships no stubs).
    """
    import onnxruntime as ort

    if threads < 1:
        raise ConfigError(f"onnx threads={threads} must be >= 1")
    if not path.is_file():
        raise ConfigError(f"model file {path} does not exist")
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads
    options.inter_op_num_threads = 1
    options.log_severity_level = 3
    try:
        return ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
    except onnxruntime_errors() as err:
        raise ConfigError(f"model file {path} cannot be loaded: {err}".splitlines()[0]) from err
