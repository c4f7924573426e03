"""Methods: each module registers one paper's pairing (detector + tracker), its defaults
file, its default gating and its experiments for ``rgbd-eval reproduce`` (see
:mod:`rgbd_eval.plugins`)."""
