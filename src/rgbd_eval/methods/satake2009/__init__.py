"""satake2009: stereo multi-person tracking with distance templates and an odometry-aware EKF.

The package holds the detector (:mod:`.detector`: SGBM depth and the distance-template
search, :mod:`.search`, with its templates :mod:`.templates` (shipped as ``templates.npz``)
and colour test :mod:`.colour`), the tracker (:mod:`.tracker`, its odometry-aware EKF
:mod:`.ekf`), the closed loop that follows a person (:mod:`.follow`, ``synth --follow``), the
defaults (``method.yaml``), the paper's numbers and claims (``paper.yaml``) and the
experiments of ``rgbd-eval reproduce satake2009`` (:mod:`.experiments`); see ``README.md``.
Importing it registers the detector, the tracker, the method and the paper.
"""

from __future__ import annotations

from pathlib import Path

from rgbd_eval.methods.satake2009 import detector, tracker  # noqa: F401  (they register)
from rgbd_eval.plugins import (
    MethodSpec,
    PaperSpec,
    register_method,
    register_paper,
)

HERE = Path(__file__).resolve().parent

register_method(
    MethodSpec(
        name="satake2009",
        detector="satake2009",
        tracker="satake2009",
        title="Multiple person tracking by a stereo camera on a mobile robot (Satake & Miura 2009)",
        seed="002",
        gating="metric",
        config_file=HERE / "method.yaml",
        paper_file=HERE / "paper.yaml",
    )
)


register_paper(
    PaperSpec(
        method="satake2009",
        title="seed 002 section 4: Fig. 8 as a closed loop (follow A while B and C cross), timing",
        scenarios=(),  # the closed loop renders its own frames: its path depends on the tracker
        run="rgbd_eval.methods.satake2009.experiments:reproduce",
    )
)
