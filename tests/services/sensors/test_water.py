"""The water surface along rays: the same sum as WaveField, evaluated per ray."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.sensors.water import BLOCK, RaySurface, wave_hits

SEA = WaveField(WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2), 1)


def _rays(n: int, shared: bool) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(5)
    d = rng.normal(size=(n, 3)) * [1.0, 1.0, 0.2] - [0.0, 0.0, 0.1]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = rng.uniform(-300.0, 300.0, (n, 3)) * [1.0, 1.0, 0.0] + [0.0, 0.0, 2.0]
    return (np.broadcast_to(o[0], d.shape) if shared else o), d


@pytest.mark.parametrize("shared", [True, False])
def test_ray_surface_is_the_wave_field(shared: bool) -> None:
    o, d = _rays(500, shared)
    along = RaySurface(SEA, o, d, 7.5)
    t = np.random.default_rng(6).uniform(0.0, 100.0, 500)
    rows = np.arange(500)
    p = o + t[:, None] * d
    expected = p[:, 2] - SEA.height(p[:, 0], p[:, 1], 7.5)
    assert np.abs(along.gap(rows, t) - expected).max() < 1e-5
    assert np.abs(along.normal(rows, t) - SEA.normal(p[:, 0], p[:, 1], 7.5)).max() < 1e-5


def test_hits_over_several_blocks_lie_on_the_surface() -> None:
    o, d = _rays(2 * BLOCK + 300, shared=True)
    rows, t, normal = wave_hits(SEA, float(SEA.amplitudes_m.sum()), o, d, np.full(len(d), 1e3), 3.0)
    assert rows.size > BLOCK
    p = o[rows] + t[:, None] * d[rows]
    assert np.abs(p[:, 2] - SEA.height(p[:, 0], p[:, 1], 3.0)).max() < 1e-3
    assert np.abs(normal - SEA.normal(p[:, 0], p[:, 1], 3.0)).max() < 1e-5


def test_steep_rays_meet_the_surface_once_where_dense_sampling_finds_it() -> None:
    rng = np.random.default_rng(8)
    el, az = rng.uniform(np.radians(20.0), np.radians(85.0), 300), rng.uniform(0, 6.3, 300)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=1)
    o = np.broadcast_to(np.array([10.0, -20.0, 1.5]), d.shape)
    rows, t, _ = wave_hits(SEA, float(SEA.amplitudes_m.sum()), o, d, np.full(300, 1e3), 4.0)
    assert rows.size == 300
    s = np.linspace(0.0, 4.0 / np.sin(el)[:, None], 4001, axis=1)[..., 0]  # (300, 4001)
    p = o[:, None, :] + s[..., None] * d[:, None, :]
    f = p[..., 2] - SEA.height(p[..., 0], p[..., 1], 4.0)
    first = np.argmax(f <= 0.0, axis=1)  # the first sample under the surface
    step = s[:, 1] - s[:, 0]
    assert np.all(np.abs(t - s[np.arange(300), first]) <= step + 1e-3 / np.sin(el))
