"""pinto2022: Re-ID based multi-people 3D tracker for service robots (seed 001)."""

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

#: The dataset scenarios of Table I (seed 001, IV-B), in its order, and the held-out test (V-D).
DATASET = (
    "still",
    "moving_head",
    "moving_base",
    "chairs",
    "people_following",
    "changing_clothes_1",
    "changing_clothes_2",
)
TEST = "test_sequence"

register_method(
    MethodSpec(
        name="pinto2022",
        detector="pinto2022",
        tracker="pinto2022",
        title="Re-ID based multi-people 3D tracker for service robots (Pinto et al., 2022)",
        seed="001",
        gating="metric",
        config_file="methods/pinto2022.yaml",
        paper_file="papers/pinto2022.yaml",
    )
)


def _scenario(name: str) -> str:
    return str(scenarios_dir() / "pinto2022" / f"{name}.yaml")


def _run(recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    from rgbd_eval.experiments.pinto2022 import run

    return run(recordings, options)


register_paper(
    PaperSpec(
        method="pinto2022",
        title="seed 001 section V: Tables II-IV, Figures 9 and 10 on synthetic Re-ID scenarios",
        scenarios=tuple(_scenario(n) for n in (*DATASET, TEST)),
        run=_run,
    )
)
