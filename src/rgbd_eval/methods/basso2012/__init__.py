"""basso2012: RGB-D people tracking by detection for a mobile robot (seed 000, the reference).

The package holds the detector (:mod:`.detector`, its config :mod:`.detector_config`, the
per-cluster features :mod:`.features`), the tracker (:mod:`.tracker`, :mod:`.tracker_config`),
the defaults (``method.yaml``), the thesis' numbers and claims (``paper.yaml``) and the
experiments of ``rgbd-eval reproduce basso2012`` (:mod:`.experiments`); see ``README.md``.
Importing it registers the detector, the tracker, the method and the paper.
"""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.methods.basso2012 import detector, tracker  # noqa: F401  (they register)
from rgbd_eval.plugins import MethodSpec, PaperSpec, register_method, register_paper

HERE = Path(__file__).resolve().parent

#: The thesis test set (seed 000, chapter 7).
SCENARIOS = (
    "static_simple",
    "static_complex",
    "static_obstacles",
    "moving_simple",
    "moving_complex",
    "moving_obstacles",
)
#: Beyond the thesis: the obstacle sequences plus person-sized clutter, for the tracker's
#: ``static`` variant (reported by ``reproduce`` without paper values).
CLUTTER = ("static_clutter", "moving_clutter")

register_method(
    MethodSpec(
        name="basso2012",
        detector="basso2012",
        tracker="basso2012",
        title="RGB-D people tracking by detection for a mobile robot (Basso, thesis 2012)",
        seed="000",
        gating="iou",
        config_file=HERE / "method.yaml",
        paper_file=HERE / "paper.yaml",
    )
)


register_paper(
    PaperSpec(
        method="basso2012",
        title="seed 000 chapter 7: Tables 7.1-7.6, Figures 7.7 and 7.9",
        scenarios=(*SCENARIOS, *CLUTTER),
        run="rgbd_eval.methods.basso2012.experiments:reproduce",
    )
)
