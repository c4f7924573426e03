"""cielniak2010: thermal + colour people tracking on a mobile robot (seed 004).

The package holds the detector (:mod:`.detector`: none, the tracker detects), the tracker
(:mod:`.tracker`: a particle filter per person on the thermal image, with the warm-region
proposals of :mod:`.warm_regions`, the height prior of :mod:`.person_geometry` and the
occlusion order of :mod:`.occlusion`, whose classifier ships as ``occlusion.json`` and is
trained by :mod:`.occlusion_training`), the defaults (``method.yaml``), the paper's numbers
and claims (``paper.yaml``) and the experiments of ``rgbd-eval reproduce cielniak2010``
(:mod:`.experiments`); see ``README.md``. Importing it registers the detector, the tracker,
the method and the paper.
"""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.methods.cielniak2010 import detector, tracker  # noqa: F401  (they register)
from rgbd_eval.plugins import (
    MethodSpec,
    PaperSpec,
    register_method,
    register_paper,
)

HERE = Path(__file__).resolve().parent


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
        config_file=HERE / "method.yaml",
        paper_file=HERE / "paper.yaml",
    )
)


register_paper(
    PaperSpec(
        method="cielniak2010",
        title="seed 004 section 7: tracker ablation, occlusion classifier per feature group, "
        "over scenario seeds",
        # each scenario seed's recordings are rendered by the experiments (experiments.py)
        scenarios=(),
        run="rgbd_eval.methods.cielniak2010.experiments:run",
    )
)
