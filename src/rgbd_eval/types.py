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
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

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


# ----------------------------------------------------------------------------- lens distortion

#: The ``CameraInfo.distortion_model`` values that :class:`CameraModel` applies, and how many
#: coefficients of ``D`` each takes (ROS ``sensor_msgs/distortion_models.h``, OpenCV's
#: order). ``plumb_bob`` (k1 k2 p1 p2 k3) and ``rational_polynomial`` (then k4 k5 k6, the
#: denominator) are OpenCV's ``projectPoints`` model; ``equidistant`` (k1 k2 k3 k4) is
#: OpenCV's ``fisheye`` model.
DISTORTION_MODELS: Mapping[str, int] = {"plumb_bob": 8, "rational_polynomial": 8, "equidistant": 4}

#: The polynomial model is searched for a fold up to this undistorted radius (84 deg off axis).
_FOLD_SEARCH_RADIUS = 10.0
_FOLD_SEARCH_STEPS = 20_000
#: Newton iterations of :meth:`Lens.undistort` at most; it stops at this relative step (the
#: error after it is far smaller: convergence is quadratic).
_NEWTON_STEPS = 50
_NEWTON_TOLERANCE = 1e-12


@dataclass(frozen=True)
class Lens:
    """Lens distortion in normalised image coordinates (``x = X / Z``, ``y = Y / Z``).

    ``coefficients``: k1 k2 p1 p2 k3 k4 k5 k6 of the polynomial model, or k1 k2 k3 k4 of the
    ``fisheye`` (equidistant) model, as OpenCV defines them. A model folds back where its
    distorted radius stops growing (two rays would meet at one pixel); beyond the first
    fold (searched once per lens) the radial factor is held at its value there, so points
    far outside the view project outside the image and every pixel has exactly one ray.
    """

    fisheye: bool
    coefficients: tuple[float, ...]

    def _factor(self, s2: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The radial factor ``f`` at the squared radius ``s2`` (polynomial: ``r^2``; fisheye:
        ``theta^2``), and its derivative ``df / ds2``."""
        if self.fisheye:
            k1, k2, k3, k4 = self.coefficients
            f = 1.0 + s2 * (k1 + s2 * (k2 + s2 * (k3 + s2 * k4)))
            df = k1 + s2 * (2.0 * k2 + s2 * (3.0 * k3 + s2 * 4.0 * k4))
            return f, df
        k1, k2, _, _, k3, k4, k5, k6 = self.coefficients
        num = 1.0 + s2 * (k1 + s2 * (k2 + s2 * k3))
        den = 1.0 + s2 * (k4 + s2 * (k5 + s2 * k6))
        dnum = k1 + s2 * (2.0 * k2 + s2 * 3.0 * k3)
        dden = k4 + s2 * (2.0 * k5 + s2 * 3.0 * k6)
        return num / den, (dnum * den - num * dden) / (den * den)

    def _held(self, s2: FloatArray) -> tuple[FloatArray, FloatArray]:
        """:meth:`_factor`, held at its value beyond the fold (derivative 0 there)."""
        s2_fold, f_fold = _fold(self)
        f, df = self._factor(s2)
        inside = s2 <= s2_fold
        return np.where(inside, f, f_fold), np.where(inside, df, 0.0)

    def distort(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Undistorted -> distorted normalised coordinates (OpenCV's forward model)."""
        r2 = x * x + y * y
        if self.fisheye:
            r = np.sqrt(r2)
            theta = exact.atan(r)
            f = self._held(theta * theta)[0]
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(r > 1e-8, theta * f / r, 1.0)
            return x * scale, y * scale
        f = self._held(r2)[0]
        return self._tangential(x, y, r2, f)

    def _tangential(
        self, x: FloatArray, y: FloatArray, r2: FloatArray, f: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """The polynomial model: radial factor ``f`` and the tangential terms (p1, p2)."""
        p1, p2 = self.coefficients[2:4]
        xy2 = 2.0 * x * y
        return (
            x * f + p1 * xy2 + p2 * (r2 + 2.0 * x * x),
            y * f + p1 * (r2 + 2.0 * y * y) + p2 * xy2,
        )

    def undistort(self, xd: FloatArray, yd: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Distorted -> undistorted normalised coordinates: :meth:`distort` inverted (NaN for a
        fisheye point 90 deg or more off the axis).

        The radius first (Newton's method kept between 0 and the fold, where the distorted
        radius grows monotonically), then, for the polynomial model, Newton's method in 2D
        for the tangential terms, from there.
        """
        xd = np.asarray(xd, dtype=np.float64)
        yd = np.asarray(yd, dtype=np.float64)
        d = np.sqrt(xd * xd + yd * yd)  # distorted radius (fisheye: the angle theta_d)
        s = self._radius(d)
        with np.errstate(divide="ignore", invalid="ignore"):
            # A fisheye pixel 90 deg or more off the axis has no ray with z > 0: NaN.
            r = np.where(s < np.pi / 2, exact.tan(s), np.nan) if self.fisheye else s
            scale = np.where(d > 1e-8, r / d, 1.0)
        x, y = xd * scale, yd * scale
        if self.fisheye or not any(self.coefficients[2:4]):
            return x, y
        for _ in range(_NEWTON_STEPS):
            r2 = x * x + y * y
            f, df = self._held(r2)
            ex, ey = self._tangential(x, y, r2, f)
            ex, ey = xd - ex, yd - ey
            # The Jacobian of the model (symmetric), and one Newton step.
            p1, p2 = self.coefficients[2:4]
            j11 = f + 2.0 * x * x * df + 2.0 * p1 * y + 6.0 * p2 * x
            j12 = 2.0 * x * y * df + 2.0 * p1 * x + 2.0 * p2 * y
            j22 = f + 2.0 * y * y * df + 6.0 * p1 * y + 2.0 * p2 * x
            with np.errstate(divide="ignore", invalid="ignore"):
                det = j11 * j22 - j12 * j12
                dx = (j22 * ex - j12 * ey) / det
                dy = (j11 * ey - j12 * ex) / det
            x, y = x + dx, y + dy
            if _largest(dx / (1.0 + np.abs(x)), dy / (1.0 + np.abs(y))) <= _NEWTON_TOLERANCE:
                break
        return x, y

    def _radius(self, d: FloatArray) -> FloatArray:
        """The radius (fisheye: angle) ``s`` whose distorted radius ``s f(s^2)`` is ``d``:
        Newton's method inside a bracket ``[0, fold]`` it narrows, bisecting when a step
        would leave it."""
        s2_fold, f_fold = _fold(self)
        s_fold = float(np.sqrt(s2_fold))
        beyond = d > s_fold * f_fold  # held factor: solved below, not iterated
        lo, hi = np.where(beyond, s_fold, 0.0), np.full_like(d, s_fold)
        s = np.minimum(d, s_fold)
        for _ in range(_NEWTON_STEPS):
            f, df = self._factor(s * s)
            g = s * f - d
            lo, hi = np.where(g < 0, s, lo), np.where(g < 0, hi, s)
            with np.errstate(divide="ignore", invalid="ignore"):
                newton = s - g / (f + 2.0 * s * s * df)
            inside = (newton >= lo) & (newton <= hi)
            step = np.where(inside, newton, 0.5 * (lo + hi)) - s
            s = s + step
            if _largest(step / (1.0 + s)) <= _NEWTON_TOLERANCE:
                break
        out: FloatArray = np.where(beyond, d / f_fold, s)
        return out


def _largest(*arrays: FloatArray) -> float:
    """The largest finite absolute value in ``arrays`` (0 when there is none)."""
    return max(float(np.max(np.abs(a), initial=0.0, where=np.isfinite(a))) for a in arrays)


@functools.lru_cache(maxsize=64)
def _fold(lens: Lens) -> tuple[float, float]:
    """``(s^2, f)`` at the lens' first fold: the squared radius (fisheye: angle) where the
    distorted radius ``s f(s^2)`` stops growing, and the radial factor there."""
    if lens.fisheye:  # theta below 90 deg, where tan is finite
        s = np.linspace(0.0, np.pi / 2, _FOLD_SEARCH_STEPS + 1, endpoint=False)[1:]
    else:
        s = np.linspace(0.0, _FOLD_SEARCH_RADIUS, _FOLD_SEARCH_STEPS + 1)[1:]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        f = lens._factor(s * s)[0]
        d = s * f
        growing = np.isfinite(d[1:]) & (f[1:] > 0) & (d[1:] > d[:-1])
    stops = np.flatnonzero(~growing)
    i = int(stops[0]) if stops.size else s.size - 1
    return float(s[i] * s[i]), float(f[i])


@functools.lru_cache(maxsize=64)
def _lens(model: str, coefficients: tuple[float, ...]) -> Lens | None:
    """The lens a CameraInfo's model and ``D`` describe; None for none or an unknown model."""
    n = DISTORTION_MODELS.get(model)
    if n is None or not any(coefficients[:n]):
        return None
    k = tuple(float(c) for c in coefficients[:n]) + (0.0,) * (n - len(coefficients))
    return Lens(model == "equidistant", k)


@dataclass(frozen=True)
class CameraModel:
    """A camera: pinhole intrinsics and the lens distortion of its ``CameraInfo``.

    :meth:`project`, :meth:`rays`, :meth:`rays_at`, :meth:`points_at` and :meth:`backproject`
    apply the distortion (:data:`DISTORTION_MODELS`); with all coefficients zero, or a
    model not supported (:meth:`distortion_problem` says which), they are plain pinhole
    arithmetic.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    #: ``CameraInfo.D``: k1 k2 p1 p2 k3 [k4 k5 k6] (plumb_bob, rational_polynomial) or
    #: k1 k2 k3 k4 (equidistant).
    distortion: tuple[float, ...] = ()
    frame_id: str = ""
    #: ``P[0, 3]`` of CameraInfo: ``-fx * baseline`` for the right camera of a rectified
    #: stereo pair (ROS convention), 0 for any other camera.
    tx: float = 0.0
    #: ``CameraInfo.distortion_model``.
    distortion_model: str = "plumb_bob"

    def __post_init__(self) -> None:
        if self.width <= 0 or self.height <= 0:
            raise ValueError(f"camera size must be positive, got {self.width}x{self.height}")
        if not (self.fx > 0 and self.fy > 0):
            raise ValueError(f"focal lengths must be positive, got fx={self.fx}, fy={self.fy}")

    @property
    def K(self) -> FloatArray:  # noqa: N802 - the textbook name of the intrinsic matrix
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def lens(self) -> Lens | None:
        """The distortion applied; None for a pinhole (no non-zero coefficient of a supported
        model)."""
        return _lens(self.distortion_model, self.distortion)

    def distortion_problem(self) -> str | None:
        """What of the distortion is ignored (an unsupported model, extra coefficients)."""
        n = DISTORTION_MODELS.get(self.distortion_model)
        ignored = self.distortion if n is None else self.distortion[n:]
        if not any(ignored):
            return None
        values = ", ".join(f"{v:g}" for v in ignored)
        if n is None:
            return (
                f"distortion model {self.distortion_model!r} is not supported (only "
                f"{', '.join(DISTORTION_MODELS)}): its coefficients ({values}) are ignored"
            )
        return (
            f"{self.distortion_model} distortion takes {n} coefficients: "
            f"the further ones ({values}) are ignored"
        )

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
            self.distortion_model,
        )

    def project(self, points: FloatArray) -> FloatArray:
        """Project ``(N, 3)`` optical-frame points to ``(N, 2)`` pixel coordinates (u, v)."""
        p = np.asarray(points, dtype=np.float64)
        z = p[:, 2]
        lens = self.lens
        with np.errstate(divide="ignore", invalid="ignore"):
            if lens is None:
                u = self.fx * p[:, 0] / z + self.cx
                v = self.fy * p[:, 1] / z + self.cy
            else:
                x, y = lens.distort(p[:, 0] / z, p[:, 1] / z)
                u = self.fx * x + self.cx
                v = self.fy * y + self.cy
        return np.stack([u, v], axis=1)

    def rays_at(self, u: ArrayLike, v: ArrayLike) -> FloatArray:
        """Unit-depth rays (z = 1) through pixels ``(u, v)``, shape ``u.shape + (3,)``."""
        x = (np.asarray(u, dtype=np.float64) - self.cx) / self.fx
        y = (np.asarray(v, dtype=np.float64) - self.cy) / self.fy
        lens = self.lens
        if lens is None:
            return np.stack([x, y, np.ones_like(x)], axis=-1)
        x, y = lens.undistort(x, y)
        return np.stack([x, y, np.where(np.isnan(x), np.nan, 1.0)], axis=-1)  # NaN: no ray

    def points_at(self, u: ArrayLike, v: ArrayLike, z: ArrayLike) -> FloatArray:
        """Optical-frame points at depth ``z`` (along the optical axis) seen at pixels ``(u, v)``."""
        z = np.asarray(z, dtype=np.float64)
        if self.lens is not None:
            out: FloatArray = self.rays_at(u, v) * z[..., None]
            return out
        x = (np.asarray(u, dtype=np.float64) - self.cx) * z / self.fx
        y = (np.asarray(v, dtype=np.float64) - self.cy) * z / self.fy
        return np.stack(np.broadcast_arrays(x, y, z), axis=-1)

    def rays(self) -> FloatArray:
        """Unit-depth rays ``(H, W, 3)`` through every pixel centre (z = 1; NaN where a fisheye
        sees 90 deg or more off its axis); computed once per camera and shared (read-only)."""
        return _ray_table(self)

    def backproject(self, depth: NDArray[np.floating]) -> FloatArray:
        """Depth image (metres, NaN invalid) -> ``(H, W, 3)`` optical-frame points (NaN invalid)."""
        if depth.shape != (self.height, self.width):
            raise ValueError(
                f"depth image is {depth.shape[1]}x{depth.shape[0]}, camera is {self.width}x{self.height}"
            )
        return self.rays() * depth[..., None].astype(np.float64)


@functools.lru_cache(maxsize=8)
def _ray_table(camera: CameraModel) -> FloatArray:
    """:meth:`CameraModel.rays`, kept per camera (the table of a distorted lens is iterated)."""
    if camera.lens is None:
        u = (np.arange(camera.width, dtype=np.float64) - camera.cx) / camera.fx
        v = (np.arange(camera.height, dtype=np.float64) - camera.cy) / camera.fy
        uu, vv = np.meshgrid(u, v)
        rays = np.stack([uu, vv, np.ones_like(uu)], axis=-1)
    else:
        uu, vv = np.meshgrid(
            np.arange(camera.width, dtype=np.float64), np.arange(camera.height, dtype=np.float64)
        )
        rays = camera.rays_at(uu, vv)
    rays.flags.writeable = False
    return rays


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
    """A tracker's output for one track in one frame (seed 000, Listing 6.1).

    ``confidence`` is the score the tracker gives the track in this frame, where it has one
    (basso2012: the HOG confidence of the detection it was updated with; tracker output
    files: their ``conf`` column); ``score --curve`` and ``run --curve`` sweep a threshold on it.
    """

    track_id: int
    x: float
    y: float
    height: float
    box2d: Box2D | None
    visibility: Visibility
    status: TrackStatus = TrackStatus.VALIDATED
    confidence: float | None = None


@dataclass(frozen=True)
class TrackerOutput:
    """Tracker output of one sequence: (frame, stamp_ns, tracks) sorted by stamp, then frame."""

    source: str
    frames: tuple[tuple[int, int, tuple[TrackOutput, ...]], ...]
    num_frames: int | None = None
    """The sequence length when the source states it (MOTChallenge ``seqinfo.ini``)."""
    sensor_poses: tuple[Pose | None, ...] = ()
    """Per frame, the world pose of the frame the tracks were published in (a recording's
    tf), None where unknown; empty when the source has none (text files)."""


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
