"""Message definitions of the people-tracker output types ``rgbd-eval score`` reads.

Registered with the package's typestores (:mod:`rgbd_eval.io.messages`); the texts
follow the upstream packages: spencer_messages, people (people_msgs), vision_msgs
4.x (ROS2) and 0.0.x (ROS1 Noetic), and OpenPTrack's opt_msgs (v1 ``Track``; v2
adds ``face_id`` and ``object_name``, read from the bag's own definitions).
"""

from __future__ import annotations

SPENCER_TYPE = "spencer_tracking_msgs/msg/TrackedPersons"
PEOPLE_TYPE = "people_msgs/msg/People"
DETECTION3D_TYPE = "vision_msgs/msg/Detection3DArray"
DETECTION2D_TYPE = "vision_msgs/msg/Detection2DArray"
OPT_TYPE = "opt_msgs/msg/TrackArray"
TRACK_TYPES = (SPENCER_TYPE, PEOPLE_TYPE, DETECTION3D_TYPE, DETECTION2D_TYPE, OPT_TYPE)

_COMMON = {
    "spencer_tracking_msgs/msg/TrackedPerson": """\
uint64 track_id
bool is_occluded
bool is_matched
uint64 detection_id
builtin_interfaces/Duration age
geometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist
""",
    SPENCER_TYPE: "std_msgs/Header header\nspencer_tracking_msgs/TrackedPerson[] tracks\n",
    "people_msgs/msg/Person": """\
string name
geometry_msgs/Point position
geometry_msgs/Point velocity
float64 reliability
string[] tagnames
string[] tags
""",
    PEOPLE_TYPE: "std_msgs/Header header\npeople_msgs/Person[] people\n",
    "opt_msgs/msg/BoundingBox2D": "int32 x\nint32 y\nint32 width\nint32 height\n",
    "opt_msgs/msg/Track": """\
uint8 VISIBLE = 0
uint8 OCCLUDED = 1
uint8 NOT_VISIBLE = 2
int32 id
float64 x
float64 y
float64 height
float64 distance
float64 age
float64 confidence
uint8 visibility
opt_msgs/BoundingBox2D box_2D
""",
    OPT_TYPE: "std_msgs/Header header\nopt_msgs/Track[] tracks\n",
    "vision_msgs/msg/BoundingBox3D": "geometry_msgs/Pose center\ngeometry_msgs/Vector3 size\n",
}
# vision_msgs 4.x (ROS2): hypotheses hold a class id string; detections an `id` string.
_ROS2 = {
    "vision_msgs/msg/ObjectHypothesis": "string class_id\nfloat64 score\n",
    "vision_msgs/msg/ObjectHypothesisWithPose": """\
vision_msgs/ObjectHypothesis hypothesis
geometry_msgs/PoseWithCovariance pose
""",
    "vision_msgs/msg/Point2D": "float64 x\nfloat64 y\n",
    "vision_msgs/msg/Pose2D": "vision_msgs/Point2D position\nfloat64 theta\n",
    "vision_msgs/msg/BoundingBox2D": "vision_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y\n",
    "vision_msgs/msg/Detection2D": """\
std_msgs/Header header
vision_msgs/ObjectHypothesisWithPose[] results
vision_msgs/BoundingBox2D bbox
string id
""",
    "vision_msgs/msg/Detection3D": """\
std_msgs/Header header
vision_msgs/ObjectHypothesisWithPose[] results
vision_msgs/BoundingBox3D bbox
string id
""",
}
# vision_msgs 0.0.x (ROS1 Noetic): `is_tracking` and `tracking_id`, a Pose2D centre.
_ROS1 = {
    "vision_msgs/msg/ObjectHypothesisWithPose": """\
int64 id
float64 score
geometry_msgs/PoseWithCovariance pose
""",
    "vision_msgs/msg/BoundingBox2D": "geometry_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y\n",
    "vision_msgs/msg/Detection2D": """\
std_msgs/Header header
vision_msgs/ObjectHypothesisWithPose[] results
vision_msgs/BoundingBox2D bbox
sensor_msgs/Image source_img
bool is_tracking
string tracking_id
""",
    "vision_msgs/msg/Detection3D": """\
std_msgs/Header header
vision_msgs/ObjectHypothesisWithPose[] results
vision_msgs/BoundingBox3D bbox
sensor_msgs/PointCloud2 source_cloud
bool is_tracking
string tracking_id
""",
}
_ARRAYS = {
    DETECTION2D_TYPE: "std_msgs/Header header\nvision_msgs/Detection2D[] detections\n",
    DETECTION3D_TYPE: "std_msgs/Header header\nvision_msgs/Detection3D[] detections\n",
}


def track_message_definitions(ros_version: int) -> dict[str, str]:
    """``.msg`` texts by type name for one ROS version (dependencies before dependents)."""
    return {**_COMMON, **(_ROS1 if ros_version == 1 else _ROS2), **_ARRAYS}
