"""Detection building blocks shared by methods: point clouds, ground plane, clustering, HOG
(OpenCV's and the authors'), 2D person detectors (SSDLite, YOLO ONNX, HOG), re-ID embedding,
depth localisation, background subtraction, density maps, blobs, stereo matching; and the
detector protocol (:mod:`rgbd_eval.detect.protocol`). Each paper's detector lives in its
method package, ``rgbd_eval.methods.<key>``."""
