"""Errors of the package, each with a documented process exit code.

Every error the package raises on purpose derives from :class:`RgbdEvalError`;
third-party errors are re-raised as one of these with ``from err``. The CLI
catches only these and prints ``str(err)`` as one line.

Exit codes (also in README.md):

====  =====================================================================
0     success (scored, or nothing to score and the report says so)
1     ``compare``: a metric regressed beyond its tolerance
2     command-line usage error; ``compare``: unusable reports; an optional dependency
      missing (``run --rerun``, ``view``: the Rerun SDK)
3     bad input recording (missing, truncated, wrong content)
4     bad configuration (unknown key, wrong type, value out of range)
5     bad ground truth (missing, unreadable, contradictory)
6     the run could not be scored
7     an output cannot be written (not a folder, not writable, someone else's folder,
      no MP4 encoder for ``--video``, a detection cache folder that is a file)
8     the Dask cluster cannot be reached, or a task killed every worker it ran on
====  =====================================================================
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


class RgbdEvalError(Exception):
    """Base class. ``exit_code`` is what the CLI exits with."""

    exit_code: int = 1

    def __reduce__(self) -> tuple[Any, ...]:
        # Errors raised on a cluster worker are pickled back to the client; the subclasses'
        # own __init__ signatures would break the default (cls(*args)) reconstruction.
        return (_rebuild, (type(self), str(self), dict(self.__dict__)))


def _rebuild(cls: type[RgbdEvalError], message: str, state: dict[str, Any]) -> RgbdEvalError:
    err = cls.__new__(cls)
    Exception.__init__(err, message)
    err.__dict__.update(state)
    return err


class InputError(RgbdEvalError):
    """A recording cannot be read or does not hold what is expected."""

    exit_code = 3

    def __init__(self, path: Path | str, message: str, topic: str | None = None) -> None:
        self.path = Path(path)
        self.topic = topic
        where = f"{self.path}" + (f" [{topic}]" if topic else "")
        super().__init__(f"{where}: {message}")


class TopicError(InputError):
    """Topic detection failed (none, or several candidates)."""


class DecodeError(InputError):
    """A message could not be decoded (encoding, size, compression)."""


class SyncError(InputError):
    """Stamps cannot be synchronised (non-monotonic, nothing paired)."""


class TransformError(InputError):
    """The tf chain from the world frame to the camera is broken."""


class ExtraError(RgbdEvalError):
    """A feature needs an optional dependency (a pip extra) that is not installed."""

    exit_code = 2


class ConfigError(RgbdEvalError):
    """A configuration file or override is invalid."""

    exit_code = 4


class GroundTruthError(RgbdEvalError):
    """Ground truth is missing, unreadable or contradictory (``topic``: inside a recording)."""

    exit_code = 5

    def __init__(self, path: Path | str, message: str, topic: str | None = None) -> None:
        self.path = Path(path)
        self.topic = topic
        self.message = message
        where = f"{self.path}" + (f" [{topic}]" if topic else "")
        super().__init__(f"{where}: {message}")


class ScoringError(RgbdEvalError):
    """A run could not be scored."""

    exit_code = 6


class CompareInputError(RgbdEvalError):
    """Reports given to ``compare`` cannot be compared."""

    exit_code = 2


class OutputError(RgbdEvalError):
    """An output file or folder cannot be written (or would overwrite a user's files)."""

    exit_code = 7

    def __init__(self, path: Path | str, message: str) -> None:
        self.path = Path(path)
        super().__init__(f"{self.path}: {message}")


class ClusterError(RgbdEvalError):
    """The Dask scheduler cannot be reached, or a task lost every worker that ran it."""

    exit_code = 8


class TaskError(RgbdEvalError):
    """Tasks of a sweep failed; the exit code is that of the first failure in grid order."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code


class CacheError(OutputError):
    """The detection cache folder cannot be used (a file, not writable)."""
