"""Self-contained HTML pages for people: a run's ``report.html`` and the pages of sweep, compare, reproduce, bench."""

from rgbd_eval.report_html.pages import (
    bench_page,
    compare_page,
    reproduce_page,
    run_page,
    sweep_page,
    write_run_html,
    write_score_html,
    write_sweep_html,
)

__all__ = [
    "bench_page",
    "compare_page",
    "reproduce_page",
    "run_page",
    "sweep_page",
    "write_run_html",
    "write_score_html",
    "write_sweep_html",
]
