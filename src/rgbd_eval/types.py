"""The data model shared by every stage: frames -> detections -> tracks -> scores.

Conventions (used everywhere in the package):

- Stamps are integer nanoseconds.
- Camera (optical) frames follow ROS REP-103: x right, y down, z forward.
- The world frame (odometry ``odom``/``map``) is z-up; the ground plane is
  spanned by world x and y. Without odometry, the world frame is the camera's
  body frame at the camera (x forward, y left, z up), see :data:`OPTICAL_TO_BODY`.
- Images: RGB is ``HxWx3 uint8`` in RGB channel order; depth is ``hxw float32``
  in metres with NaN for invalid pixels.
- 2D boxes are ``(left, top, width, height)`` in RGB image pixels.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact

FloatArray = NDArray[np.float64]


class Visibility(enum.IntEnum):
    """Visibility of a track, as in the thesis' Track message (seed 000, Listing 6.1)."""

    VISIBLE = 0
    OCCLUDED = 1
    NOT_VISIBLE = 2


class TrackStatus(enum.Enum):
    """Life-cycle state of a track (seed 000, 6.4)."""

    NEW = "new"
    VALIDATED = "validated"


# ----------------------------------------------------------------------------- geometry


def _quat_to_matrix(q: tuple[float, float, float, float]) -> FloatArray:
    x, y, z, w = q
    n = x * x + y * y + z * z + w * w
    if n < 1e-12:
        raise ValueError(f"quaternion {q} has zero norm")
    s = 2.0 / n
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def _matrix_to_quat(R: FloatArray) -> tuple[float, float, float, float]:
    """Rotation matrix -> unit quaternion (x, y, z, w), w >= 0 (Shepperd's method)."""
    m = R
    tr = float(m[0, 0] + m[1, 1] + m[2, 2])
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        w, x, y, z = (
            0.25 * s,
            (m[2, 1] - m[1, 2]) / s,
            (m[0, 2] - m[2, 0]) / s,
            (m[1, 0] - m[0, 1]) / s,
        )
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        w, x, y, z = (
            (m[2, 1] - m[1, 2]) / s,
            0.25 * s,
            (m[0, 1] + m[1, 0]) / s,
            (m[0, 2] + m[2, 0]) / s,
        )
    elif m[1, 1] > m[2, 2]:
        s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        w, x, y, z = (
            (m[0, 2] - m[2, 0]) / s,
            (m[0, 1] + m[1, 0]) / s,
            0.25 * s,
            (m[1, 2] + m[2, 1]) / s,
        )
    else:
        s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        w, x, y, z = (
            (m[1, 0] - m[0, 1]) / s,
            (m[0, 2] + m[2, 0]) / s,
            (m[1, 2] + m[2, 1]) / s,
            0.25 * s,
        )
    x, y, z, w = float(x), float(y), float(z), float(w)
    n = math.sqrt(x * x + y * y + z * z + w * w)  # in a fixed order: not BLAS (exact.py)
    if w < 0:
        n = -n
    return (x / n, y / n, z / n, w / n)


@dataclass(frozen=True)
class Pose:
    """A rigid transform ``parent_T_child``: maps points in the child frame to the parent frame.

    ``rotation`` is a unit quaternion ``(x, y, z, w)`` as in ROS messages.
    """

    translation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    @staticmethod
    def identity() -> Pose:
        return Pose()

    @staticmethod
    def from_matrix(T: FloatArray) -> Pose:
        """Build from a 4x4 homogeneous matrix."""
        t = T[:3, 3]
        return Pose((float(t[0]), float(t[1]), float(t[2])), _matrix_to_quat(T[:3, :3]))

    def rotation_matrix(self) -> FloatArray:
        return _quat_to_matrix(self.rotation)

    def matrix(self) -> FloatArray:
        """The 4x4 homogeneous matrix."""
        T = np.eye(4)
        T[:3, :3] = self.rotation_matrix()
        T[:3, 3] = self.translation
        return T

    def compose(self, other: Pose) -> Pose:
        """``self * other``: if self is a_T_b and other is b_T_c, the result is a_T_c."""
        return Pose.from_matrix(exact.matmul(self.matrix(), other.matrix()))

    def inverse(self) -> Pose:
        R = self.rotation_matrix()
        t = np.asarray(self.translation)
        T = np.eye(4)
        T[:3, :3] = R.T
        T[:3, 3] = -exact.matmul(t, R)  # -R^T t
        return Pose.from_matrix(T)

    def transform_points(self, points: FloatArray) -> FloatArray:
        """Apply to an ``(N, 3)`` array of points."""
        return exact.transform(points, self.rotation_matrix(), self.translation)


#: body_T_optical for a camera: optical (x right, y down, z forward) -> body (x fwd, y left, z up).
OPTICAL_TO_BODY = Pose((0.0, 0.0, 0.0), (-0.5, 0.5, -0.5, 0.5))


@dataclass(frozen=True)
class CameraModel:
    """A pinhole camera (plumb-bob distortion kept for reference, images assumed rectified)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    distortion: tuple[float, ...] = ()
    frame_id: str = ""
    #: ``P[0, 3]`` of CameraInfo: ``-fx * baseline`` for the right camera of a rectified
    #: stereo pair (ROS convention), 0 for any other camera.
    tx: float = 0.0

    def __post_init__(self) -> None:
        if self.width <= 0 or self.height <= 0:
            raise ValueError(f"camera size must be positive, got {self.width}x{self.height}")
        if not (self.fx > 0 and self.fy > 0):
            raise ValueError(f"focal lengths must be positive, got fx={self.fx}, fy={self.fy}")

    @property
    def K(self) -> FloatArray:  # noqa: N802 - the textbook name of the intrinsic matrix
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def scaled(self, width: int, height: int) -> CameraModel:
        """The same camera at another resolution (decimation or up-sampling)."""
        sx, sy = width / self.width, height / self.height
        return CameraModel(
            width,
            height,
            self.fx * sx,
            self.fy * sy,
            (self.cx + 0.5) * sx - 0.5,
            (self.cy + 0.5) * sy - 0.5,
            self.distortion,
            self.frame_id,
            self.tx * sx,
        )

    def project(self, points: FloatArray) -> FloatArray:
        """Project ``(N, 3)`` optical-frame points to ``(N, 2)`` pixel coordinates (u, v)."""
        p = np.asarray(points, dtype=np.float64)
        z = p[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = self.fx * p[:, 0] / z + self.cx
            v = self.fy * p[:, 1] / z + self.cy
        return np.stack([u, v], axis=1)

    def rays(self) -> FloatArray:
        """Unit-depth rays ``(H, W, 3)`` through every pixel centre (z = 1)."""
        u = (np.arange(self.width, dtype=np.float64) - self.cx) / self.fx
        v = (np.arange(self.height, dtype=np.float64) - self.cy) / self.fy
        uu, vv = np.meshgrid(u, v)
        return np.stack([uu, vv, np.ones_like(uu)], axis=-1)

    def backproject(self, depth: NDArray[np.floating]) -> FloatArray:
        """Depth image (metres, NaN invalid) -> ``(H, W, 3)`` optical-frame points (NaN invalid)."""
        if depth.shape != (self.height, self.width):
            raise ValueError(
                f"depth image is {depth.shape[1]}x{depth.shape[0]}, camera is {self.width}x{self.height}"
            )
        return self.rays() * depth[..., None].astype(np.float64)


@dataclass(frozen=True)
class Box2D:
    """An axis-aligned image box ``(left, top, width, height)`` in pixels."""

    left: float
    top: float
    width: float
    height: float

    @property
    def right(self) -> float:
        return self.left + self.width

    @property
    def bottom(self) -> float:
        return self.top + self.height

    def as_tuple(self) -> tuple[float, float, float, float]:
        return (self.left, self.top, self.width, self.height)


@dataclass(frozen=True)
class Box3D:
    """An axis-aligned world box given by its minimum and maximum corners (metres)."""

    min_corner: tuple[float, float, float]
    max_corner: tuple[float, float, float]


# ----------------------------------------------------------------------------- stream records


@dataclass(frozen=True, eq=False)
class Stream:
    """One image of a frame: a role's image with its camera, stamp and pose.

    ``encoding`` says what the pixels are: ``rgb8`` (``HxWx3 uint8``), ``mono8``/``mono16``
    (thermal or grey, raw counts) or ``depth`` (``float32`` metres, NaN invalid).
    ``pose`` is ``world_T_optical`` of this camera at the frame stamp.
    """

    image: NDArray[Any]
    encoding: str
    camera: CameraModel
    stamp_ns: int
    pose: Pose = field(default_factory=lambda: OPTICAL_TO_BODY)


@dataclass(frozen=True, eq=False)
class Frame:
    """One synchronised instant of a recording: named streams (``colour``, ``depth``,
    ``depth_2``, ``thermal``, ``left``, ``right``; see :data:`rgbd_eval.plugins.ROLES`).

    ``stamp_ns`` is the stamp of the reference stream (the first the method reads).
    ``camera_pose`` is ``world_T_optical`` of the primary geometry camera (``depth``
    when present): it maps its optical-frame points to the world frame.
    ``depth_to_rgb`` is ``colour_optical_T_depth_optical`` (identity when the depth is
    registered to colour, or either is absent). ``world_frame`` names the world frame;
    ``has_odometry`` is False when the recording has no odometry and the world frame
    is the camera body frame.
    """

    index: int
    stamp_ns: int
    streams: Mapping[str, Stream]
    depth_to_rgb: Pose = field(default_factory=Pose.identity)
    camera_pose: Pose = field(default_factory=lambda: OPTICAL_TO_BODY)
    world_frame: str = "camera"
    has_odometry: bool = False

    @staticmethod
    def rgbd(
        index: int,
        stamp_ns: int,
        rgb: NDArray[np.uint8],
        depth: NDArray[np.float32],
        rgb_camera: CameraModel,
        depth_camera: CameraModel,
        depth_to_rgb: Pose | None = None,
        camera_pose: Pose = OPTICAL_TO_BODY,
        world_frame: str = "camera",
        has_odometry: bool = False,
    ) -> Frame:
        """A colour + depth frame, both at ``stamp_ns`` (the common case, and tests)."""
        d2r = depth_to_rgb or Pose.identity()
        colour_pose = camera_pose.compose(d2r.inverse()) if depth_to_rgb else camera_pose
        return Frame(
            index=index,
            stamp_ns=stamp_ns,
            streams={
                "colour": Stream(rgb, "rgb8", rgb_camera, stamp_ns, colour_pose),
                "depth": Stream(depth, "depth", depth_camera, stamp_ns, camera_pose),
            },
            depth_to_rgb=d2r,
            camera_pose=camera_pose,
            world_frame=world_frame,
            has_odometry=has_odometry,
        )

    def stream(self, role: str) -> Stream:
        """The stream of ``role``; KeyError naming the roles present when absent."""
        try:
            return self.streams[role]
        except KeyError:
            raise KeyError(
                f"frame {self.index} has no {role!r} stream (has: {', '.join(self.streams)})"
            ) from None

    @property
    def rgb(self) -> NDArray[np.uint8]:
        """The colour image (``HxWx3 uint8``, RGB order)."""
        image: NDArray[np.uint8] = self.stream("colour").image
        return image

    @property
    def depth(self) -> NDArray[np.float32]:
        """The (first) depth image in metres, NaN invalid."""
        image: NDArray[np.float32] = self.stream("depth").image
        return image

    @property
    def rgb_camera(self) -> CameraModel:
        return self.stream("colour").camera

    @property
    def depth_camera(self) -> CameraModel:
        return self.stream("depth").camera

    def depth_streams(self) -> list[tuple[str, Stream]]:
        """Every depth camera's stream: ``depth``, ``depth_2``, ... in that order."""
        roles = [r for r in self.streams if r == "depth" or r.startswith("depth_")]
        roles.sort(key=lambda r: 1 if r == "depth" else int(r.rpartition("_")[2]))
        return [(r, self.streams[r]) for r in roles]


@dataclass(frozen=True, eq=False)
class Detection:
    """One detected person candidate, in world coordinates (seed 000, 5.3, Listing 5.2).

    ``position`` is the theoretical centroid (x, y, z) in the world frame; its x, y
    are the ground-plane position used by trackers and metric gating.
    ``appearance`` is a method-specific descriptor (e.g. a 3D colour histogram).
    ``footprint`` is the world (x, y) of the floor cells of a density-map blob, ``(N, 2)``
    (seed 003's blob splitting divides it among the tracks that share it).
    """

    position: tuple[float, float, float]
    height: float
    confidence: float
    box2d: Box2D
    box3d: Box3D | None = None
    distance: float = 0.0
    occluded: bool = False
    appearance: NDArray[np.float32] | None = None
    footprint: NDArray[np.float64] | None = None

    @property
    def ground_xy(self) -> tuple[float, float]:
        return (self.position[0], self.position[1])


@dataclass(frozen=True)
class TrackOutput:
    """A tracker's output for one track in one frame (seed 000, Listing 6.1)."""

    track_id: int
    x: float
    y: float
    height: float
    box2d: Box2D | None
    visibility: Visibility
    status: TrackStatus = TrackStatus.VALIDATED


@dataclass(frozen=True)
class GroundTruthObject:
    """One annotated person in one frame.

    Either ``box2d`` (RGB image) or ``world_xyz`` (world frame) may be missing,
    not both. ``visibility`` is the visible fraction in [0, 1]. ``ignore`` marks
    people that are fully occluded or out of view: they neither count as a miss
    nor make a false positive when a track sits on them. ``distractor`` says what an
    ignored object does to a track matched to it: ``True`` drops the track (the
    MOTChallenge distractor classes); ``False`` only lets the object take part in
    the matching, and the track stays scored (MOT17's non-person classes and
    pedestrians with the consider flag 0). It has no effect on scored objects.
    """

    frame: int
    stamp_ns: int
    object_id: int
    box2d: Box2D | None
    world_xyz: tuple[float, float, float] | None
    visibility: float = 1.0
    ignore: bool = False
    distractor: bool = True

    def __post_init__(self) -> None:
        if self.box2d is None and self.world_xyz is None:
            raise ValueError(
                f"ground truth id {self.object_id} at frame {self.frame} has no box and no position"
            )
