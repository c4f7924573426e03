"""Depth scenes of satake2009's tests: rendered figures in front of a wall, exact depth."""

from __future__ import annotations

import math

import numpy as np

from rgbd_eval.methods.satake2009 import templates as st
from rgbd_eval.sim.figure import Outfit, Posture, figure_mesh
from rgbd_eval.sim.render import make_scene, render_hits
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

W, H = 512, 384
CAM = CameraModel(W, H, st.F_REF, st.F_REF, (W - 1) / 2, (H - 1) / 2)  # fx = 214.8 px


def figure_depth(x: float, y: float) -> np.ndarray:
    """Depth (inf: nothing) of a 1.75 m figure facing the camera, camera 1.2 m up, level."""
    body = np.eye(4)
    body[2, 3] = 1.2
    pose = Pose.from_matrix(body).compose(OPTICAL_TO_BODY)
    outfit = Outfit((90, 90, 90), (50, 50, 50), (200, 160, 130), (40, 30, 20), (20, 20, 20))
    mesh, _ = figure_mesh(1.75, x, y, math.pi, Posture(), outfit, 1)
    z = render_hits(make_scene(mesh), CAM, pose).depth
    return np.nan_to_num(z, nan=np.inf).astype(np.float32)


def scene_depth(*figures: tuple[float, float], wall_m: float = 8.0) -> np.ndarray:
    """Nearest surface of several figures in front of a wall (a z-buffer)."""
    depth = np.full((H, W), wall_m, np.float32)
    for x, y in figures:
        depth = np.fmin(depth, figure_depth(x, y))
    return depth
