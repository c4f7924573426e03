"""Parameters of the pinto2022 tracker (seed 001, III-C to III-E).

The motion and track-management values are the seed's. The appearance thresholds are
Euclidean distances in the units of the detector's embedder: the seed's 300 / 700 / 400
(eqs. 17-18) are TriNet's; the defaults here are those of the default embedder
(``colour_texture``), calibrated on tuning scenes as ``methods/pinto2022/method.yaml``
records (tools/pinto2022/calibrate_reid.py).
``appearance`` names the embedder the thresholds belong to, so that a detector with
another embedder is refused instead of being gated in the wrong units.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from rgbd_eval.config import ComponentConfig


class Pinto2022TrackerConfig(ComponentConfig):
    """The pinto2022 tracker (seed 001, III-C to III-E)."""

    name: Literal["pinto2022"] = "pinto2022"
    sigma_position: float = Field(0.2, gt=0.0, description="eq. 3: sigma_x, sigma_y, sigma_z (m)")
    sigma_velocity: float = Field(1.0, gt=0.0, description="eq. 3: sigma_vx, vy, vz (m/s)")
    sigma_measurement: float = Field(0.2, gt=0.0, description="eq. 9: measurement sigma (m)")
    s_max: float = Field(0.05, ge=0.0, description="eq. 17: S_max, squared Mahalanobis on x, y")
    appearance: str = Field(
        "colour_texture", description="the embedder whose units t_lower/t_upper/t_recover are in"
    )
    t_lower: float = Field(0.305, ge=0.0, description="eq. 17 T_lower, in the embedder's units")
    t_upper: float = Field(0.549, ge=0.0, description="eq. 17 T_upper, in the embedder's units")
    t_recover: float = Field(0.328, ge=0.0, description="eq. 18 T_recover, in the embedder's units")
    confirm_hits: int = Field(3, ge=1, description="III-E: associations to confirm a track")
    max_misses: int = Field(5, ge=1, description="III-E: consecutive misses to delete a track")

    @model_validator(mode="after")
    def _check(self) -> Pinto2022TrackerConfig:
        if self.t_lower > self.t_upper:
            raise ValueError(f"t_lower={self.t_lower} must not exceed t_upper={self.t_upper}")
        return self
