"""What pinto2022's 2D person detector finds, and what it misses, and why.

    .venv/bin/python tools/pinto2022/detector_recall.py datasets/demo.mcap [more.mcap ...]
    .venv/bin/python tools/pinto2022/detector_recall.py --image photo.jpg [--image ...]
    options: --model FILE (another SSDLite ONNX file, e.g. a quantised one), --json

Recordings (each with its ``<name>.gt.csv``): the detector runs with no score threshold, so
every box the network's own NMS keeps (up to 100) is seen. Each scored ground-truth box
(not ignored, at least ``MIN_HEIGHT_PX`` tall) is matched greedily, best score first, to a
box with IoU >= 0.5. Printed per recording and in total: recall and precision at the
published threshold (0.5, ``methods/pinto2022/method.yaml``); recall at lower thresholds
(what a lower threshold would buy, *not* a recommendation: the threshold stays); and the
missed people split by why: no box at all within IoU 0.5 (the network does not see a person
there), a box with a score below 0.5 (seen, but not confidently), and by the person's size
and visible fraction.

Images (``--image``): the boxes with score >= 0.1 on a photo, full frame and resized to
640x480 as a Kinect frame, to compare the same network on real people.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from rgbd_eval.detect.person2d import ColourImage, PersonBox
from rgbd_eval.detect.ssdlite import SsdLiteDetector, SsdParams
from rgbd_eval.io.groundtruth import read_csv
from rgbd_eval.io.recording import open_recording
from rgbd_eval.metrics.gating import iou_matrix
from rgbd_eval.types import GroundTruthObject

PUBLISHED_THRESHOLD = 0.5
LOWER_THRESHOLDS = (0.3, 0.1)
MIN_IOU = 0.5
MIN_HEIGHT_PX = 40.0
HEIGHT_BANDS = ((0.0, 120.0), (120.0, 200.0), (200.0, 300.0), (300.0, 1e9))
VISIBILITY_BANDS = ((0.0, 0.5), (0.5, 0.95), (0.95, 1.01))


@dataclass
class Tally:
    """Counts of one recording (or the total)."""

    people: int = 0
    boxes_at_published: int = 0
    true_at_published: int = 0
    found: dict[float, int] = field(default_factory=dict)
    unseen: int = 0  # no box of any score with IoU >= 0.5
    weak_scores: list[float] = field(default_factory=list)  # best score < 0.5
    by_height: dict[str, list[int]] = field(default_factory=dict)  # band -> [people, found]
    by_visibility: dict[str, list[int]] = field(default_factory=dict)
    by_person: dict[str, list[int]] = field(default_factory=dict)  # "<recording>:<id>"

    def add(self, other: Tally) -> None:
        self.people += other.people
        self.boxes_at_published += other.boxes_at_published
        self.true_at_published += other.true_at_published
        for t, n in other.found.items():
            self.found[t] = self.found.get(t, 0) + n
        self.unseen += other.unseen
        self.weak_scores += other.weak_scores
        pairs = (
            (self.by_height, other.by_height),
            (self.by_visibility, other.by_visibility),
            (self.by_person, other.by_person),
        )
        for mine, theirs in pairs:
            for k, (n, f) in theirs.items():
                row = mine.setdefault(k, [0, 0])
                row[0] += n
                row[1] += f

    def summary(self) -> dict[str, object]:
        people = max(self.people, 1)
        weak = np.asarray(self.weak_scores)
        return {
            "people": self.people,
            "recall": {f"{t:g}": n / people for t, n in sorted(self.found.items(), reverse=True)},
            "precision_at_published": self.true_at_published / max(self.boxes_at_published, 1),
            "missed_unseen": self.unseen,
            "missed_weak": len(self.weak_scores),
            "weak_score_median": float(np.median(weak)) if weak.size else None,
            "recall_by_height_px": {k: v[1] / max(v[0], 1) for k, v in self.by_height.items()},
            "people_by_height_px": {k: v[0] for k, v in self.by_height.items()},
            "recall_by_visibility": {k: v[1] / max(v[0], 1) for k, v in self.by_visibility.items()},
            "people_by_visibility": {k: v[0] for k, v in self.by_visibility.items()},
            "recall_by_person": {k: v[1] / max(v[0], 1) for k, v in sorted(self.by_person.items())},
        }


def _band(value: float, bands: Sequence[tuple[float, float]]) -> str:
    for lo, hi in bands:
        if lo <= value < hi:
            return f"{lo:g}-{hi:g}" if hi < 1e8 else f">={lo:g}"
    return "other"


def _best_scores(people: Sequence[GroundTruthObject], boxes: Sequence[PersonBox]) -> list[float]:
    """Greedy one-to-one matching at IoU >= 0.5, best-scoring box first: each person's score
    (0 when no box is left for them)."""
    if not people or not boxes:
        return [0.0] * len(people)
    gt = np.array(
        [[p.box2d.left, p.box2d.top, p.box2d.width, p.box2d.height] for p in people if p.box2d]
    )
    det = np.array([[b.box.left, b.box.top, b.box.width, b.box.height] for b in boxes])
    iou = iou_matrix(gt, det)
    taken = np.zeros(len(people), dtype=bool)
    best = [0.0] * len(people)
    for j in np.argsort([-b.score for b in boxes], kind="stable"):
        candidates = np.where(~taken & (iou[:, j] >= MIN_IOU))[0]
        if candidates.size:
            i = int(candidates[np.argmax(iou[candidates, j])])
            taken[i] = True
            best[i] = boxes[j].score
    return best


def tally_recording(path: Path, detector: SsdLiteDetector) -> Tally:
    gt = read_csv(path.with_name(path.name.rsplit(".", 1)[0] + ".gt.csv"))
    rec = open_recording(path)
    frames = list(rec.frames())
    per_frame, _ = gt.align([f.stamp_ns for f in frames], 1_000_000)
    out = Tally()
    for frame, objects in zip(frames, per_frame, strict=True):
        people = [
            o
            for o in objects
            if o.box2d is not None and not o.ignore and o.box2d.height >= MIN_HEIGHT_PX
        ]
        boxes = detector.detect(ColourImage(frame.index, frame.stamp_ns, frame.rgb))
        scores = _best_scores(people, boxes)
        published = [b for b in boxes if b.score >= PUBLISHED_THRESHOLD]
        out.boxes_at_published += len(published)
        out.true_at_published += sum(s >= PUBLISHED_THRESHOLD for s in scores)
        out.people += len(people)
        for t in (PUBLISHED_THRESHOLD, *LOWER_THRESHOLDS):
            out.found[t] = out.found.get(t, 0) + sum(s >= t for s in scores)
        for person, score in zip(people, scores, strict=True):
            hit = int(score >= PUBLISHED_THRESHOLD)
            if not hit:
                if score == 0.0:
                    out.unseen += 1
                else:
                    out.weak_scores.append(score)
            for table, key in (
                (out.by_height, _band(person.box2d.height if person.box2d else 0.0, HEIGHT_BANDS)),
                (out.by_visibility, _band(person.visibility, VISIBILITY_BANDS)),
                (out.by_person, f"{path.stem}:{person.object_id}"),
            ):
                row = table.setdefault(key, [0, 0])
                row[0] += 1
                row[1] += hit
    return out


def image_boxes(path: Path, detector: SsdLiteDetector) -> dict[str, object]:
    bgr = cv2.imread(str(path))
    if bgr is None:
        raise SystemExit(f"error: {path}: not an image OpenCV can read")
    rgb = np.ascontiguousarray(bgr[..., ::-1])
    result: dict[str, object] = {"image": str(path), "size": [rgb.shape[1], rgb.shape[0]]}
    for label, img in (
        ("full", rgb),
        ("640x480", cv2.resize(rgb, (640, 480), interpolation=cv2.INTER_AREA)),
    ):
        boxes = [b for b in detector.detect(ColourImage(0, 0, img)) if b.score >= 0.1]
        result[label] = [
            {
                "score": round(b.score, 3),
                "box": [
                    round(b.box.left),
                    round(b.box.top),
                    round(b.box.width),
                    round(b.box.height),
                ],
            }
            for b in boxes
        ]
    return result


def main(argv: list[str]) -> None:
    as_json = "--json" in argv
    model: Path | None = None
    images: list[Path] = []
    recordings: list[Path] = []
    args = iter(a for a in argv if a != "--json")
    for a in args:
        if a == "--model":
            model = Path(next(args))
        elif a == "--image":
            images.append(Path(next(args)))
        else:
            recordings.append(Path(a))
    detector = SsdLiteDetector(model, SsdParams(score_threshold=0.0))
    report: dict[str, object] = {"model": str(model or "built-in"), "recordings": {}, "images": []}
    total = Tally()
    for path in recordings:
        one = tally_recording(path, detector)
        total.add(one)
        report["recordings"][path.name] = one.summary()  # type: ignore[index]
    if recordings:
        report["total"] = total.summary()
    report["images"] = [image_boxes(p, detector) for p in images]
    if as_json:
        json.dump(report, sys.stdout, indent=2)
        print()
        return
    for name, s in [
        *report["recordings"].items(),
        *([("TOTAL", report["total"])] if recordings else []),
    ]:  # type: ignore[union-attr]
        rec = ", ".join(f"{k}: {v:.3f}" for k, v in s["recall"].items())
        print(
            f"{name:24s} people {s['people']:5d}  recall at {rec}  precision@0.5 "
            f"{s['precision_at_published']:.3f}  missed: {s['missed_unseen']} no box, "
            f"{s['missed_weak']} weak (median {s['weak_score_median']})"
        )
    if recordings:
        t = report["total"]
        print(
            "recall by box height (px):",
            {
                k: f"{v:.2f} of {t['people_by_height_px'][k]}"
                for k, v in t["recall_by_height_px"].items()
            },
        )  # type: ignore[index]
        print("recall by person:", {k: round(v, 2) for k, v in t["recall_by_person"].items()})  # type: ignore[index]
        print(
            "recall by visibility:",
            {
                k: f"{v:.2f} of {t['people_by_visibility'][k]}"
                for k, v in t["recall_by_visibility"].items()
            },
        )  # type: ignore[index]
    for im in report["images"]:  # type: ignore[union-attr]
        print(json.dumps(im))


if __name__ == "__main__":
    main(sys.argv[1:])
