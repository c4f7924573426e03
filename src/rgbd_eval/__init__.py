"""rgbd-eval: batch evaluation of RGB-D people trackers on recorded robot data."""

__version__ = "0.1.0"
