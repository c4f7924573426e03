"""The scenario model: a validated description of one synthetic recording.

A scenario names a room, obstacles, people with their paths, the robot with
its path, the sensor and the odometry error model. Unknown keys are rejected
(``extra="forbid"``) and every model is frozen, as in :mod:`rgbd_eval.config`.

World frame: z up, metres; the robot starts at ``robot.start`` and the world
frame coincides with odometry's ``odom`` frame at t = 0.
"""

from __future__ import annotations

import enum
import hashlib
import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    SerializeAsAny,
    ValidationError,
    field_validator,
    model_validator,
)

from rgbd_eval import exact
from rgbd_eval.config import config_dir, format_validation_error, load_yaml, set_dotted
from rgbd_eval.errors import ConfigError
from rgbd_eval.sim.rig_config import RigSensorConfig, rig_sensor_config

Colour = tuple[int, int, int]


class _Model(BaseModel):
    model_config = ConfigDict(
        extra="forbid", frozen=True, validate_default=True, allow_inf_nan=False
    )


def _check_colour(name: str, colour: Colour) -> None:
    if not all(0 <= c <= 255 for c in colour):
        raise ValueError(f"{name}={colour} must have channels in [0, 255]")


# ----------------------------------------------------------------------------- room and obstacles


class Room(_Model):
    """A rectangular room: floor and (optionally) four walls."""

    x_min: float = Field(-1.0, description="room extent along world x (m)")
    x_max: float = Field(11.0)
    y_min: float = Field(-5.0, description="room extent along world y (m)")
    y_max: float = Field(5.0)
    wall_height: float = Field(2.8, gt=0.5, le=10.0)
    walls: bool = Field(True, description="draw the four walls")
    ceiling: bool = Field(True, description="close the room with a ceiling at wall_height")
    floor_colour: Colour = Field((150, 132, 110), description="floor base colour (RGB)")
    floor_tile: float = Field(0.6, gt=0.05, le=5.0, description="floor tile side (m)")
    wall_colour: Colour = Field((205, 200, 188), description="wall base colour (RGB)")

    @model_validator(mode="after")
    def _check(self) -> Room:
        if self.x_max - self.x_min < 1.0 or self.y_max - self.y_min < 1.0:
            raise ValueError(
                f"room x [{self.x_min}, {self.x_max}] and y [{self.y_min}, {self.y_max}] "
                "must each span at least 1 m"
            )
        _check_colour("floor_colour", self.floor_colour)
        _check_colour("wall_colour", self.wall_colour)
        return self


class ObstacleKind(enum.Enum):
    """Furniture and person-sized non-person objects (false candidates for clustering).

    The thesis' obstacles (seed 000, 7.1) occlude people: box, pillar, table, chair, sofa.
    Coat stand, plant, cabinet and mannequin are person-sized clutter for the stress
    scenarios ``static_clutter`` and ``moving_clutter``. A door (leaf, frame and handle) stands
    against a wall, its leaf facing +x before ``yaw_deg``; a shelf is a bookcase with books.
    """

    BOX = "box"
    PILLAR = "pillar"
    TABLE = "table"
    CHAIR = "chair"
    SOFA = "sofa"
    COAT_STAND = "coat_stand"
    PLANT = "plant"
    CABINET = "cabinet"
    PICTURE = "picture"
    MANNEQUIN = "mannequin"
    DOOR = "door"
    SHELF = "shelf"


#: Default (length x, width y, height z) in metres per kind.
DEFAULT_SIZES: dict[ObstacleKind, tuple[float, float, float]] = {
    ObstacleKind.BOX: (0.6, 0.6, 0.8),
    ObstacleKind.PILLAR: (0.5, 0.5, 2.8),
    ObstacleKind.TABLE: (1.2, 0.8, 0.75),
    ObstacleKind.CHAIR: (0.45, 0.45, 0.9),
    ObstacleKind.SOFA: (0.9, 2.0, 0.85),
    ObstacleKind.COAT_STAND: (0.7, 0.7, 1.8),
    ObstacleKind.PLANT: (1.0, 1.0, 1.7),
    ObstacleKind.CABINET: (0.5, 0.9, 1.85),
    ObstacleKind.PICTURE: (0.03, 0.8, 0.6),
    ObstacleKind.MANNEQUIN: (0.5, 0.5, 1.75),
    ObstacleKind.DOOR: (0.06, 0.95, 2.05),
    ObstacleKind.SHELF: (0.35, 0.9, 1.9),
}

DEFAULT_COLOURS: dict[ObstacleKind, Colour] = {
    ObstacleKind.BOX: (160, 120, 70),
    ObstacleKind.PILLAR: (190, 190, 195),
    ObstacleKind.TABLE: (120, 80, 45),
    ObstacleKind.CHAIR: (60, 60, 70),
    ObstacleKind.SOFA: (90, 40, 40),
    ObstacleKind.COAT_STAND: (70, 45, 25),
    ObstacleKind.PLANT: (40, 110, 45),
    ObstacleKind.CABINET: (175, 170, 160),
    ObstacleKind.PICTURE: (60, 90, 140),
    ObstacleKind.MANNEQUIN: (200, 180, 160),
    ObstacleKind.DOOR: (150, 112, 72),
    ObstacleKind.SHELF: (186, 150, 108),
}


class Obstacle(_Model):
    """One static object standing on the floor (a picture hangs on a wall at ``z``)."""

    kind: ObstacleKind
    x: float
    y: float
    yaw_deg: float = Field(0.0, ge=-360.0, le=360.0)
    size: tuple[float, float, float] | None = Field(
        None, description="(x, y, z) extent in metres; default per kind"
    )
    colour: Colour | None = Field(None, description="RGB; default per kind")
    z: float = Field(0.0, ge=0.0, le=5.0, description="height of the object's base (m)")
    shiny: bool = Field(False, description="specular surface: random depth dropout")

    @model_validator(mode="after")
    def _check(self) -> Obstacle:
        if self.size is not None and not all(0.01 <= s <= 10.0 for s in self.size):
            raise ValueError(f"size={self.size} must have extents in [0.01, 10] m")
        if self.colour is not None:
            _check_colour("colour", self.colour)
        return self

    @property
    def extent(self) -> tuple[float, float, float]:
        return self.size if self.size is not None else DEFAULT_SIZES[self.kind]

    @property
    def rgb(self) -> Colour:
        return self.colour if self.colour is not None else DEFAULT_COLOURS[self.kind]


# ----------------------------------------------------------------------------- people


class Waypoint(_Model):
    """A point of a person's path; ``speed`` is the walking speed on the segment reaching it."""

    x: float
    y: float
    speed: float = Field(1.2, gt=0.05, le=3.0, description="m/s on the way to this point")
    wait_s: float = Field(0.0, ge=0.0, le=600.0, description="stand still here (s)")
    sit_s: float = Field(
        0.0, ge=0.0, le=600.0, description="sit down here for this long (s), after waiting"
    )
    face_deg: float | None = Field(
        None, ge=-360.0, le=360.0, description="heading while waiting/sitting (default: keep)"
    )


class ClothesChange(_Model):
    """From ``at_s`` on, the person wears other clothes."""

    at_s: float = Field(ge=0.0)
    shirt: Colour
    trousers: Colour

    @model_validator(mode="after")
    def _check(self) -> ClothesChange:
        _check_colour("shirt", self.shirt)
        _check_colour("trousers", self.trousers)
        return self


class Follow(_Model):
    """Walk beside (or behind) another person, keeping an offset in that person's frame.

    The follower appears, moves, waits, sits and leaves with its leader.
    """

    id: int = Field(ge=1, le=10_000, description="the leader's id")
    right_m: float = Field(0.7, ge=-5.0, le=5.0, description="offset to the leader's right (m)")
    behind_m: float = Field(0.0, ge=-5.0, le=5.0, description="offset behind the leader (m)")


class Person(_Model):
    """A walking person: an articulated figure following a waypoint path or a leader."""

    id: int = Field(ge=1, le=10_000)
    height: float = Field(1.75, ge=1.5, le=1.95, description="standing height (m)")
    shirt: Colour = (40, 70, 150)
    trousers: Colour = (35, 35, 45)
    skin: Colour = (205, 160, 130)
    hair: Colour = (50, 35, 25)
    shoes: Colour = (25, 25, 25)
    bag: bool = Field(False, description="carries a shoulder bag")
    bag_colour: Colour = (110, 70, 40)
    start_s: float = Field(0.0, ge=0.0, description="appears at the first waypoint at this time")
    path: list[Waypoint] = Field(default_factory=list)
    follow: Follow | None = Field(None, description="walk with another person instead of a path")
    leave: Literal["stay", "vanish"] = Field(
        "stay", description="after the last waypoint: keep standing or disappear"
    )
    clothes: list[ClothesChange] = Field(default_factory=list)
    # What the person looks like beyond the colours above; each one left out is drawn from
    # the person's own random stream (rgbd_eval.sim.people), as are the colours left out.
    sex: float | None = Field(None, ge=0.0, le=1.0, description="0 female .. 1 male")
    age: float | None = Field(None, ge=18.0, le=80.0, description="years")
    weight: float | None = Field(None, ge=0.0, le=1.0, description="build, 0.5 average")
    muscle: float | None = Field(None, ge=0.0, le=1.0, description="0.5 average")
    top: Literal["tshirt", "shirt", "sweater", "jacket", "dress"] | None = None
    bottom: Literal["trousers", "jeans", "shorts", "skirt"] | None = None
    pattern: Literal["plain", "stripes", "check", "dots", "weave"] | None = Field(
        None, description="of the top"
    )
    hair_style: Literal["short", "long", "bald"] | None = None

    @model_validator(mode="after")
    def _check(self) -> Person:
        for name in ("shirt", "trousers", "skin", "hair", "shoes", "bag_colour"):
            _check_colour(name, getattr(self, name))
        if bool(self.path) == (self.follow is not None):
            raise ValueError(f"person {self.id}: give either a non-empty path or follow, not both")
        if self.top == "dress" and self.bottom is not None:
            raise ValueError(f"person {self.id}: a dress has no bottom (bottom: {self.bottom})")
        times = [c.at_s for c in self.clothes]
        if times != sorted(times):
            raise ValueError(
                f"person {self.id}: clothes changes must be in time order, got {times}"
            )
        return self


# ----------------------------------------------------------------------------- robot, sensor


class RobotWaypoint(_Model):
    """A point of the robot's path, reached at ``speed``; the robot turns in place first."""

    x: float
    y: float
    speed: float = Field(0.4, gt=0.01, le=2.0, description="m/s on the way to this point")
    wait_s: float = Field(0.0, ge=0.0, le=600.0)


class Robot(_Model):
    """The mobile base carrying the camera; static when ``path`` is empty."""

    x: float = 0.0
    y: float = 0.0
    yaw_deg: float = Field(0.0, ge=-360.0, le=360.0)
    start_s: float = Field(0.0, ge=0.0, description="starts moving at this time")
    path: list[RobotWaypoint] = Field(default_factory=list)
    turn_rate_deg_s: float = Field(45.0, gt=1.0, le=360.0, description="in-place turning rate")
    camera_x: float = Field(0.1, ge=-1.0, le=1.0, description="camera_link ahead of base_link (m)")
    camera_height: float = Field(1.1, ge=0.2, le=3.0, description="camera_link above the floor (m)")
    camera_tilt_deg: float = Field(0.0, ge=-45.0, le=45.0, description="positive looks down")


class Sensor(_Model):
    """A Kinect v1-like RGB-D camera (seed 000, 2.1: 640x480, 57x43 degrees, 30 Hz)."""

    rate_hz: float = Field(30.0, gt=0.0, le=120.0, description="seed 000 2.1: 30 Hz")
    width: int = Field(640, ge=32, le=4096, description="seed 000 2.1: VGA 640x480")
    height: int = Field(480, ge=24, le=4096)
    hfov_deg: float = Field(57.0, gt=10.0, lt=170.0, description="seed 000 2.1: 57 degrees")
    vfov_deg: float = Field(43.0, gt=10.0, lt=170.0, description="seed 000 2.1: 43 degrees")
    depth_decimation: Literal[1, 2, 4] = Field(
        1, description="1: 640x480, 2: 320x240 (QVGA), 4: 160x120 (QQVGA), seed 000 3.2.2"
    )
    depth_offset_m: float = Field(
        0.025,
        ge=-0.2,
        le=0.2,
        description="depth (IR) camera, metres to the RGB camera's left (Kinect, openni tf)",
    )
    depth_noise_k: float = Field(
        0.001425,
        ge=0.0,
        le=0.05,
        description="depth sigma = k * z^2 (seed 000 Figure 6.1; same k as TrackerConfig)",
    )
    quantise: bool = Field(True, description="quantise disparity to 1/subpixel pixel")
    baseline_m: float = Field(
        0.075,
        gt=0.0,
        le=1.0,
        description="projector-camera baseline; the projector sits this far to the IR camera's right",
    )
    projector_shadows: bool = Field(
        True, description="invalid depth where the projector's pattern is occluded"
    )
    disparity_subpixel: int = Field(8, ge=1, le=64, description="disparity steps per pixel")
    min_range_m: float = Field(0.5, ge=0.0, le=5.0)
    max_range_m: float = Field(8.0, gt=0.5, le=20.0, description="seed 000 2.1/8: poor beyond 8 m")
    edge_jump: float = Field(
        0.05, gt=0.0, le=1.0, description="relative depth jump that marks a depth edge"
    )
    edge_dropout: float = Field(0.4, ge=0.0, le=1.0, description="P(invalid) on a depth edge")
    dark_level: float = Field(
        45.0, ge=0.0, le=255.0, description="albedo luminance below which a surface is dark"
    )
    dark_dropout: float = Field(0.25, ge=0.0, le=1.0, description="P(invalid) on dark surfaces")
    shiny_dropout: float = Field(0.35, ge=0.0, le=1.0, description="P(invalid) on shiny surfaces")
    rgb_noise_std: float = Field(2.5, ge=0.0, le=50.0, description="RGB pixel noise (levels)")
    rgb_blur_px: float = Field(
        0.6,
        ge=0.0,
        le=5.0,
        description="Gaussian blur (sigma, pixels) of the colour image: the Kinect's lens and "
        "Bayer demosaicing; 0 for a sharp image",
    )
    exposure_amplitude: float = Field(
        0.08, ge=0.0, le=0.8, description="relative amplitude of slow exposure changes"
    )
    exposure_period_s: float = Field(11.0, gt=0.1, le=1000.0)
    illumination: float = Field(
        1.0, ge=0.0, le=2.0, description="scene light level (1: office light; 0.03: darkness)"
    )
    light_azimuth_deg: float = Field(30.0, ge=-360.0, le=360.0)
    light_elevation_deg: float = Field(55.0, ge=0.0, le=90.0)

    @model_validator(mode="after")
    def _check(self) -> Sensor:
        if self.width % self.depth_decimation or self.height % self.depth_decimation:
            raise ValueError(
                f"image {self.width}x{self.height} not divisible by "
                f"depth_decimation={self.depth_decimation}"
            )
        if self.min_range_m >= self.max_range_m:
            raise ValueError(
                f"min_range_m={self.min_range_m} must be below max_range_m={self.max_range_m}"
            )
        return self

    @property
    def fx(self) -> float:
        return (self.width / 2.0) / exact.tan(math.radians(self.hfov_deg) / 2.0)

    @property
    def fy(self) -> float:
        return (self.height / 2.0) / exact.tan(math.radians(self.vfov_deg) / 2.0)


class Odometry(_Model):
    """Wheel odometry error: scale error and random walk growing with distance travelled."""

    scale_error: float = Field(0.01, ge=-0.2, le=0.2, description="relative distance error")
    translation_noise: float = Field(
        0.01, ge=0.0, le=1.0, description="m of lateral/longitudinal noise per sqrt(m)"
    )
    rotation_noise_deg: float = Field(
        0.5, ge=0.0, le=45.0, description="heading noise in degrees per sqrt(m or rad)"
    )


class Recording(_Model):
    """How images are stored (mirrors the writer's StreamOptions)."""

    rgb_format: Literal["raw", "jpeg"] = "jpeg"
    depth_encoding: Literal["16UC1", "32FC1"] = "16UC1"
    depth_compressed: bool = False
    jpeg_quality: int = Field(90, ge=1, le=100)
    start_stamp_ns: int = Field(1_600_000_000_000_000_000, ge=0, description="first frame's stamp")


class Scenario(_Model):
    """One synthetic recording."""

    #: sha256 of the file the scenario was read from (None when built in code).
    _source_sha256: str | None = PrivateAttr(default=None)

    name: str = Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$")
    description: str = ""
    duration_s: float = Field(gt=0.0, le=3600.0)
    seed: int = Field(0, ge=0, description="default seed (overridden by synthesize's seed)")
    vary_paths_m: float = Field(
        0.0,
        ge=0.0,
        le=2.0,
        description="per seed, move each waypoint of each walking person by up to this far "
        "(m), off obstacles and walls (rgbd_eval.sim.variation); 0: the paths as written",
    )
    vary_speed: float = Field(
        0.0,
        ge=0.0,
        le=0.5,
        description="per seed, scale each segment's walking speed by up to this share "
        "(0.1: 0.9x-1.1x); 0: the speeds as written",
    )
    room: Room = Room()
    obstacles: list[Obstacle] = Field(default_factory=list)
    people: list[Person] = Field(default_factory=list)
    robot: Robot = Robot()
    sensor: Sensor = Sensor()
    odometry: Odometry = Odometry()
    recording: Recording = Recording()
    truth_visibility: Literal["kinect", "present"] = Field(
        "kinect",
        description="ground-truth visibility: as seen by the robot's Kinect (people it cannot "
        "see are ignored), or 'present': everyone in the scene counts, for static multi-camera "
        "rigs (seed 003 4.1 annotates occluded people too)",
    )
    robot_camera: bool = Field(
        True,
        description="render and write the robot's Kinect (RGB and depth topics); false for "
        "static rigs whose runs read only the rig's sensors (needs truth_visibility 'present': "
        "the ground truth then has no image boxes)",
    )
    rig: list[SerializeAsAny[RigSensorConfig]] = Field(
        default_factory=list,
        description="extra sensors beside the robot's Kinect, each selected by its 'kind' "
        "(rgbd_eval.sim.rig_sensors), on topics /<name>/...",
    )

    @field_validator("rig", mode="before")
    @classmethod
    def _rig(cls, value: Any) -> Any:
        if not isinstance(value, list):
            return value
        return [rig_sensor_config(v) if isinstance(v, Mapping) else v for v in value]

    @model_validator(mode="after")
    def _check(self) -> Scenario:
        if not self.robot_camera and self.truth_visibility != "present":
            raise ValueError(
                "robot_camera: false needs truth_visibility: present (visibility and image "
                "boxes come from the robot's Kinect)"
            )
        names = [r.name for r in self.rig]
        if len(set(names)) != len(names):
            raise ValueError(f"rig sensor names must be unique, got {names}")
        ids = [p.id for p in self.people]
        if len(set(ids)) != len(ids):
            raise ValueError(f"person ids must be unique, got {ids}")
        leaders = {p.id for p in self.people if p.follow is None}
        for p in self.people:
            if p.follow is not None and p.follow.id not in leaders:
                raise ValueError(
                    f"person {p.id}: follow.id={p.follow.id} must be a person with a path "
                    f"(one of {sorted(leaders)})"
                )
        return self

    @property
    def source_sha256(self) -> str | None:
        """sha256 of the scenario file it was read from, if any."""
        return self._source_sha256

    def digest(self) -> str:
        """sha256 of the resolved scenario (every value, overrides applied) as canonical JSON.

        Fields added after recordings were made (:data:`_LATER_FIELDS`) count only when set,
        so that a scene that does not use them keeps its digest, and its recordings their
        bytes.
        """
        data = self.model_dump(mode="json")
        for name, default in _LATER_FIELDS.items():
            if data.get(name) == default:
                del data[name]
        text = json.dumps(data, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode("utf-8")).hexdigest()

    @property
    def n_frames(self) -> int:
        return max(1, round(self.duration_s * self.sensor.rate_hz))

    def stamp_ns(self, index: int) -> int:
        """The header stamp of frame ``index``."""
        return self.recording.start_stamp_ns + round(index * 1e9 / self.sensor.rate_hz)


# ----------------------------------------------------------------------------- loading


#: Scenario fields added after the first recordings, with the default that leaves them out of
#: :meth:`Scenario.digest`.
_LATER_FIELDS: dict[str, float] = {"vary_paths_m": 0.0, "vary_speed": 0.0}


def parse_scenario(data: object, source: str = "scenario") -> Scenario:
    """Validate a scenario mapping; a :class:`ConfigError` names the offending keys."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as err:
        raise ConfigError(format_validation_error(err, source)) from err


def load_scenario(path: Path | str, overrides: Iterable[tuple[str, Any]] = ()) -> Scenario:
    """Read and validate a scenario YAML file, with dotted-key overrides (raises ConfigError).

    ``overrides`` are ``(key, value)`` pairs such as ``("recording.rgb_format", "raw")``
    (see :func:`rgbd_eval.config.parse_overrides`), applied as ``run --set`` applies them.
    """
    p = Path(path)
    data = load_yaml(p)
    for key, value in overrides:
        try:
            set_dotted(data, key, value, Scenario)
        except ConfigError as err:
            raise ConfigError(f"{p}: {err}") from err
    scenario = parse_scenario(data, str(p))
    scenario._source_sha256 = hashlib.sha256(p.read_bytes()).hexdigest()
    return scenario


def scenarios_dir() -> Path:
    """``configs/scenarios`` of the source checkout."""
    return config_dir() / "scenarios"


def scenario_paths() -> list[Path]:
    """All scenario files (``rgbd-eval synth --all``), sorted by name."""
    return sorted(scenarios_dir().glob("*.yaml"))
