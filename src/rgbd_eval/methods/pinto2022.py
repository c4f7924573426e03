"""pinto2022: Re-ID based multi-people 3D tracker for service robots (seed 001)."""

from __future__ import annotations

from rgbd_eval.plugins import MethodSpec, register_method

register_method(
    MethodSpec(
        name="pinto2022",
        detector="pinto2022",
        tracker="pinto2022",
        title="Re-ID based multi-people 3D tracker for service robots (Pinto et al., 2022)",
        seed="001",
        gating="metric",
        config_file="methods/pinto2022.yaml",
    )
)
