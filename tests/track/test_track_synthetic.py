"""Synthetic detection streams used by the tracker tests and benchmark."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.track.synthetic import WalkingPerson, colour_histogram, walking_stream


def test_colour_histogram_is_normalised_and_centred() -> None:
    h = colour_histogram(np.random.default_rng(0), (200.0, 40.0, 40.0), bins=8, spread=1.0)
    assert h.shape == (512,) and h.dtype == np.float32
    assert float(h.sum()) == pytest.approx(1.0)
    # 200 // 32 = 6, 40 // 32 = 1: all pixels in bin (6, 1, 1) = 6*64 + 1*8 + 1 = 393
    assert int(h.argmax()) == 393 and h[393] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="pixels=0"):
        colour_histogram(np.random.default_rng(0), (0.0, 0.0, 0.0), pixels=0)


def test_walking_person_paces_between_the_ends() -> None:
    p = WalkingPerson(y=1.0, colour=(0.0, 0.0, 0.0), x_min=2.0, x_max=5.0, speed=1.0)
    # span 3 m at 1 m/s: out in 3 s, back in 6 s
    assert p.position(0.0) == (2.0, 1.0)
    assert p.position(1.5) == (3.5, 1.0)
    assert p.position(4.0) == (4.0, 1.0)
    assert p.position(6.0) == (2.0, 1.0)


def test_stream_stamps_and_counts() -> None:
    people = [WalkingPerson(y=0.0, colour=(0.0, 0.0, 0.0))]
    s = walking_stream(people, 4, rate_hz=20.0)
    assert [stamp for stamp, _ in s] == [0, 50_000_000, 100_000_000, 150_000_000]
    assert all(len(d) == 1 for _, d in s)
    with pytest.raises(ValueError, match="rate_hz=0"):
        walking_stream(people, 4, rate_hz=0.0)
