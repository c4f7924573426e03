"""``rgbd-eval synth``: render synthetic RGB-D recordings with exact ground truth."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import typer

from rgbd_eval.cli.common import advance_callback, console, handle_errors, progress_bar
from rgbd_eval.errors import ConfigError, OutputError
from rgbd_eval.outdir import check_output_file

if TYPE_CHECKING:
    from rgbd_eval.sim.scenario import Scenario


def _scenario_file(name_or_path: str) -> Path:
    from rgbd_eval.datasets import known_names, scenario_name, scenarios_dir

    path = Path(name_or_path)
    if path.exists():
        return path
    if scenario_name(name_or_path) in known_names():
        return scenarios_dir() / f"{scenario_name(name_or_path)}.yaml"
    raise ConfigError(
        f"{name_or_path}: no such scenario file or name (known: {', '.join(known_names())})"
    )


@handle_errors
def synth(
    scenario: Annotated[
        str | None, typer.Argument(help="scenario YAML file or name (e.g. moving_complex)")
    ] = None,
    out: Annotated[Path | None, typer.Option("-o", "--out", help="output .mcap or .bag")] = None,
    fmt: Annotated[
        str | None,
        typer.Option("--format", help="container: mcap or bag (default: from --out, else mcap)"),
    ] = None,
    seed: Annotated[int | None, typer.Option(help="random seed (default: the scenario's)")] = None,
    all_scenarios: Annotated[
        bool, typer.Option("--all", help="every scenario in configs/scenarios/")
    ] = False,
    preview: Annotated[
        Path | None, typer.Option(help="write a contact sheet PNG with ground-truth boxes")
    ] = None,
    frames: Annotated[int | None, typer.Option(help="render only the first N frames")] = None,
    overrides: Annotated[
        list[str] | None,
        typer.Option("--set", help="scenario KEY=VALUE override, e.g. recording.rgb_format=raw"),
    ] = None,
    rig: Annotated[
        str | None,
        typer.Option(help="re-render through another rig: 'stereo' (satake2009's pair, 512x384)"),
    ] = None,
    follow: Annotated[
        int | None,
        typer.Option(
            help="closed loop: drive the robot after person TARGET with the satake2009 "
            "tracker (seed 002 section 3); writes <out>.follow.csv and .follow.json",
            metavar="TARGET",
        ),
    ] = None,
) -> None:
    """Render scenarios to ROS1 .bag or ROS2 .mcap plus a <name>.gt.csv sidecar; deterministic for a seed."""
    from rgbd_eval.config import parse_overrides
    from rgbd_eval.sim.preview import write_preview
    from rgbd_eval.sim.scenario import load_scenario, scenario_paths
    from rgbd_eval.sim.stereo_rig import with_stereo_rig
    from rgbd_eval.sim.synth import OWNER, dataset_path, ground_truth_path, synthesize

    changes = parse_overrides(overrides or [])
    if rig not in (None, "stereo"):
        raise ConfigError(f"--rig {rig!r}: expected stereo")
    if follow is not None and all_scenarios:
        raise ConfigError("--follow drives one scenario: give a SCENARIO, not --all")

    def prepare(scenario_path: Path) -> Scenario:
        sc = load_scenario(scenario_path, changes)
        return with_stereo_rig(sc) if rig == "stereo" else sc

    if fmt is None:
        fmt = out.suffix[1:] if out is not None and out.suffix in (".mcap", ".bag") else "mcap"
    if fmt not in ("mcap", "bag"):
        raise ConfigError(f"--format {fmt!r}: expected mcap or bag")
    if out is not None and out.suffix not in ("", f".{fmt}"):
        raise ConfigError(f"--out {out}: a {fmt} recording needs a .{fmt} name")
    container: Literal["ros1", "mcap"] = "ros1" if fmt == "bag" else "mcap"
    targets = [preview]
    if out is not None:  # the recording, its ground truth and (--follow) its following record
        targets += [out, ground_truth_path(out)]
        if follow is not None:
            from rgbd_eval.methods.satake2009.follow import follow_paths

            targets += follow_paths(out)
    for target in targets:
        if target is not None:  # before rendering: only files synth wrote are replaced
            check_output_file(target, OWNER)
    if all_scenarios:
        if scenario is not None or out is not None or preview is not None:
            raise ConfigError(
                "--all writes every scenario to datasets/; give no SCENARIO, --out or --preview"
            )
        jobs = [(p, dataset_path(prepare(p).name, container)) for p in scenario_paths()]
    elif scenario is None:
        raise ConfigError("give a SCENARIO (file or name) or --all")
    else:
        path = _scenario_file(scenario)
        if out is None and (preview is None or follow is not None):
            out = dataset_path(prepare(path).name, container)
        jobs = [(path, out)] if out is not None else []
        if preview is not None:
            written = write_preview(prepare(path), preview, seed)
            console.print(f"preview: {written}")
    with progress_bar() as bar:
        for scenario_path, target in jobs:
            sc = prepare(scenario_path)
            task = bar.add_task(scenario_path.stem, total=None)
            advance = advance_callback(bar, task)
            if follow is not None:
                _follow(sc, follow, target, container, seed, frames, advance)
                bar.remove_task(task)
                continue
            try:
                result = synthesize(sc, target, container, seed, advance, max_frames=frames)
            except ValueError as err:
                raise ConfigError(f"{scenario_path}: {err}") from err
            bar.remove_task(task)
            console.print(
                f"{result.recording} ({result.recording_bytes / 1e6:.1f} MB, {result.frames} frames, "
                f"{result.people_instances} people instances, {result.frames_per_second:.1f} frames/s) "
                f"+ {result.ground_truth_csv.name}"
            )


def _follow(
    scenario: Scenario,
    target: int,
    out: Path,
    container: Literal["ros1", "mcap"],
    seed: int | None,
    frames: int | None,
    advance: Callable[[int, int], None],
) -> None:
    """``synth --follow``: the closed loop, its recording and its following record."""
    from rgbd_eval.methods.satake2009.follow import follow, write_follow
    from rgbd_eval.sim.synth import ground_truth_path

    try:
        result = follow(scenario, target, seed, None, None, out, container, frames, advance)
    except ValueError as err:
        raise ConfigError(f"{scenario.name}: {err}") from err
    except OSError as err:  # a full disk: the recording's writer removed its temporary file
        raise OutputError(out, f"cannot write ({err.strerror or err})") from err
    csv_path, json_path = write_follow(result, out)
    s = result.summary

    def metres(v: float | None) -> str:
        return "-" if v is None else f"{v:.2f} m"

    kept = "kept" if s.kept else f"NOT kept (first lost at frame {s.first_lost_frame})"
    console.print(
        f"{out} + {ground_truth_path(out).name}: followed person {target} as track "
        f"{s.locked_track} from frame {s.lock_frame}: {kept}; distance mean "
        f"{metres(s.distance_mean_m)} (min {metres(s.distance_min_m)}, max "
        f"{metres(s.distance_max_m)}), mean |bearing| "
        f"{'-' if s.bearing_mean_abs_deg is None else f'{s.bearing_mean_abs_deg:.1f} deg'}"
    )
    console.print(f"following record: {csv_path} + {json_path.name}")
