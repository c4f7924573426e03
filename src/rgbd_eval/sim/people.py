"""People as the cameras see them: MakeHuman bodies with skin, face, hair, clothes and shoes.

A :class:`Person` of a scenario becomes a :class:`Dressed` body once per recording: the
body shaped from its sex, age, build and height (:mod:`rgbd_eval.sim.body`), and an
:class:`Appearance` (skin tone, hair, eyes, lips; a top, a bottom and shoes, each with its
colour and pattern). What a scenario does not say is drawn from the person's own random
stream (scenario seed and person id), from catalogues of how people look: skin tones
measured on photographs, natural hair colours, the colours clothing catalogues sell most,
anthropometric heights. Nothing here is chosen by a detector's score.

Clothes are the body's own surface, pushed out along its normals by the cloth's thickness
(a shirt 5 mm, a jacket 22 mm) where the garment covers it, and painted per pixel with the
garment's pattern (stripes, checks, a print, a weave) through the body's texture
coordinates; a skirt or a dress is MakeHuman's skirt helper, cut at its hem. Garment edges
are cut along the bones (a sleeve ends a given share of the way from shoulder to wrist).
Hair is a cap on the scalp, long hair adds the back of MakeHuman's hair helper; the face
has eyes (iris and pupil on the eyeball helpers), lashes, eyebrows and lips.

Posing: walking uses the body's walk cycle, posed at :data:`PHASES` phases of each stride
and interpolated; standing and sitting use their poses; the transitions blend vertices.
Everything goes through :mod:`rgbd_eval.exact`: the same person renders to the same bytes
on every CPU.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.body import (
    BodyModel,
    BodyShape,
    RestBody,
    natural_stride,
    sit_pose,
    stand_pose,
    vertex_normals,
    walk_pose,
)
from rgbd_eval.sim.body import (
    Pose as BodyPose,
)
from rgbd_eval.sim.meshes import (
    MAT_MATTE,
    MAT_SKIN,
    PATTERN_CHECK,
    PATTERN_DOTS,
    PATTERN_NONE,
    PATTERN_STRIPES,
    PATTERN_WEAVE,
    Mesh,
    MeshBuilder,
    Surface,
    concatenate,
)
from rgbd_eval.sim.scenario import Person

F64 = NDArray[np.float64]
I32 = NDArray[np.int32]
Colour = tuple[int, int, int]

TopKind = Literal["tshirt", "shirt", "sweater", "jacket", "dress"]
BottomKind = Literal["trousers", "jeans", "shorts", "skirt"]
HairStyle = Literal["short", "long", "bald"]
Pattern = Literal["plain", "stripes", "check", "dots", "weave"]
PATTERN_CODES = {
    "plain": PATTERN_NONE,
    "stripes": PATTERN_STRIPES,
    "check": PATTERN_CHECK,
    "dots": PATTERN_DOTS,
    "weave": PATTERN_WEAVE,
}

# ----------------------------------------------------------------------------- catalogues

#: Skin tones (sRGB) from light to dark, the spread of skin colour measured on photographs
#: of faces under indoor light.
SKIN_TONES: tuple[Colour, ...] = (
    (236, 200, 176),
    (226, 182, 152),
    (212, 164, 132),
    (192, 140, 108),
    (168, 118, 88),
    (141, 95, 68),
    (112, 74, 52),
    (84, 56, 40),
)
#: Natural hair colours (sRGB), darkest first; grey and white for older people.
HAIR_COLOURS: tuple[Colour, ...] = (
    (24, 20, 18),
    (48, 34, 26),
    (78, 54, 38),
    (120, 88, 60),
    (176, 142, 98),
    (118, 56, 34),
)
GREY_HAIR: tuple[Colour, ...] = ((140, 138, 134), (196, 192, 186))
#: Iris colours: brown, dark brown, hazel, green, blue, grey.
IRIS_COLOURS: tuple[Colour, ...] = (
    (90, 60, 40),
    (55, 38, 28),
    (120, 95, 55),
    (85, 110, 80),
    (80, 110, 150),
    (110, 118, 125),
)
#: Clothing colours in everyday wear: neutrals most, then muted and a few bright ones.
CLOTH_COLOURS: tuple[Colour, ...] = (
    (28, 28, 30),  # black
    (58, 60, 64),  # charcoal
    (118, 118, 122),  # grey
    (222, 222, 218),  # white
    (30, 38, 66),  # navy
    (62, 82, 118),  # denim blue
    (150, 178, 208),  # light blue
    (176, 156, 118),  # khaki
    (86, 92, 58),  # olive
    (108, 32, 40),  # burgundy
    (172, 42, 42),  # red
    (40, 78, 52),  # forest green
    (200, 186, 160),  # beige
    (98, 70, 50),  # brown
    (200, 160, 52),  # mustard
    (214, 150, 166),  # pink
    (42, 108, 118),  # teal
    (206, 112, 52),  # orange
)
#: How often each colour is worn (the neutrals first); sums to 1.
CLOTH_WEIGHTS = (
    0.13, 0.09, 0.09, 0.09, 0.1, 0.08, 0.06, 0.05, 0.04,
    0.04, 0.04, 0.03, 0.04, 0.04, 0.02, 0.02, 0.02, 0.02,
)  # fmt: skip
DENIM: tuple[Colour, ...] = ((52, 70, 104), (72, 92, 128), (38, 44, 58), (110, 128, 156))
SHOE_COLOURS: tuple[Colour, ...] = ((24, 22, 22), (70, 48, 34), (220, 220, 216), (96, 96, 100))
#: Adult stature (m): mean and standard deviation by sex (anthropometric surveys of adults).
HEIGHT_MEAN = {0: 1.63, 1: 1.76}
HEIGHT_SD = {0: 0.065, 1: 0.07}

#: Cloth thickness (m) pushed out from the skin, per garment.
THICKNESS = {
    "tshirt": 0.005,
    "shirt": 0.006,
    "sweater": 0.012,
    "jacket": 0.022,
    "dress": 0.006,
    "trousers": 0.010,
    "jeans": 0.008,
    "shorts": 0.010,
    "skirt": 0.006,
    "shoes": 0.008,
    "hair": 0.008,
}
#: Where sleeves end: shoulder 0, elbow 1, wrist 2 (along the arm's bones).
SLEEVE_END = {"tshirt": 0.45, "shirt": 2.0, "sweater": 2.0, "jacket": 2.0, "dress": 0.3}
#: Where legs end: hip 0, knee 1, ankle 2.
LEG_END = {"trousers": 2.0, "jeans": 2.0, "shorts": 0.6}
#: A skirt's hem, as a share of the way from hip to ankle height.
SKIRT_HEM = {"skirt": 0.55, "dress": 0.5}
#: Tiles of a pattern per texture unit (MakeHuman's texture: the torso spans ~0.45 units).
PATTERN_SCALE = {"stripes": 52.0, "check": 28.0, "dots": 40.0, "weave": 400.0}

#: Walk cycle phases posed per stride (the rest interpolated).
PHASES = 32
#: Slower than this (m/s) nobody walks steadily (people's slowest comfortable walk is about
#: 0.6 m/s): see :meth:`Dressed.stride`.
SLOWEST_WALK = 0.5


@dataclass(frozen=True)
class Garment:
    kind: str
    colour: Colour
    pattern: Pattern = "plain"
    colour2: Colour = (0, 0, 0)


@dataclass(frozen=True)
class Appearance:
    """How one person looks besides the shape of their body."""

    skin: Colour
    hair: Colour
    hair_style: HairStyle
    iris: Colour
    top: Garment
    bottom: Garment | None  # None under a dress
    shoes: Colour
    lips: Colour = (0, 0, 0)  # (0, 0, 0): from the skin tone


# ----------------------------------------------------------------------------- drawing


def _choice(
    rng: np.random.Generator, options: tuple[Colour, ...], weights: tuple[float, ...] | None = None
) -> Colour:
    p = None if weights is None else np.asarray(weights) / sum(weights)
    return options[int(rng.choice(len(options), p=p))]


def _other_colour(rng: np.random.Generator, colour: Colour) -> Colour:
    """A second colour for a pattern: any catalogue colour but ``colour``."""
    options = tuple(c for c in CLOTH_COLOURS if c != colour)
    return _choice(rng, options)


def draw_shape(rng: np.random.Generator, sex: float | None, height: float | None) -> BodyShape:
    """A body: sex, age 18-75, build and (unless given) a height from the adult distribution."""
    s = float(rng.integers(0, 2)) if sex is None else sex
    age = float(rng.uniform(18.0, 75.0))
    z = exact.standard_normal(rng, 3)
    weight = float(np.clip(0.5 + 0.18 * z[0], 0.1, 0.95))
    muscle = float(np.clip(0.5 + 0.15 * z[1], 0.15, 0.9))
    if height is None:
        k = round(s)
        height = float(np.clip(HEIGHT_MEAN[k] + HEIGHT_SD[k] * z[2], 1.5, 1.95))
    return BodyShape(sex=s, age_years=age, muscle=muscle, weight=weight, height_m=height)


def draw_appearance(rng: np.random.Generator, shape: BodyShape) -> Appearance:
    """Skin, hair, eyes and clothes for a body, from the catalogues above."""
    female = shape.sex < 0.5
    skin = _choice(rng, SKIN_TONES)
    older = shape.age_years > 55 and rng.random() < 0.6
    hair = _choice(rng, GREY_HAIR) if older else _choice(rng, HAIR_COLOURS)
    if female:
        style: HairStyle = "long" if rng.random() < 0.65 else "short"
    else:
        style = (
            "bald"
            if shape.age_years > 40 and rng.random() < 0.2
            else ("long" if rng.random() < 0.08 else "short")
        )
    tops: tuple[str, ...] = ("tshirt", "shirt", "sweater", "jacket") + (
        ("dress",) if female else ()
    )
    top_kind = tops[int(rng.integers(len(tops)))]
    top_colour = _choice(rng, CLOTH_COLOURS, CLOTH_WEIGHTS)
    r = rng.random()
    pattern: Pattern = (
        "stripes" if r < 0.15 else "check" if r < 0.25 else "dots" if r < 0.32 else "plain"
    )
    if top_kind in ("sweater",) and pattern == "plain":
        pattern = "weave"
    top = Garment(top_kind, top_colour, pattern, _other_colour(rng, top_colour))
    bottom = None
    if top_kind != "dress":
        bottoms: tuple[str, ...] = ("jeans", "trousers", "shorts") + (("skirt",) if female else ())
        weights = (0.45, 0.4, 0.08) + ((0.2,) if female else ())
        kind = bottoms[int(rng.choice(len(bottoms), p=np.asarray(weights) / sum(weights)))]
        if kind == "jeans":
            bottom = Garment(kind, _choice(rng, DENIM), "weave", (200, 205, 215))
        else:
            colour = _choice(rng, CLOTH_COLOURS, CLOTH_WEIGHTS)
            bottom = Garment(kind, colour, "plain", colour)
    iris = _choice(rng, IRIS_COLOURS)
    shoes = _choice(rng, SHOE_COLOURS)
    return Appearance(skin, hair, style, iris, top, bottom, shoes)


# ----------------------------------------------------------------------------- dressing


@dataclass(frozen=True)
class _Landmarks:
    eye: F64  # (2, 3) eyeball centres, left then right
    eye_radius: float
    brow_z: float
    mouth_z: float
    face_x: float  # the front of the face (forward), at the eyes


def _landmarks(model: BodyModel, v: F64) -> _Landmarks:
    names = model.group_names
    groups = model.face_group
    eyes = []
    radius = 0.0
    for g in ("helper-l-eye", "helper-r-eye"):
        idx = np.unique(model.faces[groups == names.index(g)])
        c = v[idx].mean(axis=0)
        eyes.append(c)
        radius = max(radius, float(np.max(exact.norm(v[idx] - c))))
    eye = np.stack(eyes)
    ez = float(eye[:, 2].mean())
    head = np.unique(model.faces[groups == 0])
    head = head[model.vertex_label[head] == model.label_names.index("head")]
    mid = head[np.abs(v[head, 1]) < 0.01]
    below = mid[v[mid, 2] < ez - 0.01]
    nose = below[np.argmax(v[below, 0])]
    chin_z = float(v[below[v[below, 0] > float(eye[:, 0].mean()) - 0.01], 2].min())
    nose_z = float(v[nose, 2])
    return _Landmarks(
        eye=eye,
        eye_radius=radius,
        brow_z=ez + 0.018 * v[:, 2].max() / 1.7,
        mouth_z=nose_z - 0.38 * (nose_z - chin_z),
        face_x=float(eye[:, 0].mean()),
    )


#: Rounds of smoothing of the skin under clothes (each moves a vertex to its neighbours' mean).
CLOTH_SMOOTHING = 12


def _smoothed(v: F64, faces: I32, covered: NDArray[np.bool_]) -> F64:
    """``v`` with the covered vertices whose neighbours are all covered moved, round by round,
    to the mean of their neighbours (Laplacian smoothing: breasts, navel, muscle folds)."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = np.concatenate([edges, edges[:, ::-1]])
    a, b = edges[:, 0].astype(np.int64), edges[:, 1].astype(np.int64)
    degree = np.bincount(a, minlength=len(v)).astype(np.float64)
    uncovered_neighbour = np.bincount(a, weights=(~covered[b]).astype(np.float64), minlength=len(v))
    movable = covered & (degree > 0) & (uncovered_neighbour == 0)
    out = v.copy()
    for _ in range(CLOTH_SMOOTHING):
        mean = (
            np.stack(
                [np.bincount(a, weights=out[b, k], minlength=len(v)) for k in range(3)], axis=1
            )
            / np.maximum(degree, 1.0)[:, None]
        )
        out = np.where(movable[:, None], mean, out)
    return out


def _chain_parameter(v: F64, points: list[F64]) -> F64:
    """Where each vertex lies along a chain of joints: 0 at the first, 1 at the second, ..."""
    best = np.full(len(v), np.inf)
    out = np.zeros(len(v))
    for k in range(len(points) - 1):
        a, b = points[k], points[k + 1]
        d = b - a
        t = np.clip(
            exact.dot(v - a, np.broadcast_to(d, v.shape)) / float(exact.dot(d, d)), 0.0, 1.0
        )
        p = a + t[:, None] * d
        dist = exact.norm(v - p)
        closer = dist < best
        best = np.where(closer, dist, best)
        out = np.where(closer, k + t, out)
    return out


@dataclass(frozen=True)
class Dressed:
    """One person's body with everything that makes them look like them (built once)."""

    body: RestBody
    appearance: Appearance
    rest: F64  # (V, 3) rest vertices with the clothes' thickness
    faces: I32  # (T, 3) the triangles shown
    surface: Surface
    colours: F64  # (T, 3) flat colours (the corner mean)
    materials: I32  # (T,)
    hip: NDArray[np.int64]  # skin vertices of the left hip, where a shoulder bag hangs
    used: NDArray[np.int64]  # the body's mesh vertices the triangles use (rest is all of them)
    _tables: dict[float, NDArray[np.float32]] = field(
        default_factory=dict, repr=False, compare=False
    )
    _fixed: dict[str, F64] = field(default_factory=dict, repr=False, compare=False)

    def stride(self, speed: float) -> float:
        """Metres per gait cycle at ``speed`` m/s, to the centimetre (few tables per person).

        Below SLOWEST_WALK m/s a person is starting or stopping: the gait fades into standing
        (its amplitude), and the stride of an ordinary walk (1.2 m/s) serves, rather than a
        walk table of its own for a few frames.
        """
        return round(natural_stride(self.body, speed if speed >= SLOWEST_WALK else 1.2), 2)

    def _posed(self, pose: BodyPose) -> NDArray[np.float32]:
        """Vertices and vertex normals (2, V, 3) in ``pose``, body frame."""
        v = self.body.skinned(self.rest, pose)[self.used]
        out = np.empty((2, len(v), 3), dtype=np.float32)
        out[0] = v
        out[1] = vertex_normals(v, self.faces)
        return out

    def walking(self, phase: float, speed: float) -> tuple[F64, F64]:
        """Vertices and normals (V, 3), body frame, at ``phase`` (cycles) of a walk at ``speed``
        m/s (the normals interpolated too: not unit length, the shading normalises)."""
        stride = self.stride(speed)
        table = self._tables.get(stride)
        if table is None:
            table = np.stack(
                [self._posed(walk_pose(self.body, i / PHASES, stride)) for i in range(PHASES)]
            )
            if len(self._tables) >= 3:
                del self._tables[next(iter(self._tables))]
            self._tables[stride] = table
        x = (phase - math.floor(phase)) * PHASES
        i = min(int(x), PHASES - 1)
        t = x - i
        a = table[i].astype(np.float64)
        b = table[(i + 1) % PHASES].astype(np.float64)
        out = a + t * (b - a)
        return out[0], out[1]

    def fixed(self, kind: Literal["stand", "sit"]) -> tuple[F64, F64]:
        """Vertices and normals (V, 3), body frame, standing or seated."""
        out = self._fixed.get(kind)
        if out is None:
            pose = stand_pose(self.body) if kind == "stand" else sit_pose(self.body)
            out = self._posed(pose).astype(np.float64)
            self._fixed[kind] = out
        return out[0], out[1]

    def mesh(
        self,
        x: float,
        y: float,
        heading: float,
        phase: float,
        speed: float,
        amplitude: float,
        sit: float,
        object_id: int,
        bag: Colour | None = None,
    ) -> tuple[Mesh, float]:
        """The posed mesh in the world (with a shoulder bag of colour ``bag`` at the left hip),
        and the body's top height (m)."""
        stand_v, stand_n = self.fixed("stand")
        if sit > 0.0:
            sit_v, sit_n = self.fixed("sit")
            v, n = stand_v + sit * (sit_v - stand_v), stand_n + sit * (sit_n - stand_n)
        elif amplitude >= 1.0:
            v, n = self.walking(phase, speed)
        elif amplitude <= 0.0:
            v, n = stand_v, stand_n
        else:
            walk_v, walk_n = self.walking(phase, speed)
            v = stand_v + amplitude * (walk_v - stand_v)
            n = stand_n + amplitude * (walk_n - stand_n)
        top = float(v[:, 2].max())
        s, c = exact.sincos(heading)
        world = np.stack(
            [c * v[:, 0] - s * v[:, 1] + x, s * v[:, 0] + c * v[:, 1] + y, v[:, 2]], axis=1
        )
        normals = np.stack([c * n[:, 0] - s * n[:, 1], s * n[:, 0] + c * n[:, 1], n[:, 2]], axis=1)
        person = Mesh(
            world,
            normals,
            self.faces,
            self.colours,
            np.full(len(self.faces), object_id, dtype=np.int32),
            self.materials,
            self.surface,
            np.ones(len(self.faces), dtype=bool),
        )
        if bag is None:
            return person, top
        anchor = world[self.hip].mean(axis=0)  # the bag hangs outside the hip, below it
        side = np.array([-s, c, 0.0])
        centre = anchor + 0.075 * side + np.array([0.0, 0.0, -0.04])
        b = MeshBuilder()
        b.box(centre, (0.30, 0.08, 0.24), exact.rotation_z(heading), _rgb(bag), object_id)
        return concatenate([person, b.build()]), top


def dress(shape: BodyShape, look: Appearance) -> Dressed:
    """Build one person (about 0.1 s)."""
    return _dress(shape, look)


@lru_cache(maxsize=32)
def _dress(shape: BodyShape, look: Appearance) -> Dressed:
    model = BodyModel.load()
    body = model.shaped(shape)
    v = body.vertices
    names = model.group_names
    label_names = model.label_names
    n = len(v)
    lab = model.vertex_label[:n]
    group_of_vertex = np.zeros(n, dtype=np.int64)
    for g in range(len(names)):
        group_of_vertex[np.unique(model.faces[model.face_group == g])] = g
    body_v = group_of_vertex == 0
    marks = _landmarks(model, v)
    height = float(v[:, 2].max())
    normals = vertex_normals(v, model.faces)

    def label(*which: str) -> NDArray[np.bool_]:
        out: NDArray[np.bool_] = np.isin(lab, [label_names.index(w) for w in which]) & body_v
        return out

    # where each vertex lies along its limb
    arm = np.zeros(n)
    leg = np.zeros(n)
    for side in ("L", "R"):
        chain = [
            body.bone_head(f"upperarm01.{side}"),
            body.bone_head(f"lowerarm01.{side}"),
            body.bone_head(f"wrist.{side}"),
        ]
        sel = label("upper_arm", "forearm", "hand") & (
            np.sign(v[:, 1]) == (1 if side == "L" else -1)
        )
        arm[sel] = _chain_parameter(v[sel], chain)
        chain = [
            body.bone_head(f"upperleg01.{side}"),
            body.bone_head(f"lowerleg01.{side}"),
            body.bone_head(f"foot.{side}"),
        ]
        sel = label("thigh", "shin", "foot") & (np.sign(v[:, 1]) == (1 if side == "L" else -1))
        leg[sel] = _chain_parameter(v[sel], chain)
    hip_z = float(body.bone_head("upperleg01.L")[2])
    ankle_z = float(body.bone_head("foot.L")[2])
    waist_z = float(body.bone_head("spine03")[2])
    neck_z = float(body.bone_head("neck01")[2])

    # --- garments on the skin: a code per vertex (0 skin)
    SKIN, TOP, BOTTOM, SHOES, HAIR = 0, 1, 2, 3, 4
    wear = np.zeros(n, dtype=np.int64)
    top = look.top
    torso = label("torso", "neck") & (v[:, 2] < neck_z - 0.01)
    hem_z = waist_z - (0.16 if top.kind in ("jacket", "sweater") else 0.1)
    wear[torso | (label("pelvis") & (v[:, 2] >= hem_z))] = TOP
    wear[label("upper_arm", "forearm") & (arm <= SLEEVE_END[top.kind])] = TOP
    bottom = look.bottom
    if bottom is not None:
        below = label("pelvis", "thigh", "shin") & (v[:, 2] < hem_z)
        if bottom.kind in LEG_END:
            below &= ~label("thigh", "shin") | (leg <= LEG_END[bottom.kind])
        else:  # a skirt: briefs under it, bare legs below
            below &= label("pelvis") | (leg <= 0.15)
        wear[below & (wear == SKIN)] = BOTTOM
    elif top.kind == "dress":
        wear[label("pelvis") | (label("thigh") & (leg <= 0.15))] = TOP
    wear[label("foot") | (label("shin") & (leg >= 1.93))] = SHOES

    # --- hair: a cap on the scalp
    head = label("head")
    eye_x = marks.face_x
    scalp = head & (
        (v[:, 2] > marks.brow_z + 0.028) | ((v[:, 0] < eye_x - 0.085) & (v[:, 2] > marks.mouth_z))
    )
    if look.hair_style != "bald":
        wear[scalp] = HAIR

    # cloth does not follow every fold of the skin: smooth what garments cover (their edges
    # stay where they are), then push it out by the cloth's thickness
    base = _smoothed(v, model.faces[model.face_group == 0], (wear == TOP) | (wear == BOTTOM))
    thickness = np.zeros(n)
    for code, kind in (
        (TOP, top.kind),
        (BOTTOM, bottom.kind if bottom else "skirt"),
        (SHOES, "shoes"),
        (HAIR, "hair"),
    ):
        thickness[wear == code] = THICKNESS[kind]
    if look.hair_style == "long":
        # the long-hair shell lies on the skin of the back: it goes over the top's cloth, or
        # the back shows through it where the shoulders move in the walk
        shell = np.unique(model.faces[model.face_group == names.index("helper-hair")])
        thickness[shell] += THICKNESS[top.kind] + THICKNESS["hair"]
    rest = base + normals * thickness[:, None]

    # --- colours per vertex
    skin = np.asarray(look.skin, dtype=np.float64)
    col = np.tile(skin, (n, 1))
    brow = (
        head
        & (np.abs(np.abs(v[:, 1]) - abs(float(marks.eye[0, 1]))) < 0.022)
        & (np.abs(v[:, 2] - marks.brow_z) < 0.005 * height / 1.7)
        & (v[:, 0] > eye_x - 0.01)
    )
    col[brow] = 0.55 * skin + 0.45 * np.asarray(look.hair, dtype=np.float64) * 0.8
    lips_colour = (
        np.asarray(look.lips, dtype=np.float64)
        if look.lips != (0, 0, 0)
        else skin * np.array([0.82, 0.62, 0.62])
    )
    lips = (
        head
        & (np.abs(v[:, 1]) < 0.021)
        & (np.abs(v[:, 2] - marks.mouth_z) < 0.0065)
        & (v[:, 0] > eye_x - 0.005)
    )
    col[lips] = lips_colour
    col[wear == TOP] = top.colour
    if bottom is not None:
        col[wear == BOTTOM] = bottom.colour
    col[wear == SHOES] = look.shoes
    col[wear == HAIR] = look.hair
    # eyes: white, iris and pupil facing forward
    eye_groups = [names.index("helper-l-eye"), names.index("helper-r-eye")]
    for k, group in enumerate(eye_groups):
        idx = np.unique(model.faces[model.face_group == group])
        d = v[idx] - marks.eye[k]
        forward = d[:, 0] / np.maximum(exact.norm(d), 1e-9)
        c = np.where(
            forward[:, None] > 0.97,
            15.0,
            np.where(forward[:, None] > 0.86, np.asarray(look.iris, dtype=np.float64), 225.0),
        )
        col[idx] = c
    for name in names:
        if "eyelashes" in name:
            col[np.unique(model.faces[model.face_group == names.index(name)])] = (20.0, 18.0, 16.0)

    # --- the triangles shown
    keep = np.isin(model.face_group, [0, *eye_groups]) | np.array(
        ["eyelashes" in names[g] for g in model.face_group]
    )
    show_hair = np.zeros(len(model.faces), dtype=bool)
    if look.hair_style == "long":
        hair_faces = model.face_group == names.index("helper-hair")
        fv = v[model.faces]  # (T, 3, 3)
        behind = fv[:, :, 0].max(axis=1) < eye_x - 0.05
        show_hair = hair_faces & behind
        col[np.unique(model.faces[show_hair])] = look.hair
    skirt = np.zeros(len(model.faces), dtype=bool)
    hem_share = SKIRT_HEM.get(top.kind if top.kind == "dress" else (bottom.kind if bottom else ""))
    if hem_share is not None:
        hem = hip_z - hem_share * (hip_z - ankle_z)
        fv = v[model.faces]
        skirt = (model.face_group == names.index("helper-skirt")) & (fv[:, :, 2].min(axis=1) >= hem)
        garment = top if top.kind == "dress" or bottom is None else bottom
        col[np.unique(model.faces[skirt])] = garment.colour
    keep = keep | show_hair | skirt
    faces = model.faces[keep].astype(np.int32)
    corner = col[faces]  # (T, 3, 3)
    # --- patterns per triangle (the garment of its first corner)
    t_wear = wear[faces[:, 0]]
    pattern = np.zeros(len(faces), dtype=np.int32)
    colour2 = corner[:, 0].copy()
    scale = np.ones(len(faces))
    for code, worn in ((TOP, top), (BOTTOM, bottom)):
        if worn is None or worn.pattern == "plain":
            continue
        sel = t_wear == code
        pattern[sel] = PATTERN_CODES[worn.pattern]
        colour2[sel] = worn.colour2
        scale[sel] = PATTERN_SCALE[worn.pattern]
    uv = model.face_uv[keep].astype(np.float64)
    # the helper shells (long hair, the skirt) carry no garment code of their own: they are
    # hair and cloth, not skin (the thermal camera and the depth model read skin apart)
    t_worn = t_wear.copy()
    t_worn[show_hair[keep]] = HAIR
    t_worn[skirt[keep]] = TOP if top.kind == "dress" or bottom is None else BOTTOM
    materials = np.where(t_worn == SKIN, MAT_SKIN, MAT_MATTE).astype(np.int32)
    surface = Surface(corner, uv, pattern, colour2, scale)
    surface = Surface(corner, uv, pattern, colour2, scale, surface.detailed())
    pelvis = label("pelvis")
    hip = np.flatnonzero(pelvis & (v[:, 1] > 0.8 * float(v[pelvis, 1].max())))
    # only the vertices of shown triangles: hidden helpers (the unused hair shell, the skirt
    # when none is worn, the tights) must not widen boxes or cost posing time
    used = np.unique(faces)
    index = np.full(n, -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    return Dressed(
        body,
        look,
        rest,
        index[faces].astype(np.int32),
        surface,
        corner.mean(axis=1),
        materials,
        index[hip[index[hip] >= 0]],
        used,
    )


def _rgb(c: Colour) -> tuple[float, float, float]:
    return (float(c[0]), float(c[1]), float(c[2]))


# ----------------------------------------------------------------------------- scenario people


#: Random streams of people: (scenario seed, STREAM, person id).
STREAM = 7


def look_of(
    person: Person, seed: int, shirt: Colour, trousers: Colour
) -> tuple[BodyShape, Appearance]:
    """The body and appearance of a scenario's person wearing ``shirt`` and ``trousers``.

    What the scenario gives is kept (``height``, ``sex``, ``age``, ``weight``, ``muscle``,
    the colours, ``top``, ``bottom``, ``pattern``, ``hair_style``); the rest is drawn from
    the person's stream, the same for every frame.
    """
    given = person.model_fields_set
    rng = np.random.default_rng([seed, STREAM, person.id])
    shape = draw_shape(rng, person.sex, person.height if "height" in given else None)
    shape = BodyShape(
        sex=shape.sex,
        age_years=person.age if person.age is not None else shape.age_years,
        muscle=person.muscle if person.muscle is not None else shape.muscle,
        weight=person.weight if person.weight is not None else shape.weight,
        height_m=shape.height_m,
    )
    look = draw_appearance(rng, shape)
    top = look.top
    kind = person.top or top.kind
    pattern = person.pattern or (top.pattern if kind == top.kind else "plain")
    colour = shirt if "shirt" in given or person.clothes else top.colour
    top = Garment(kind, colour, pattern, top.colour2 if top.colour2 != colour else (0, 0, 0))
    bottom = look.bottom
    if kind == "dress":
        bottom = None
    else:
        b_kind = person.bottom or (bottom.kind if bottom is not None else "trousers")
        if bottom is None or b_kind != bottom.kind:
            bottom = Garment(
                b_kind, trousers, "weave" if b_kind == "jeans" else "plain", (200, 205, 215)
            )
        if "trousers" in given or person.clothes:
            bottom = Garment(bottom.kind, trousers, bottom.pattern, bottom.colour2)
    return shape, Appearance(
        skin=person.skin if "skin" in given else look.skin,
        hair=person.hair if "hair" in given else look.hair,
        hair_style=person.hair_style or look.hair_style,
        iris=look.iris,
        top=top,
        bottom=bottom,
        shoes=person.shoes if "shoes" in given else look.shoes,
    )
