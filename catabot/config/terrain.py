"""The scenario's `terrain`: an elevation image and how its pixels map to metres.

`catabot.world.terrain.load_terrain` reads the image into a `Terrain`; this module is only
the settings and their checks (DESIGN.md §2 for the frame the image defines).
"""

from __future__ import annotations

from pydantic import Field, model_validator

from catabot.config.base import ConfigError, Strict


class TerrainError(ConfigError):
    """A terrain that cannot be used, or a start pose it refuses; the message says why."""


class TerrainConfig(Strict):
    """The scenario's terrain: elevation image and how its pixel values and size map to metres.

    `resolution_m` is the grid spacing of the collision/ray mesh; None picks the finest
    spacing (not below one pixel) that keeps the mesh within MAX_MESH_TRIANGLES.
    """

    elevation_image: str = Field(min_length=1, description="PNG or (Geo)TIFF path")
    min_elevation_m: float = Field(-35.0, description="elevation of pixel value 0")
    max_elevation_m: float = Field(60.0, description="elevation of the bit depth's max value")
    metres_per_pixel: float = Field(5.0, gt=0)
    resolution_m: float | None = Field(None, gt=0, description="mesh spacing; null = auto")

    @model_validator(mode="after")
    def _ordered(self) -> TerrainConfig:
        if self.max_elevation_m <= self.min_elevation_m:
            raise ValueError(
                f"max_elevation_m ({self.max_elevation_m}) must be greater than "
                f"min_elevation_m ({self.min_elevation_m})"
            )
        return self
