"""The scenario's `water.waves`: a sea state as a spectrum, a direction and a spreading.

`catabot.world.waves.WaveField` turns a validated `WaveConfig` and the scenario seed into
the surface every service shares; this module is only the settings and their checks.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import Field, ValidationError, model_validator

from catabot.config.base import Angle, ConfigError, Strict, explain

GRAVITY = 9.81
PRESETS: dict[str, dict[str, Any]] = {
    # The paper's Fig. 6 gives swell "amplitude" 0.62 m (medium) and 1.25 m (heavy). We read
    # it as the significant amplitude Hs / 2 (for a regular wave, amplitude = height / 2), so
    # Hs = 1.24 m and 2.5 m. Peak periods are typical of swell; a JONSWAP spectrum with
    # gamma 3.3 and narrow spreading (s = 25) because swell is peaked and long-crested.
    "calm": {"significant_height_m": 0.0},
    "medium": {"significant_height_m": 1.24, "peak_period_s": 8.0, "spreading": 25.0},
    "heavy": {"significant_height_m": 2.5, "peak_period_s": 10.0, "spreading": 25.0},
}
MAX_STEEPNESS = 0.1  # Hs / Lp; beyond it a real sea breaks, which linear waves do not model


class WaveError(ConfigError):
    """A wave configuration or input that cannot give a meaningful sea surface."""


class WaveConfig(Strict):
    """Sea state: a spectrum (Hs, Tp, gamma), a mean direction, spreading, component counts.

    `preset` fills the fields it defines ("calm", "medium", "heavy"); fields given explicitly
    override the preset, so `{"preset": "heavy", "direction_rad": 1.57}` is heavy swell from
    the south travelling north. With neither, the defaults below give calm water (Hs = 0).
    `spreading` is the exponent s of the cos-2s law D(theta) ~ cos^(2s)((theta - mean) / 2):
    larger is narrower (s = 25 spreads ~16 degrees rms); None gives long-crested waves, all
    travelling along `direction_rad`. `gamma` is used by JONSWAP only (1 gives PM).
    """

    preset: Literal["calm", "medium", "heavy"] | None = None
    spectrum: Literal["pierson-moskowitz", "jonswap"] = "jonswap"
    significant_height_m: Annotated[float, Field(ge=0.0, le=20.0)] = 0.0  # 20 m: beyond records
    peak_period_s: Annotated[float, Field(gt=0.0, le=30.0)] = 8.0  # the longest swells: 25 s
    direction_rad: Angle = 0.0
    spreading: Annotated[float, Field(gt=0.0, le=1000.0)] | None = 25.0
    gamma: Annotated[float, Field(ge=1.0, le=10.0)] = 3.3
    frequency_components: Annotated[int, Field(ge=1, le=256)] = 12
    direction_components: Annotated[int, Field(ge=1, le=64)] = 4

    @model_validator(mode="before")
    @classmethod
    def _apply_preset(cls, data: Any) -> Any:
        """Preset values first, explicit fields on top (only for mapping input)."""
        if isinstance(data, dict) and data.get("preset") in PRESETS:
            return {**PRESETS[data["preset"]], **data}
        return data

    @model_validator(mode="after")
    def _not_breaking(self) -> WaveConfig:
        steepness = self.significant_height_m / self.peak_wavelength_m
        if steepness > MAX_STEEPNESS:
            raise ValueError(
                f"significant steepness Hs/Lp = {steepness:.3g} exceeds {MAX_STEEPNESS} "
                f"(Hs {self.significant_height_m} m, Lp = g Tp^2/2pi = "
                f"{self.peak_wavelength_m:.3g} m): such a sea breaks, which linear waves do "
                "not model; lower significant_height_m or raise peak_period_s"
            )
        return self

    @property
    def peak_frequency_radps(self) -> float:
        return 2.0 * math.pi / self.peak_period_s

    @property
    def peak_wavelength_m(self) -> float:
        """Deep-water wavelength of the peak period."""
        return GRAVITY * self.peak_period_s**2 / (2.0 * math.pi)

    @property
    def is_calm(self) -> bool:
        return self.significant_height_m == 0.0


def parse_wave_config(data: Any, *, where: str = "waves") -> WaveConfig:
    """Validate decoded JSON into a WaveConfig; errors are WaveError naming the field."""
    try:
        return WaveConfig.model_validate(data)
    except ValidationError as exc:
        raise WaveError(explain(exc, model=WaveConfig, where=where)) from None
