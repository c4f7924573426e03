"""Write RGB-D recordings with the real ROS libraries (rosbags for bags, mcap for lone .mcap).

One API for every container, so that a synthetic sequence can be written as a
ROS1 bag and as a ROS2 MCAP with identical content. The output appears
atomically: it is written under a temporary name and renamed when closed
without error. With ``owner`` (the command writing it) a single-file recording is
an output the user named: it replaces only a recording that command wrote
(:func:`rgbd_eval.outdir.check_output_file`, checked when the writer is made).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any, Literal

import numpy as np
import yaml
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from numpy.typing import NDArray
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer

from rgbd_eval.io import images, provenance
from rgbd_eval.io.messages import (
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    GT_ARRAY_TYPE,
    IMAGE_TYPE,
    ODOMETRY_TYPE,
    TF_TYPE,
    typestore,
)
from rgbd_eval.outdir import check_output_file, publish_file
from rgbd_eval.types import CameraModel, GroundTruthObject, Pose

Container = Literal["ros1", "mcap", "ros2-sqlite3", "ros2-mcap"]
CONTAINERS: tuple[str, ...] = ("ros1", "mcap", "ros2-sqlite3", "ros2-mcap")

RGB_TOPIC = "/camera/rgb/image_color"
RGB_INFO_TOPIC = "/camera/rgb/camera_info"
DEPTH_TOPIC = "/camera/depth/image"
DEPTH_INFO_TOPIC = "/camera/depth/camera_info"
ODOM_TOPIC = "/odom"
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
GT_TOPIC = "/ground_truth"


@dataclass(frozen=True)
class StreamOptions:
    """How images are stored."""

    rgb_format: Literal["raw", "jpeg"] = "raw"
    depth_encoding: Literal["16UC1", "32FC1"] = "16UC1"
    depth_compressed: bool = False
    jpeg_quality: int = 90
    ros1_compression: Literal["none", "lz4", "bz2"] = "none"

    def __post_init__(self) -> None:
        if self.rgb_format not in ("raw", "jpeg"):
            raise ValueError(f"rgb_format={self.rgb_format!r} must be 'raw' or 'jpeg'")
        if self.depth_encoding not in ("16UC1", "32FC1"):
            raise ValueError(f"depth_encoding={self.depth_encoding!r} must be '16UC1' or '32FC1'")
        if not 1 <= self.jpeg_quality <= 100:
            raise ValueError(f"jpeg_quality={self.jpeg_quality} must be in 1..100")
        if self.ros1_compression not in ("none", "lz4", "bz2"):
            raise ValueError(f"ros1_compression={self.ros1_compression!r} must be none, lz4 or bz2")

    @property
    def rgb_topic(self) -> str:
        return RGB_TOPIC + ("/compressed" if self.rgb_format == "jpeg" else "")

    @property
    def depth_topic(self) -> str:
        base = DEPTH_TOPIC if self.depth_encoding == "32FC1" else "/camera/depth/image_raw"
        return base + ("/compressedDepth" if self.depth_compressed else "")


def container_for_path(path: Path) -> Container:
    """Guess the container from the output name: .bag -> ros1, .mcap -> mcap, else a ROS2 folder."""
    if path.suffix == ".bag":
        return "ros1"
    if path.suffix == ".mcap":
        return "mcap"
    return "ros2-mcap"


class RecordingWriter:
    """Context manager writing one recording; see the module docstring."""

    def __init__(
        self,
        path: Path | str,
        container: Container | None = None,
        options: StreamOptions | None = None,
        overwrite: bool = False,
        owner: str | None = None,
    ) -> None:
        self.path = Path(path)
        self.container: Container = container or container_for_path(self.path)
        if self.container not in CONTAINERS:
            raise ValueError(f"container={self.container!r} must be one of {', '.join(CONTAINERS)}")
        self.owner = owner
        if owner is not None:
            if self.container not in ("ros1", "mcap"):
                raise ValueError(f"owner={owner!r} needs a single-file container (ros1 or mcap)")
            check_output_file(self.path, owner)  # OutputError: not ours to replace
        elif self.path.exists() and not overwrite:
            raise FileExistsError(f"{self.path} exists; pass overwrite=True to replace it")
        if self.path.is_dir() and not (self.path / "metadata.yaml").is_file():
            raise IsADirectoryError(f"{self.path} is a folder, not a recording: not replaced")
        self.options = options or StreamOptions()
        self.ros_version: Literal[1, 2] = 1 if self.container == "ros1" else 2
        self.store = typestore(self.ros_version)
        self._tmp = self.path.with_name(f".{self.path.name}.tmp-{os.getpid()}")
        self._remove(self._tmp)
        self._connections: dict[str, Any] = {}
        self._seq: dict[str, int] = {}
        self._writer: Any = None
        self._mcap_file: Any = None

    # -- lifecycle

    def __enter__(self) -> RecordingWriter:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if self.container == "ros1":
            writer = Ros1Writer(self._tmp)
            if self.options.ros1_compression != "none":
                fmt = Ros1Writer.CompressionFormat[self.options.ros1_compression.upper()]
                writer.set_compression(fmt)
            writer.open()
            self._writer = writer
        elif self.container == "mcap":
            self._mcap_file = self._tmp.open("wb")
            mw = McapWriter(self._mcap_file, compression=CompressionType.ZSTD)
            mw.start(profile="ros2", library="rgbd-eval")
            self._writer = mw
        else:
            plugin = StoragePlugin.MCAP if self.container == "ros2-mcap" else StoragePlugin.SQLITE3
            writer2 = Ros2Writer(self._tmp, version=9, storage_plugin=plugin)
            writer2.open()
            self._writer = writer2
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is not None:
            self._abort()
            return
        try:
            if self.container == "mcap":
                self._writer.finish()
                self._mcap_file.close()
            else:
                self._writer.close()
                if self.container != "ros1":
                    self._name_storage_files()
        except BaseException:  # a full disk fails here too: no half-written file is left
            self._abort()
            raise
        if self.owner is not None:
            publish_file(self._tmp, self.path, self.owner)  # removes the temporary file
            return
        self._remove(self.path)
        os.replace(self._tmp, self.path)

    def _name_storage_files(self) -> None:
        """Give a ROS 2 folder's storage file the recording's name, not the temporary one.

        rosbags names the file after the folder it writes (``.<name>.tmp-PID``); once the
        folder is renamed that name would be left inside it, so the file is renamed and
        ``metadata.yaml`` (``relative_file_paths``, ``files[].path``) follows.
        """
        meta_path = self._tmp / "metadata.yaml"
        meta = yaml.safe_load(meta_path.read_text(encoding="utf-8"))
        info = meta["rosbag2_bagfile_information"]
        renames: dict[str, str] = {}
        for old in info.get("relative_file_paths", []):
            new = f"{self.path.name}{Path(old).suffix}"
            os.replace(self._tmp / old, self._tmp / new)
            renames[old] = new
        info["relative_file_paths"] = [renames[f] for f in info.get("relative_file_paths", [])]
        for entry in info.get("files") or []:
            entry["path"] = renames.get(entry["path"], entry["path"])
        meta_path.write_text(yaml.safe_dump(meta, sort_keys=False), encoding="utf-8")

    def _abort(self) -> None:
        try:
            if self.container == "mcap":
                self._mcap_file.close()
            elif self._writer is not None:
                self._writer.close()
        except (OSError, ValueError, RuntimeError):
            pass
        self._remove(self._tmp)

    @staticmethod
    def _remove(path: Path) -> None:
        if path.is_dir():
            shutil.rmtree(path)
        elif path.exists():
            path.unlink()

    # -- low level

    def _connection(self, topic: str, msgtype: str) -> Any:
        conn = self._connections.get(topic)
        if conn is not None:
            return conn
        if self.container == "mcap":
            msgdef, _ = self.store.generate_msgdef(msgtype, ros_version=2)
            schema_id = self._writer.register_schema(
                name=msgtype, encoding="ros2msg", data=msgdef.encode()
            )
            conn = self._writer.register_channel(
                topic=topic, message_encoding="cdr", schema_id=schema_id
            )
        elif self.container == "ros1":
            latching = 1 if topic == TF_STATIC_TOPIC else None
            conn = self._writer.add_connection(
                topic, msgtype, typestore=self.store, latching=latching
            )
        else:
            conn = self._writer.add_connection(topic, msgtype, typestore=self.store)
        self._connections[topic] = conn
        return conn

    def write_message(self, topic: str, msgtype: str, stamp_ns: int, msg: Any) -> None:
        """Serialise and write one message with log time ``stamp_ns``."""
        conn = self._connection(topic, msgtype)
        if self.ros_version == 1:
            data = self.store.serialize_ros1(msg, msgtype)
            self._writer.write(conn, stamp_ns, data)
        elif self.container == "mcap":
            data = self.store.serialize_cdr(msg, msgtype)
            seq = self._seq.get(topic, 0)
            self._seq[topic] = seq + 1
            self._writer.add_message(
                channel_id=conn,
                log_time=stamp_ns,
                data=bytes(data),
                publish_time=stamp_ns,
                sequence=seq,
            )
        else:
            self._writer.write(conn, stamp_ns, self.store.serialize_cdr(msg, msgtype))

    def _t(self, name: str) -> Any:
        return self.store.types[name]

    def header(self, stamp_ns: int, frame_id: str, topic: str = "") -> Any:
        stamp = self._t("builtin_interfaces/msg/Time")(
            sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000
        )
        if self.ros_version == 1:
            seq = self._seq.get("hdr" + topic, 0)
            self._seq["hdr" + topic] = seq + 1
            return self._t("std_msgs/msg/Header")(seq=seq, stamp=stamp, frame_id=frame_id)
        return self._t("std_msgs/msg/Header")(stamp=stamp, frame_id=frame_id)

    # -- typed helpers

    def _transform(self, stamp_ns: int, parent: str, child: str, pose: Pose) -> Any:
        t = self._t
        return t("geometry_msgs/msg/TransformStamped")(
            header=self.header(stamp_ns, parent, "tf"),
            child_frame_id=child,
            transform=t("geometry_msgs/msg/Transform")(
                translation=t("geometry_msgs/msg/Vector3")(*pose.translation),
                rotation=t("geometry_msgs/msg/Quaternion")(*pose.rotation),
            ),
        )

    def write_transform(self, stamp_ns: int, parent: str, child: str, pose: Pose) -> None:
        """``parent_T_child`` on ``/tf``."""
        msg = self._t(TF_TYPE)(transforms=[self._transform(stamp_ns, parent, child, pose)])
        self.write_message(TF_TOPIC, TF_TYPE, stamp_ns, msg)

    def write_static_transform(self, stamp_ns: int, parent: str, child: str, pose: Pose) -> None:
        """``parent_T_child`` on ``/tf_static``."""
        msg = self._t(TF_TYPE)(transforms=[self._transform(stamp_ns, parent, child, pose)])
        self.write_message(TF_STATIC_TOPIC, TF_TYPE, stamp_ns, msg)

    def write_provenance(self, stamp_ns: int, record: Mapping[str, Any]) -> None:
        """Where the recording came from, as JSON on :data:`provenance.PROVENANCE_TOPIC`."""
        msg = self._t(provenance.PROVENANCE_TYPE)(data=provenance.encode(record))
        self.write_message(provenance.PROVENANCE_TOPIC, provenance.PROVENANCE_TYPE, stamp_ns, msg)

    def write_odometry(self, stamp_ns: int, frame_id: str, child_frame_id: str, pose: Pose) -> None:
        """``nav_msgs/Odometry`` on ``/odom`` (pose ``frame_id_T_child``, zero twist)."""
        t = self._t
        vec = t("geometry_msgs/msg/Vector3")
        msg = t(ODOMETRY_TYPE)(
            header=self.header(stamp_ns, frame_id, ODOM_TOPIC),
            child_frame_id=child_frame_id,
            pose=t("geometry_msgs/msg/PoseWithCovariance")(
                pose=t("geometry_msgs/msg/Pose")(
                    position=t("geometry_msgs/msg/Point")(*pose.translation),
                    orientation=t("geometry_msgs/msg/Quaternion")(*pose.rotation),
                ),
                covariance=np.zeros(36),
            ),
            twist=t("geometry_msgs/msg/TwistWithCovariance")(
                twist=t("geometry_msgs/msg/Twist")(
                    linear=vec(0.0, 0.0, 0.0), angular=vec(0.0, 0.0, 0.0)
                ),
                covariance=np.zeros(36),
            ),
        )
        self.write_message(ODOM_TOPIC, ODOMETRY_TYPE, stamp_ns, msg)

    def camera_info(self, stamp_ns: int, camera: CameraModel, topic: str) -> Any:
        K = camera.K.reshape(-1)
        P = np.array(
            [camera.fx, 0, camera.cx, camera.tx, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0],
            dtype=np.float64,
        )
        D = np.asarray(camera.distortion or (0.0,) * 5, dtype=np.float64)
        R = np.eye(3).reshape(-1)
        roi = self._t("sensor_msgs/msg/RegionOfInterest")(
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        )
        mats = {"D": D, "K": K, "R": R, "P": P}
        if self.ros_version == 2:
            mats = {k.lower(): v for k, v in mats.items()}
        return self._t(CAMERA_INFO_TYPE)(
            header=self.header(stamp_ns, camera.frame_id, topic),
            height=camera.height,
            width=camera.width,
            distortion_model=camera.distortion_model,
            binning_x=0,
            binning_y=0,
            roi=roi,
            **mats,
        )

    def write_rgb(self, stamp_ns: int, rgb: NDArray[np.uint8], camera: CameraModel) -> None:
        """The RGB image (raw rgb8 or jpeg) and its CameraInfo."""
        if rgb.shape != (camera.height, camera.width, 3):
            raise ValueError(
                f"rgb image shape {rgb.shape} does not match camera {camera.width}x{camera.height}"
            )
        topic = self.options.rgb_topic
        header = self.header(stamp_ns, camera.frame_id, topic)
        if self.options.rgb_format == "jpeg":
            fields = images.encode_color_jpeg(rgb, self.options.jpeg_quality)
            msg = self._t(COMPRESSED_IMAGE_TYPE)(header=header, **fields)
            self.write_message(topic, COMPRESSED_IMAGE_TYPE, stamp_ns, msg)
        else:
            msg = self._t(IMAGE_TYPE)(header=header, **images.encode_color_raw(rgb))
            self.write_message(topic, IMAGE_TYPE, stamp_ns, msg)
        self.write_message(
            RGB_INFO_TOPIC,
            CAMERA_INFO_TYPE,
            stamp_ns,
            self.camera_info(stamp_ns, camera, RGB_INFO_TOPIC),
        )

    def write_depth(self, stamp_ns: int, depth: NDArray[np.floating], camera: CameraModel) -> None:
        """The depth image (metres, NaN invalid) in the configured encoding, and its CameraInfo."""
        if depth.shape != (camera.height, camera.width):
            raise ValueError(
                f"depth image shape {depth.shape} does not match camera {camera.width}x{camera.height}"
            )
        topic = self.options.depth_topic
        header = self.header(stamp_ns, camera.frame_id, topic)
        if self.options.depth_compressed:
            fields = images.encode_depth_compressed(depth, self.options.depth_encoding)
            msg = self._t(COMPRESSED_IMAGE_TYPE)(header=header, **fields)
            self.write_message(topic, COMPRESSED_IMAGE_TYPE, stamp_ns, msg)
        else:
            msg = self._t(IMAGE_TYPE)(
                header=header, **images.encode_depth_raw(depth, self.options.depth_encoding)
            )
            self.write_message(topic, IMAGE_TYPE, stamp_ns, msg)
        self.write_message(
            DEPTH_INFO_TOPIC,
            CAMERA_INFO_TYPE,
            stamp_ns,
            self.camera_info(stamp_ns, camera, DEPTH_INFO_TOPIC),
        )

    def write_image(
        self,
        topic: str,
        info_topic: str,
        stamp_ns: int,
        image: NDArray[Any],
        camera: CameraModel,
        encoding: str,
    ) -> None:
        """A raw ``sensor_msgs/Image`` on any topic, and its CameraInfo on ``info_topic``.

        ``encoding``: ``rgb8`` (``HxWx3 uint8``), ``mono8`` (uint8), ``mono16`` (uint16 raw
        counts, e.g. a thermal camera), ``16UC1``/``32FC1`` (depth in metres, NaN invalid).
        One sensor per topic pair: a rig of several cameras calls this once per camera.
        """
        if image.shape[:2] != (camera.height, camera.width):
            raise ValueError(
                f"image shape {image.shape} does not match camera {camera.width}x{camera.height}"
            )
        if encoding in ("16UC1", "32FC1"):
            fields = images.encode_depth_raw(image, encoding)
        elif encoding == "rgb8":
            fields = images.encode_color_raw(image)
        elif encoding in ("mono8", "mono16"):
            arr = np.ascontiguousarray(image, dtype=np.uint8 if encoding == "mono8" else "<u2")
            fields = {
                "height": camera.height,
                "width": camera.width,
                "encoding": encoding,
                "is_bigendian": 0,
                "step": camera.width * arr.itemsize,
                "data": np.frombuffer(arr.tobytes(), dtype=np.uint8),
            }
        else:
            raise ValueError(f"encoding={encoding!r}: expected rgb8, mono8, mono16, 16UC1 or 32FC1")
        header = self.header(stamp_ns, camera.frame_id, topic)
        self.write_message(
            topic, IMAGE_TYPE, stamp_ns, self._t(IMAGE_TYPE)(header=header, **fields)
        )
        self.write_message(
            info_topic, CAMERA_INFO_TYPE, stamp_ns, self.camera_info(stamp_ns, camera, info_topic)
        )

    def write_ground_truth(
        self, stamp_ns: int, world_frame: str, objects: list[GroundTruthObject]
    ) -> None:
        """One ``GroundTruthArray`` on ``/ground_truth`` for the frame at ``stamp_ns``."""
        person = self._t("rgbd_eval_msgs/msg/GroundTruthPerson")
        people = []
        for o in objects:
            x, y, z = o.world_xyz if o.world_xyz is not None else (np.nan, np.nan, np.nan)
            box = o.box2d.as_tuple() if o.box2d is not None else (0.0, 0.0, 0.0, 0.0)
            people.append(
                person(
                    id=o.object_id,
                    x=x,
                    y=y,
                    z=z,
                    bb_left=box[0],
                    bb_top=box[1],
                    bb_width=box[2],
                    bb_height=box[3],
                    visibility=float(o.visibility),
                    ignore=bool(o.ignore),
                )
            )
        msg = self._t(GT_ARRAY_TYPE)(
            header=self.header(stamp_ns, world_frame, GT_TOPIC), people=people
        )
        self.write_message(GT_TOPIC, GT_ARRAY_TYPE, stamp_ns, msg)
