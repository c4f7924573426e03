"""Reading and writing recordings: ROS1 bags, ROS2 bag folders, lone MCAP/SQLite3 files.

``open_recording`` yields synchronised :class:`~rgbd_eval.types.Frame` objects;
``RecordingWriter`` writes the same content (used by ``synth`` and the tests).
"""
