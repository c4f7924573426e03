"""Trackers: the protocol and name registry, filters, association, and one module per method."""

from rgbd_eval.track import basso2012 as _basso2012  # noqa: F401  (registers "basso2012")
from rgbd_eval.track.protocol import Tracker, create_tracker, known_trackers, register_tracker

__all__ = ["Tracker", "create_tracker", "known_trackers", "register_tracker"]
