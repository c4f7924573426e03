"""cielniak2010: thermal + colour people tracking on a mobile robot (seed 004)."""

from __future__ import annotations

from rgbd_eval.plugins import MethodSpec, register_method

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
    )
)
