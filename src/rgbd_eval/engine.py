"""The execution engine: a Dask cluster, local worker processes or a remote scheduler.

``--cluster local`` (one worker per usable CPU), ``local:N`` or
``tcp://host:8786``. ``local:1`` runs its single worker as a thread of this
process (no process start-up, no copies), through the same client calls as
every other cluster. Workers run one task at a time (one thread each): the
work is CPU-bound Python and numpy. A worker that dies mid-task has its task
retried on another worker by the scheduler; the tasks are pure, so a retry
gives the same result.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rgbd_eval.errors import ClusterError, ConfigError, RgbdEvalError

if TYPE_CHECKING:
    from distributed import Client

#: How long to wait for a remote scheduler and for its first worker.
CONNECT_TIMEOUT_S = 20.0


@dataclass(frozen=True)
class ClusterSpec:
    """Where tasks run: ``address`` of a scheduler, or a local cluster of ``workers``."""

    address: str | None
    workers: int

    def describe(self) -> str:
        if self.address is not None:
            return self.address
        return f"local cluster, {self.workers} worker{'s' if self.workers != 1 else ''}"


def usable_cpus() -> int:
    """CPUs this process may run on (its affinity mask), at least 1."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def parse_cluster(spec: str | None, tasks: int | None = None) -> ClusterSpec:
    """``local``, ``local:N`` or ``tcp://host:port`` -> ClusterSpec.

    Plain ``local`` starts one worker per usable CPU, but no more than ``tasks``.
    """
    text = (spec or "local").strip()
    if "://" in text:
        scheme, _, rest = text.partition("://")
        if scheme not in ("tcp", "tls", "ucx", "ws", "wss") or not rest:
            raise ConfigError(f"--cluster {text!r}: expected local, local:N or tcp://host:port")
        check_transport(text)
        return ClusterSpec(text, 0)
    name, sep, count = text.partition(":")
    if name != "local":
        raise ConfigError(f"--cluster {text!r}: expected local, local:N or tcp://host:port")
    if not sep:
        workers = usable_cpus()
        return ClusterSpec(None, max(1, min(workers, tasks)) if tasks else workers)
    try:
        workers = int(count)
    except ValueError:
        raise ConfigError(f"--cluster {text!r}: N in local:N must be a whole number") from None
    if workers < 1:
        raise ConfigError(f"--cluster {text!r}: N in local:N must be at least 1")
    return ClusterSpec(None, workers)


def check_transport(address: str) -> None:
    """ClusterError unless Dask can open a connection of ``address``'s kind from here.

    Checked before any work, without connecting: ``ucx://`` needs a UCX package this
    installation may lack, ``tls://`` and ``wss://`` need certificates in Dask's
    configuration. (Dask fails on either only inside its client, and then waits 40 s to
    close the half-made client.)
    """
    from distributed.comm.registry import get_backend
    from distributed.security import Security

    scheme = address.partition("://")[0]
    try:
        get_backend(scheme).get_connector()
    except (ValueError, TypeError, ImportError, RuntimeError) as err:
        raise ClusterError(
            f"--cluster {address}: this installation of Dask cannot connect over {scheme}:// "
            f"({' '.join(str(err).split())})"
        ) from err
    if (
        scheme in ("tls", "wss")
        and Security().get_connection_args("client").get("ssl_context") is None
    ):
        raise ClusterError(
            f"--cluster {address}: {scheme}:// needs TLS certificates in Dask's configuration "
            "(distributed.comm.tls.ca-file, .client.cert and .client.key)"
        )


@contextmanager
def connect(
    spec: ClusterSpec,
    timeout_s: float = CONNECT_TIMEOUT_S,
    warm_up: Callable[[], None] | None = None,
) -> Iterator[Client]:
    """A client of the cluster ``spec``; a local cluster is started and shut down with it.

    A remote scheduler must answer, and have a worker, within ``timeout_s``. ``warm_up``
    runs in every new worker process of a local cluster while it starts (e.g.
    :func:`rgbd_eval.sweep.warm_up`: it imports the task code and the methods there, all
    workers at once, rather than in each worker's first task).
    """
    import dask
    from distributed import Client

    if spec.address is not None:
        check_transport(spec.address)
        try:
            client = Client(spec.address, timeout=timeout_s, set_as_default=False)
        except (OSError, TimeoutError, TypeError, ValueError) as err:
            raise ClusterError(f"cannot reach the scheduler at {spec.address}: {err}") from err
        try:
            client.wait_for_workers(1, timeout=timeout_s)
        except (OSError, TimeoutError) as err:
            client.close()
            raise ClusterError(
                f"the scheduler at {spec.address} has no worker after {timeout_s:g} s"
            ) from err
        with client:
            yield client
        return
    # No dashboard here, so no use for the workers' statistical profiler, which samples the
    # running task's stack every 10 ms (measured: 0.40 -> 0.36 CPU s per tracking task), nor
    # for the event-loop health check every 20 ms and the system monitor every 0.5 s in
    # every worker and in the scheduler's process: on 2 cores they took 1.3-1.8 CPU s of a
    # 7 s sweep on local:2, 1.0-1.1 s at 1 s and 5 s. (A blocked loop is still reported after
    # 3 s; the workers' memory limits have their own 0.1 s monitor.)
    settings: dict[str, object] = {
        "distributed.worker.profile.enabled": False,
        "distributed.admin.tick.interval": "1s",
        "distributed.admin.system-monitor.interval": "5s",
        "distributed.nanny.pre-spawn-environ": worker_environ(
            dask.config.get("distributed.nanny.pre-spawn-environ", {})
        ),
    }
    with dask.config.set(settings):
        yield from _local(spec, warm_up)


def worker_environ(environ: Mapping[str, object]) -> dict[str, object]:
    """Dask's environment for new worker processes, less ``MALLOC_TRIM_THRESHOLD_``.

    Dask sets it (to 65536) to hand freed memory back to the system sooner, but setting
    it turns off glibc's dynamic mmap threshold, so every array over 128 KB (a depth
    image, a point cloud, a voxel grid: every frame makes several) is mapped and
    page-faulted afresh. Detecting 300 frames of moving_complex took 3.87-4.00 CPU s
    with it, 3.05-3.19 s without (+26%). The thread limits (``OMP_NUM_THREADS``...) stay.
    """
    return {k: v for k, v in environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}


def _local(spec: ClusterSpec, warm_up: Callable[[], None] | None) -> Iterator[Client]:
    from distributed import Client, LocalCluster

    try:
        cluster = LocalCluster(
            n_workers=spec.workers,
            threads_per_worker=1,
            processes=spec.workers > 1,
            dashboard_address=":0",  # a free port: several clusters may run on one machine
            silence_logs=logging.ERROR,
        )
    except (OSError, RuntimeError) as err:  # RuntimeError: "Nanny failed to start."
        raise ClusterError(f"cannot start a {spec.describe()}: {err}") from err
    with cluster, Client(cluster, set_as_default=False) as client:
        if spec.workers > 1 and warm_up is not None:
            client.run(warm_up)
        yield client


def map_ordered(
    client: Client,
    func: Callable[..., Any],
    args: Sequence[tuple[Any, ...]],
    progress: Callable[[int, int], None] | None = None,
) -> list[Any]:
    """``[func(*a) for a in args]`` on the cluster, in input order; ``progress(done, total)``
    is called as tasks complete. The first failing task (in input order) re-raises its error.

    The package's own errors come back as values (:class:`_Raised`): a task that raised
    would have its worker log a "Compute Failed" block with a traceback on stderr, before
    our one error line.
    """
    from distributed import KilledWorker, as_completed

    futures = [client.submit(_returning_errors, func, *a, pure=False) for a in args]
    try:
        for done, _ in enumerate(as_completed(futures, loop=client.loop), start=1):
            if progress is not None:
                progress(done, len(futures))
        results = [f.result() for f in futures]
    except KilledWorker as err:
        raise ClusterError(killed_worker_message(err)) from err
    finally:
        client.cancel(futures)
    for result in results:
        if isinstance(result, _Raised):
            raise result.error
    return results


@dataclass(frozen=True)
class _Raised:
    """What a task of :func:`map_ordered` raised, returned to the client."""

    error: RgbdEvalError


def _returning_errors(func: Callable[..., Any], *args: Any) -> Any:
    try:
        return func(*args)
    except RgbdEvalError as err:
        return _Raised(err)


def killed_worker_message(err: BaseException) -> str:
    """One line for a task that lost every worker it ran on (``distributed.KilledWorker``)."""
    return f"a worker died each time it ran this task (out of memory?): {err}"
