"""cielniak2010: thermal + colour people tracking on a mobile robot (seed 004)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.plugins import (
    MethodSpec,
    PaperSpec,
    ReproduceOptions,
    ReproduceResult,
    register_method,
    register_paper,
)

#: Section 7's stand-ins: corridor following, a stationary robot with crossings (~13%
#: occluded), the same in darkness (configs/scenarios/cielniak2010/), and main's scene.
SCENARIOS = ("thermal_corridor", "thermal_crossings", "thermal_darkness")

register_method(
    MethodSpec(
        name="cielniak2010",
        detector="cielniak2010",
        tracker="cielniak2010",
        title=(
            "Data association and occlusion handling for vision-based people tracking "
            "by mobile robots (Cielniak, Duckett, Lilienthal 2010)"
        ),
        seed="004",
        gating="iou",
        config_file="methods/cielniak2010.yaml",
        paper_file="papers/cielniak2010.yaml",
    )
)


def _run(recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    from rgbd_eval.experiments.cielniak2010 import run

    return run(recordings, options)


register_paper(
    PaperSpec(
        method="cielniak2010",
        title="seed 004 section 7: tracker ablation, occlusion classifier per feature group",
        scenarios=(
            *(str(scenarios_dir() / "cielniak2010" / f"{n}.yaml") for n in SCENARIOS),
            "thermal_stationary",
        ),
        run=_run,
    )
)
