"""Summable counts, the derived ratios, and their JSON round trip."""

from __future__ import annotations

import json
from dataclasses import fields, replace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rgbd_eval.config import Convention, Gating
from rgbd_eval.metrics.counts import COUNTS_SCHEMA, Counts, summarize, total


def _example() -> Counts:
    # 100 GT instances of 4 GT tracks: 90 matched (2 of them id switches), 10 missed;
    # 95 track instances: 90 matched, 5 false positives.
    return Counts(
        gating=Gating.IOU,
        threshold=0.5,
        num_frames=40,
        num_gt=100,
        num_tracks=95,
        num_matches=90,
        fp=5,
        fn=10,
        id_switches=2,
        fragmentations=3,
        similarity_sum=72.0,
        num_gt_tracks=4,
        mostly_tracked=2,
        partly_tracked=1,
        mostly_lost=1,
        main_tr_matches=80,
        idtp=70,
        idfp=25,
        idfn=30,
        recall_errors=1,
        ignored_gt=6,
        ignored_tracks=2,
    )


def test_summary_hand_computed() -> None:
    s = summarize(_example())
    assert s["mota"] == pytest.approx(1 - (10 + 5 + 2) / 100)  # eq. 7.1: 0.83
    assert s["motp"] == pytest.approx(72.0 / 90)  # mean IoU of matches: 0.8
    assert s["fp_rate"] == pytest.approx(0.05)
    assert s["fn_rate"] == pytest.approx(0.10)
    assert s["id_switch_rate"] == pytest.approx(0.02)
    assert s["main_tr"] == pytest.approx(0.80)  # 80 / 100
    assert s["all_tr"] == pytest.approx(0.90)  # 90 / 100 = 1 - FN%
    assert s["precision"] == pytest.approx(90 / 95)
    assert s["idf1"] == pytest.approx(140 / (140 + 25 + 30))  # 2 IDTP / (2 IDTP + IDFP + IDFN)
    assert s["idp"] == pytest.approx(70 / 95)
    assert s["idr"] == pytest.approx(70 / 100)
    assert (s["mt"], s["pt"], s["ml"]) == (2, 1, 1)
    assert s["mt_rate"] == pytest.approx(0.5)
    assert (s["id_switches"], s["recall_errors"], s["fragmentations"]) == (2, 1, 3)
    assert (s["num_gt"], s["num_matches"], s["fp"], s["fn"]) == (100, 90, 5, 10)
    assert (s["ignored_gt"], s["ignored_tracks"]) == (6, 2)


def test_metric_motp_is_mean_distance() -> None:
    c = replace(_example(), gating=Gating.METRIC, threshold=1.0, similarity_sum=18.0)
    assert summarize(c)["motp"] == pytest.approx(0.2)  # 18 m over 90 matches


def test_empty_counts_give_none_ratios() -> None:
    s = summarize(Counts.empty(Gating.IOU, 0.5))
    for key in ("mota", "motp", "fp_rate", "fn_rate", "main_tr", "all_tr", "idf1", "mt_rate"):
        assert s[key] is None, key
    assert s["num_gt"] == 0
    assert s["fp"] == 0


def test_summary_values_are_json_scalars() -> None:
    s = summarize(_example())
    assert all(v is None or type(v) in (int, float) for v in s.values())
    assert json.loads(json.dumps(s)) == s


def test_addition_sums_every_count() -> None:
    a = _example()
    b = replace(a, num_frames=1)
    c = a + b
    for f in fields(Counts):
        if f.name in ("gating", "threshold", "convention"):
            assert getattr(c, f.name) == getattr(a, f.name)
        else:
            assert getattr(c, f.name) == getattr(a, f.name) + getattr(b, f.name)
    assert total([a, b]) == c
    assert sum([a, b]) == c  # the built-in sum starts from 0
    assert total([a]) == a
    assert a + Counts.empty(Gating.IOU, 0.5) == a


def test_adding_differently_gated_counts_raises() -> None:
    with pytest.raises(ValueError, match="gating=metric"):
        _ = _example() + Counts.empty(Gating.METRIC, 1.0)
    with pytest.raises(ValueError, match=r"threshold=0\.3"):
        _ = _example() + Counts.empty(Gating.IOU, 0.3)
    with pytest.raises(ValueError, match="convention=motmetrics"):
        _ = _example() + Counts.empty(Gating.IOU, 0.5, Convention.MOTMETRICS)
    with pytest.raises(ValueError, match="must not be empty"):
        total([])


def test_json_round_trip() -> None:
    c = _example()
    data = json.loads(json.dumps(c.to_dict()))
    assert data["schema"] == COUNTS_SCHEMA
    assert data["gating"] == "iou"
    assert Counts.from_dict(data) == c


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"fp": -1}, "fp=-1 must be a non-negative integer"),
        ({"fp": 1.5}, "fp=1.5 must be a non-negative integer"),
        ({"fp": True}, "fp=True"),
        ({"gating": "box"}, "gating='box'"),
        ({"schema": 99}, "schema=99"),
        ({"threshold": "0.5"}, "threshold='0.5' must be a number"),
        ({"threshold": 2.0}, r"threshold=2.0 for IoU gating must be in \(0, 1\]"),
        ({"fn": 11}, "num_matches \\+ fn == num_gt"),
        ({"unexpected": 1}, "unknown keys \\['unexpected'\\]"),
    ],
)
def test_from_dict_rejects_bad_data(change: dict[str, object], message: str) -> None:
    data: dict[str, object] = dict(_example().to_dict())
    data.update(change)
    with pytest.raises(ValueError, match=message):
        Counts.from_dict(data)


def test_from_dict_rejects_missing_key() -> None:
    data: dict[str, object] = dict(_example().to_dict())
    del data["idtp"]
    with pytest.raises(ValueError, match="missing keys \\['idtp'\\]"):
        Counts.from_dict(data)


def test_inconsistent_counts_are_rejected() -> None:
    with pytest.raises(ValueError, match="recall_errors <= id_switches"):
        replace(_example(), recall_errors=3)
    with pytest.raises(ValueError, match="similarity_sum <= num_matches"):
        replace(_example(), similarity_sum=90.5)  # mean IoU above 1


@st.composite
def counts(draw: st.DrawFn) -> Counts:
    """Random consistent counts."""
    n = st.integers(0, 50)
    matches, fp, fn = draw(n), draw(n), draw(n)
    switches = draw(st.integers(0, matches))
    idtp = draw(st.integers(0, matches))
    tracks = draw(st.integers(0, min(matches + fn, 20)))
    mt = draw(st.integers(0, tracks))
    pt = draw(st.integers(0, tracks - mt))
    return Counts(
        gating=Gating.IOU,
        threshold=0.5,
        num_frames=draw(n),
        num_gt=matches + fn,
        num_tracks=matches + fp,
        num_matches=matches,
        fp=fp,
        fn=fn,
        id_switches=switches,
        fragmentations=draw(st.integers(0, matches + fn)),
        similarity_sum=draw(st.floats(0, 1)) * matches,
        num_gt_tracks=tracks,
        mostly_tracked=mt,
        partly_tracked=pt,
        mostly_lost=tracks - mt - pt,
        main_tr_matches=draw(st.integers(0, matches)),
        idtp=idtp,
        idfp=matches + fp - idtp,
        idfn=matches + fn - idtp,
        recall_errors=draw(st.integers(0, switches)),
        ignored_gt=draw(n),
        ignored_tracks=draw(n),
    )


@given(st.lists(counts(), min_size=1, max_size=4))
def test_sum_then_derive(items: list[Counts]) -> None:
    c = total(items)
    assert Counts.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    s = summarize(c)
    gt = sum(i.num_gt for i in items)
    assert s["num_gt"] == gt
    if gt:
        errors = sum(i.fn + i.fp + i.id_switches for i in items)
        assert s["mota"] == pytest.approx(1 - errors / gt)
        mota = s["mota"]
        assert isinstance(mota, float)
        assert mota <= 1.0
        assert s["all_tr"] == pytest.approx(1 - s["fn_rate"])  # type: ignore[operator]
        assert s["main_tr"] <= s["all_tr"]  # type: ignore[operator]
    else:
        assert s["mota"] is None
