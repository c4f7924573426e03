"""Detection in frame chunks equals one pass, bit for bit; frame ranges and undecoded roles."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from rgbd_eval.chunked import ChunkPlan, advance, advance_cost, detect_chunk, join, resumable
from rgbd_eval.components import create_detector
from rgbd_eval.config import RunConfig, build_config, load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.detect.ground import GroundState
from rgbd_eval.errors import ConfigError
from rgbd_eval.io.recording import Recording
from rgbd_eval.methods.basso2012.detector import Basso2012Detector
from rgbd_eval.pipeline import detect_sequence, open_for
from rgbd_eval.sim import load_scenario, synthesize

FRAMES = 24


def config(method: str = "basso2012") -> RunConfig:
    return build_config(load_config(method=method).model_dump(mode="json"), [], source="test")


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Recording:
    """The thesis' moving platform (odometry moves the floor plane every frame), 24 frames."""
    scenario = load_scenario(scenarios_dir() / "moving_simple.yaml")
    path = tmp_path_factory.mktemp("chunked") / "moving.mcap"
    synthesize(scenario, path, max_frames=FRAMES)
    return open_for(path, config())


def test_spans_cover_the_frames_in_order() -> None:
    # 24 frames in 3 chunks: bounds 24*i//3 = 0, 8, 16, 24.
    assert ChunkPlan(3, 1).spans(24) == [(0, 8), (8, 16), (16, 24)]
    # 10 frames in 3: bounds 0, 3, 6, 10 (integer division).
    assert ChunkPlan(3, 1).spans(10) == [(0, 3), (3, 6), (6, 10)]
    # 130 frames, chunks of at least 60: 130 // 60 = 2 used, the third empty at the end.
    assert ChunkPlan(3, 60).spans(130) == [(0, 65), (65, 130), (130, 130)]
    # Too short for two chunks: one, the rest empty.
    assert ChunkPlan(2, 60).spans(59) == [(0, 59), (59, 59)]


def test_spans_shrink_by_the_advance_cost() -> None:
    # r = 0.25, 2 chunks: lengths in proportion 1 : 0.75, bound int(70 / 1.75) = 40. The
    # worker detecting chunk 0 does 40 frames; the one advancing over 0:40 (a quarter of a
    # detection each) and detecting 40:70 does 0.25 * 40 + 30 = 40 too.
    assert ChunkPlan(2, 1, 0.25).spans(70) == [(0, 40), (40, 70)]
    # r = 0.5, 3 chunks: 1 : 0.5 : 0.25, cumulative 1, 1.5, 1.75 of 70 -> 40, 60, 70.
    assert ChunkPlan(3, 1, 0.5).spans(70) == [(0, 40), (40, 60), (60, 70)]
    # The last chunk (30 frames) is under min_frames 31: one chunk fewer, the rest empty.
    assert ChunkPlan(2, 30, 0.25).spans(70) == [(0, 40), (40, 70)]
    assert ChunkPlan(2, 31, 0.25).spans(70) == [(0, 70), (70, 70)]
    # 0 is the equal split.
    assert ChunkPlan(2, 1, 0.0).spans(70) == [(0, 35), (35, 70)]


def test_advance_cost_is_declared_by_the_detector() -> None:
    assert advance_cost(config()) == Basso2012Detector.advance_cost
    assert 0.0 < Basso2012Detector.advance_cost < 1.0
    assert ChunkPlan(2, advance_cost=advance_cost(config())).spans(750)[0][1] > 375
    assert advance_cost(config("pinto2022")) == 0.0  # not resumable: declares none


def test_plan_refuses_zero_chunks() -> None:
    with pytest.raises(ConfigError, match="at least 1"):
        ChunkPlan(0)
    for cost in (-0.1, 1.0):
        with pytest.raises(ConfigError, match="advance_cost"):
            ChunkPlan(2, advance_cost=cost)


def test_frame_range_and_skipped_roles(recording: Recording) -> None:
    whole = list(recording.frames())
    part = list(recording.frames(5, 9))
    assert [f.index for f in part] == [5, 6, 7, 8]
    for a, b in zip(whole[5:9], part, strict=True):
        assert a.stamp_ns == b.stamp_ns and a.camera_pose == b.camera_pose
        assert np.array_equal(a.depth, b.depth, equal_nan=True)
        assert np.array_equal(a.rgb, b.rgb)
    skipped = list(recording.frames(5, 7, skip={"colour"}))
    assert skipped[0].rgb.shape == (0, 0) and skipped[0].stream("colour").encoding == "none"
    assert skipped[0].rgb_camera == whole[5].rgb_camera
    assert np.array_equal(skipped[1].depth, whole[6].depth, equal_nan=True)
    assert list(recording.frames(7, 7)) == []
    with pytest.raises(ValueError, match="outside"):
        list(recording.frames(3, FRAMES + 1))


@pytest.mark.parametrize(("chunks", "cost"), [(2, 0.0), (5, 0.0), (3, 0.5)])
def test_chunks_equal_one_pass_bit_for_bit(recording: Recording, chunks: int, cost: float) -> None:
    cfg = config()
    assert resumable(cfg)
    whole = detect_sequence(recording, cfg)
    # Not vacuous: people are detected, before and after the first chunk boundary.
    assert sum(map(len, whole.detections[:4])) > 0 and sum(map(len, whole.detections[8:])) > 0
    # 24 frames, 3 chunks at cost 0.5: 1 : 0.5 : 0.25 of 24 -> bounds 13, 20 (unequal chunks).
    spans = ChunkPlan(chunks, 1, cost).spans(len(recording))
    if cost:
        assert spans == [(0, 13), (13, 20), (20, 24)]
    state: object | None = None
    parts = []
    for span in spans:
        parts.append(detect_chunk(recording, cfg, span, state))
        state = advance(recording, cfg, span, state)
    assert isinstance(state, GroundState) and state.plane is not None and state.last_pose
    joined = join(recording, parts)
    assert joined.stamps_ns == whole.stamps_ns
    # Floats, histograms and all: the pickles of the detections are the same bytes.
    assert pickle.dumps(joined.detections) == pickle.dumps(whole.detections)


def test_advance_carries_what_detect_carries(recording: Recording) -> None:
    cfg = config()
    detecting, advancing = create_detector(cfg), create_detector(cfg)
    assert isinstance(detecting, Basso2012Detector) and isinstance(advancing, Basso2012Detector)
    for frame in recording.frames(0, 12):
        detecting.detect(frame)
    for frame in recording.frames(0, 12, skip={"colour"}):
        advancing.advance(frame)
    a, b = detecting.carry_state(), advancing.carry_state()
    assert a.plane is not None and b.plane is not None
    assert a.plane.tobytes() == b.plane.tobytes()
    assert (a.inliers, a.last_pose) == (b.inliers, b.last_pose) and a.inliers > 0


def test_a_restored_state_is_used(recording: Recording) -> None:
    """On this synthetic floor the per-frame refit finds the same inliers from the carried
    plane as from a fresh one, so the chunk test above would pass were the state ignored;
    a floor 0.3 m too high (no inliers within one voxel: the plane is kept) shows it is not."""
    cfg = config()
    whole = detect_sequence(recording, cfg)
    state = advance(recording, cfg, (0, 12), None)
    assert isinstance(state, GroundState) and state.plane is not None
    plane = state.plane.copy()
    plane[3] -= 0.3  # (a, b, c, d) with a unit normal: the plane moves 0.3 m along it
    wrong = GroundState(plane, state.inliers, state.last_pose)
    moved = detect_sequence(recording, cfg, span=(12, FRAMES), state=wrong)
    assert pickle.dumps(moved.detections) != pickle.dumps(whole.detections[12:])


def test_restore_refuses_a_foreign_state() -> None:
    detector = create_detector(config())
    assert isinstance(detector, Basso2012Detector)
    with pytest.raises(TypeError, match="GroundState"):
        detector.restore_state({"plane": None})


def test_join_refuses_missing_frames(recording: Recording) -> None:
    cfg = config()
    part = detect_chunk(recording, cfg, (0, 4), None)
    with pytest.raises(ValueError, match=f"4 of {FRAMES}"):
        join(recording, [part])
