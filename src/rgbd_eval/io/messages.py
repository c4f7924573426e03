"""Message types: the ROS typestores the package uses, and its own ground-truth messages.

The ground-truth topic carries ``rgbd_eval_msgs/msg/GroundTruthArray``; its
definition is registered with every typestore this module hands out, and the
ROS1 Noetic typestore also gets ``tf2_msgs/msg/TFMessage``, which it lacks. The
people-tracker output types ``rgbd-eval score`` reads are registered too
(:mod:`rgbd_eval.io.track_message_types`, which includes ``vision_msgs``), and so is
``darknet_ros_msgs/BoundingBoxes`` (recorded 2D detections): neither stock typestore
has them.
"""

from __future__ import annotations

from functools import cache
from typing import Literal

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from rgbd_eval.io.track_message_types import track_message_definitions

GT_PERSON_TYPE = "rgbd_eval_msgs/msg/GroundTruthPerson"
GT_ARRAY_TYPE = "rgbd_eval_msgs/msg/GroundTruthArray"

GT_PERSON_MSG = """\
# One annotated person in one frame.
int32 id
# World position (metres) in header.frame_id of the enclosing array; NaN when unknown.
float64 x
float64 y
float64 z
# Full-body box on the RGB image (pixels); width <= 0 when unknown.
float64 bb_left
float64 bb_top
float64 bb_width
float64 bb_height
# Visible fraction in [0, 1].
float32 visibility
# True when fully occluded or out of view: neither a miss nor a false positive.
bool ignore
"""

GT_ARRAY_MSG = """\
std_msgs/Header header
rgbd_eval_msgs/GroundTruthPerson[] people
"""

TF_MESSAGE_MSG = "geometry_msgs/TransformStamped[] transforms\n"

DARKNET_MSGS = {
    "darknet_ros_msgs/msg/BoundingBox": (
        "float64 probability\nint64 xmin\nint64 ymin\nint64 xmax\nint64 ymax\nint16 id\nstring Class\n"
    ),
    "darknet_ros_msgs/msg/BoundingBoxes": (
        "std_msgs/Header header\nstd_msgs/Header image_header\n"
        "darknet_ros_msgs/BoundingBox[] bounding_boxes\n"
    ),
}
DETECTION2D_ARRAY_TYPE = "vision_msgs/msg/Detection2DArray"
BOUNDING_BOXES_TYPE = "darknet_ros_msgs/msg/BoundingBoxes"

IMAGE_TYPE = "sensor_msgs/msg/Image"
COMPRESSED_IMAGE_TYPE = "sensor_msgs/msg/CompressedImage"
#: A stereo matcher's output: a 32FC1 disparity image with the focal length and baseline.
DISPARITY_TYPE = "stereo_msgs/msg/DisparityImage"
CAMERA_INFO_TYPE = "sensor_msgs/msg/CameraInfo"
ODOMETRY_TYPE = "nav_msgs/msg/Odometry"
TF_TYPE = "tf2_msgs/msg/TFMessage"

RosVersion = Literal[1, 2]


def extra_types(ros_version: RosVersion) -> dict[str, tuple[list[object], list[object]]]:
    """Type definitions to add to a stock typestore."""
    types: dict[str, tuple[list[object], list[object]]] = {}
    types.update(get_types_from_msg(GT_PERSON_MSG, GT_PERSON_TYPE))  # type: ignore[arg-type]
    types.update(get_types_from_msg(GT_ARRAY_MSG, GT_ARRAY_TYPE))  # type: ignore[arg-type]
    if ros_version == 1:
        types.update(get_types_from_msg(TF_MESSAGE_MSG, TF_TYPE))  # type: ignore[arg-type]
    for name, text in (*track_message_definitions(ros_version).items(), *DARKNET_MSGS.items()):
        types.update(get_types_from_msg(text, name))  # type: ignore[arg-type]
    return types


@cache
def typestore(ros_version: RosVersion) -> Typestore:
    """ROS1 Noetic or ROS2 Humble typestore with the package's extra types registered."""
    store = get_typestore(Stores.ROS1_NOETIC if ros_version == 1 else Stores.ROS2_HUMBLE)
    store.register(extra_types(ros_version))  # type: ignore[arg-type]
    return store
