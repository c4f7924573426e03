"""satake2009: stereo multi-person tracking with distance templates and an odometry-aware EKF."""

from __future__ import annotations

from rgbd_eval.plugins import MethodSpec, register_method

register_method(
    MethodSpec(
        name="satake2009",
        detector="satake2009",
        tracker="satake2009",
        title="Multiple person tracking by a stereo camera on a mobile robot (Satake & Miura 2009)",
        seed="002",
        gating="metric",
        config_file="methods/satake2009.yaml",
    )
)
