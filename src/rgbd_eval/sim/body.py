"""People from the MakeHuman body model: shape, rig, skinning and motion.

The asset ``assets/makehuman.npz`` (``tools/bodies/extract_makehuman.py``; provenance in
``assets/README.md``) holds MakeHuman's hm08 mesh, the macro targets MPFB blends, a rig with
skinning weights and MPFB's walk cycle. Everything here is numpy with the exact operations
of :mod:`rgbd_eval.exact`, so a body is the same bytes on every CPU.

The body frame: x forward, y to the body's left, z up, the soles on z = 0, the origin
between the ankles. A :class:`BodyShape` is shaped once (:meth:`BodyModel.shaped`) into a
:class:`RestBody` (the rest A-pose, bone frames); :meth:`RestBody.posed` skins it
(linear-blend skinning) for a :class:`Pose`, which :func:`stand_pose`, :func:`sit_pose` and
:func:`walk_pose` make.

The rig is MPFB's ``default_no_toes`` (the one its walk cycle was made on) reduced to the 38
bones people are posed with; the weights of the others (fingers, face, toes) went to their
parents, which skins the same while those stay at rest. Measured (``tests/sim/test_body.py``
measures the same way), six varied people at 0.8-1.5 m/s (:func:`natural_stride`): a
planted foot's sole slides 1-20 mm per gait cycle (the touching vertices' horizontal travel,
sampled 120 times a cycle); a 750-frame walk costs 3.5 ms of one core per person and frame
(:meth:`RestBody.walk_vertices`: about 2 s to pose a stride's table once, then 0.6 ms a
frame; posing and skinning a frame without the table takes 20 ms).
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

ASSET = Path(__file__).parent / "assets" / "makehuman.npz"
#: MakeHuman's age scale: 0 is 1 year, 0.5 is 25 years, 1 is 90 years (human.py, setAgeYears).
MIN_AGE, MID_AGE, MAX_AGE = 1.0, 25.0, 90.0
HEIGHT_RANGE_M = (1.50, 1.95)
AGE_RANGE_YEARS = (18.0, 80.0)


# ----------------------------------------------------------------------------- shape


@dataclass(frozen=True)
class BodyShape:
    """What makes one person's body (MakeHuman's macro sliders, but height in metres).

    ``sex`` 0 female .. 1 male; ``muscle`` and ``weight`` 0..1 (0.5 average; weight is
    MakeHuman's, BMI-like); ``proportions`` 0 uncommon .. 0.5 neutral .. 1 ideal;
    ``ancestry`` the (african, asian, caucasian) shares of MakeHuman's ethnic shape targets
    (face and body shape only: skin colour is the renderer's).
    """

    sex: float = 0.5
    age_years: float = 30.0
    muscle: float = 0.5
    weight: float = 0.5
    height_m: float = 1.70
    proportions: float = 0.5
    ancestry: tuple[float, float, float] = (1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0)

    def __post_init__(self) -> None:
        for name in ("sex", "muscle", "weight", "proportions"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise ValueError(f"BodyShape.{name}={value} is outside 0..1")
        lo, hi = AGE_RANGE_YEARS
        if not lo <= self.age_years <= hi:
            raise ValueError(f"BodyShape.age_years={self.age_years} is outside {lo:g}..{hi:g}")
        lo, hi = HEIGHT_RANGE_M
        if not lo <= self.height_m <= hi:
            raise ValueError(f"BodyShape.height_m={self.height_m} is outside {lo:g}..{hi:g}")
        if len(self.ancestry) != 3 or min(self.ancestry) < 0 or sum(self.ancestry) <= 0:
            raise ValueError(f"BodyShape.ancestry={self.ancestry} must be 3 shares, not all 0")


def age_slider(age_years: float) -> float:
    """MakeHuman's age value (0..1) of an age in years (human.py, setAgeYears)."""
    if age_years < MID_AGE:
        return (age_years - MIN_AGE) / ((MID_AGE - MIN_AGE) * 2.0)
    return (age_years - MID_AGE) / ((MAX_AGE - MID_AGE) * 2.0) + 0.5


def macro_components(parts: list[dict[str, Any]], value: float) -> list[tuple[str, float]]:
    """The (target suffix, weight) pairs of one macro slider, as MPFB computes them.

    MPFB (``TargetService._interpolate_macro_components``) reads ``macro.json``: each
    slider has parts spanning ``lowest``..``highest`` with a ``low`` and a ``high`` name;
    a value strictly inside a part weighs its low name by 1 - p and its high name by p,
    p = (value - lowest) / (highest - lowest); an empty name is no target. MPFB also rounds
    the weights to 4 decimals and skips combined weights under 0.01; we keep them exact, so
    a body changes smoothly with its sliders.
    """
    out = []
    for part in parts:
        lowest, highest = float(part["lowest"]), float(part["highest"])
        if lowest < value < highest:
            p = (value - lowest) / (highest - lowest)
            if part["low"]:
                out.append((str(part["low"]), 1.0 - p))
            if part["high"]:
                out.append((str(part["high"]), p))
    return out


# ----------------------------------------------------------------------------- the model


@dataclass(frozen=True, eq=False)
class BodyModel:
    """The MakeHuman body: mesh, macro targets, rig, weights (load with :meth:`load`)."""

    meta: dict[str, Any]
    base: F64  # (N, 3) metres: the mesh vertices, then joint-cube vertices
    n_vertices: int  # mesh vertices (the first n_vertices of ``base``)
    faces: NDArray[np.int32]  # (T, 3)
    face_group: NDArray[np.uint8]  # (T,) index into group_names
    face_uv: NDArray[np.float32]  # (T, 3, 2) UV per corner
    vertex_label: NDArray[np.uint8]  # (V,) index into label_names
    vertex_side: NDArray[np.int8]  # (V,) 1 left, 0 middle, -1 right
    skin_bone: I64  # (V, 4)
    skin_weight: F64  # (V, 4), rows sum to 1
    joint_points: I64  # (P, 8) indices into base, -1 padded
    target_rows: list[I64]
    target_offsets: list[F64]  # metres, (rows, 3) each
    bone_parent: I64  # (B,) -1 for the root
    bone_roll: F64  # (B,)
    bone_head: I64  # (B,) index into joint_points
    bone_tail: I64

    @staticmethod
    def load(path: Path | None = None) -> BodyModel:
        """The model in ``path`` (default: the shipped asset), read once per process."""
        return _load(Path(path) if path is not None else ASSET)

    @property
    def group_names(self) -> list[str]:
        return list(self.meta["groups"])

    @property
    def label_names(self) -> list[str]:
        return list(self.meta["labels"])

    @property
    def bone_names(self) -> list[str]:
        return [b["name"] for b in self.meta["rig"]["bones"]]

    def bone(self, name: str) -> int:
        """Index of the bone ``name``."""
        return _bone_index(self)[name]

    def target_weights(self, shape: BodyShape, height: float) -> F64:
        """Weight of each stored target for ``shape`` at MakeHuman height slider ``height``.

        MPFB's ``calculate_target_stack_from_macro_info_dict``: ``universal`` targets weigh
        gender x age x muscle x weight; ``height`` and ``proportions`` targets that times
        the height or proportions weight; ethnic targets race share x gender x age.
        """
        parts = self.meta["macrotargets"]["height"]["parts"]
        return self._weights(shape, macro_components(parts, height))

    def _weights(self, shape: BodyShape, height: list[tuple[str, float]]) -> F64:
        macro = self.meta["macrotargets"]
        comp = {
            "gender": macro_components(macro["gender"]["parts"], shape.sex),
            "age": macro_components(macro["age"]["parts"], age_slider(shape.age_years)),
            "muscle": macro_components(macro["muscle"]["parts"], shape.muscle),
            "weight": macro_components(macro["weight"]["parts"], shape.weight),
            "proportions": macro_components(macro["proportions"]["parts"], shape.proportions),
        }
        index: dict[str, int] = self.meta["targets"]
        out = np.zeros(len(self.target_rows))

        def add(name: str, w: float) -> None:
            if name not in index:
                raise KeyError(f"the body model has no target {name}")
            out[index[name]] += w

        total = sum(shape.ancestry)
        for race, share in zip(self.meta["macro_values"]["race"], shape.ancestry, strict=True):
            for g, wg in comp["gender"]:
                for a, wa in comp["age"]:
                    if share > 0:
                        add(f"macrodetails/{race}-{g}-{a}", share / total * wg * wa)
        for g, wg in comp["gender"]:
            for a, wa in comp["age"]:
                for m, wm in comp["muscle"]:
                    for w, ww in comp["weight"]:
                        base = wg * wa * wm * ww
                        add(f"macrodetails/universal-{g}-{a}-{m}-{w}", base)
                        for h, wh in height:
                            add(f"macrodetails/height/{g}-{a}-{m}-{w}-{h}", base * wh)
                        for p, wp in comp["proportions"]:
                            add(f"macrodetails/proportions/{g}-{a}-{m}-{w}-{p}", base * wp)
        return out

    def blend(self, weights: F64, base: F64 | None = None) -> F64:
        """``base`` (default: the base mesh) plus the weighted targets, in the order stored."""
        out = (self.base if base is None else base).copy()
        for k in np.flatnonzero(weights):
            rows = self.target_rows[k]
            out[rows] = out[rows] + float(weights[k]) * self.target_offsets[k]
        return out

    def shaped(self, shape: BodyShape) -> RestBody:
        """The body of ``shape`` in its rest pose, ``shape.height_m`` tall, soles on z = 0.

        MakeHuman's height slider is chosen (by bisection) so that the blended mesh is as
        tall as asked, within the slider's range; a uniform scale then makes the height
        exact. Height is the skin's (group ``body``) top minus its lowest point.
        """
        return _shaped(self, shape)

    def skin_vertex_indices(self) -> I64:
        """The vertices of the skin (group ``body``)."""
        return _skin_vertices(self)

    def _height_slider(self, shape: BodyShape) -> tuple[float, F64]:
        """The height slider for ``shape`` and the blended vertices at it.

        The blend is linear in the height weights: vertices(s) = no_height + c_min(s) D_min
        + c_max(s) D_max, where D are the weighted min- and max-height targets.
        """
        parts = self.meta["macrotargets"]["height"]["parts"]
        w0 = self._weights(shape, [])
        no_height = self.blend(w0)
        zero = np.zeros_like(self.base)
        d_min = self.blend(self._weights(shape, [("minheight", 1.0)]) - w0, zero)
        d_max = self.blend(self._weights(shape, [("maxheight", 1.0)]) - w0, zero)
        skin = self.skin_vertex_indices()

        def at(s: float, rows: I64 | slice) -> F64:
            out = no_height[rows]
            for name, w in macro_components(parts, s):
                out = out + w * (d_min if name == "minheight" else d_max)[rows]
            return out

        def height(s: float) -> float:
            z = at(s, skin)[:, 2]
            return float(z.max() - z.min())

        lo, hi = 0.0, 1.0
        if height(lo) >= shape.height_m:
            s = lo
        elif height(hi) <= shape.height_m:
            s = hi
        else:
            for _ in range(40):
                mid = 0.5 * (lo + hi)
                if height(mid) < shape.height_m:
                    lo = mid
                else:
                    hi = mid
            s = 0.5 * (lo + hi)
        return s, at(s, slice(None))


@lru_cache(maxsize=4)
def _bone_index(model: BodyModel) -> dict[str, int]:
    return {name: i for i, name in enumerate(model.bone_names)}


@lru_cache(maxsize=4)
def _skin_vertices(model: BodyModel) -> I64:
    out = np.unique(model.faces[model.face_group == 0]).astype(np.int64)
    out.setflags(write=False)
    return out


@lru_cache(maxsize=4)
def _load(path: Path) -> BodyModel:
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(bytes(arrays["meta"]).decode())
    units = meta["units"]
    ptr = arrays["target_ptr"].astype(np.int64)
    steps = arrays["target_row_steps"].astype(np.int64)
    offsets = (arrays["target_hi"].astype(np.int64) * 256 + arrays["target_lo"]).T
    rows_list, offsets_list = [], []
    for a, b in itertools.pairwise(ptr):
        rows_list.append(np.cumsum(steps[a:b]))
        offsets_list.append(offsets[a:b] * float(units["offsets_m"]))
    bones = meta["rig"]["bones"]
    weight = arrays["skin_weight"].astype(np.float64)
    total = ((weight[:, 0] + weight[:, 1]) + weight[:, 2]) + weight[:, 3]
    return BodyModel(
        meta=meta,
        base=arrays["vertices"].astype(np.float64) * float(units["vertices_m"]),
        n_vertices=int(meta["n_mesh_vertices"]),
        faces=arrays["faces"],
        face_group=arrays["face_group"],
        face_uv=arrays["face_uv"],
        vertex_label=arrays["vertex_label"],
        vertex_side=arrays["vertex_side"],
        skin_bone=arrays["skin_bone"].astype(np.int64),
        skin_weight=weight / total[:, None],
        joint_points=arrays["joint_points"].astype(np.int64),
        target_rows=rows_list,
        target_offsets=offsets_list,
        bone_parent=np.asarray([b["parent"] for b in bones], dtype=np.int64),
        bone_roll=np.asarray([b["roll"] for b in bones], dtype=np.float64),
        bone_head=np.asarray([b["head"] for b in bones], dtype=np.int64),
        bone_tail=np.asarray([b["tail"] for b in bones], dtype=np.int64),
    )


# ----------------------------------------------------------------------------- rest body


def _joint_positions(vertices: F64, points: I64) -> F64:
    """Mean of each point's vertices (a fixed order of exact operations)."""
    valid = points >= 0
    count = valid.sum(axis=1).astype(np.float64)
    total = np.zeros((len(points), 3))
    for k in range(points.shape[1]):
        total = total + np.where(valid[:, k, None], vertices[np.maximum(points[:, k], 0)], 0.0)
    out: F64 = total / count[:, None]
    return out


def _to_blender(v: F64) -> F64:
    """Body frame (x forward, y left, z up) to Blender's (x left, y backward, z up)."""
    return np.stack([v[..., 1], -v[..., 0], v[..., 2]], axis=-1)


def _from_blender(v: F64) -> F64:
    return np.stack([-v[..., 1], v[..., 0], v[..., 2]], axis=-1)


def _axis_angle(axis: F64, angle: float) -> F64:
    """Rotation matrix about unit ``axis`` by ``angle`` (right-handed)."""
    s, c = exact.sincos(float(angle))
    x, y, z = (float(a) for a in axis)
    t = 1.0 - c
    return np.array(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def bone_rest_rotation(head: F64, tail: F64, roll: float) -> F64:
    """A bone's rest axes (columns, body frame) from its ends and roll, as Blender makes them.

    Blender's ``vec_roll_to_mat3_normalized`` (in Blender's frame): y along the bone; the
    rotation that takes Blender's y axis to the bone by the shortest arc, then a turn of
    ``roll`` about the bone.
    """
    d = _to_blender(np.asarray(tail, dtype=np.float64) - np.asarray(head, dtype=np.float64))
    nor = d / float(exact.norm(d))
    x, y, z = (float(a) for a in nor)
    theta = 1.0 + y
    theta_alt = x * x + z * z
    if theta > 1.0e-5 or theta_alt > 1.0e-9:
        if theta <= 1.0e-5:
            theta = theta_alt * 0.5 + theta_alt * theta_alt * 0.125
        b = np.array(
            [
                [1.0 - x * x / theta, x, -x * z / theta],
                [-x, y, -z],
                [-x * z / theta, z, 1.0 - z * z / theta],
            ]
        )
    else:
        b = np.diag([-1.0, -1.0, 1.0])
    m = exact.matmul(_axis_angle(nor, roll), b)
    return _from_blender(m.T).T  # each column (an axis) back to the body frame


@dataclass(frozen=True, eq=False)
class RestBody:
    """One person's body in the rest pose (metres, body frame)."""

    model: BodyModel
    shape: BodyShape
    height_slider: float  # MakeHuman's height value used before the exact scaling
    all_vertices: F64  # (N, 3) mesh vertices then joint-cube vertices
    joints: F64  # (P, 3) bone-end points
    rest_rotation: F64  # (B, 3, 3) bone axes (columns)
    rest_head: F64  # (B, 3)
    _poses: dict[Any, Pose] = field(default_factory=dict, repr=False, compare=False)
    _vectors: dict[Any, Any] = field(default_factory=dict, repr=False, compare=False)

    @property
    def vertices(self) -> F64:
        """Mesh vertices (V, 3) in the rest pose."""
        out: F64 = self.all_vertices[: self.model.n_vertices]
        return out

    def bone_head(self, name: str) -> F64:
        """Rest position of the head of bone ``name``."""
        out: F64 = self.rest_head[self.model.bone(name)]
        return out

    def sole_vertices(self) -> I64:
        """Skin vertices of the feet within 3 cm of the floor at rest (the soles)."""
        cached: I64 | None = self._vectors.get("sole")
        if cached is None:
            m = self.model
            foot = m.label_names.index("foot")
            skin = m.skin_vertex_indices()
            cached = skin[(m.vertex_label[skin] == foot) & (self.vertices[skin, 2] < 0.03)]
            self._vectors["sole"] = cached
        return cached

    def bone_tail(self, name: str) -> F64:
        """Rest position of the tail of bone ``name``."""
        out: F64 = self.joints[self.model.bone_tail[self.model.bone(name)]]
        return out

    def bone_matrices(self, pose: Pose) -> tuple[F64, F64]:
        """Posed bone axes (B, 3, 3) and heads (B, 3), world frame."""
        skin_r, skin_t = self.skinning(pose)
        return _bmm(skin_r, self.rest_rotation), _bmv(skin_r, self.rest_head) + skin_t

    def skinning(self, pose: Pose) -> tuple[F64, F64]:
        """Per bone, the rotation (B, 3, 3) and translation (B, 3) taking rest to posed (world)."""
        skin_r, skin_t = _forward_kinematics(self, pose)
        heading = np.broadcast_to(exact.rotation_z(pose.heading), skin_r.shape)
        place = np.asarray(pose.translation, dtype=np.float64)
        return _bmm(heading, skin_r), _bmv(heading, skin_t) + place

    def posed(self, pose: Pose) -> F64:
        """Mesh vertices (V, 3) in ``pose``, world frame (linear-blend skinning)."""
        skin_r, skin_t = self.skinning(pose)
        return _skin(self.vertices, self.model.skin_bone, self.model.skin_weight, skin_r, skin_t)

    def skinned(self, vertices: F64, pose: Pose) -> F64:
        """Other rest positions of this body's mesh vertices (V, 3), e.g. pushed out by the
        thickness of clothes, in ``pose`` with this body's skinning weights."""
        skin_r, skin_t = self.skinning(pose)
        return _skin(vertices, self.model.skin_bone, self.model.skin_weight, skin_r, skin_t)

    def walk_vertices(
        self,
        phase: float,
        stride_m: float | None = None,
        heading: float = 0.0,
        translation: tuple[float, float, float] = (0.0, 0.0, 0.0),
        speed_mps: float | None = None,
    ) -> F64:
        """Mesh vertices (V, 3) walking: :func:`walk_pose` at ``phase``, turned by ``heading``
        and moved by ``translation``, fast.

        The cycle is posed once per stride at VERTEX_PHASES phases (kept in float32: 7 MB,
        about 2 s of CPU; the last WALK_TABLES strides are kept); a phase between them is
        interpolated linearly, vertex by vertex. In the body frame a planted foot moves back
        uniformly, so the interpolation keeps it in place.
        """
        stride = _stride(self, stride_m, speed_mps)
        key = ("vertices", stride)
        table = self._vectors.pop(key, None)
        if table is None:
            n = VERTEX_PHASES
            table = np.empty((n, self.model.n_vertices, 3), dtype=np.float32)
            for i in range(n):
                table[i] = self.posed(walk_pose(self, i / n, stride))
            tables = [k for k in self._vectors if isinstance(k, tuple) and k[0] == "vertices"]
            for old in tables[: max(len(tables) - WALK_TABLES + 1, 0)]:
                del self._vectors[old]
        self._vectors[key] = table  # the most recently used last
        n = len(table)
        x = (phase - math.floor(phase)) * n
        i = min(int(x), n - 1)
        t = x - i
        a = table[i].astype(np.float64)
        b = table[(i + 1) % n].astype(np.float64)
        v = a + t * (b - a)
        r = exact.rotation_z(heading)
        x0, y0 = v[:, 0:1], v[:, 1:2]
        out = np.concatenate(
            [r[0, 0] * x0 + r[0, 1] * y0, r[1, 0] * x0 + r[1, 1] * y0, v[:, 2:3]], axis=1
        )
        out = out + np.asarray(translation, dtype=np.float64)
        return out


@lru_cache(maxsize=16)  # a body keeps its walk tables (7 MB per stride): a few people's worth
def _shaped(model: BodyModel, shape: BodyShape) -> RestBody:
    slider, blended = model._height_slider(shape)
    z = blended[model.skin_vertex_indices(), 2]
    bottom, top = float(z.min()), float(z.max())
    joints = _joint_positions(blended, model.joint_points)
    ankles = [
        joints[model.bone_head[model.bone("foot.L")]],
        joints[model.bone_head[model.bone("foot.R")]],
    ]
    origin = np.array(
        [0.5 * (ankles[0][0] + ankles[1][0]), 0.5 * (ankles[0][1] + ankles[1][1]), bottom]
    )
    scale = shape.height_m / (top - bottom)
    vertices = (blended - origin) * scale
    joints = _joint_positions(vertices, model.joint_points)
    heads = joints[model.bone_head]
    tails = joints[model.bone_tail]
    rot = np.stack(
        [
            bone_rest_rotation(h, t, float(r))
            for h, t, r in zip(heads, tails, model.bone_roll, strict=True)
        ]
    )
    return RestBody(model, shape, slider, vertices, joints, rot, heads)


# ----------------------------------------------------------------------------- posing


@dataclass(frozen=True)
class Pose:
    """Local joint rotations, and where the body stands.

    ``rotations`` maps a bone name to Euler angles (rx, ry, rz) in radians about the bone's
    own rest axes (Blender's XYZ order: x first; y runs along the bone, head to tail; the
    rig's roll sets x and z). ``root_offset`` moves the root bone (body frame, metres);
    the posed body is then turned by ``heading`` (radians about z, 0: facing +x) and moved
    by ``translation`` (world, metres).
    """

    rotations: Mapping[str, tuple[float, float, float]] = field(default_factory=dict)
    root_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    heading: float = 0.0
    translation: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def placed(self, translation: tuple[float, float, float], heading: float) -> Pose:
        """The same pose at another place and heading."""
        return Pose(self.rotations, self.root_offset, heading, translation)


def euler_matrix(rx: F64 | float, ry: F64 | float, rz: F64 | float) -> F64:
    """Rotation matrices Rz Ry Rx (Blender's XYZ Euler) for arrays of angles: (..., 3, 3)."""
    sx, cx = exact.sincos(np.asarray(rx, dtype=np.float64))
    sy, cy = exact.sincos(np.asarray(ry, dtype=np.float64))
    sz, cz = exact.sincos(np.asarray(rz, dtype=np.float64))
    return np.stack(
        [
            np.stack([cy * cz, sx * sy * cz - cx * sz, cx * sy * cz + sx * sz], axis=-1),
            np.stack([cy * sz, sx * sy * sz + cx * cz, cx * sy * sz - sx * cz], axis=-1),
            np.stack([-sy, sx * cy, cx * cy], axis=-1),
        ],
        axis=-2,
    )


def euler_from_matrix(m: F64) -> tuple[float, float, float]:
    """(rx, ry, rz) with Rz Ry Rx = ``m`` (ry in [-pi/2, pi/2])."""
    cy = math.sqrt(float(m[0, 0]) * float(m[0, 0]) + float(m[1, 0]) * float(m[1, 0]))
    ry = exact.atan2(-float(m[2, 0]), cy)
    if cy > 1e-12:
        return (
            exact.atan2(float(m[2, 1]), float(m[2, 2])),
            ry,
            exact.atan2(float(m[1, 0]), float(m[0, 0])),
        )
    return exact.atan2(-float(m[1, 2]), float(m[1, 1])), ry, 0.0


def _bmm(a: F64, b: F64) -> F64:
    """Batched 3x3 products a[i] b[i], summing k = 0, 1, 2 in order."""
    out: F64 = a[..., :, 0:1] * b[..., 0:1, :]
    out = out + a[..., :, 1:2] * b[..., 1:2, :]
    out = out + a[..., :, 2:3] * b[..., 2:3, :]
    return out


def _bmv(a: F64, v: F64) -> F64:
    """Batched matrix-vector products a[i] v[i]."""
    out: F64 = a[..., :, 0] * v[..., 0:1]
    out = out + a[..., :, 1] * v[..., 1:2]
    out = out + a[..., :, 2] * v[..., 2:3]
    return out


@lru_cache(maxsize=8)
def _levels(parents: tuple[int, ...]) -> list[I64]:
    """Bone indices grouped by depth in the tree (parents first)."""
    depth = [0] * len(parents)
    for i, p in enumerate(parents):
        depth[i] = 0 if p < 0 else depth[p] + 1  # parents come before children
    return [np.asarray([i for i, d in enumerate(depth) if d == k]) for k in range(max(depth) + 1)]


def _forward_kinematics(body: RestBody, pose: Pose) -> tuple[F64, F64]:
    """Per bone, S and t with posed = S rest + t (body frame).

    A bone's local rotation L about its rest axes R is Q = R L R^T in the body's axes; a
    bone turns with its parent, S = S_parent Q, and its head moves with its parent, so
    t = t_parent + (S_parent - S) head. Q is computed as I + R (L - I) R^T so that a bone at
    rest has exactly S = I and t = t_parent: the rest pose skins to the rest vertices, bit
    for bit.
    """
    model = body.model
    n = len(model.bone_names)
    angles = np.zeros((n, 3))
    for name, rxyz in pose.rotations.items():
        angles[model.bone(name)] = rxyz
    eye = np.eye(3)
    local = euler_matrix(angles[:, 0], angles[:, 1], angles[:, 2]) - eye
    rest_r = body.rest_rotation
    q = _bmm(_bmm(rest_r, local), np.swapaxes(rest_r, 1, 2)) + eye
    parent = model.bone_parent
    heads = body.rest_head
    skin_r = np.zeros((n, 3, 3))
    skin_t = np.zeros((n, 3))
    offset = np.asarray(pose.root_offset, dtype=np.float64)
    for level in _levels(tuple(int(x) for x in parent)):
        top = parent[level] < 0
        p = np.maximum(parent[level], 0)
        pr = np.where(top[:, None, None], eye, skin_r[p])
        pt = np.where(top[:, None], offset, skin_t[p])
        r = _bmm(pr, q[level])
        skin_r[level] = r
        skin_t[level] = pt + _bmv(pr - r, heads[level])
    return skin_r, skin_t


def _skin(vertices: F64, bones: I64, weights: F64, skin_r: F64, skin_t: F64) -> F64:
    """Linear-blend skinning, sum_k w_k (R_k v + t_k), as M_0 + sum_k>0 w_k (M_k - M_0)."""
    m = np.concatenate([skin_r, skin_t[:, :, None]], axis=2).reshape(len(skin_r), 12)
    b = m[bones[:, 0]]
    for k in range(1, bones.shape[1]):
        b = b + weights[:, k : k + 1] * (m[bones[:, k]] - m[bones[:, 0]])
    x, y, z = vertices[:, 0:1], vertices[:, 1:2], vertices[:, 2:3]
    out = np.concatenate(
        [
            ((b[:, 0:1] * x + b[:, 1:2] * y) + b[:, 2:3] * z) + b[:, 3:4],
            ((b[:, 4:5] * x + b[:, 5:6] * y) + b[:, 6:7] * z) + b[:, 7:8],
            ((b[:, 8:9] * x + b[:, 9:10] * y) + b[:, 10:11] * z) + b[:, 11:12],
        ],
        axis=1,
    )
    return out


def vertex_normals(vertices: F64, faces: NDArray[np.int32]) -> F64:
    """Unit vertex normals: area-weighted sums of the face normals (in face order)."""
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    n = exact.cross(b - a, c - a)
    out = np.zeros_like(vertices)
    for axis in range(3):
        for corner in range(3):
            out[:, axis] += np.bincount(faces[:, corner], n[:, axis], minlength=len(vertices))
    length = exact.norm(out)
    normals: F64 = out / np.maximum(length, 1e-300)[:, None]
    return normals


# ----------------------------------------------------------------------------- helpers


def _rotation_between(a: F64, b: F64) -> F64:
    """The shortest rotation taking unit vector ``a`` to unit vector ``b``."""
    v = exact.cross(a, b)
    c = float(exact.dot(a, b))
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    if c < -1.0 + 1e-12:  # opposite: half a turn about any axis normal to a
        axis = exact.cross(
            a, np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        )
        axis = axis / float(exact.norm(axis))
        return 2.0 * np.outer(axis, axis) - np.eye(3)
    out: F64 = np.eye(3) + k + exact.matmul(k, k) / (1.0 + c)
    return out


def _unit(v: F64) -> F64:
    out: F64 = v / float(exact.norm(v))
    return out


def _local_euler(
    body: RestBody, bone: int, parent_r: F64, world_r: F64
) -> tuple[float, float, float]:
    """Euler angles of ``bone`` that turn it by ``world_r`` (body axes) under a parent turned
    by ``parent_r``: S = S_parent Q, L = R^T Q R."""
    q = exact.matmul(parent_r.T, world_r)
    rest = body.rest_rotation[bone]
    return euler_from_matrix(exact.matmul(exact.matmul(rest.T, q), rest))


def _two_bone(root: F64, target: F64, pole: F64, l1: float, l2: float) -> tuple[F64, F64]:
    """Middle joint and end of a two-bone chain from ``root`` reaching for ``target``, the
    middle joint towards ``pole`` (the chain is stretched straight if the target is too far)."""
    d = target - root
    dist = float(exact.norm(d))
    u = d / dist
    reach = (l1 + l2) * 0.9999
    if dist > reach:
        dist = reach
    dist = max(dist, abs(l1 - l2) * 1.0001)
    end = root + u * dist
    along = (l1 * l1 - l2 * l2 + dist * dist) / (2.0 * dist)
    side = math.sqrt(max(l1 * l1 - along * along, 0.0))
    p = pole - root
    n = p - u * float(exact.dot(u, p))
    n = n / float(exact.norm(n))
    return root + u * along + n * side, end


# ----------------------------------------------------------------------------- walk cycle


@dataclass(frozen=True, eq=False)
class WalkCycle:
    """MPFB's walk cycle (``crappy_experimental_female.json``): Blender f-curves of Bezier keys.

    ``keys[c]`` holds curve c's keys as (frame, value, left handle x, y, right handle x, y),
    padded by repeating the last key; ``channels`` maps (bone, channel) to the rows of its
    x, y, z curves. The cycle runs over frames 0..``frames``; a curve whose keys stop before
    ``frames`` goes on to its first key again at ``frames``.
    """

    channels: dict[tuple[str, str], int]
    keys: F64  # (C, K, 6)
    n_keys: I64  # (C,)
    frames: float
    leg_length: float  # of the body it was made on (metres): to scale it to another
    arm_length: float

    @staticmethod
    def from_meta(walk: dict[str, Any]) -> WalkCycle:
        rows: list[list[list[float]]] = []
        channels: dict[tuple[str, str], int] = {}
        for bone in sorted(walk["curves"]):
            for channel in sorted(walk["curves"][bone]):
                channels[(bone, channel)] = len(rows)
                rows.extend(walk["curves"][bone][channel])
        # a curve whose keys stop before the cycle's last frame runs on to its first key, a
        # cycle later (the toes' keys stop at frame 35 of 40)
        end = max(key[0] for r in rows for key in r)
        for r in rows:
            if r[-1][0] < end and r[0][0] == 0.0:
                f, v, lx, ly, rx, ry = r[0]
                r.append([f + end, v, lx + end, ly, rx + end, ry])
        k = max(len(r) for r in rows)
        keys = np.asarray([r + [r[-1]] * (k - len(r)) for r in rows], dtype=np.float64)
        meta = walk["metadata"]
        return WalkCycle(
            channels,
            keys,
            np.asarray([len(r) for r in rows], dtype=np.int64),
            float(keys[:, :, 0].max()),
            float(meta["leg_length"]),
            float(meta["arm_length"]),
        )

    def evaluate(self, frame: float) -> F64:
        """Every curve's value at ``frame`` (C,): Blender's Bezier interpolation between keys,
        the first or last key's value outside them.

        Each key's handles lie within its segment (MPFB's auto-clamped handles at a third of
        it), so a segment's x(u) rises monotonically and is inverted by bisection.
        """
        k = self.keys
        c = np.arange(len(k))
        last = self.n_keys - 1
        seg = np.minimum(
            np.maximum((k[:, :, 0] <= frame).sum(axis=1) - 1, 0), np.maximum(last - 1, 0)
        )
        k0, k1 = k[c, seg], k[c, np.minimum(seg + 1, last)]
        x0, x1, x2, x3 = k0[:, 0], k0[:, 4], k1[:, 2], k1[:, 0]
        y0, y1, y2, y3 = k0[:, 1], k0[:, 5], k1[:, 3], k1[:, 1]
        lo, hi = np.zeros(len(k)), np.ones(len(k))
        for _ in range(48):
            u = 0.5 * (lo + hi)
            v = 1.0 - u
            x = ((v * v * v) * x0 + (3.0 * v * v * u) * x1) + (
                (3.0 * v * u * u) * x2 + (u * u * u) * x3
            )
            below = x < frame
            lo, hi = np.where(below, u, lo), np.where(below, hi, u)
        u = 0.5 * (lo + hi)
        v = 1.0 - u
        y = ((v * v * v) * y0 + (3.0 * v * v * u) * y1) + (
            (3.0 * v * u * u) * y2 + (u * u * u) * y3
        )
        out = np.where(frame <= k[:, 0, 0], k[:, 0, 1], y)
        out = np.where(frame >= k[c, last, 0], k[c, last, 1], out)
        return np.asarray(out, dtype=np.float64)

    def get(self, values: F64, bone: str, channel: str, default: float = 0.0) -> F64:
        """The (x, y, z) of ``bone``'s ``channel`` from :meth:`evaluate`'s values."""
        row = self.channels.get((bone, channel))
        if row is None:
            return np.full(3, default)
        return np.asarray(values[row : row + 3], dtype=np.float64)


@lru_cache(maxsize=4)
def _walk_cycle(model: BodyModel) -> WalkCycle:
    return WalkCycle.from_meta(model.meta["walk"])


def _chain_length(body: RestBody, bones: tuple[str, ...]) -> float:
    return sum(float(exact.norm(body.bone_tail(b) - body.bone_head(b))) for b in bones)


_LEG = ("upperleg01", "upperleg02", "lowerleg01", "lowerleg02")
_ARM = ("upperarm01", "upperarm02", "lowerarm01", "lowerarm02")
#: Bones the walk cycle poses directly (the others follow from its IK targets).
_WALK_FK = (
    "root",
    "spine05",
    "spine04",
    "spine03",
    "spine02",
    "spine01",
    "neck01",
    "head",
    "clavicle.L",
    "clavicle.R",
    "toe1-1.L",
    "toe1-1.R",
)


#: Phases per cycle of the foot-lock table and of the posed-vertex cache; strides cached.
LOCK_SAMPLES = 32
VERTEX_PHASES = 32
WALK_TABLES = 4
#: A sole vertex touches the floor when it is this low (metres).
CONTACT_M = 0.003
#: How far the pelvis may drop below the cycle's for a leg to reach its foot (metres).
MAX_DROP_M = 0.015
#: Added height of a swinging foot at mid-swing: the cycle's toes clear the floor by only
#: millimetres on some bodies, where people's clear it by 1-2 cm (metres).
SWING_LIFT_M = 0.02
#: Sekiya & Nagasaki (1998): the walk ratio, step length over cadence, stays near
#: 0.0064 m/(steps/min) in young adults across walking speeds; scaled here by height / 1.70 m.
WALK_RATIO = 0.0064


def natural_stride(body: RestBody, speed_mps: float) -> float:
    """Stride length (two steps, metres) of a person walking at ``speed_mps``.

    With a constant walk ratio r = step / cadence (steps per minute), speed v = step x
    cadence / 60 gives step = sqrt(60 v r).
    """
    ratio = WALK_RATIO * body.shape.height_m / 1.70
    return 2.0 * math.sqrt(60.0 * max(float(speed_mps), 0.0) * ratio)


def walk_pose(
    body: RestBody, phase: float, stride_m: float | None = None, speed_mps: float | None = None
) -> Pose:
    """The pose at ``phase`` (cycles; 0 and 1 the same) of MPFB's walk cycle.

    The cycle is evaluated as Blender would: the f-curves at frame ``phase x frames``; root,
    spine, neck, head, clavicles and toes directly; legs and arms by two-bone IK towards
    MPFB's IK helper bones (``*_foot_ik`` and ``*_hand_ik`` at the foot and hand bones' rest
    frames, whose rotation the foot and hand copy; ``*_knee_ik`` and ``*_elbow_ik`` past
    the knee and elbow, bending them towards themselves). Lengths are scaled from the body
    the cycle was made on by the ratio of leg (arm) lengths.

    The feet targets are in the world and move forward one stride per cycle; the pose is in
    a body frame that moves forward uniformly, ``stride_m`` per cycle (default: the
    :func:`natural_stride` of ``speed_mps`` if given, else the cycle's own, scaled: a slow
    walk), so a caller moving the body ``stride_m`` per cycle keeps a planted foot in place. Fixes to the
    recorded cycle: its small mismatches between the first and last frame (2 cm of pelvis
    height, 1 cm of foot width) are spread linearly over the cycle; another stride scales
    the forward positions of the feet and pelvis, and the pelvis is lowered where a leg
    could not reach its foot; a foot on the floor is held where it is (the cycle's planted
    feet slide 2-6 cm; :func:`_foot_lock`); last, the body is moved up or down so that its
    lowest sole point touches z = 0 (a walker always has a foot on the ground).
    """
    stride = _stride(body, stride_m, speed_mps)
    phase = phase - math.floor(phase)
    lock = _foot_lock(body, stride)
    x = phase * LOCK_SAMPLES
    i = min(int(x), LOCK_SAMPLES - 1)
    t = x - i
    return _walk_pose(body, phase, stride, lock[i] + t * (lock[i + 1] - lock[i]))


def _stride(body: RestBody, stride_m: float | None, speed_mps: float | None) -> float:
    if stride_m is not None:
        return float(stride_m)
    if speed_mps is not None:
        return natural_stride(body, speed_mps)
    return _walk_stride(body)


def _walk_vector(body: RestBody, phase: float, stride: float) -> F64:
    """What the cycle gives at ``phase`` in [0, 1], body frame, before the periodic fix.

    Layout: the Euler angles of :data:`_WALK_FK` (12 x 3), the root offset (3), then per
    side (L, R): foot target, knee target, foot Euler, hand location, elbow location and
    hand Euler (6 x 3 each).
    """
    model = body.model
    cycle = _walk_cycle(model)
    values = cycle.evaluate(phase * cycle.frames)
    k_leg = _chain_length(body, tuple(b + ".L" for b in _LEG)) / cycle.leg_length
    own = _walk_stride(body)
    f = stride / own

    def rest_r(name: str) -> F64:
        out: F64 = body.rest_rotation[model.bone(name)]
        return out

    def to_body(p: F64) -> F64:
        return np.array([f * (float(p[0]) - own * phase), float(p[1]), float(p[2])])

    parts = [cycle.get(values, bone, "rotation_euler") for bone in _WALK_FK]
    parts.append(to_body(_bmv(rest_r("root"), k_leg * cycle.get(values, "root", "location"))))
    for side, name in (("L", "left"), ("R", "right")):
        ankle = body.bone_head(f"foot.{side}")
        knee = body.bone_tail(f"upperleg02.{side}")
        step = cycle.get(values, f"{name}_foot_ik", "location")
        parts.append(to_body(ankle + _bmv(rest_r(f"foot.{side}"), k_leg * step)))
        r_knee = _knee_helper(body, side)
        bend = cycle.get(values, f"{name}_knee_ik", "location")
        parts.append(to_body(knee + _bmv(r_knee, k_leg * bend)))
        parts.append(cycle.get(values, f"{name}_foot_ik", "rotation_euler"))
        parts.append(cycle.get(values, f"{name}_hand_ik", "location"))
        parts.append(cycle.get(values, f"{name}_elbow_ik", "location"))
        parts.append(cycle.get(values, f"{name}_hand_ik", "rotation_euler"))
    return np.concatenate(parts)


def _knee_helper(body: RestBody, side: str) -> F64:
    """Rest axes of MPFB's knee IK helper: from the knee on along the thigh's lower bone."""
    knee = body.bone_tail(f"upperleg02.{side}")
    mid = body.bone_head(f"upperleg02.{side}")
    return bone_rest_rotation(knee, knee + (knee - mid) / 5.0, 0.0)


def _elbow_helper(body: RestBody, side: str) -> F64:
    """Rest axes of MPFB's elbow IK helper: from the elbow on along the upper arm's lower bone."""
    elbow = body.bone_tail(f"upperarm02.{side}")
    mid = body.bone_head(f"upperarm02.{side}")
    return bone_rest_rotation(elbow, elbow + (elbow - mid) / 3.0, 0.0)


def _walk_pose(body: RestBody, phase: float, stride: float, lock: F64) -> Pose:
    """The walk pose; ``lock`` (2, 3) moves the L and R foot (and knee) targets."""
    model = body.model
    key = ("ends", stride)
    ends = body._vectors.get(key)
    if ends is None:
        ends = _walk_vector(body, 1.0, stride) - _walk_vector(body, 0.0, stride)
        body._vectors[key] = ends
    q = _walk_vector(body, phase, stride) - phase * ends
    n_fk = len(_WALK_FK)
    rotations: dict[str, tuple[float, float, float]] = {
        bone: _tuple(q[3 * i : 3 * i + 3]) for i, bone in enumerate(_WALK_FK)
    }
    offset = q[3 * n_fk : 3 * n_fk + 3]
    sides = q[3 * n_fk + 3 :].reshape(2, 6, 3)
    cycle = _walk_cycle(model)
    k_arm = _chain_length(body, tuple(b + ".L" for b in _ARM)) / cycle.arm_length

    # lower the pelvis where a leg cannot reach its target, by up to MAX_DROP_M; a leg still
    # short of its target rises on the ball of its foot (the heel comes off the floor)
    skin_r, skin_t = _forward_kinematics(body, Pose(rotations, _tuple(offset)))
    legs = []
    drop = 0.0
    for k, side in enumerate(("L", "R")):
        hip = body.bone_head(f"upperleg01.{side}")
        knee = body.bone_tail(f"upperleg02.{side}")
        ankle = body.bone_head(f"foot.{side}")
        i = model.bone(f"pelvis.{side}")
        start = _bmv(skin_r[i], hip) + skin_t[i]
        target = sides[k, 0] + lock[k]
        r_foot = body.rest_rotation[model.bone(f"foot.{side}")]
        axes = exact.matmul(r_foot, euler_matrix(*sides[k, 2]))
        reach = 0.995 * (float(exact.norm(knee - hip)) + float(exact.norm(ankle - knee)))
        d = target - start
        flat = float(d[0]) * float(d[0]) + float(d[1]) * float(d[1])
        if flat < reach * reach:
            drop = max(drop, -math.sqrt(reach * reach - flat) - float(d[2]))
        legs.append((start, target, axes, reach))
    drop = min(drop, MAX_DROP_M)
    offset = offset - np.array([0.0, 0.0, drop])
    skin_r, skin_t = _forward_kinematics(body, Pose(rotations, _tuple(offset)))

    def posed_point(bone: str, p: F64) -> F64:
        i = model.bone(bone)
        out: F64 = _bmv(skin_r[i], p) + skin_t[i]
        return out

    root = model.bone("root")
    for k, side in enumerate(("L", "R")):
        start, target, axes, reach = legs[k]
        start = start - np.array([0.0, 0.0, drop])
        if float(exact.norm(target - start)) > reach:
            target, axes = _heel_off(body, rotations, side, start, target, axes, reach)
        _, knee_target, _, hand, bend, hand_euler = sides[k]
        hip, knee = body.bone_head(f"upperleg01.{side}"), body.bone_tail(f"upperleg02.{side}")
        _limb(
            body,
            rotations,
            skin_r[model.bone(f"pelvis.{side}")],
            start,
            (f"upperleg01.{side}", f"lowerleg01.{side}", f"foot.{side}"),
            (hip, knee, body.bone_head(f"foot.{side}")),
            target,
            knee_target + lock[k],
            axes,
        )
        # arms: IK helpers that move with the root
        shoulder = body.bone_head(f"upperarm01.{side}")
        elbow, wrist = body.bone_tail(f"upperarm02.{side}"), body.bone_head(f"wrist.{side}")
        r_wrist = body.rest_rotation[model.bone(f"wrist.{side}")]
        target = posed_point("root", wrist + _bmv(r_wrist, k_arm * hand))
        pole = posed_point("root", elbow + _bmv(_elbow_helper(body, side), k_arm * bend))
        axes = exact.matmul(skin_r[root], exact.matmul(r_wrist, euler_matrix(*hand_euler)))
        _limb(
            body,
            rotations,
            skin_r[model.bone(f"shoulder01.{side}")],
            posed_point(f"shoulder01.{side}", shoulder),
            (f"upperarm01.{side}", f"lowerarm01.{side}", f"wrist.{side}"),
            (shoulder, elbow, wrist),
            target,
            pole,
            axes,
        )
    pose = Pose(rotations, _tuple(offset))
    lowest = float(_skin_subset(body, pose, body.sole_vertices())[:, 2].min())
    return Pose(rotations, _tuple(offset - np.array([0.0, 0.0, lowest])))


def _foot_lock(body: RestBody, stride: float) -> F64:
    """Per phase (LOCK_SAMPLES + 1, the last the first again) and foot, the shift (2, 3) that
    holds a foot on the floor in place and lifts it in its swing.

    The cycle is sampled without shifts; while a foot's sole touches the floor (vertices
    below CONTACT_M at two samples running, the longest such run in the cycle: its stance),
    the shift takes back the touching vertices' mean horizontal motion, sample by sample;
    while the foot is in the air the shift returns linearly to zero by its next touch, and
    rises by up to SWING_LIFT_M.
    """
    key = ("lock", stride)
    cached: F64 | None = body._vectors.get(key)
    if cached is not None:
        return cached
    n = LOCK_SAMPLES
    sole = body.sole_vertices()
    side = body.model.vertex_side[sole]
    zero = np.zeros((2, 3))
    world = []
    for i in range(n):
        phase = i / n
        v = _skin_subset(body, _walk_pose(body, phase, stride, zero), sole)
        world.append(v + np.array([stride * phase, 0.0, 0.0]))
    out = np.zeros((n + 1, 2, 3))
    for k, s in enumerate((1, -1)):
        mine = side == s
        step = np.zeros((n, 2))
        touch = np.zeros(n, dtype=bool)
        for i in range(n):
            a, b = world[i][mine], world[(i + 1) % n][mine]
            if (i + 1) == n:
                b = b + np.array([stride, 0.0, 0.0])
            both = (a[:, 2] < CONTACT_M) & (b[:, 2] < CONTACT_M)
            if both.any():
                step[i] = (b[both, :2] - a[both, :2]).mean(axis=0)
                # planted, not brushing the floor in mid-swing (at twice the body's speed and
                # more); a toe leaving the floor may slide at about the body's speed
                touch[i] = float(exact.norm(step[i])) < 4.0 * stride / n
        touch = _longest_run(touch)  # the stance; other touches are a swing brushing the floor
        shift = np.zeros((n + 1, 2))
        if touch.any() and not touch.all():
            start = int(np.flatnonzero(touch & ~np.roll(touch, 1))[0])  # a touch's first step
            i = start
            for _ in range(n - 1):
                j = (i + 1) % n
                if touch[i]:
                    shift[j] = shift[i] - step[i]
                else:  # in the air: back to zero, linearly, by the next touch
                    left = 1
                    while not touch[(i + left) % n]:
                        left += 1
                    shift[j] = 0.0 if left == 1 else shift[i] - shift[i] / left
                i = j
            shift[n] = shift[0]
        out[:, k, :2] = shift
        # and lifted in its swing, by SWING_LIFT_M times a half sine over the samples in the air
        air = ~touch & ~np.roll(touch, 1)
        if air.any() and not air.all():
            start = int(np.flatnonzero(air & ~np.roll(air, 1))[0])
            run: list[int] = []
            for i in [*range(start, n), *range(start)]:
                if air[i]:
                    run.append(i)
                if run and (not air[i] or i == (start - 1) % n):
                    for p, j in enumerate(run, start=1):
                        out[j, k, 2] = SWING_LIFT_M * exact.sin(exact.PI * p / (len(run) + 1))
                    run = []
            out[n, k, 2] = out[0, k, 2]
    body._vectors[key] = out
    return out


def _longest_run(flags: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``flags`` with only its longest run of True kept (runs wrap around the end)."""
    n = len(flags)
    if flags.all() or not flags.any():
        return flags.copy()
    start = int(np.flatnonzero(~flags)[0])  # walk from a False so no run is cut in two
    best: list[int] = []
    run: list[int] = []
    for i in [*range(start, n), *range(start)]:
        if flags[i]:
            run.append(i)
        else:
            run = []
        if len(run) > len(best):
            best = list(run)
    out = np.zeros(n, dtype=bool)
    out[best] = True
    return out


def _heel_off(
    body: RestBody,
    rotations: dict[str, tuple[float, float, float]],
    side: str,
    hip: F64,
    ankle: F64,
    axes: F64,
    reach: float,
) -> tuple[F64, F64]:
    """The ankle target and foot axes with the foot turned about the ball of the foot (its
    toe bone's head) until the ankle is ``reach`` from ``hip`` (at most 1 radian); the toes
    keep their turn in the body frame."""
    model = body.model
    foot, toe = model.bone(f"foot.{side}"), model.bone(f"toe1-1.{side}")
    s_foot = exact.matmul(axes, body.rest_rotation[foot].T)
    ball = ankle + _bmv(s_foot, body.rest_head[toe] - body.rest_head[foot])
    lateral = _unit(_bmv(axes, np.array([1.0, 0.0, 0.0])))
    if float(_bmv(_axis_angle(lateral, 0.1), ankle - ball)[2]) < float((ankle - ball)[2]):
        lateral = -lateral  # turn the way that lifts the heel

    def lifted(angle: float) -> F64:
        return ball + _bmv(_axis_angle(lateral, angle), ankle - ball)

    lo, hi = 0.0, 1.0
    if float(exact.norm(lifted(hi) - hip)) > reach:
        lo = hi
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        if float(exact.norm(lifted(mid) - hip)) > reach:
            lo = mid
        else:
            hi = mid
    turn = _axis_angle(lateral, hi)
    toe_rest = body.rest_rotation[toe]
    e = rotations.get(f"toe1-1.{side}", (0.0, 0.0, 0.0))
    toe_q = exact.matmul(exact.matmul(toe_rest, euler_matrix(*e)), toe_rest.T)
    new_foot = exact.matmul(turn, s_foot)
    rotations[f"toe1-1.{side}"] = _local_euler(body, toe, new_foot, exact.matmul(s_foot, toe_q))
    return lifted(hi), exact.matmul(turn, axes)


def _tuple(v: F64) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _skin_subset(body: RestBody, pose: Pose, rows: I64) -> F64:
    """The posed (body frame) positions of the mesh vertices ``rows``."""
    skin_r, skin_t = _forward_kinematics(body, pose)
    m = body.model
    return _skin(body.vertices[rows], m.skin_bone[rows], m.skin_weight[rows], skin_r, skin_t)


def _limb(
    body: RestBody,
    rotations: dict[str, tuple[float, float, float]],
    parent_r: F64,
    start: F64,
    bones: tuple[str, str, str],
    rest: tuple[F64, F64, F64],
    target: F64,
    pole: F64,
    end_axes: F64 | None,
) -> None:
    """Rotations of a limb (upper bone, lower bone, end bone) reaching ``target``, bending
    towards ``pole``, the end bone's axes ``end_axes`` (None: as the lower bone turns); the
    twist bones in between stay."""
    model = body.model
    j0, j1, j2 = rest
    l1 = float(exact.norm(j1 - j0))
    l2 = float(exact.norm(j2 - j1))
    mid, end = _two_bone(start, target, pole, l1, l2)
    upper = exact.matmul(
        _rotation_between(_unit(_bmv(parent_r, j1 - j0)), _unit(mid - start)), parent_r
    )
    rotations[bones[0]] = _local_euler(body, model.bone(bones[0]), parent_r, upper)
    lower = exact.matmul(_rotation_between(_unit(_bmv(upper, j2 - j1)), _unit(end - mid)), upper)
    rotations[bones[1]] = _local_euler(body, model.bone(bones[1]), upper, lower)
    if end_axes is not None:
        end_rest = body.rest_rotation[model.bone(bones[2])]
        end = exact.matmul(end_axes, end_rest.T)
        rotations[bones[2]] = _local_euler(body, model.bone(bones[2]), lower, end)


def _walk_stride(body: RestBody) -> float:
    """Forward distance the walk cycle's root travels per cycle, scaled to ``body``."""
    cached = body._vectors.get("stride")
    if cached is None:
        cached = np.asarray(_own_stride(body))
        body._vectors["stride"] = cached
    return float(cached)


def _own_stride(body: RestBody) -> float:
    cycle = _walk_cycle(body.model)
    k_leg = _chain_length(body, tuple(b + ".L" for b in _LEG)) / cycle.leg_length
    start = cycle.get(cycle.evaluate(0.0), "root", "location")
    end = cycle.get(cycle.evaluate(cycle.frames), "root", "location")
    travel = _bmv(body.rest_rotation[body.model.bone("root")], k_leg * (end - start))
    return float(travel[0])


def _width(body: RestBody, labels: tuple[str, ...], side: float, z: float) -> float:
    """How far the skin of body parts ``labels`` reaches to ``side`` (+1 left, -1 right) within
    5 cm of height ``z``, rest pose (0 if none there)."""
    m = body.model
    skin = m.skin_vertex_indices()
    ids = [m.label_names.index(label) for label in labels]
    v = body.vertices[skin]
    near = np.isin(m.vertex_label[skin], ids) & (np.abs(v[:, 2] - z) < 0.05) & (v[:, 1] * side > 0)
    return float(np.max(np.abs(v[near, 1]))) if near.any() else 0.0


def _arms_down(
    body: RestBody,
    rotations: dict[str, tuple[float, float, float]],
    skin_r: F64,
    skin_t: F64,
    hands: dict[str, F64] | None = None,
) -> None:
    """Arms hanging beside the body (or reaching ``hands[side]``), elbows bent a little,
    outwards and back, clear of the torso and hips."""
    model = body.model
    for side, sign in (("L", 1.0), ("R", -1.0)):
        shoulder = body.bone_head(f"upperarm01.{side}")
        elbow, wrist = body.bone_tail(f"upperarm02.{side}"), body.bone_head(f"wrist.{side}")
        parent = model.bone(f"shoulder01.{side}")
        start = _bmv(skin_r[parent], shoulder) + skin_t[parent]
        upper = float(exact.norm(elbow - shoulder))
        reach = upper + float(exact.norm(wrist - elbow))
        if hands is not None and side in hands:
            target = hands[side]
        else:
            hand_z = float(start[2]) - 0.96 * reach
            clear = _width(body, ("pelvis", "thigh", "torso"), sign, hand_z) + 0.045
            target = np.array(
                [float(start[0]) + 0.02, sign * max(clear, abs(float(start[1]))), hand_z]
            )
        elbow_z = float(start[2]) - upper
        clear = _width(body, ("torso",), sign, elbow_z) + 0.05
        pole = np.array(
            [float(start[0]) - 0.3, sign * max(clear, abs(float(start[1])) + 0.1), elbow_z]
        )
        _limb(
            body,
            rotations,
            skin_r[parent],
            start,
            (f"upperarm01.{side}", f"lowerarm01.{side}", f"wrist.{side}"),
            (shoulder, elbow, wrist),
            target,
            pole,
            None,
        )


def stand_pose(body: RestBody) -> Pose:
    """Standing at ease: feet under the hips, legs straight, arms hanging beside the body.

    The feet keep their rest orientation, flat on the floor; the pelvis rises as far as the
    straightened legs lift it (the rest A-pose spreads the legs).
    """
    cached = body._poses.get("stand")
    if cached is not None:
        return cached
    model = body.model
    rotations: dict[str, tuple[float, float, float]] = {}
    targets = {}
    lift = -1.0
    for side in ("L", "R"):
        hip, knee = body.bone_head(f"upperleg01.{side}"), body.bone_tail(f"upperleg02.{side}")
        ankle = body.bone_head(f"foot.{side}")
        target = np.array([float(ankle[0]), 0.95 * float(hip[1]), float(ankle[2])])
        reach = 0.998 * (float(exact.norm(knee - hip)) + float(exact.norm(ankle - knee)))
        d = target - hip
        flat = float(d[0]) * float(d[0]) + float(d[1]) * float(d[1])
        lift = max(lift, math.sqrt(reach * reach - flat) + float(d[2]))
        targets[side] = target
    offset = np.array([0.0, 0.0, max(lift, 0.0)])
    skin_r, skin_t = _forward_kinematics(body, Pose(rotations, _tuple(offset)))
    for side in ("L", "R"):
        hip, knee = body.bone_head(f"upperleg01.{side}"), body.bone_tail(f"upperleg02.{side}")
        ankle = body.bone_head(f"foot.{side}")
        pelvis = model.bone(f"pelvis.{side}")
        _limb(
            body,
            rotations,
            skin_r[pelvis],
            _bmv(skin_r[pelvis], hip) + skin_t[pelvis],
            (f"upperleg01.{side}", f"lowerleg01.{side}", f"foot.{side}"),
            (hip, knee, ankle),
            targets[side],
            knee + np.array([0.5, 0.0, 0.0]) + offset,
            body.rest_rotation[model.bone(f"foot.{side}")],
        )
    _arms_down(body, rotations, skin_r, skin_t)
    pose = Pose(rotations, _tuple(offset))
    body._poses["stand"] = pose
    return pose


def _buttocks(body: RestBody) -> I64:
    """Skin vertices of the pelvis and thighs behind the hip joints (rest pose)."""
    model = body.model
    skin = model.skin_vertex_indices()
    parts = [model.label_names.index(x) for x in ("pelvis", "thigh")]
    rows = skin[np.isin(model.vertex_label[skin], parts)]
    hips = float(body.bone_head("upperleg01.L")[0])
    out: I64 = rows[body.vertices[rows, 0] < hips]
    return out


def seat_extent(body: RestBody, pose: Pose, above: float = 0.02) -> tuple[float, float]:
    """The x range (body frame) of the buttocks within ``above`` metres of their lowest point
    in ``pose``: where a seat must be to carry them."""
    v = _skin_subset(body, pose, _buttocks(body))
    low = v[v[:, 2] < float(v[:, 2].min()) + above]
    return float(low[:, 0].min()), float(low[:, 0].max())


def _seated(body: RestBody, drop: float) -> Pose:
    """Sitting with the pelvis ``drop`` below its rest height."""
    model = body.model
    rotations: dict[str, tuple[float, float, float]] = {}
    offset = np.array([0.0, 0.0, -drop])
    skin_r, skin_t = _forward_kinematics(body, Pose(rotations, _tuple(offset)))
    hands = {}
    for side in ("L", "R"):
        hip, knee = body.bone_head(f"upperleg01.{side}"), body.bone_tail(f"upperleg02.{side}")
        ankle = body.bone_head(f"foot.{side}")
        pelvis = model.bone(f"pelvis.{side}")
        start = _bmv(skin_r[pelvis], hip) + skin_t[pelvis]
        thigh = float(exact.norm(knee - hip))
        shin = float(exact.norm(ankle - knee))
        # the thigh forward on the seat, 4 degrees down; the shin down to the foot flat on the
        # floor ahead of the knee, or hanging straight down if the floor is out of reach
        bend = start + thigh * _unit(np.array([1.0, 0.06 * float(np.sign(start[1])), -0.07]))
        height = float(bend[2]) - float(ankle[2])
        ahead = math.sqrt(shin * shin - height * height) if height < shin else 0.0
        target = bend + np.array([ahead, 0.0, -min(height, shin)])
        _limb(
            body,
            rotations,
            skin_r[pelvis],
            start,
            (f"upperleg01.{side}", f"lowerleg01.{side}", f"foot.{side}"),
            (hip, knee, ankle),
            target,
            bend + np.array([0.0, 0.0, 0.05]),
            body.rest_rotation[model.bone(f"foot.{side}")],
        )
        hands[side] = start + np.array([0.55 * thigh, 0.0, 0.11])
    _arms_down(body, rotations, skin_r, skin_t, hands)
    return Pose(rotations, _tuple(offset))


def sit_pose(body: RestBody, seat_height: float = 0.45) -> Pose:
    """Sitting upright on a seat ``seat_height`` high: thighs forward (4 degrees down), shins
    down to the feet flat on the floor (a little ahead of the knees if the shins are longer
    than the seat is high; hanging if shorter), hands on the thighs. The hip joints stay
    above the body origin; :func:`seat_extent` says where the seat must be.

    The pelvis is lowered until the lowest point of the buttocks (the skin of the pelvis
    and thighs behind the hip joints) is at the seat height (four rounds of posing and
    measuring).
    """
    key = ("sit", float(seat_height))
    cached = body._poses.get(key)
    if cached is not None:
        return cached
    rows = _buttocks(body)
    drop = float(body.bone_head("upperleg01.L")[2]) - seat_height - 0.10
    pose = _seated(body, drop)
    for _ in range(4):
        drop += float(_skin_subset(body, pose, rows)[:, 2].min()) - seat_height
        pose = _seated(body, drop)
    body._poses[key] = pose
    return pose
