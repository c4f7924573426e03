"""Scenario recordings rendered where ``reproduce`` runs its experiments: on a cluster's workers.

A paper judged over several scenario seeds needs each scored scene rendered at each seed
(:func:`rgbd_eval.sim.synth.ensure_scenario`: rendered when absent or out of date, kept in
``--data``). One render is minutes of CPU and the renders do not depend on each other, so
:func:`ensure_recordings` hands the missing ones to the cluster of ``reproduce --cluster``
(``local:2``: two at a time) and counts the CPU they took in this process's rendering
figure, as the page reports it.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rgbd_eval.engine import map_ordered
from rgbd_eval.sim import synth

if TYPE_CHECKING:
    from distributed import Client

#: One recording to have: the scenario's YAML, the folder (None: the generated datasets) and
#: the scenario seed (None: the scenario's own).
Job = tuple[Path, Path | None, int | None]


def render_seeded(scenario: Path, folder: Path | None, seed: int | None) -> tuple[int, float]:
    """The scenario file's recording at ``seed`` in ``folder`` (one task of
    :func:`ensure_recordings`); returns the process id and the CPU seconds it rendered."""
    before = synth.rendering_cpu_s()
    synth.ensure_scenario(scenario, folder, seed=seed)
    return os.getpid(), synth.rendering_cpu_s() - before


def ensure_recordings(
    jobs: Sequence[Job],
    client: Client | None = None,
    say: Callable[[str], None] | None = None,
    render: Callable[[Path, Path | None, int | None], tuple[int, float]] = render_seeded,
) -> list[Path]:
    """Each job's recording path (:func:`rgbd_eval.sim.synth.recording_path`), the absent or
    out-of-date ones rendered first: on ``client``'s workers when given (a worker in another
    process counts its rendering there, so it is counted here too), else one by one here."""
    files = [(synth.scenario_file(s), folder, seed) for s, folder, seed in jobs]
    paths = [synth.recording_path(s, folder, seed) for s, folder, seed in files]
    missing: dict[Path, Job] = {}  # by path: a recording two jobs name is rendered once
    for job, path in zip(files, paths, strict=True):
        if path not in missing and not synth.is_current(path, job[0], job[2]):
            missing[path] = job
    if missing:
        if say is not None:
            where = "on the cluster's workers" if client is not None else "one by one"
            say(f"generating {len(missing)} recording(s) {where} ...")
        done = (
            (render(*job) for job in missing.values())
            if client is None
            else map_ordered(client, render, list(missing.values()))
        )
        for k, (path, (pid, seconds)) in enumerate(zip(missing, done, strict=True), start=1):
            if pid != os.getpid():
                synth.add_rendering_cpu(seconds)
            if say is not None:
                say(f"rendered {path} ({k} of {len(missing)})")
    return paths
