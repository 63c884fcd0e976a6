"""Ray hits on the water surface z = eta(x, y, t): the same WaveField physics floats on.

Calm water is the plane z = 0: one division per ray. With waves, most rays of a LiDAR scan
or a camera frame are solved on a grid of the surface sampled once per cast
(services/sensors/wave_cast.py); this module's exact march takes the rest: casts of a few
rays (a radar tick), rays that leave the grid (a camera's few rays near the horizon) and
seas whose grid would be too fine to pay.

The exact march: |eta| <= A (the sum of the component amplitudes), so a downward ray can
only cross the surface between the heights z = +A and z = -A. That bracket (cut at the
nearest other hit) is sampled at MARCH_SAMPLES points to find the FIRST sign change of
f(t) = z(t) - eta(x(t), y(t), t_now) (a grazing ray can pass over a trough and meet the next
crest), then refined by Newton steps on the exact slope kept inside the bracket, until the
point is within TOLERANCE_M (0.5 mm) of the surface. Rays pointing up or level never hit
water from above. Eight samples over +-A are no proof of the first crossing: a crest that
pokes through between two samples of a ray grazing it far away is missed (seen on rays
within ~0.2 deg of the horizon beyond ~300 m); the grid's walk finds it (wave_kernel.py).

A ray steeper than the steepest possible surface (slope sum a k) meets it exactly once:
it skips the march, and one evaluation where it crosses z = 0 brackets its root tightly
(the root is within |f| / (its minimum descent rate) of there). Known signs are not
evaluated: at z = +A the ray is above every crest, at z = -A below every trough.

Cost: (downward rays in the band) x (~10 evaluations: ~4.5 march samples and 2-6 Newton
steps; fewer for steep rays) of the sum, one float32 multiply-add, cosine and (in Newton
steps) sine per wave component: ~0.4 us a ray for 48 components, compiled
(services/sensors/wave_march.py; NumPy took ~0.76 us, and a few rays cost its calls rather
than their cosines: a radar tick ~0.6 ms, a camera's 729 far rays 1.3-1.6 ms).
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

from catabot.world.waves import WaveField
from services.sensors.wave_bounds import origins, plain
from services.sensors.wave_march import Sea, marcher, sea_tables

F64 = NDArray[np.float64]


def calm_hits(o: F64, d: F64, max_range: float) -> F64:
    """Distance along each unit ray to the plane z = 0 from above (inf: none within
    `max_range`); the normal there is +z."""
    dz = np.ascontiguousarray(d[:, 2])
    shared = o.strides[0] == 0  # one origin: a scalar height (a camera's 300 k rays)
    oz = o[0, 2] if shared else o[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -oz / dz
    hit = (dz < -1e-12) & (t <= max_range)
    hit &= (oz >= 0.0) if not shared else bool(oz >= 0.0)
    t[~hit] = np.inf
    return t


def wave_hits(
    waves: WaveField, o: F64, d: F64, limit: F64, time_s: float
) -> tuple[NDArray[np.intp], F64, F64]:
    """The rays that meet the wave surface before `limit`, their distances and the
    surface's unit normals there (world frame): the compiled march (wave_march.py)."""
    shift = waves.phases_rad - waves.frequencies_radps * time_s
    t, normal = np.empty(d.shape[0]), np.zeros((d.shape[0], 3))
    marcher()(_sea(waves), shift, origins(o), plain(d), plain(limit), t, normal)
    rows = np.flatnonzero(t < np.inf)
    return rows, np.take(t, rows), np.take(normal, rows, axis=0)


@functools.lru_cache(maxsize=8)  # a scene's sea, and the next one a run-time setting sets
def _sea(waves: WaveField) -> Sea:
    """The march's tables of a sea, built once for it, not at every cast."""
    return sea_tables(waves.wavenumbers_radpm, waves.directions_rad, waves.amplitudes_m)
