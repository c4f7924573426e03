"""Where a reproduction's CPU went: generating recordings, rendering inside, the method."""

from __future__ import annotations

from rgbd_eval.cli.reproduce_cmd import cpu_summary


def test_rendering_inside_the_experiments_counts_as_rendering() -> None:
    # 10 s generating + 50 s of experiments = 60 s; the experiments rendered 20 s of their
    # own (closed loops, camera layouts): rendering 10 + 20 = 30 s, the method 50 - 20 = 30 s.
    line = cpu_summary(10.0, 50.0, {"cpu_s": {"render": 20.0, "method": 30.0}})
    assert line.startswith("CPU time: 60 s, of which rendering 30 s and the experiments 30 s")


def test_experiments_that_render_nothing() -> None:
    # No cpu_s in the data: all of the experiments' time is the method's.
    line = cpu_summary(4.0, 6.0, {"tables": {}})
    assert line.startswith("CPU time: 10 s, of which rendering 4 s and the experiments 6 s")


def test_recordings_rendered_at_other_seeds_count_as_rendering() -> None:
    # 10 s generating + 50 s of experiments, of which 15 s rendered recordings at other
    # scenario seeds and 5 s the paper's own rendering: rendering 10 + 15 + 5 = 30 s,
    # the method 50 - 20 = 30 s.
    line = cpu_summary(10.0, 50.0, {"cpu_s": {"render": 5.0}}, seeded_s=15.0)
    assert line.startswith("CPU time: 60 s, of which rendering 30 s and the experiments 30 s")
