"""The extra sensors of a scenario's rig, as config: one model per kind, nothing rendered.

A scenario's ``rig`` lists extra sensors beside the robot's Kinect, each a mapping whose
``kind`` selects its config model and whose ``name`` becomes its topic namespace
(``/<name>/...``) and tf frame (``<name>_optical_frame``). The scenario model validates
them here, without the renderer; the sensors themselves (what each kind renders and
writes) are in :mod:`rgbd_eval.sim.rig_sensors`, which registers further kinds' models here
too. Built in: ``static_depth`` (a fixed time-of-flight depth camera), ``stereo_pair``
(:mod:`rgbd_eval.sim.stereo_rig`) and ``thermal`` (:mod:`rgbd_eval.sim.thermal_camera`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field


class RigSensorConfig(BaseModel):
    """Base of every rig sensor's config: its kind and its name (topics, tf frame)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: str
    name: str = Field(min_length=1, max_length=40, pattern=r"^[A-Za-z][A-Za-z0-9_]*$")


class StaticDepthConfig(RigSensorConfig):
    """A fixed depth camera (time of flight), placed in the world.

    Defaults are the Kinect for Xbox One's depth camera: 512x424, 70.6 x 60 degrees.
    The noise is Gaussian with sigma ``noise_k * z^2 * (1 + off_centre_gain * rho^2)`` (0:
    ideal; ``rho`` the pixel's distance from the image centre over the half-diagonal) plus
    independent ``extra_noise_m``; pixels are invalid beyond ``max_range_m`` and below
    ``min_range_m``, with probability ``edge_dropout`` on depth edges and ``random_dropout``
    anywhere (see :mod:`rgbd_eval.sim.tof`, seed 003 4.3).
    """

    kind: Literal["static_depth"] = "static_depth"
    x: float
    y: float
    z: float = Field(gt=0.0, le=20.0)
    yaw_deg: float = Field(0.0, ge=-360.0, le=360.0, description="heading in the world")
    pitch_deg: float = Field(0.0, ge=-90.0, le=90.0, description="tilt down (positive)")
    width: int = Field(512, ge=8, le=4096)
    height: int = Field(424, ge=8, le=4096)
    hfov_deg: float = Field(70.6, gt=10.0, lt=170.0)
    vfov_deg: float = Field(60.0, gt=10.0, lt=170.0)
    noise_k: float = Field(0.0, ge=0.0, le=0.1, description="depth sigma = k z^2 (m)")
    min_range_m: float = Field(0.5, ge=0.0)
    max_range_m: float = Field(8.0, gt=0.5, le=50.0)
    off_centre_gain: float = Field(
        0.0, ge=0.0, le=10.0, description="noise growth from the image centre to a corner"
    )
    extra_noise_m: float = Field(
        0.0, ge=0.0, le=1.0, description="added Gaussian depth noise std (m), seed 003 Fig. 10"
    )
    edge_jump: float = Field(0.05, gt=0.0, le=1.0, description="relative jump marking an edge")
    edge_dropout: float = Field(0.0, ge=0.0, le=1.0, description="P(invalid) on a depth edge")
    random_dropout: float = Field(0.0, ge=0.0, le=1.0, description="P(invalid) anywhere")


class StereoPairConfig(RigSensorConfig):
    """A stereo camera on the robot, looking ahead (Bumblebee2-like defaults)."""

    kind: Literal["stereo_pair"] = "stereo_pair"
    x: float = Field(0.1, ge=-2.0, le=2.0, description="ahead of base_link (m)")
    z: float = Field(1.2, gt=0.0, le=3.0, description="height of the left camera (m)")
    tilt_deg: float = Field(0.0, ge=-45.0, le=45.0, description="pitched down (positive)")
    baseline_m: float = Field(0.12, gt=0.0, le=1.0)
    width: int = Field(1024, ge=16, le=4096)
    height: int = Field(768, ge=16, le=4096)
    hfov_deg: float = Field(100.0, gt=10.0, lt=170.0)
    texture_seed: int = Field(0, ge=0)
    texture_scale_m: float = Field(0.05, gt=0.0, le=1.0, description="finest texture feature (m)")
    texture_contrast: float = Field(0.45, ge=0.0, le=0.9)
    noise_std: float = Field(2.0, ge=0.0, le=50.0, description="image noise (grey levels)")


class ThermalCameraConfig(RigSensorConfig):
    """A thermal camera on the colour camera. Temperatures in deg C.

    Defaults: 320x240 (the NEC Thermal Tracer TS7302 of seed 004, section 2, is a
    320x240 microbolometer); skin 34 C and clothing 28 C surface temperatures in a 20 C
    room (typical indoor values; the clothing surface lies between skin and air).
    """

    kind: Literal["thermal"] = "thermal"
    width: int = Field(320, ge=16, le=2048)
    height: int = Field(240, ge=16, le=2048)
    hfov_deg: float = Field(56.0, gt=5.0, lt=170.0)
    vfov_deg: float = Field(43.0, gt=5.0, lt=170.0)
    baseline_m: float = Field(0.06, ge=-0.5, le=0.5, description="right of the colour camera")
    offset_y_m: float = Field(0.0, ge=-0.5, le=0.5, description="below the colour camera")
    ambient_c: float = Field(20.0, ge=-30.0, le=45.0)
    floor_c: float = Field(19.0, ge=-30.0, le=45.0)
    skin_c: float = Field(34.0, ge=20.0, le=40.0)
    clothing_c: float = Field(28.0, ge=10.0, le=40.0)
    warm_obstacles: dict[int, float] = Field(
        default_factory=dict, description="obstacle index -> surface temperature (C)"
    )
    limb_contrast: float = Field(
        0.25, ge=0.0, le=1.0, description="share of the contrast lost at grazing view"
    )
    blur_px: float = Field(0.7, ge=0.0, le=10.0, description="Gaussian optics blur sigma")
    netd_k: float = Field(0.08, ge=0.0, le=2.0, description="noise sigma (K)")


_MODELS: dict[str, type[RigSensorConfig]] = {}


def register_rig_config(kind: str, model: type[RigSensorConfig]) -> None:
    """Register the config model of a sensor kind (its ``kind`` must default to it)."""
    if model.model_fields["kind"].default != kind:
        raise ValueError(f"rig sensor {kind!r}: its config model must default kind to it")
    if kind in _MODELS and _MODELS[kind] is not model:
        raise ValueError(f"rig sensor kind {kind!r} is already registered")
    _MODELS[kind] = model


def rig_sensor_config(data: Mapping[str, Any]) -> RigSensorConfig:
    """Validate one ``rig`` entry by its ``kind`` (ValueError naming the known kinds)."""
    kind = data.get("kind")
    model = _MODELS.get(kind) if isinstance(kind, str) else None
    if model is None:
        raise ValueError(f"unknown rig sensor kind {kind!r} (known: {', '.join(sorted(_MODELS))})")
    return model.model_validate(data)


for _kind, _model in (
    ("static_depth", StaticDepthConfig),
    ("stereo_pair", StereoPairConfig),
    ("thermal", ThermalCameraConfig),
):
    register_rig_config(_kind, _model)
