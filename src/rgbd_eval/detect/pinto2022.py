"""The pinto2022 detector (seed 001, III-B): 2D person boxes -> localiser -> re-ID embedding.

Per frame: a 2D person detector on the colour image (the seed uses YOLOv3; here any
:class:`~rgbd_eval.detect.person2d.PersonDetector2D`), the people localiser on the depth
image (:mod:`.localise`), and an appearance embedding of each localised box
(:mod:`.reid`). Each :class:`~rgbd_eval.types.Detection` carries the world position, the
box, the detector's score and the embedding; ``dropped_without_depth`` counts the boxes the
localiser dropped over the detector's life.

``last_timings`` holds the seconds of the last call's stages: ``person2d``, ``localise``,
``embed``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping

from rgbd_eval.detect.localise import DepthView, localise
from rgbd_eval.detect.person2d import ColourImage, PersonDetector2D
from rgbd_eval.detect.reid import Embedder
from rgbd_eval.types import Detection, Frame

STAGES = ("person2d", "localise", "embed")


class Pinto2022Detector:
    """Detector protocol implementation composing the three stages of III-B."""

    def __init__(self, person: PersonDetector2D, embedder: Embedder) -> None:
        self.person = person
        self.embedder = embedder
        self.dropped_without_depth = 0
        self._timings: dict[str, float] = dict.fromkeys(STAGES, 0.0)

    @property
    def last_timings(self) -> Mapping[str, float]:
        return self._timings

    def detect(self, frame: Frame) -> list[Detection]:
        t0 = time.perf_counter()
        boxes = self.person.detect(ColourImage(frame.index, frame.stamp_ns, frame.rgb))
        t1 = time.perf_counter()
        view = DepthView(
            depth=frame.depth,
            depth_camera=frame.depth_camera,
            rgb_camera=frame.rgb_camera,
            depth_to_rgb=frame.depth_to_rgb,
            camera_pose=frame.camera_pose,
        )
        located = localise(view, [b.box for b in boxes])
        self.dropped_without_depth += located.dropped
        t2 = time.perf_counter()
        embeddings = self.embedder.embed(frame.rgb, [lb.box for lb in located.boxes])
        t3 = time.perf_counter()
        self._timings = {"person2d": t1 - t0, "localise": t2 - t1, "embed": t3 - t2}
        return [
            Detection(
                position=lb.position,
                height=lb.height,
                confidence=boxes[i].score,
                box2d=lb.box,
                distance=lb.depth,
                appearance=embeddings[k],
            )
            for k, (i, lb) in enumerate(zip(located.kept, located.boxes, strict=True))
        ]
