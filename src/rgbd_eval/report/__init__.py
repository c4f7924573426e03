"""Reports for people and machines, the top of the package with the command line.

- :mod:`.run`: a run's ``report.json`` (schema versioned), ``report.md``, terminal tables and
  the per-sequence CSVs (detections, tracks, events);
- :mod:`.scoring`: ``rgbd-eval score``, recorded tracker output scored into the same report;
- :mod:`.html`: the self-contained HTML pages (run, sweep, compare, reproduce, bench), with
  plots, event markers and overlay video; their Jinja2 templates are in ``templates/``.

``compare`` (:mod:`rgbd_eval.compare`) reads two reports and sits at this level too.
"""
