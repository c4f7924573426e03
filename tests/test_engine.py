"""The --cluster option and connecting to a cluster."""

from __future__ import annotations

import pytest

from rgbd_eval.engine import ClusterSpec, connect, map_ordered, parse_cluster, usable_cpus
from rgbd_eval.errors import ClusterError, ConfigError, InputError


def test_parse_cluster() -> None:
    assert parse_cluster("local:3") == ClusterSpec(None, 3)
    assert parse_cluster(None) == ClusterSpec(None, usable_cpus())
    # Plain `local` never starts more workers than there are tasks.
    assert parse_cluster("local", tasks=1) == ClusterSpec(None, 1)
    assert parse_cluster("tcp://10.0.0.5:8786") == ClusterSpec("tcp://10.0.0.5:8786", 0)
    for bad, why in [
        ("local:0", "at least 1"),
        ("local:two", "whole number"),
        ("remote", "expected local"),
        ("http://host:8786", "expected local"),
        ("tcp://", "expected local"),
    ]:
        with pytest.raises(ConfigError, match=why):
            parse_cluster(bad)


def test_unreachable_scheduler_is_a_one_line_cluster_error() -> None:
    # Port 9 (discard) on the loopback: nothing listens, the connection is refused.
    with (
        pytest.raises(ClusterError, match=r"cannot reach the scheduler at tcp://127.0.0.1:9"),
        connect(parse_cluster("tcp://127.0.0.1:9"), timeout_s=1.0),
    ):
        pass


def _half(x: int) -> int:
    if x % 2:
        raise InputError(f"in{x}", "odd")
    return x // 2


def test_map_ordered_keeps_input_order_and_reraises_the_first_error() -> None:
    seen: list[tuple[int, int]] = []
    with connect(ClusterSpec(None, 1)) as client:
        assert map_ordered(client, _half, [(8,), (2,), (6,)], lambda d, n: seen.append((d, n))) == [
            4,
            1,
            3,
        ]
        assert seen == [(1, 3), (2, 3), (3, 3)]
        with pytest.raises(InputError, match="in3: odd"):
            map_ordered(client, _half, [(2,), (3,), (5,)])


def test_every_error_survives_the_trip_back_from_a_worker() -> None:
    import pickle

    from rgbd_eval import errors

    made = [
        errors.InputError("a.bag", "truncated", topic="/rgb"),
        errors.TopicError("a.bag", "no depth topic"),
        errors.GroundTruthError("a.gt.csv", "short row"),
        errors.TaskError("2 of 6 sweep point(s) failed", 3),
        errors.CacheError("c", "is a file, not a detection cache folder"),
        errors.ClusterError("cannot reach the scheduler"),
        errors.ScoringError("nothing to score"),
    ]
    for err in made:
        back = pickle.loads(pickle.dumps(err))
        assert type(back) is type(err)
        assert (str(back), back.exit_code, back.__dict__) == (str(err), err.exit_code, err.__dict__)
    assert pickle.loads(pickle.dumps(made[0])).topic == "/rgb"


@pytest.mark.parametrize(
    ("address", "reason"),
    [("ucx://127.0.0.1:1", "cannot connect over ucx://"), ("tls://127.0.0.1:1", "certificates")],
)
def test_a_transport_dask_cannot_use_here_is_refused_before_connecting(
    address: str, reason: str
) -> None:
    # Dask fails on these only inside its client, then waits 40 s to close it (issue 28).
    from distributed.comm.registry import get_backend

    if address.startswith("ucx"):
        try:
            get_backend("ucx").get_connector()
            pytest.skip("this installation has a UCX package")
        except TypeError:
            pass
    with pytest.raises(ClusterError, match=reason):
        parse_cluster(address)
