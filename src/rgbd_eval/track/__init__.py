"""Trackers: the protocol, filters, association, and one module per method (registered on import)."""

from rgbd_eval.track.protocol import Tracker, create_tracker, needs_frame

__all__ = ["Tracker", "create_tracker", "needs_frame"]
