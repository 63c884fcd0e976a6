"""The exact march: hits on the same sum as WaveField, the first crossing of each ray."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.sensors.water import wave_hits
from services.sensors.wave_march import marcher
from services.sensors.wave_pass import warm_up

SEA = WaveField(WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2), 1)


def _rays(n: int, shared: bool) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(5)
    d = rng.normal(size=(n, 3)) * [1.0, 1.0, 0.2] - [0.0, 0.0, 0.1]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = rng.uniform(-300.0, 300.0, (n, 3)) * [1.0, 1.0, 0.0] + [0.0, 0.0, 2.0]
    return (np.broadcast_to(o[0], d.shape) if shared else o), d


@pytest.mark.parametrize("shared", [True, False])
def test_hits_lie_on_the_wave_field_with_its_normals(shared: bool) -> None:
    """Within the march's 0.5 mm (float32 phases and polynomial cosines included), shared
    and own origins alike."""
    o, d = _rays(3000, shared)
    rows, t, normal = wave_hits(SEA, o, d, np.full(len(d), 1e3), 7.5)
    assert rows.size > 1000
    p = o[rows] + t[:, None] * d[rows]
    assert np.abs(p[:, 2] - SEA.height(p[:, 0], p[:, 1], 7.5)).max() < 6e-4
    assert np.abs(normal - SEA.normal(p[:, 0], p[:, 1], 7.5)).max() < 1e-5


def test_rays_cut_short_or_pointing_up_find_no_water() -> None:
    o, d = _rays(500, shared=True)
    d[:250, 2] = np.abs(d[:250, 2])  # up or level: never from above
    rows, _, _ = wave_hits(SEA, o, d, np.full(500, 1e3), 7.5)
    assert rows.size and rows.min() >= 250
    near = np.full(500, 0.5)  # something nearer than any water on every ray
    assert wave_hits(SEA, o, d, near, 7.5)[0].size == 0


def test_warm_up_compiles_the_march_for_the_casts_types() -> None:
    warm_up()
    o, d = _rays(50, shared=True)
    wave_hits(SEA, o, d, np.full(50, 1e3), 1.0)  # a read-only broadcast origin
    wave_hits(SEA, np.ascontiguousarray(o), d, np.full(50, 1e3), 1.0)
    assert len(marcher().signatures) == 1


def test_steep_rays_meet_the_surface_once_where_dense_sampling_finds_it() -> None:
    rng = np.random.default_rng(8)
    el, az = rng.uniform(np.radians(20.0), np.radians(85.0), 300), rng.uniform(0, 6.3, 300)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=1)
    o = np.broadcast_to(np.array([10.0, -20.0, 1.5]), d.shape)
    rows, t, _ = wave_hits(SEA, o, d, np.full(300, 1e3), 4.0)
    assert rows.size == 300
    s = np.linspace(0.0, 4.0 / np.sin(el)[:, None], 4001, axis=1)[..., 0]  # (300, 4001)
    p = o[:, None, :] + s[..., None] * d[:, None, :]
    f = p[..., 2] - SEA.height(p[..., 0], p[..., 1], 4.0)
    first = np.argmax(f <= 0.0, axis=1)  # the first sample under the surface
    step = s[:, 1] - s[:, 0]
    assert np.all(np.abs(t - s[np.arange(300), first]) <= step + 1e-3 / np.sin(el))
