"""Parameters of the basso2012 detector (seed 000, chapter 5; defaults from Table 5.1)."""

from __future__ import annotations

import enum
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig
from rgbd_eval.detect.ground import GroundMode
from rgbd_eval.detect.plane import normalise_plane, plane_from_points


class HogClassifier(enum.Enum):
    """Which person classifier scores the clusters (seed 000, 5.4.2)."""

    AUTHORS = "authors"  # Dollár's HOG + the authors' SVM: the thesis' confidence units
    OPENCV = "opencv"  # OpenCV's Dalal-Triggs INRIA people detector: another scale


class HogBorder(enum.Enum):
    """Clusters whose person window is not wholly visible (seed 000, 5.4.2)."""

    SKIP = "skip"  # the thesis: not scored, hog_default_confidence (-100)
    PAD = "pad"  # the authors' later code (PCL): scored, the window's outside black


class Basso2012DetectorConfig(ComponentConfig):
    """The basso2012 detector (seed 000, chapter 5; defaults from Table 5.1, voxel 0.06 m)."""

    name: Literal["basso2012"] = "basso2012"

    voxel_size: float = Field(
        0.06,
        ge=0.01,
        le=0.5,
        description="voxel grid side (m), Table 5.1; at least 1 cm (finer than the Kinect's "
        "depth noise; a tiny voxel's grid keys overflow and its clusters exhaust memory)",
    )
    min_height: float = Field(1.4, ge=0.0, description="Table 5.1 ~people/min_height (m)")
    max_height: float = Field(2.3, gt=0.0, description="Table 5.1 ~people/max_height (m)")
    min_confidence: float = Field(-1.5, description="Table 5.1 ~people/min_confidence")
    publish_all: bool = Field(True, description="Table 5.1 ~people/publish_all")
    head_centroid: bool = Field(True, description="Table 5.1 ~people/head_centroid")
    max_distance: float = Field(6.5, gt=0.0, description="Table 5.1 ~people/max_distance (m)")
    min_points: int = Field(30, ge=1, description="Table 5.1 ~cluster/min_points")
    max_points: int = Field(600, ge=1, description="Table 5.1 ~cluster/max_points")
    cluster_tolerance_voxels: float = Field(
        2.0, gt=0.0, description="Euclidean clustering tolerance in voxels (5.4.2: 2 x voxel)"
    )
    ground_mode: GroundMode = Field(
        GroundMode.AUTO,
        description="initial ground plane source: 'auto' (RANSAC, gravity from odometry), "
        "'points' (three floor points or pixels, 5.4.1), 'plane' (given), 'world' (the world "
        "frame's z = 0 seen from the first camera pose; `reproduce basso2012` uses it)",
    )
    ground_points: list[tuple[float, float, float]] | None = Field(
        None, description="three floor points (x, y, z) in the depth optical frame, mode 'points'"
    )
    ground_plane: tuple[float, float, float, float] | None = Field(
        None, description="plane a, b, c, d in the depth optical frame, mode 'plane'"
    )
    histogram_bins: int = Field(
        8, ge=2, le=32, description="bins per channel of the blob's 3D colour histogram (6.2.2)"
    )
    hog_default_confidence: float = Field(
        -100.0, description="confidence of clusters not visible top to bottom (5.4.2)"
    )
    ground_pixels: list[tuple[float, float]] | None = Field(
        None,
        description="three floor pixels (u, v) on the RGB image, mode 'points' "
        "(the ground_detector's mouse clicks, 5.4.1)",
    )
    ground_max_tilt_deg: float = Field(
        30.0,
        gt=0.0,
        lt=90.0,
        description="largest angle between the floor normal and gravity (odometry up) accepted "
        "by the automatic ground search; covers the Kinect's +-27 deg tilt (seed 000, 2.1)",
    )
    ground_min_points: int = Field(
        30,
        ge=3,
        description="fewest floor voxels within one voxel of the plane needed to refine it; "
        "with fewer the previous plane is kept (5.1, 5.4.2; as ~cluster/min_points, Table 5.1)",
    )
    subclustering: bool = Field(
        True,
        description="head-based sub-clustering of Munaro, Basso and Menegatti (IROS 2012), the "
        "thesis authors' follow-up; off = the thesis' plain Euclidean clusters (5.2)",
    )
    min_head_distance: float = Field(
        0.3,
        gt=0.0,
        le=5.0,
        description="smallest ground distance (m) between two heads and the distance below "
        "which clusters are merged (Munaro et al. IROS 2012; 0.3 m in PCL's people module)",
    )
    min_head_prominence: float = Field(
        0.1,
        ge=0.0,
        description="how far (m) a second head must rise above the lowest point between it and "
        "a higher head; the head-to-shoulder drop of an adult is about 0.3 m",
    )
    surface_correction: bool = Field(
        True,
        description="move the head centroid from the visible surface to the head's axis "
        "(4/3 of the across-view spread, exact for a sphere or upright cylinder); off = the "
        "surface mean of 5.3",
    )
    hog: HogClassifier = Field(
        HogClassifier.AUTHORS,
        description="person classifier: 'authors' (Dollár's HOG and the thesis authors' SVM, "
        "the units of the thesis' confidence thresholds) or 'opencv' (INRIA people detector)",
    )
    hog_border: HogBorder = Field(
        HogBorder.PAD,
        description="'pad' (default): every cluster is scored, the window's outside the image "
        "black (the authors' later PCL code), so people cut by the image or whose feet are "
        "hidden can start tracks; 'skip': clusters not visible top to bottom get "
        "hog_default_confidence (the thesis, 5.4.2; what `reproduce basso2012` uses)",
    )
    hog_max_ground_gap: float = Field(
        0.3,
        gt=0.0,
        description="a cluster is 'visible from top to bottom' (5.4.2), so HOG-scored, when its "
        "lowest point is at most this high (m) and its full-body box is on the image",
    )

    @model_validator(mode="after")
    def _check(self) -> Basso2012DetectorConfig:
        if self.min_height >= self.max_height:
            raise ValueError(
                f"min_height={self.min_height} must be below max_height={self.max_height}"
            )
        if self.min_points > self.max_points:
            raise ValueError(
                f"min_points={self.min_points} must not exceed max_points={self.max_points}"
            )
        if self.ground_mode is GroundMode.POINTS and not (
            (self.ground_points is not None and len(self.ground_points) == 3)
            or (self.ground_pixels is not None and len(self.ground_pixels) == 3)
        ):
            raise ValueError(
                "ground_mode 'points' needs exactly three ground_points (3D) or ground_pixels "
                f"(RGB image), got ground_points={self.ground_points}, "
                f"ground_pixels={self.ground_pixels}"
            )
        if self.ground_mode is GroundMode.PLANE and self.ground_plane is None:
            raise ValueError("ground_mode 'plane' needs ground_plane: [a, b, c, d]")
        # The detector's own plane checks, at load time rather than mid-run (issue 21).
        if self.ground_plane is not None:
            normalise_plane(self.ground_plane)
        if self.ground_points is not None and len(self.ground_points) == 3:
            plane_from_points(*(np.asarray(p, dtype=np.float64) for p in self.ground_points))
        if self.ground_pixels is not None and any(u < 0 or v < 0 for u, v in self.ground_pixels):
            raise ValueError(f"ground_pixels={self.ground_pixels}: pixel coordinates must be >= 0")
        return self
