"""tools/realism/measure.py's per-person report: who each rendered person is, and their row."""

from __future__ import annotations

from rgbd_eval.sim.scenario import parse_scenario
from rgbd_eval.sim.simulate import Simulator
from tests.tools import load_tool

TOOL = load_tool("tools/realism/measure.py", "realism_measure")


def test_describe_names_the_drawn_person() -> None:
    # person 3 of the grid: height 1.55 + 0.08 * 3 = 1.79 m, as the scene gives it
    sim = Simulator(parse_scenario(TOOL.scene(4.0, 90, 3, False), "realism"))
    text = TOOL.describe(sim, sim.time(sim.n_frames - 1))
    sex, height, weight, *_clothes, hair = text.split(", ")
    assert sex in ("female", "male")
    assert height == "1.79 m"
    assert weight.startswith("weight 0.")
    assert hair.endswith(" hair")
    # the same person at the same seed looks the same in every cell
    other = Simulator(parse_scenario(TOOL.scene(6.0, 180, 3, False), "realism"))
    assert TOOL.describe(other, other.time(other.n_frames - 1)) == text


def test_people_table_rows() -> None:
    # person 2: found in 3 of 4 shots; best scores 0.1, 0.6, 0.7, 0.9 -> median (0.6 + 0.7) / 2
    persons = {
        2: {"look": "male, 1.71 m", "shown": 4, "found": 3, "ssd_best": [0.1, 0.6, 0.7, 0.9]},
        1: {"look": "female, 1.63 m", "shown": 2, "found": 0, "ssd_best": [0.2, 0.0]},
    }
    lines = TOOL._people_table(persons).splitlines()
    assert lines[2] == "| 1 | female, 1.63 m | 0/2 | 0.10 |"
    assert lines[3] == "| 2 | male, 1.71 m | 3/4 | 0.65 |"


def test_mirrored_box() -> None:
    # a 640-pixel image: the box 100..150 flips to 640 - 150 = 490 .. 540
    box = TOOL.Box2D(100.0, 20.0, 50.0, 200.0)
    assert TOOL.mirrored(box, 640) == TOOL.Box2D(490.0, 20.0, 50.0, 200.0)


def test_variants_table_counts_found_and_changed_verdicts() -> None:
    names = ("rendered", "no blur", "no noise", "grey background", "mirrored")

    def row(o: int, *scores: float) -> dict:
        return {"orientation": o, "scores": dict(zip(names, scores, strict=True))}

    rows = [
        row(0, 0.9, 0.4, 0.9, 0.8, 0.6),
        row(0, 0.2, 0.6, 0.1, 0.7, 0.1),
        row(90, 0.5, 0.5, 0.5, 0.1, 0.49),
    ]
    lines = TOOL.variants_table(rows).splitlines()
    # rendered: 0.9 and 0.5 reach 0.5 (0 deg: 1 of 2, 90 deg: 1 of 1); median of 0.2, 0.5, 0.9
    assert lines[2].startswith("| rendered | 1/2 | - | 1/1 | -")
    assert lines[2].endswith("| 2/3 | 0.50 | 0 |")
    # no blur: 0.6 and 0.5 found; verdicts unlike rendered: the first (0.4) and second (0.6)
    assert lines[3].endswith("| 2/3 | 0.50 | 2 |")
    # no noise: the same verdicts as rendered (0.9, 0.1, 0.5)
    assert lines[4].endswith("| 2/3 | 0.50 | 0 |")
    # grey: 0.8 and 0.7 found, 0.1 missed: the second and third verdicts changed
    assert lines[5].endswith("| 2/3 | 0.70 | 2 |")
    # mirrored: only 0.6; 0.49 misses the threshold where rendered's 0.5 reached it
    assert lines[6].endswith("| 1/3 | 0.49 | 1 |")


def test_variant_shots_keep_the_person_and_grey_the_room() -> None:
    shot = next(TOOL.variant_shots(1, (4.0,)))
    rendered, grey = shot.images["rendered"], shot.images["grey background"]
    assert set(shot.images) == set(TOOL.VARIANTS)
    kept = (grey == rendered).all(axis=-1)
    # every pixel changed became mid-grey; the kept ones are the person (about 10k pixels of
    # the 307k at 4 m: a 1.63 m person is about 210 by 50 pixels)
    assert (grey[~kept] == TOOL.GREY).all()
    assert 5_000 < kept.sum() < 20_000
    assert (shot.images["mirrored"] == rendered[:, ::-1]).all()
    # the same scene without the blur, or without the noise: the same size, other values
    for variant in ("no blur", "no noise"):
        assert shot.images[variant].shape == rendered.shape
        assert (shot.images[variant] != rendered).any()
    assert (shot.images["no blur"] != shot.images["no noise"]).any()
