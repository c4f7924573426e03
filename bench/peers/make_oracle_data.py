"""Write the classifier oracle's test data: images, windows, and the C++ confidences.

Run from the repository root after building the oracle (README.md here)::

    .venv/bin/python -m bench.peers.make_oracle_data /tmp/pcl_people_oracle

It writes ``tests/detect/data/authors_hog/``: a 640x480 PNG image (a ray-cast room
with five people, the nearest cut by the image border; a second image, integer
colour rings, is rebuilt by ``tests.detect.scenes.ring_texture``), and
``oracle.json`` holding the windows, the confidences the authors' C++
(``pcl::people::PersonClassifier::evaluate``, PCL 1.13) printed for them, and the
command that printed them. ``tests/detect/test_authors_hog.py`` compares our
confidences with those, without needing PCL.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
from tests.detect.scenes import RGB_CAMERA, Person, Scene, camera_pose, render, ring_texture

from rgbd_eval.types import Pose

OUT = Path("tests/detect/data/authors_hog")
MODEL = Path("src/rgbd_eval/data/pcl_people/trainedLinearSVMForPeopleDetectionWithHOG.yaml")


def five_people_scene() -> Scene:
    """Five people from 1.6 to 5 m; the nearest two are cut by the image's bottom and side."""
    return Scene(
        people=[
            Person(1.6, 0.2, 1.75, shirt=(40, 120, 40)),
            Person(2.4, 1.05, 1.70, yaw=0.6),
            Person(3.2, -0.5, 1.82, trousers=(20, 20, 20)),
            Person(4.2, 0.6, 1.62, shirt=(220, 200, 60)),
            Person(5.0, -1.4, 1.78, yaw=-0.8, shirt=(90, 90, 200)),
        ]
    )


def fixed_windows() -> list[tuple[float, float, float]]:
    """Hand-picked ``(height, xc, yc)``: up- and down-scaling, every border, fractions."""
    return [
        (40.0, 320.0, 240.0),  # window 53 x 27: enlarged, last row/column black
        (96.0, 200.5, 180.25),  # window 128 x 64: identity scale, shifted
        (150.3, 100.7, 300.2),
        (240.0, 320.0, 240.0),  # window 320 x 160: shrunk by 2.5
        (400.0, 330.0, 260.0),  # taller than the image: cut at top and bottom
        (180.0, 12.0, 200.0),  # cut by the left border
        (180.0, 630.0, 200.0),  # cut by the right border
        (200.0, 400.0, 430.0),  # cut by the bottom border
        (220.0, 250.0, 60.0),  # cut by the top border
        (75.0, 600.5, 470.5),  # bottom-right corner
        (3.0, 320.0, 240.0),  # a 4 x 2 window
    ]


def people_windows(scene: Scene, pose: Pose) -> list[tuple[float, float, float]]:
    """Each person's window as the detector places it, from the true geometry.

    Height: the projected head-to-ground span; centre: the projected mid point.
    """
    to_optical = pose.inverse()
    out = []
    for p in scene.people:
        ends = np.array([[p.x, p.y, p.height], [p.x, p.y, 0.0], [p.x, p.y, 0.5 * p.height]])
        uv = RGB_CAMERA.project(to_optical.transform_points(ends))
        out.append((float(uv[1, 1] - uv[0, 1]), float(uv[2, 0]), float(uv[2, 1])))
    return out


def main(oracle: str) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    scene = five_people_scene()
    pose = camera_pose(height=1.1, pitch_deg=4.0)
    frame = render(scene, pose, depth_size=(160, 120))
    people = people_windows(scene, pose)
    images = {"scene.png": frame.rgb, "rings": ring_texture()}
    cases: list[dict[str, object]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, rgb in images.items():
            if name.endswith(".png"):  # the rings are rebuilt by the test
                cv2.imwrite(str(OUT / name), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
            ppm = Path(tmp) / "image.ppm"
            h, w = rgb.shape[:2]
            ppm.write_bytes(f"P6\n{w} {h}\n255\n".encode() + rgb.tobytes())
            windows = fixed_windows() + (people if name == "scene.png" else [])
            listing = Path(tmp) / "windows.txt"
            listing.write_text("".join(f"{a!r} {b!r} {c!r}\n" for a, b, c in windows))
            out = subprocess.run(
                [oracle, "classify", str(MODEL), str(ppm), str(listing)],
                check=True,
                capture_output=True,
                text=True,
            ).stdout.split()
            for (height, xc, yc), conf in zip(windows, out, strict=True):
                cases.append(
                    {"image": name, "height": height, "xc": xc, "yc": yc, "confidence": float(conf)}
                )
    doc = {
        "source": "pcl::people::PersonClassifier<pcl::RGB>::evaluate(height, xc, yc, image), "
        "PCL 1.13 (Debian 12 libpcl-dev), via bench/peers/pcl_people_oracle.cpp",
        "command": "pcl_people_oracle classify "
        "src/rgbd_eval/data/pcl_people/trainedLinearSVMForPeopleDetectionWithHOG.yaml "
        "<image>.ppm <windows>.txt  (driven by: python -m bench.peers.make_oracle_data)",
        "cases": cases,
    }
    (OUT / "oracle.json").write_text(json.dumps(doc, indent=1) + "\n")
    print(f"{len(cases)} cases written to {OUT / 'oracle.json'}")


if __name__ == "__main__":
    main(sys.argv[1])
