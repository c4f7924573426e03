"""Parameters of the pinto2022 detector (seed 001, III-B): 2D person detector and re-ID embedder."""

from __future__ import annotations

import enum
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from rgbd_eval.config import ComponentConfig


class _Part(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)


class PersonBackend(enum.Enum):
    """Which 2D person detector runs on the colour image."""

    SSDLITE = "ssdlite"  # the shipped SSDLite-MobileNetV2 pedestrian model (default)
    ONNX = "onnx"  # a YOLO-family ONNX file (v3/v5/v7 or v8/v11 output layout)
    HOG = "hog"  # OpenCV's Dalal-Triggs people detector, no weights
    RECORDED = "recorded"  # boxes recorded in a bag topic or a MOTChallenge det.txt


class PersonDetectorConfig(_Part):
    """The 2D person detector (the seed's YOLOv3, III-B)."""

    backend: PersonBackend = Field(PersonBackend.SSDLITE, description="2D person detector")
    model: Path | None = Field(
        None, description="ONNX file (onnx: required; ssdlite: replaces the shipped model)"
    )
    score_threshold: float = Field(0.5, ge=0.0, le=1.0, description="minimum box score")
    nms_iou: float = Field(0.45, gt=0.0, le=1.0, description="non-maximum suppression IoU")
    layout: Literal["auto", "v5", "v8"] = Field("auto", description="onnx: YOLO output layout")
    person_class: int = Field(0, ge=0, description="onnx: index of the person class (COCO: 0)")
    input_size: int = Field(
        640, ge=32, le=4096, description="onnx: input side when the model's is dynamic"
    )
    hog_scale: float = Field(  # closer to 1, the pyramid has more levels (1.01: ~200)
        1.05, ge=1.01, le=2.0, description="hog: pyramid scale factor"
    )
    source: Path | None = Field(
        None, description="recorded: the bag/.mcap holding the topic, or a det.txt"
    )
    topic: str | None = Field(None, description="recorded: the detection topic in source")
    classes: list[str] = Field(
        default_factory=lambda: ["person", "0"],
        description="recorded: labels counted as people (empty: all)",
    )
    max_gap_ms: float = Field(5.0, ge=0.0, description="recorded: stamp matching tolerance")

    @model_validator(mode="after")
    def _check(self) -> PersonDetectorConfig:
        if self.backend is PersonBackend.ONNX and self.model is None:
            raise ValueError("person.backend 'onnx' needs person.model (an ONNX file)")
        if self.backend is PersonBackend.RECORDED:
            if self.source is None:
                raise ValueError("person.backend 'recorded' needs person.source")
            if self.source.suffix != ".txt" and not self.topic:
                raise ValueError("person.backend 'recorded' from a recording needs person.topic")
        return self


class ReidBackend(enum.Enum):
    """Which appearance embedding each box gets."""

    COLOUR_TEXTURE = "colour_texture"  # hand-crafted, the default (chosen by measurement)
    MOBILENET = "mobilenet"  # the shipped ImageNet MobileNetV2 (not re-ID trained)
    ONNX = "onnx"  # any embedding network by path (TriNet, OSNet, ...)


class ReidConfig(_Part):
    """The re-ID embedder (the seed's TriNet, III-B)."""

    backend: ReidBackend = Field(ReidBackend.COLOUR_TEXTURE, description="embedder")
    model: Path | None = Field(None, description="onnx: the embedding network file")
    input_width: int = Field(128, ge=1, le=2048, description="onnx: network input width")
    input_height: int = Field(256, ge=1, le=2048, description="onnx: network input height")
    mean: tuple[float, float, float] = Field(
        (0.485, 0.456, 0.406), description="onnx: per-channel mean (RGB, after scaling to [0, 1])"
    )
    std: tuple[float, float, float] = Field(
        (0.229, 0.224, 0.225), description="onnx: per-channel std (RGB)"
    )
    l2_normalise: bool = Field(False, description="onnx: L2-normalise the embeddings")

    @model_validator(mode="after")
    def _check(self) -> ReidConfig:
        if self.backend is ReidBackend.ONNX and self.model is None:
            raise ValueError("reid.backend 'onnx' needs reid.model (an ONNX file)")
        if any(s <= 0 for s in self.std):
            raise ValueError(f"reid.std={self.std} must be positive")
        return self


class Pinto2022DetectorConfig(ComponentConfig):
    """The pinto2022 detector (seed 001, III-B)."""

    name: Literal["pinto2022"] = "pinto2022"
    person: PersonDetectorConfig = Field(default_factory=PersonDetectorConfig)
    reid: ReidConfig = Field(default_factory=ReidConfig)
    threads: int = Field(1, ge=1, le=256, description="onnxruntime intra-op threads")

    def appearance_kind(self) -> str:
        """The name of the embedding this config produces (thresholds are in its units)."""
        if self.reid.backend is ReidBackend.ONNX:
            return f"onnx:{self.reid.model.name if self.reid.model else ''}"
        return str(self.reid.backend.value)
