"""pinto2022: Re-ID based multi-people 3D tracker for service robots (seed 001).

The package holds the detector (:mod:`.detector`, :mod:`.detector_config`), the tracker
(:mod:`.tracker`, :mod:`.tracker_config`), the re-expression of the paper's appearance
thresholds in an embedder's units (:mod:`.reid_calibration`), the defaults (``method.yaml``),
the paper's numbers and claims (``paper.yaml``) and the experiments of
``rgbd-eval reproduce pinto2022`` (:mod:`.experiments`); see ``README.md``. Importing it
registers the detector, the tracker, the method and the paper.
"""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.methods.pinto2022 import detector, tracker  # noqa: F401  (they register)
from rgbd_eval.plugins import (
    MethodSpec,
    PaperSpec,
    register_method,
    register_paper,
)

HERE = Path(__file__).resolve().parent

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
        config_file=HERE / "method.yaml",
        paper_file=HERE / "paper.yaml",
    )
)


def _scenario(name: str) -> str:
    return str(scenarios_dir() / "pinto2022" / f"{name}.yaml")


register_paper(
    PaperSpec(
        method="pinto2022",
        title="seed 001 section V: Tables II-IV, Figures 9 and 10 on synthetic Re-ID scenarios",
        scenarios=tuple(_scenario(n) for n in (*DATASET, TEST)),
        run="rgbd_eval.methods.pinto2022.experiments:run",
    )
)
