"""SGBM depth against the rendered depth on a textured scene (a script, not a test).

Run from the repository root::

    .venv/bin/python -m tests.sim.sgbm_error_stats [SCENARIO.yaml] [--set detector.key=value ...]

Renders frames of a stereo scenario (default ``satake2009_crossing``: people, walls and
floor with the stereo rig's procedural texture) with its stereo pair, computes depth with
the satake2009 detector's SGBM settings at its processed size, and compares it with the
ray-cast depth of the left camera (which a method never sees). Prints, per band of true
distance: the share of pixels SGBM gives a depth (coverage), the median and 90th
percentile of the absolute error, and the share of gross errors (> 10 % of the distance).
Pixels within ``num_disparities`` of the left border (no search range) are left out.
"""

from __future__ import annotations

import sys

import numpy as np

from rgbd_eval.config import load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.detect import stereo
from rgbd_eval.sim import Simulator, load_scenario
from rgbd_eval.sim.rig_config import StereoPairConfig
from rgbd_eval.sim.stereo_rig import StereoPair

BANDS = ((1.0, 2.0), (2.0, 4.0), (4.0, 6.0), (6.0, 8.0))


def main(argv: list[str]) -> int:
    """Print SGBM error statistics of a stereo scenario."""
    args = [a for a in argv if a != "--set"]
    paths = [a for a in args if "=" not in a]
    scenario = load_scenario(paths[0] if paths else scenarios_dir() / "satake2009_crossing.yaml")
    det = load_config(method="satake2009", overrides=[a for a in args if "=" in a]).detector
    rig = next(r for r in scenario.rig if r.kind == "stereo_pair")
    pair = StereoPair(StereoPairConfig.model_validate(rig.model_dump()), "odom")
    sim = Simulator(scenario, seed=scenario.seed)
    matcher = stereo.make_matcher(det.sgbm)
    n_frames = int(scenario.duration_s * scenario.sensor.rate_hz)
    errors: dict[tuple[float, float], list[np.ndarray]] = {b: [] for b in BANDS}
    totals = dict.fromkeys(BANDS, 0)
    for index in range(0, n_frames, max(1, n_frames // 8)):
        view = sim.scene_view(index, 0)
        left = pair.render(view, pair.left, pair.base_to_left)
        right = pair.render(view, pair.right, pair.base_to_right)
        sd = stereo.stereo_depth(left, right, pair.left, pair.cfg.baseline_m,
                                 (det.width, det.height), matcher)  # fmt: skip
        truth = view.render(sd.camera, view.base_pose.compose(pair.base_to_left)).depth
        truth[:, : det.num_disparities] = np.nan
        for lo, hi in BANDS:
            sel = (truth >= lo) & (truth < hi)
            totals[(lo, hi)] += int(sel.sum())
            got = sd.depth[sel & np.isfinite(sd.depth)]
            errors[(lo, hi)].append(np.abs(got - truth[sel & np.isfinite(sd.depth)]))
    print(f"{scenario.name}: SGBM {det.num_disparities} disparities, block {det.block_size}, "
          f"uniqueness {det.uniqueness_ratio}, speckle window {det.speckle_window}, "
          f"{det.width}x{det.height}")  # fmt: skip
    print("true depth   pixels  coverage  median |err|  p90 |err|  gross (>10%)")
    for (lo, hi), parts in errors.items():
        e = np.concatenate(parts) if parts else np.zeros(0)
        if not totals[(lo, hi)] or not e.size:
            continue
        gross = float(np.mean(e > 0.1 * (lo + hi) / 2))
        print(f"{lo:3.0f}-{hi:1.0f} m  {totals[(lo, hi)]:9d}  {e.size / totals[(lo, hi)]:7.1%}  "
              f"{np.median(e):10.3f} m  {np.percentile(e, 90):7.3f} m  {gross:9.1%}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
