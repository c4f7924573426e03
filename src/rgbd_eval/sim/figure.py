"""Articulated human figures: head, neck, torso, arms, legs, with a walking gait.

Proportions are fractions of the standing height H (anthropometric segment
lengths after Drillis & Contini: thigh and shank each about 0.245 H, upper arm
0.186 H, forearm 0.146 H, shoulders at 0.818 H, hips at 0.53 H). Widths scale
with ``s = H / 1.75``. The body frame has x forward, y left, z up, the origin
on the floor between the feet; :func:`figure_mesh` places it in the world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rgbd_eval import exact
from rgbd_eval.sim.meshes import (
    F64,
    MAT_SKIN,
    Mesh,
    MeshBuilder,
    rotation_z,
)

Colour = tuple[int, int, int]

#: Segment lengths as fractions of height (Drillis & Contini anthropometry).
HIP_Z, SHOULDER_Z = 0.53, 0.818
THIGH, SHANK = 0.245, 0.246
UPPER_ARM, FOREARM = 0.186, 0.146
#: Peak hip flexion, knee flexion and arm swing at normal walking speed (degrees),
#: typical values of human gait.
HIP_SWING_DEG, KNEE_SWING_DEG, ARM_SWING_DEG = 24.0, 55.0, 22.0


@dataclass(frozen=True)
class Outfit:
    """Colours of one figure."""

    shirt: Colour
    trousers: Colour
    skin: Colour
    hair: Colour
    shoes: Colour
    bag: Colour | None = None


@dataclass(frozen=True)
class Posture:
    """Gait phase (radians), gait amplitude in [0, 1] and sitting fraction in [0, 1]."""

    phase: float = 0.0
    amplitude: float = 0.0
    sit: float = 0.0


def _c(colour: Colour) -> tuple[float, float, float]:
    return (float(colour[0]), float(colour[1]), float(colour[2]))


def _dir(angle: float, side: float = 0.0) -> F64:
    """Unit vector hanging down, rotated forward by ``angle`` and out sideways by ``side``."""
    v = np.array([exact.sin(angle), side, -exact.cos(angle)])
    out: F64 = v / exact.norm(v)
    return out


def leg_angles(posture: Posture) -> tuple[tuple[float, float], tuple[float, float]]:
    """(hip flexion, knee flexion) in radians for the left and right leg."""
    out = []
    for offset in (0.0, math.pi):
        ph = posture.phase + offset
        hip = math.radians(HIP_SWING_DEG) * posture.amplitude * exact.sin(ph)
        # the knee flexes while the leg swings forward (hip flexion increasing)
        bend = max(0.0, exact.cos(ph))
        knee = math.radians(KNEE_SWING_DEG) * posture.amplitude * (bend * bend)
        knee += math.radians(5.0) * posture.amplitude
        hip = hip * (1.0 - posture.sit) + math.radians(88.0) * posture.sit
        knee = knee * (1.0 - posture.sit) + math.radians(88.0) * posture.sit
        out.append((hip, knee))
    return (out[0], out[1])


def figure_mesh(
    height: float,
    x: float,
    y: float,
    heading: float,
    posture: Posture,
    outfit: Outfit,
    object_id: int,
) -> tuple[Mesh, float]:
    """The figure's mesh in the world and the current top-of-head height (m)."""
    if not 0.5 <= height <= 2.5:
        raise ValueError(f"height={height} must be in [0.5, 2.5] m")
    if not (0.0 <= posture.amplitude <= 1.0 and 0.0 <= posture.sit <= 1.0):
        raise ValueError(f"posture {posture} needs amplitude and sit in [0, 1]")
    H = height
    s = H / 1.75
    b = MeshBuilder()
    skin, shirt, trousers = _c(outfit.skin), _c(outfit.shirt), _c(outfit.trousers)
    thigh, shank = THIGH * H, SHANK * H
    ankle = HIP_Z * H - thigh - shank  # ankle joint height when standing

    # legs: place the pelvis so that the lower foot rests on the floor
    legs = leg_angles(posture)
    lowest = min(-thigh * exact.cos(h) - shank * exact.cos(h - k) for h, k in legs)
    hip_z = ankle - lowest
    drop = HIP_Z * H - hip_z  # how much the upper body is lowered (gait bob, sitting)
    for side, (hip, knee) in zip((1.0, -1.0), legs, strict=True):
        h0 = np.array([0.0, side * 0.09 * s, hip_z])
        k0 = h0 + thigh * _dir(hip)
        a0 = k0 + shank * _dir(hip - knee)
        b.sphere(h0, (0.08 * s,) * 3, np.eye(3), trousers, object_id)
        b.limb(h0, k0, 0.075 * s, trousers, object_id)
        b.limb(k0, a0, 0.056 * s, trousers, object_id)
        # the sole is at the floor when the ankle is at its standing height
        foot_c = a0 + np.array([0.05 * s, 0.0, 0.03 * s - ankle])
        b.box(foot_c, (0.25 * s, 0.095 * s, 0.06 * s), np.eye(3), _c(outfit.shoes), object_id)

    # torso: pelvis (trousers), waist and chest (shirt), rounded shoulders
    def z(fraction: float) -> float:
        """Height of a body landmark given as a fraction of H, lowered with the pelvis."""
        return fraction * H - drop

    lean = np.eye(3)
    sit_back = -0.05 * s * posture.sit  # a seated torso leans back on the seat
    b.sphere((sit_back, 0.0, z(0.50)), (0.11 * s, 0.165 * s, 0.08 * H), lean, trousers, object_id)
    b.sphere((sit_back, 0.0, z(0.62)), (0.115 * s, 0.165 * s, 0.1 * H), lean, shirt, object_id)
    b.sphere((sit_back, 0.0, z(0.71)), (0.125 * s, 0.19 * s, 0.11 * H), lean, shirt, object_id)
    b.sphere((sit_back, 0.0, z(0.79)), (0.11 * s, 0.2 * s, 0.045 * H), lean, shirt, object_id)
    neck_a = np.array([sit_back, 0.0, z(0.80)])
    neck_b = np.array([sit_back, 0.0, z(0.885)])
    b.limb(neck_a, neck_b, 0.05 * s, skin, object_id, MAT_SKIN, joint=False)

    # head with hair on top and back
    head_c = np.array([sit_back, 0.0, z(1.0) - 0.115 * s])
    b.sphere(head_c, (0.095 * s, 0.078 * s, 0.115 * s), np.eye(3), skin, object_id, MAT_SKIN)
    hair_c = head_c + np.array([-0.015 * s, 0.0, 0.013 * s])  # hair top at exactly H
    b.sphere(hair_c, (0.095 * s, 0.083 * s, 0.102 * s), np.eye(3), _c(outfit.hair), object_id)

    # arms swing opposite to the legs
    for side, sign in ((1.0, -1.0), (-1.0, 1.0)):
        swing = sign * math.radians(ARM_SWING_DEG) * posture.amplitude * exact.sin(posture.phase)
        swing = swing * (1.0 - posture.sit) + math.radians(25.0) * posture.sit
        elbow = math.radians(12.0 + 18.0 * posture.amplitude + 45.0 * posture.sit)
        sh = np.array([sit_back, side * 0.195 * s, z(SHOULDER_Z - 0.02)])
        el = sh + UPPER_ARM * H * _dir(swing, side * 0.09)
        wr = el + FOREARM * H * _dir(swing + elbow, side * 0.06)
        b.sphere(sh, (0.052 * s,) * 3, np.eye(3), shirt, object_id)
        b.limb(sh, el, 0.046 * s, shirt, object_id)
        b.limb(el, wr, 0.037 * s, shirt, object_id, joint=False)
        hand = wr + 0.05 * s * _dir(swing + elbow)
        b.sphere(hand, (0.03 * s, 0.045 * s, 0.06 * s), np.eye(3), skin, object_id, MAT_SKIN)

    if outfit.bag is not None:
        # hangs from the left shoulder on the right hip, outside the swinging arm
        bag_c = np.array([sit_back - 0.04 * s, -0.3 * s, z(0.52)])
        b.box(bag_c, (0.28 * s, 0.09 * s, 0.24 * s), np.eye(3), _c(outfit.bag), object_id)
        strap_top = np.array([sit_back, 0.15 * s, z(SHOULDER_Z)])
        b.limb(
            strap_top, bag_c + np.array([0.0, 0.0, 0.1 * s]), 0.012 * s, _c(outfit.bag), object_id
        )

    local = b.build()
    R = rotation_z(heading)
    verts = exact.transform(local.vertices, R, (x, y, 0.0))
    normals = exact.matmul(local.normals, R.T)
    mesh = Mesh(verts, normals, local.triangles, local.colours, local.object_ids, local.materials)
    top = float(local.vertices[:, 2].max())
    return mesh, top
