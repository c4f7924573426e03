"""satake2009: stereo multi-person tracking with distance templates and an odometry-aware EKF."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from rgbd_eval.plugins import (
    MethodSpec,
    PaperSpec,
    ReproduceOptions,
    ReproduceResult,
    register_method,
    register_paper,
)

register_method(
    MethodSpec(
        name="satake2009",
        detector="satake2009",
        tracker="satake2009",
        title="Multiple person tracking by a stereo camera on a mobile robot (Satake & Miura 2009)",
        seed="002",
        gating="metric",
        config_file="methods/satake2009.yaml",
        paper_file="papers/satake2009.yaml",
    )
)


def _reproduce(_recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    from rgbd_eval.experiments.satake2009 import run

    return run(options)


register_paper(
    PaperSpec(
        method="satake2009",
        title="seed 002 section 4: Fig. 8 as a closed loop (follow A while B and C cross), timing",
        scenarios=(),  # the closed loop renders its own frames: its path depends on the tracker
        run=_reproduce,
    )
)
