"""Wave-grid casts as the kernel tests make them: a medium sea's grid about one origin and
fans of rays at chosen elevations."""

from __future__ import annotations

import numpy as np

from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.sensors.wave_grid import Scratch, WaveGrid, grid_spec
from services.sensors.wave_pass import CastRays, cast_on_grid

MEDIUM = WaveField(WaveConfig(preset="medium"), 1)
ORIGIN = np.array([4.0, -2.0, 1.2])


class Near:
    def __init__(self, n: int) -> None:
        self.rng = np.full(n, np.inf)
        self.normal = np.zeros((n, 3), np.float32)
        self.cls = np.zeros(n, np.uint8)
        self.inst = np.zeros(n, np.int32)


def wave_grid(time_s: float = 3.5) -> WaveGrid:
    spec = grid_spec(MEDIUM)
    assert spec is not None
    box = (np.array([-70.0, -70.0]), np.array([70.0, 70.0]))
    return WaveGrid(spec, MEDIUM, time_s, ORIGIN[:2].copy(), box, Scratch())


def fan(n: int, seed: int, elevations_deg: tuple[float, float]) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = np.log(elevations_deg[0]), np.log(elevations_deg[1])
    el = -np.radians(np.exp(rng.uniform(lo, hi, n)))
    az = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)


def cast(grid: WaveGrid, d: np.ndarray, max_range: float) -> tuple[Near, np.ndarray]:
    near = Near(d.shape[0])
    o = np.broadcast_to(ORIGIN, d.shape)
    rays = CastRays.of(o, d, np.full(d.shape[0], max_range), grid.spec.rot)
    far = cast_on_grid(grid, rays, near, (10.0, max_range), normals=True)
    return near, far
