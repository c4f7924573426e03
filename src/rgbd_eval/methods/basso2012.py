"""basso2012: RGB-D people tracking by detection for a mobile robot (seed 000, the reference)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from rgbd_eval.plugins import (
    MethodSpec,
    PaperSpec,
    ReproduceOptions,
    ReproduceResult,
    register_method,
    register_paper,
)

#: The thesis test set (seed 000, chapter 7).
SCENARIOS = (
    "static_simple",
    "static_complex",
    "static_obstacles",
    "moving_simple",
    "moving_complex",
    "moving_obstacles",
)
#: Beyond the thesis: the obstacle sequences plus person-sized clutter, for the tracker's
#: ``static`` variant (reported by ``reproduce`` without paper values).
CLUTTER = ("static_clutter", "moving_clutter")

register_method(
    MethodSpec(
        name="basso2012",
        detector="basso2012",
        tracker="basso2012",
        title="RGB-D people tracking by detection for a mobile robot (Basso, thesis 2012)",
        seed="000",
        gating="iou",
        config_file="methods/basso2012.yaml",
    )
)


def _reproduce(recordings: Mapping[str, Path], options: ReproduceOptions) -> ReproduceResult:
    from rgbd_eval.reproduce import paper_values, render_markdown, reproduce_basso2012, to_json

    res = reproduce_basso2012(
        recordings, jobs=options.jobs, cache=options.cache, progress=options.progress
    )
    return ReproduceResult(
        markdown=render_markdown(res, paper_values()),
        data=to_json(res),
        claims=tuple((c.sentence, c.held) for c in res.claims),
    )


register_paper(
    PaperSpec(
        method="basso2012",
        title="seed 000 chapter 7: Tables 7.1-7.6, Figures 7.7 and 7.9",
        scenarios=(*SCENARIOS, *CLUTTER),
        run=_reproduce,
    )
)
