"""The experiments behind ``rgbd-eval reproduce <method>``: simulated rigs, sweeps of one
factor at a time, and the checks of each paper's claims.

Each method's ``_reproduce`` (``rgbd_eval.methods.<name>``) imports its module here when it
runs. Plug-in discovery scans ``detect``, ``track`` and ``methods`` only, so every CLI call
and every Dask worker loads no simulator (``rgbd_eval.sim``, open3d) unless it reproduces.
"""
