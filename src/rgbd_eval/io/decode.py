"""Decoding: image messages of each role into arrays, CameraInfo into camera models.

Image encodings are in :mod:`rgbd_eval.io.images`; here each role's image is decoded and
checked against its camera, and each stream gets its camera model: from its CameraInfo
(rectified images take ``P``'s intrinsics), or, for a registered depth image without
CameraInfo of its own, the colour camera's.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from rgbd_eval.errors import DecodeError, TopicError
from rgbd_eval.io import images, validate
from rgbd_eval.io.index import MessageIndex
from rgbd_eval.io.streams import SelectedTopics
from rgbd_eval.plugins import role_kind
from rgbd_eval.types import CameraModel

#: The image of a stream read with ``Recording.frames(skip=...)``.
NOT_DECODED = np.zeros((0, 0), dtype=np.uint8)


def decode_image(
    path: Path, msg: Any, topic: str, role: str, camera: CameraModel
) -> tuple[Any, str]:
    """The image of a message of ``role`` and its encoding (``depth``: metres, NaN invalid;
    ``mono16``/``mono8``: thermal; ``rgb8``); a DecodeError when it cannot be decoded or its
    size is not its camera's."""
    kind = role_kind(role)
    try:
        img: Any
        if kind == "disparity":
            img = images.depth_from_disparity_message(msg)
            encoding = "depth"
        elif kind == "depth":
            img = images.decode_depth(msg)
            encoding = "depth"
        elif kind == "thermal":
            img = images.decode_mono(msg)
            encoding = "mono16" if img.dtype == np.uint16 else "mono8"
        else:
            img = images.decode_color(msg)
            encoding = "rgb8"
    except images.ImageFormatError as err:
        raise DecodeError(path, str(err), topic) from err
    if (problem := validate.image_size_problem(img)) is not None:
        raise DecodeError(path, problem, topic)
    if img.shape[:2] != (camera.height, camera.width):
        raise DecodeError(
            path,
            f"image is {img.shape[1]}x{img.shape[0]} but its CameraInfo says "
            f"{camera.width}x{camera.height}",
            topic,
        )
    return img, encoding


def camera_model_from_info(msg: Any, rectified: bool = False) -> CameraModel:
    """``sensor_msgs/CameraInfo`` (ROS1 ``K``/``D``/``P`` or ROS2 ``k``/``d``/``p``) -> CameraModel.

    ``rectified``: the image is a rectified one (:func:`is_rectified`). Its CameraInfo (shared
    with the raw image, as image_proc publishes it) has the raw image's ``K`` and ``D``; the
    rectified image has no distortion left and the intrinsics of ``P`` (of ``K`` when ``P``
    is not set). Without distortion in ``D``, ``K`` is taken as for any image.
    """
    K = np.asarray(msg.K if hasattr(msg, "K") else msg.k, dtype=np.float64).reshape(3, 3)
    D = tuple(float(v) for v in (msg.D if hasattr(msg, "D") else msg.d))
    P = np.asarray(msg.P if hasattr(msg, "P") else getattr(msg, "p", ()), dtype=np.float64)
    fx, fy, cx, cy = float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2])
    if rectified and any(D):
        D = ()
        if P.size == 12 and P[0] > 0 and P[5] > 0:
            fx, fy, cx, cy = float(P[0]), float(P[5]), float(P[2]), float(P[6])
    return CameraModel(
        width=int(msg.width),
        height=int(msg.height),
        fx=fx,
        fy=fy,
        cx=cx,
        cy=cy,
        distortion=D,
        frame_id=msg.header.frame_id.lstrip("/"),
        tx=float(P[3]) if P.size == 12 else 0.0,
        distortion_model=str(getattr(msg, "distortion_model", "")),
    )


def is_rectified(topic: str) -> bool:
    """An image topic image_proc rectified: ``.../image_rect``, ``image_rect_color``,
    ``image_rect_raw`` (a ``compressed`` transport aside)."""
    parts = topic.rstrip("/").split("/")
    if parts[-1] in ("compressed", "compressedDepth"):
        parts = parts[:-1]
    return bool(parts) and parts[-1].startswith("image_rect")


def camera_models(
    path: Path,
    sel: SelectedTopics,
    index: MessageIndex,
    first: Mapping[str, Any],
    warnings: list[str],
) -> dict[str, CameraModel]:
    """Each stream's camera model from its CameraInfo.

    A depth image without CameraInfo of its own that has the colour image's frame id
    and size is registered to it (``depth_registered`` topics): it takes the colour
    camera's model (:attr:`SelectedTopics.registration`, also when the method reads no
    colour images), with a warning.
    """
    cameras: dict[str, CameraModel] = {}
    order = sorted(sel.streams, key=lambda r: r in sel.infos, reverse=True)  # own info first
    for role in order:
        topic = sel.streams[role]
        info_topic = sel.infos.get(role)
        msg = index.first_msgs.get(info_topic) if info_topic else None
        if msg is None and info_topic is not None and info_topic in index.skips.counts:
            raise DecodeError(
                path,
                f"no usable CameraInfo: all {index.skips.counts[info_topic]} messages are "
                f"damaged ({index.skips.first[info_topic]})",
                info_topic,
            )
        if msg is None:
            colour = _registered_camera(path, sel, index, first, cameras, warnings)
            img = first[topic]
            left = cameras.get("left")
            if role_kind(role) == "disparity" and left is not None:
                inner = img.image
                if (int(inner.width), int(inner.height)) != (left.width, left.height):
                    raise TopicError(
                        path,
                        f"disparity image is {inner.width}x{inner.height} but the left camera "
                        f"is {left.width}x{left.height} (give --topic disparity_info=/name)",
                        topic,
                    )
                cameras[role] = left  # a DisparityImage is in the left camera's frame
                continue
            frame_id = img.header.frame_id.lstrip("/")
            if (
                role_kind(role) == "depth"
                and colour is not None
                and frame_id == colour.frame_id
                and (
                    hasattr(img, "format")
                    or (int(img.width), int(img.height)) == (colour.width, colour.height)
                )
            ):
                warnings.append(
                    f"{topic} has no CameraInfo of its own: registered to the colour image "
                    f"({sel.registration[1] if sel.registration else None}), whose camera "
                    "model it takes"
                )
                cameras[role] = colour
                continue
            raise TopicError(
                path,
                f"no CameraInfo for this image topic (choose it with --topic {role}_info=/name)",
                topic,
            )
        cameras[role] = _camera(path, info_topic, msg, first[topic], topic, warnings)
    return {role: cameras[role] for role in sel.streams}


def _registered_camera(
    path: Path,
    sel: SelectedTopics,
    index: MessageIndex,
    first: Mapping[str, Any],
    cameras: Mapping[str, CameraModel],
    warnings: list[str],
) -> CameraModel | None:
    """The model of the colour camera of :attr:`SelectedTopics.registration`, if usable."""
    if sel.registration is None:
        return None
    if "colour" in cameras:  # read by the method: its model, from the same CameraInfo
        return cameras["colour"]
    topic, info_topic = sel.registration
    msg = index.first_msgs.get(info_topic)
    return None if msg is None else _camera(path, info_topic, msg, first[topic], topic, warnings)


def _camera(
    path: Path, info_topic: str | None, msg: Any, first: Any, topic: str, warnings: list[str]
) -> CameraModel:
    """The camera model of ``topic`` from its CameraInfo ``msg``; what of the distortion is
    not applied goes to ``warnings``."""
    first = first.image if hasattr(first, "f") else first  # a DisparityImage's image
    rectified = is_rectified(topic)
    try:
        camera = camera_model_from_info(msg, rectified)
    except ValueError as err:
        raise DecodeError(path, f"bad CameraInfo: {err}", info_topic) from err
    if not camera.frame_id:
        camera = replace(camera, frame_id=first.header.frame_id.lstrip("/"))
    notes = []
    if rectified and any(msg.D if hasattr(msg, "D") else msg.d):
        notes.append(
            f"{topic} is rectified: the {camera.distortion_model} distortion in {info_topic} "
            "describes the raw image and is not applied (intrinsics from its P, where set)"
        )
    problem = camera.distortion_problem()
    if problem is not None:
        notes.append(f"{info_topic}: {problem}")
    warnings.extend(n for n in notes if n not in warnings)  # once per camera
    return camera
