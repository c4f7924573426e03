"""dmtbs: Density Map Tracking with Blob Splitting, depth only, 1..N static cameras (seed 003).

The package holds the detector (:mod:`.detector`: background subtraction, density map,
blobs), the tracker (:mod:`.tracker`, with the blob splitting of :mod:`.blob_split`), the
defaults (``method.yaml``), the claims of the seed and their thresholds (``paper.yaml``) and
the experiments of ``rgbd-eval reproduce dmtbs`` (:mod:`.experiments`); see ``README.md``.
Importing it registers the detector, the tracker, the method and the paper.
"""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.methods.dmtbs import detector, tracker  # noqa: F401  (they register)
from rgbd_eval.plugins import MethodSpec, PaperSpec, register_method, register_paper

HERE = Path(__file__).resolve().parent

register_method(
    MethodSpec(
        name="dmtbs",
        detector="dmtbs",
        tracker="dmtbs",
        title="Density Map Tracking with Blob Splitting: depth-only people tracking with "
        "one or more static range cameras",
        seed="003",
        gating="metric",
        config_file=HERE / "method.yaml",
        paper_file=HERE / "paper.yaml",
    )
)


register_paper(
    PaperSpec(
        method="dmtbs",
        title="seed 003 4.3: Figs. 8-11 (camera angle on scene 1; cameras, depth noise, "
        "calibration error on scene 2) and the left-behind object",
        scenarios=(),
        run="rgbd_eval.methods.dmtbs.experiments:reproduce",
    )
)
