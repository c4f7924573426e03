"""Methods, one package per paper: ``basso2012``, ``pinto2022``, ``satake2009``, ``dmtbs``,
``cielniak2010``.

Each package holds its detector and tracker with their config models, the pieces special
to its paper, its default config (``method.yaml``), its paper's numbers and claims
(``paper.yaml``), its experiments for ``rgbd-eval reproduce`` and a ``README.md``. Importing
a package registers its detector, tracker, method and paper (:mod:`rgbd_eval.plugins` scans
this folder); building blocks shared by methods are in :mod:`rgbd_eval.detect` and
:mod:`rgbd_eval.track`. A third-party method is one package shaped like these, registered
through the ``rgbd_eval.plugins`` entry point or ``$RGBD_EVAL_PLUGINS``.
"""
