"""Depth scenes of satake2009's tests: rendered people in front of a wall, exact depth.

The person is what scenarios render (:mod:`rgbd_eval.sim.people`): a 1.75 m man drawn
from the people's stream of scenario seed 0, person 1 (scored people's stream, not the
templates' tuning bodies), standing.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from rgbd_eval.methods.satake2009 import templates as st
from rgbd_eval.sim.people import STREAM, Dressed, draw_appearance, draw_shape, dress
from rgbd_eval.sim.render import make_scene, render_hits
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

W, H = 512, 384
CAM = CameraModel(W, H, st.F_REF, st.F_REF, (W - 1) / 2, (H - 1) / 2)  # fx = 214.8 px


@lru_cache(maxsize=1)
def person() -> Dressed:
    """A 1.75 m man as a scenario of seed 0 would draw its person 1."""
    rng = np.random.default_rng([0, STREAM, 1])
    shape = draw_shape(rng, 1.0, 1.75)
    return dress(shape, draw_appearance(rng, shape))


def person_depth(x: float, y: float, turned_deg: float = 0.0) -> np.ndarray:
    """Depth (inf: nothing) of the person standing at (x, y), turned ``turned_deg`` from
    facing the camera, camera 1.2 m up, level, at the origin looking along +x."""
    body = np.eye(4)
    body[2, 3] = 1.2
    pose = Pose.from_matrix(body).compose(OPTICAL_TO_BODY)
    heading = math.pi - math.radians(turned_deg)
    mesh, _ = person().mesh(x, y, heading, 0.0, 0.0, 0.0, 0.0, 1)
    z = render_hits(make_scene(mesh), CAM, pose).depth
    return np.nan_to_num(z, nan=np.inf).astype(np.float32)


def scene_depth(*people: tuple[float, float], wall_m: float = 8.0) -> np.ndarray:
    """Nearest surface of several people facing the camera in front of a wall (a z-buffer)."""
    depth = np.full((H, W), wall_m, np.float32)
    for x, y in people:
        depth = np.fmin(depth, person_depth(x, y))
    return depth
