"""Triangle meshes from a few unit primitives, with per-vertex normals and per-triangle colour.

Every part is a unit primitive (sphere, cylinder, box) mapped by a 4x4 affine
matrix; normals are mapped by the inverse transpose. A :class:`MeshBuilder`
concatenates parts into one :class:`Mesh` whose triangles also carry an object
id (for the id buffer) and a material code (for depth dropout).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact

F64 = NDArray[np.float64]
I32 = NDArray[np.int32]

#: Material codes (per triangle), used by the depth sensor model.
MAT_MATTE = 0
MAT_SHINY = 1
MAT_SKIN = 2
MAT_FLOOR = 3  # matte with a tile pattern
MAT_WALL = 4  # matte, painted plaster: a faint mottle


#: Surface patterns (per triangle), drawn per pixel from the triangle's texture coordinates.
PATTERN_NONE = 0
PATTERN_STRIPES = 1  # bands across v: a striped shirt
PATTERN_CHECK = 2  # two crossing sets of bands: a checked shirt
PATTERN_DOTS = 3  # a print: round dots on a jittered grid
PATTERN_WEAVE = 4  # fine noise of the second colour: denim, knitwear


@dataclass(frozen=True)
class Surface:
    """What a mesh's triangles look like beyond their flat colour (all arrays per triangle).

    ``corner_colours`` (T, 3, 3) are the albedos at the corners, blended across each triangle
    (skin tones, lips, eyebrows); ``uv`` (T, 3, 2) texture coordinates at the corners;
    ``pattern`` (T,) one of the ``PATTERN_*`` codes drawn with ``colour2`` (T, 3) at
    ``scale`` (T,) repeats per texture unit.
    """

    corner_colours: F64
    uv: F64
    pattern: I32
    colour2: F64
    scale: F64
    #: :meth:`detailed`, when known (None: found from the arrays).
    detail: NDArray[np.bool_] | None = None

    def detailed(self) -> NDArray[np.bool_]:
        """Triangles with more than one flat colour: a pattern or corners that differ."""
        if self.detail is not None:
            return self.detail
        cc = self.corner_colours
        varies = (cc != cc[:, :1]).any(axis=(1, 2))
        out: NDArray[np.bool_] = varies | (self.pattern != PATTERN_NONE)
        return out

    @staticmethod
    def plain(colours: F64) -> Surface:
        """Flat colours (T, 3), no texture."""
        c = np.asarray(colours, dtype=np.float64)
        n = len(c)
        return Surface(
            np.repeat(c[:, None, :], 3, axis=1),
            np.zeros((n, 3, 2)),
            np.zeros(n, dtype=np.int32),
            c.copy(),
            np.ones(n),
            np.zeros(n, dtype=bool),
        )


@dataclass(frozen=True)
class Mesh:
    """Concatenated triangles with their attributes (all arrays share the triangle axis)."""

    vertices: F64  # (V, 3)
    normals: F64  # (V, 3) unit vertex normals
    triangles: I32  # (T, 3)
    colours: F64  # (T, 3) albedo in [0, 255]
    object_ids: I32  # (T,)
    materials: I32  # (T,)
    #: Texture and colour detail; None: each triangle's flat colour.
    surface: Surface | None = None
    #: Per triangle: its vertex normals differ (a smooth surface: normals are blended).
    #: None: found from the normals when needed (:meth:`smooth_triangles`).
    smooth: NDArray[np.bool_] | None = None

    @property
    def n_triangles(self) -> int:
        return int(self.triangles.shape[0])

    def smooth_triangles(self) -> NDArray[np.bool_]:
        """Triangles whose vertex normals differ (the shading blends their normals)."""
        if self.smooth is not None:
            return self.smooth
        n = self.normals[self.triangles]  # (T, 3, 3)
        out: NDArray[np.bool_] = np.abs(n - n[:, :1]).max(axis=(1, 2)) > 1e-4
        return out

    def surface_or_plain(self) -> Surface:
        """The surface, or one of flat colours."""
        return self.surface if self.surface is not None else Surface.plain(self.colours)


@lru_cache(maxsize=8)
def unit_sphere(n_lat: int = 8, n_lon: int = 12) -> tuple[F64, I32]:
    """Unit sphere at the origin (vertices double as normals)."""
    verts = [(0.0, 0.0, 1.0)]
    for i in range(1, n_lat):
        sin_th, cos_th = exact.sincos(math.pi * i / n_lat)
        for j in range(n_lon):
            sin_ph, cos_ph = exact.sincos(2.0 * math.pi * j / n_lon)
            verts.append((sin_th * cos_ph, sin_th * sin_ph, cos_th))
    verts.append((0.0, 0.0, -1.0))
    tris: list[tuple[int, int, int]] = []
    for j in range(n_lon):
        tris.append((0, 1 + j, 1 + (j + 1) % n_lon))
    for i in range(n_lat - 2):
        a0 = 1 + i * n_lon
        b0 = a0 + n_lon
        for j in range(n_lon):
            j1 = (j + 1) % n_lon
            tris.append((a0 + j, b0 + j, b0 + j1))
            tris.append((a0 + j, b0 + j1, a0 + j1))
    last = len(verts) - 1
    base = 1 + (n_lat - 2) * n_lon
    for j in range(n_lon):
        tris.append((base + j, last, base + (j + 1) % n_lon))
    return np.asarray(verts, dtype=np.float64), np.asarray(tris, dtype=np.int32)


@lru_cache(maxsize=8)
def unit_cylinder(n: int = 12) -> tuple[F64, F64, I32]:
    """Radius-1 cylinder along z from 0 to 1, capped; returns (vertices, normals, triangles)."""
    s, c = exact.sincos(2.0 * np.pi * np.arange(n) / n)
    side = np.concatenate([np.stack([c, s, np.zeros(n)], 1), np.stack([c, s, np.ones(n)], 1)])
    side_n = np.concatenate([np.stack([c, s, np.zeros(n)], 1)] * 2)
    bottom = np.concatenate([[[0.0, 0.0, 0.0]], np.stack([c, s, np.zeros(n)], 1)])
    top = np.concatenate([[[0.0, 0.0, 1.0]], np.stack([c, s, np.ones(n)], 1)])
    verts = np.concatenate([side, bottom, top])
    normals = np.concatenate(
        [side_n, np.tile([0.0, 0.0, -1.0], (n + 1, 1)), np.tile([0.0, 0.0, 1.0], (n + 1, 1))]
    )
    tris: list[tuple[int, int, int]] = []
    for j in range(n):
        j1 = (j + 1) % n
        tris.append((j, j1, n + j1))
        tris.append((j, n + j1, n + j))
    b, t = 2 * n, 3 * n + 1
    for j in range(n):
        j1 = (j + 1) % n
        tris.append((b, b + 1 + j1, b + 1 + j))
        tris.append((t, t + 1 + j, t + 1 + j1))
    return verts, normals, np.asarray(tris, dtype=np.int32)


@lru_cache(maxsize=1)
def unit_box() -> tuple[F64, F64, I32]:
    """Box [-0.5, 0.5]^3 with flat faces (4 vertices per face)."""
    verts: list[tuple[float, float, float]] = []
    normals: list[tuple[float, float, float]] = []
    tris: list[tuple[int, int, int]] = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(verts)
            for a, b in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = 0.5 * sign, a, b
                verts.append((p[0], p[1], p[2]))
                n = [0.0, 0.0, 0.0]
                n[axis] = sign
                normals.append((n[0], n[1], n[2]))
            if sign > 0:
                tris += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
            else:
                tris += [(base, base + 2, base + 1), (base, base + 3, base + 2)]
    return np.asarray(verts), np.asarray(normals), np.asarray(tris, dtype=np.int32)


rotation_x = exact.rotation_x
rotation_y = exact.rotation_y
rotation_z = exact.rotation_z


def affine(linear: F64, translation: F64 | tuple[float, float, float]) -> F64:
    """4x4 matrix from a 3x3 linear part and a translation."""
    M = np.eye(4)
    M[:3, :3] = linear
    M[:3, 3] = translation
    return M


def segment_frame(a: F64, b: F64) -> F64:
    """A rotation whose z axis points from ``a`` to ``b``."""
    d = np.asarray(b, dtype=np.float64) - np.asarray(a, dtype=np.float64)
    n = float(exact.norm(d))
    if n < 1e-12:
        return np.eye(3)
    z = d / n
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = exact.cross(helper, z)
    x /= exact.norm(x)
    y = exact.cross(z, x)
    return np.stack([x, y, z], axis=1)


class MeshBuilder:
    """Accumulates transformed primitives; :meth:`build` concatenates them."""

    def __init__(self) -> None:
        self._v: list[F64] = []
        self._n: list[F64] = []
        self._t: list[I32] = []
        self._c: list[F64] = []
        self._o: list[I32] = []
        self._m: list[I32] = []
        self._count = 0

    def add(
        self,
        verts: F64,
        normals: F64,
        tris: I32,
        M: F64,
        colour: tuple[float, float, float],
        object_id: int,
        material: int = MAT_MATTE,
    ) -> None:
        """Add a primitive mapped by the 4x4 affine ``M``."""
        L = M[:3, :3]
        v = exact.transform(verts, L, M[:3, 3])
        n = exact.matmul(normals, exact.inv3(L))  # (L^-T n^T)^T
        n /= np.maximum(exact.norm(n), 1e-12)[:, None]
        if exact.det3(L) < 0:
            tris = tris[:, ::-1]
        self._v.append(v)
        self._n.append(n)
        self._t.append(tris + self._count)
        k = len(tris)
        self._c.append(np.tile(np.asarray(colour, dtype=np.float64), (k, 1)))
        self._o.append(np.full(k, object_id, dtype=np.int32))
        self._m.append(np.full(k, material, dtype=np.int32))
        self._count += len(v)

    def sphere(
        self,
        centre: F64 | tuple[float, float, float],
        radii: tuple[float, float, float],
        R: F64,
        colour: tuple[float, float, float],
        object_id: int,
        material: int = MAT_MATTE,
    ) -> None:
        """An ellipsoid with semi-axes ``radii`` along the columns of ``R``."""
        v, t = unit_sphere()
        self.add(
            v, v, t, affine(exact.matmul(R, np.diag(radii)), centre), colour, object_id, material
        )

    def limb(
        self,
        a: F64,
        b: F64,
        radius: float,
        colour: tuple[float, float, float],
        object_id: int,
        material: int = MAT_MATTE,
        joint: bool = True,
    ) -> None:
        """A cylinder from ``a`` to ``b`` of ``radius`` with a sphere at ``b`` (the joint)."""
        a = np.asarray(a, dtype=np.float64)
        b = np.asarray(b, dtype=np.float64)
        R = segment_frame(a, b)
        length = float(exact.norm(b - a))
        v, n, t = unit_cylinder()
        self.add(
            v,
            n,
            t,
            affine(exact.matmul(R, np.diag([radius, radius, length])), a),
            colour,
            object_id,
            material,
        )
        if joint:
            self.sphere(b, (radius, radius, radius), np.eye(3), colour, object_id, material)

    def box(
        self,
        centre: F64 | tuple[float, float, float],
        size: tuple[float, float, float],
        R: F64,
        colour: tuple[float, float, float],
        object_id: int,
        material: int = MAT_MATTE,
    ) -> None:
        v, n, t = unit_box()
        self.add(
            v, n, t, affine(exact.matmul(R, np.diag(size)), centre), colour, object_id, material
        )

    def cylinder(
        self,
        base: F64 | tuple[float, float, float],
        radius: float,
        height: float,
        colour: tuple[float, float, float],
        object_id: int,
        material: int = MAT_MATTE,
    ) -> None:
        """An upright cylinder standing on ``base``."""
        v, n, t = unit_cylinder()
        M = affine(np.diag([radius, radius, height]), base)
        self.add(v, n, t, M, colour, object_id, material)

    def extend(self, mesh: Mesh) -> None:
        """Add a ready mesh (its own colours, ids and materials) as it is."""
        self._v.append(mesh.vertices)
        self._n.append(mesh.normals)
        self._t.append(mesh.triangles + self._count)
        self._c.append(mesh.colours)
        self._o.append(mesh.object_ids)
        self._m.append(mesh.materials)
        self._count += len(mesh.vertices)

    def build(self) -> Mesh:
        if not self._t:
            return empty_mesh()
        return Mesh(
            np.concatenate(self._v),
            np.concatenate(self._n),
            np.concatenate(self._t).astype(np.int32),
            np.concatenate(self._c),
            np.concatenate(self._o),
            np.concatenate(self._m),
        )


def empty_mesh() -> Mesh:
    return Mesh(
        np.zeros((0, 3)),
        np.zeros((0, 3)),
        np.zeros((0, 3), dtype=np.int32),
        np.zeros((0, 3)),
        np.zeros(0, dtype=np.int32),
        np.zeros(0, dtype=np.int32),
    )


def concatenate(meshes: list[Mesh]) -> Mesh:
    """One mesh from several (triangle indices re-based)."""
    meshes = [m for m in meshes if m.n_triangles]
    if not meshes:
        return empty_mesh()
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    surface = None
    if any(m.surface is not None for m in meshes):
        parts = [m.surface_or_plain() for m in meshes]
        surface = Surface(
            np.concatenate([p.corner_colours for p in parts]),
            np.concatenate([p.uv for p in parts]),
            np.concatenate([p.pattern for p in parts]),
            np.concatenate([p.colour2 for p in parts]),
            np.concatenate([p.scale for p in parts]),
            np.concatenate([p.detailed() for p in parts]),
        )
    smooth = None
    if any(m.smooth is not None for m in meshes):
        smooth = np.concatenate([m.smooth_triangles() for m in meshes])
    return Mesh(
        np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.normals for m in meshes]),
        np.concatenate([m.triangles + o for m, o in zip(meshes, offsets, strict=True)]).astype(
            np.int32
        ),
        np.concatenate([m.colours for m in meshes]),
        np.concatenate([m.object_ids for m in meshes]),
        np.concatenate([m.materials for m in meshes]),
        surface,
        smooth,
    )
