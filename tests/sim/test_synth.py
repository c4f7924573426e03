"""Written recordings: deterministic bytes, read back by the project's own reader, bag == mcap."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from rgbd_eval.io.groundtruth import read_csv
from rgbd_eval.io.recording import open_recording
from rgbd_eval.sim.rig import DEPTH_FRAME, RGB_FRAME
from rgbd_eval.sim.scenario import Scenario
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.sim.synth import dataset_path, ground_truth_path, synthesize

from .conftest import tiny_scenario


@pytest.mark.parametrize("suffix", [".mcap", ".bag"])
def test_same_seed_same_bytes(tmp_path: Path, tiny: Scenario, suffix: str) -> None:
    a = synthesize(tiny, tmp_path / f"a{suffix}", seed=3)
    b = synthesize(tiny, tmp_path / f"b{suffix}", seed=3)
    c = synthesize(tiny, tmp_path / f"c{suffix}", seed=4)
    assert a.recording.read_bytes() == b.recording.read_bytes()
    assert a.ground_truth_csv.read_bytes() == b.ground_truth_csv.read_bytes()
    assert a.recording.read_bytes() != c.recording.read_bytes()
    assert a.frames == 6 and a.people_instances == 12
    assert a.ground_truth_csv == tmp_path / "a.gt.csv"


def test_frames_render_the_same_in_any_order(tiny: Scenario) -> None:
    sim = Simulator(tiny, 5)
    later = sim.frame(4)
    again = Simulator(tiny, 5)
    _ = again.frame(0)
    assert np.array_equal(again.frame(4).rgb, later.rgb)
    assert np.array_equal(again.frame(4).depth, later.depth, equal_nan=True)


@pytest.mark.parametrize("suffix", [".mcap", ".bag"])
def test_recording_reads_back(tmp_path: Path, tiny: Scenario, suffix: str) -> None:
    out = tmp_path / f"rec{suffix}"
    result = synthesize(tiny, out, seed=1)
    sim = Simulator(tiny, 1)
    rec = open_recording(out)
    assert rec.info.has_odometry
    assert rec.info.world_frame == "odom"
    assert rec.info.rgb_camera.frame_id == RGB_FRAME
    assert rec.info.depth_camera.frame_id == DEPTH_FRAME
    assert (rec.info.depth_camera.width, rec.info.depth_camera.height) == (80, 60)
    frames = list(rec.frames())
    assert len(frames) == result.frames == 6
    for f in frames:
        truth = sim.frame(f.index)
        assert f.stamp_ns == truth.stamp_ns
        assert np.array_equal(f.rgb, truth.rgb)  # raw RGB: exact
        assert np.array_equal(f.depth, truth.depth, equal_nan=True)  # 32FC1: exact
        # the reader's camera pose is odometry + static tf: odom_T_base * base_T_depth_optical
        expected = truth.base_odom.compose(sim.base_to_link).compose(sim.link_to_depth)
        assert np.allclose(f.camera_pose.matrix(), expected.matrix(), atol=1e-9)
        # the depth camera is 2.5 cm left of the RGB camera: x = -0.025 in the RGB optical frame
        assert np.allclose(f.depth_to_rgb.translation, (-tiny.sensor.depth_offset_m, 0.0, 0.0))
    # the sidecar CSV and the topic hold the same ground truth as the simulator
    csv = read_csv(ground_truth_path(out))
    topic = rec.ground_truth_topic
    assert topic is not None
    for gt in (csv, topic):
        assert gt.num_objects == 12
        for index, stamp, objects in gt.frames:
            want = {o.object_id: o for o in sim.frame(index).ground_truth}
            assert stamp == tiny.stamp_ns(index)
            for o in objects:
                w = want[o.object_id]
                assert o.ignore == w.ignore
                assert o.visibility == pytest.approx(w.visibility, abs=1e-6)
                assert o.world_xyz == pytest.approx(w.world_xyz)
                assert o.box2d is not None and w.box2d is not None
                assert o.box2d.as_tuple() == pytest.approx(w.box2d.as_tuple(), abs=1e-4)


def test_bag_and_mcap_hold_the_same_frames(tmp_path: Path) -> None:
    sc = tiny_scenario(recording={"rgb_format": "jpeg", "depth_encoding": "16UC1"})
    bag = open_recording(synthesize(sc, tmp_path / "x.bag", seed=2).recording)
    mcap = open_recording(synthesize(sc, tmp_path / "x.mcap", seed=2).recording)
    for a, b in zip(bag.frames(), mcap.frames(), strict=True):
        assert a.stamp_ns == b.stamp_ns
        assert np.array_equal(a.rgb, b.rgb)
        assert np.array_equal(a.depth, b.depth, equal_nan=True)
        assert np.allclose(a.camera_pose.matrix(), b.camera_pose.matrix())


@pytest.mark.parametrize("compressed", [False, True])
def test_16uc1_depth_is_millimetres(tmp_path: Path, compressed: bool) -> None:
    rec_opts = {"rgb_format": "jpeg", "depth_encoding": "16UC1", "depth_compressed": compressed}
    sc = tiny_scenario(recording=rec_opts)
    rec = open_recording(synthesize(sc, tmp_path / "mm.mcap", seed=0, max_frames=2).recording)
    assert rec.info.selected.depth.endswith("/compressedDepth") == compressed
    sim = Simulator(sc, 0)
    for f in rec.frames():
        truth = sim.frame(f.index).depth
        assert np.array_equal(np.isnan(f.depth), np.isnan(truth))
        assert np.nanmax(np.abs(f.depth - truth)) <= 0.0005 + 1e-6  # rounded to 1 mm


def test_progress_and_max_frames(tmp_path: Path, tiny: Scenario) -> None:
    calls: list[tuple[int, int]] = []
    r = synthesize(
        tiny, tmp_path / "p.mcap", progress=lambda d, t: calls.append((d, t)), max_frames=3
    )
    assert calls == [(1, 3), (2, 3), (3, 3)]
    assert r.frames == 3 and r.recording_bytes == (tmp_path / "p.mcap").stat().st_size


def test_bad_arguments(tmp_path: Path, tiny: Scenario) -> None:
    with pytest.raises(ValueError, match=r"must end in \.bag or \.mcap"):
        synthesize(tiny, tmp_path / "x.db3")
    with pytest.raises(ValueError, match="max_frames=0"):
        synthesize(tiny, tmp_path / "x.mcap", max_frames=0)
    with pytest.raises(ValueError, match="seed=-1"):
        Simulator(tiny, -1)
    with pytest.raises(ValueError, match="index=6"):
        Simulator(tiny).frame(6)


def test_dataset_paths() -> None:
    root = dataset_path("demo").parent
    assert dataset_path("demo") == root / "demo.mcap"  # the committed / first-use demo
    assert dataset_path("static_simple", "ros1") == root / "generated" / "static_simple.bag"
    with pytest.raises(ValueError, match="container='zip'"):
        dataset_path("demo", "zip")  # type: ignore[arg-type]


def test_synthesize_all_writes_every_scenario(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, tiny: Scenario
) -> None:
    import rgbd_eval.sim.synth as synth

    (tmp_path / "one.yaml").write_text(yaml.safe_dump(tiny.model_dump(mode="json")))
    (tmp_path / "two.yaml").write_text(yaml.safe_dump(tiny.model_dump(mode="json")))
    monkeypatch.setattr(synth, "scenario_paths", lambda: sorted(tmp_path.glob("*.yaml")))
    monkeypatch.setattr(
        synth, "dataset_path", lambda name, c="mcap": tmp_path / "out" / f"{name}.bag"
    )
    seen: list[tuple[str, int, int]] = []
    results = synth.synthesize_all("ros1", seed=1, progress=lambda *a: seen.append(a))
    assert [r.recording.name for r in results] == ["one.bag", "two.bag"]
    assert (tmp_path / "out" / "two.gt.csv").exists()
    assert seen[-1] == ("two", 6, 6) and len(seen) == 12


@pytest.mark.parametrize("suffix", [".mcap", ".bag"])
def test_the_recording_carries_its_provenance(tmp_path: Path, suffix: str) -> None:
    from rgbd_eval import __version__
    from rgbd_eval.io import provenance
    from rgbd_eval.sim.scenario import load_scenario, scenarios_dir
    from rgbd_eval.sim.synth import RENDERER_VERSION

    path = scenarios_dir() / "demo.yaml"
    sc = load_scenario(path)
    rec = open_recording(synthesize(sc, tmp_path / f"p{suffix}", seed=9, max_frames=2).recording)
    prov = rec.info.provenance
    assert prov is not None
    import hashlib

    assert prov == {
        "generator": "rgbd-eval synth",
        "tool_version": __version__,
        "renderer_version": RENDERER_VERSION,
        "scenario": "demo",
        "scenario_sha256": sc.digest(),
        "scenario_file_sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
        "seed": 9,
        "frames": 2,
        "container": "ros1" if suffix == ".bag" else "mcap",
        "closed_loop": None,
    }
    # an override changes the resolved scenario's digest, not the file's
    other = load_scenario(path, [("sensor.rgb_noise_std", 1.0)])
    assert other.digest() != sc.digest() and other.source_sha256 == sc.source_sha256
    assert provenance.differences(prov, {**prov, "seed": 1}) == ["seed: 9 -> 1"]


def test_a_damaged_provenance_is_skipped_with_a_warning(tmp_path: Path) -> None:
    from rgbd_eval.io import provenance
    from rgbd_eval.io.writer import RecordingWriter

    sc = tiny_scenario()
    good = synthesize(sc, tmp_path / "g.mcap", seed=0, max_frames=1).recording
    # the same recording with a provenance message that is not JSON
    bad = tmp_path / "b.mcap"
    with RecordingWriter(bad) as w:
        msg = w._t(provenance.PROVENANCE_TYPE)(data="{not json")
        w.write_message(provenance.PROVENANCE_TOPIC, provenance.PROVENANCE_TYPE, 1, msg)
        from rgbd_eval.io.source import open_source

        with open_source(good) as src:
            for topic, log_ns, raw in src.messages(set(src.topics) - {provenance.PROVENANCE_TOPIC}):
                msgtype = src.topics[topic].msgtype
                w.write_message(topic, msgtype, log_ns, src.deserialize(raw, msgtype))
    rec = open_recording(bad)
    assert rec.info.provenance is None
    assert any("provenance" in w and "not JSON" in w for w in rec.info.warnings)


def test_ensure_scenario_renders_again_what_is_out_of_date(tmp_path: Path, tiny: Scenario) -> None:
    import rgbd_eval.sim.synth as synth
    from rgbd_eval.errors import OutputError

    scene = tmp_path / "scene.yaml"
    data = tiny.model_dump(mode="json")
    scene.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    said: list[str] = []
    own = synth.ensure_scenario(scene, out, said.append)
    assert own == out / "scene.mcap" and said and "absent" in said[0]
    other = synth.ensure_scenario(scene, out, said.append, seed=tiny.seed + 7)
    assert other == out / f"scene-seed{tiny.seed + 7}.mcap"
    assert synth.is_current(own, scene) and synth.is_current(other, scene, tiny.seed + 7)
    # Current: not rendered again (the file keeps its modification time and bytes).
    stamp = own.stat().st_mtime_ns
    said.clear()
    assert synth.ensure_scenario(scene, out, said.append) == own
    assert not said and own.stat().st_mtime_ns == stamp
    # The scene changed (a person walks elsewhere): its recordings are out of date.
    data["people"][0]["path"][0]["x"] += 0.5
    scene.write_text(yaml.safe_dump(data))
    assert not synth.is_current(own, scene) and not synth.is_current(other, scene, tiny.seed + 7)
    synth.ensure_scenario(scene, out, said.append)
    assert said and "out of date" in said[0] and synth.is_current(own, scene)
    # A file synth did not write is never replaced, current or not.
    mine = out / "scene-seed99.mcap"
    mine.write_bytes(b"my own recording")
    ground_truth_path(mine).write_text("mine")
    assert not synth.is_current(mine, scene, 99)
    with pytest.raises(OutputError):
        synth.ensure_scenario(scene, out, seed=99)
    assert mine.read_bytes() == b"my own recording"
