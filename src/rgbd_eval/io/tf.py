"""A small tf buffer: static and time-stamped transforms, chains, interpolation (lerp + slerp)."""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np

from rgbd_eval.io.validate import MAX_POSITION_M
from rgbd_eval.types import FloatArray, Pose


def slerp(q0: FloatArray, q1: FloatArray, t: float) -> FloatArray:
    """Spherical linear interpolation between unit quaternions ``(x, y, z, w)``."""
    q0 = q0 / np.linalg.norm(q0)
    q1 = q1 / np.linalg.norm(q1)
    dot = float(np.dot(q0, q1))
    if dot < 0.0:  # take the short way round
        q1, dot = -q1, -dot
    # Nearly parallel (angle < ~1.4e-5 rad): normalised lerp differs from slerp by ~angle^3,
    # below 1e-14, and avoids dividing by sin(angle) ~ 0. A looser cut (e.g. 0.9995) errs by 1e-6.
    if dot > 1.0 - 1e-10:
        q = q0 + t * (q1 - q0)
        lerped: FloatArray = q / np.linalg.norm(q)
        return lerped
    theta = np.arccos(dot)
    out: FloatArray = (np.sin((1.0 - t) * theta) * q0 + np.sin(t * theta) * q1) / np.sin(theta)
    return out


#: A recorded quaternion's norm may differ from 1 by this much (float32 round trips, values
#: rounded to two decimals; rotations are normalised on use); zero, or far from 1 (a flipped
#: exponent bit), it is corrupt, not a rotation.
QUATERNION_NORM_TOLERANCE = 0.1


#: Fastest motion between two consecutive transforms of a moving frame (odometry): 20 m/s
#: (72 km/h) is beyond any robot an RGB-D people tracker rides on. A larger step is a
#: corrupt message, a reset or a teleport, and every pose interpolated across it is wrong.
MAX_SPEED_M_S = 20.0
#: Step allowed on top of MAX_SPEED_M_S x the time between the two transforms (noise, and
#: two messages with one stamp).
JUMP_SLACK_M = 0.1


def pose_problem(pose: Pose) -> str | None:
    """Why ``pose`` cannot be a recorded transform (None when it can)."""
    t = np.asarray(pose.translation, dtype=np.float64)
    q = np.asarray(pose.rotation, dtype=np.float64)
    if not np.all(np.isfinite(t)):
        return f"position {tuple(float(v) for v in t)} is not finite"
    if float(np.max(np.abs(t))) > MAX_POSITION_M:
        return f"position {tuple(float(v) for v in t)} lies beyond {MAX_POSITION_M:g} m"
    if not np.all(np.isfinite(q)):
        return f"quaternion {tuple(float(v) for v in q)} is not finite"
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        return f"quaternion {tuple(float(v) for v in q)} has norm {norm:.6g}, not 1"
    return None


@dataclass
class _Edge:
    parent: str
    static: bool
    stamps: list[int] = field(default_factory=list)
    translations: list[tuple[float, float, float]] = field(default_factory=list)
    rotations: list[tuple[float, float, float, float]] = field(default_factory=list)
    _arrays: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self._arrays is None:
            order = np.argsort(np.asarray(self.stamps, dtype=np.int64), kind="stable")
            self._arrays = (
                np.asarray(self.stamps, dtype=np.int64)[order],
                np.asarray(self.translations, dtype=np.float64)[order],
                np.asarray(self.rotations, dtype=np.float64)[order],
            )
        return self._arrays


class TransformLookupError(ValueError):
    """Frames are not connected, or a stamp is outside the recorded transforms."""


class TfBuffer:
    """Transforms ``parent_T_child`` keyed by child frame (a tf tree: one parent per child)."""

    def __init__(self) -> None:
        self._edges: dict[str, _Edge] = {}

    def add(self, parent: str, child: str, stamp_ns: int, pose: Pose, static: bool = False) -> None:
        """Record ``parent_T_child`` at ``stamp_ns``; TransformLookupError on a non-finite pose."""
        parent, child = parent.lstrip("/"), child.lstrip("/")
        problem = pose_problem(pose)
        if problem is not None:
            raise TransformLookupError(
                f"{parent}->{child} at stamp {stamp_ns} ns ({stamp_ns / 1e9:.9f} s): {problem}"
            )
        edge = self._edges.get(child)
        if edge is None:
            edge = self._edges[child] = _Edge(parent, static)
        elif edge.parent != parent:
            raise TransformLookupError(
                f"frame {child!r} has two parents: {edge.parent!r} and {parent!r}"
            )
        if static:
            edge.static = True
            edge.stamps, edge.translations, edge.rotations = (
                [stamp_ns],
                [pose.translation],
                [pose.rotation],
            )
        else:
            edge.stamps.append(stamp_ns)
            edge.translations.append(pose.translation)
            edge.rotations.append(pose.rotation)
        edge._arrays = None

    @property
    def frames(self) -> set[str]:
        return set(self._edges) | {e.parent for e in self._edges.values()}

    @property
    def has_dynamic(self) -> bool:
        return any(not e.static for e in self._edges.values())

    def _path_to_root(self, frame: str) -> list[str]:
        path = [frame]
        while path[-1] in self._edges:
            parent = self._edges[path[-1]].parent
            if parent in path:
                raise TransformLookupError(f"tf loop through {parent!r}")
            path.append(parent)
        return path

    def chain(self, target: str, source: str) -> list[str]:
        """Frames from ``target`` to ``source`` through their common ancestor."""
        target, source = target.lstrip("/"), source.lstrip("/")
        up_source = self._path_to_root(source)
        up_target = self._path_to_root(target)
        common = next((f for f in up_source if f in up_target), None)
        if common is None:
            known = ", ".join(sorted(self.frames)) or "none"
            raise TransformLookupError(
                f"no tf chain from {target!r} to {source!r} (root of {target!r} is "
                f"{up_target[-1]!r}, root of {source!r} is {up_source[-1]!r}; frames: {known})"
            )
        down = up_target[: up_target.index(common) + 1]
        up = up_source[: up_source.index(common)]
        return down + list(reversed(up))

    def _edge_pose(self, child: str, stamp_ns: int, tolerance_ns: int) -> Pose:
        edge = self._edges[child]
        stamps, trans, rots = edge.arrays()
        if edge.static or (len(stamps) == 1 and abs(int(stamps[0]) - stamp_ns) <= tolerance_ns):
            return Pose(tuple(trans[0]), tuple(rots[0]))
        i = int(np.searchsorted(stamps, stamp_ns, side="right"))
        if i == 0 or i == len(stamps):
            k = 0 if i == 0 else len(stamps) - 1
            if abs(int(stamps[k]) - stamp_ns) > tolerance_ns:
                raise TransformLookupError(
                    f"{edge.parent}->{child} has no transform at {stamp_ns} ns "
                    f"(recorded {int(stamps[0])}..{int(stamps[-1])})"
                )
            return Pose(tuple(trans[k]), tuple(rots[k]))
        t0, t1 = int(stamps[i - 1]), int(stamps[i])
        if t0 == stamp_ns:  # recorded at this very stamp: as recorded (slerp re-normalises)
            return Pose(tuple(trans[i - 1]), tuple(rots[i - 1]))
        a = 0.0 if t1 == t0 else (stamp_ns - t0) / (t1 - t0)
        p = trans[i - 1] + a * (trans[i] - trans[i - 1])
        q = slerp(rots[i - 1], rots[i], a)
        return Pose(
            (float(p[0]), float(p[1]), float(p[2])),
            (float(q[0]), float(q[1]), float(q[2]), float(q[3])),
        )

    def jump_problem(self, frames: list[str]) -> tuple[str, str] | None:
        """``(child frame, why)`` of the first impossible step of a moving transform along
        ``frames`` (a chain), if any.

        Between two consecutive transforms (by stamp) of a moving edge, the child may move
        at most ``MAX_SPEED_M_S`` x the time between them, plus ``JUMP_SLACK_M``.
        """
        for child in frames:
            edge = self._edges.get(child)
            if edge is None or edge.static or len(edge.stamps) < 2:
                continue
            stamps, trans, _ = edge.arrays()
            step = np.linalg.norm(np.diff(trans, axis=0), axis=1)
            dt = np.diff(stamps).astype(np.float64) / 1e9
            bad = np.flatnonzero(step > MAX_SPEED_M_S * dt + JUMP_SLACK_M)
            if bad.size:
                k = int(bad[0])
                return child, (
                    f"{edge.parent}->{child} moves {step[k]:.3g} m in {dt[k] * 1e3:.3g} ms "
                    f"(at stamp {int(stamps[k + 1])} ns): faster than {MAX_SPEED_M_S:g} m/s, "
                    "a corrupt, reset or teleporting pose"
                )
        return None

    def lookup(self, target: str, source: str, stamp_ns: int, tolerance_ns: int = 0) -> Pose:
        """``target_T_source`` at ``stamp_ns``, interpolated; held up to ``tolerance_ns`` past the ends."""
        frames = self.chain(target, source)
        T = np.eye(4)
        for parent, child in pairwise(frames):
            if self._edges.get(child) is not None and self._edges[child].parent == parent:
                T = T @ self._edge_pose(child, stamp_ns, tolerance_ns).matrix()
            else:
                T = T @ self._edge_pose(parent, stamp_ns, tolerance_ns).inverse().matrix()
        return Pose.from_matrix(T)
