"""Self-contained HTML pages for people: a run's ``report.html`` and the pages of sweep, compare,
reproduce, bench (:mod:`.pages`), drawn with :mod:`.plots`, :mod:`.events`, :mod:`.overlay` and
:mod:`.video`, rendered from the templates by :mod:`.render`."""
