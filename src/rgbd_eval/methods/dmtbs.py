"""dmtbs: Density Map Tracking with Blob Splitting, depth only, 1..N static cameras (seed 003)."""

from __future__ import annotations

from rgbd_eval.plugins import MethodSpec, register_method

register_method(
    MethodSpec(
        name="dmtbs",
        detector="dmtbs",
        tracker="dmtbs",
        title="Density Map Tracking with Blob Splitting: depth-only people tracking with "
        "one or more static range cameras",
        seed="003",
        gating="metric",
        config_file="methods/dmtbs.yaml",
    )
)
