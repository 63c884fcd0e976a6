"""Marine radar (paper III-B.2.b): a clockwise-turning antenna that reports, per sample, the
sector it swept since the previous one, as echo profiles over range bins.

Geometry. Beams are spaced half a beam width apart (480 per turn for 1.5 deg), so that
adjacent beams overlap as a real antenna pattern does. Beam j points at azimuth -2 pi j / n
from the bow (clockwise), in the HORIZONTAL plane: the antenna is stabilised, so a rolling
hull does not tilt the sweep. Which beams a sample holds follows from the stamp alone (beam
j is emitted at j T / n, T the rotation period), so the sweep is the same however the sample
period divides the turn. Each beam is `sub_rays` rays across its width times a fan of
elevations: a down-looking fan spaced so that no boat `fan_target_height_m` tall slips between
two rays at any range (from 3 m a 0.3 m boat at 200 m spans 0.78-0.86 deg down), plus
`elevations_deg` at and above the horizon for shores and tall ships. A body narrower than
the gap between a beam's rays, that they passed, is cast again at its own bearing
(radar_fill.py): a buoy far off shows on every beam whose width holds it.

Echoes. Returns from the water are sea clutter and are dropped by default (`sea_clutter`);
rain does not attenuate X-band returns at these ranges in this model. Each ray's range gets
Gaussian noise (sigma 0.2 m); its echo strength 0.3 + 0.7 |cos incidence| is summed per range
bin and mapped to 0..255 by 255 (1 - exp(-sum)), so one solid hit shows and many saturate.
A beam's first return is its nearest ray by true range, with that ray's noise: unbiased.
Ranges are slant ranges from the antenna (a buoy 29.75 m off reads 29.83 m from 3 m up).
"""

from __future__ import annotations

import math
from typing import ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

from catabot.bus.clock import NS_PER_S
from catabot.bus.messages import CLASS_NONE, CLASS_WATER, Message, RadarSweep, VesselState
from catabot.config.sensors import RadarParams
from catabot.world import rotations, seeding
from services.sensors.camera import CastScene
from services.sensors.common import SensorError, rotation_from_quaternion
from services.sensors.cull import Cones
from services.sensors.mount import Mount
from services.sensors.radar_fill import Beams, directions, fill
from services.sensors.scene import Hits

F64 = NDArray[np.float64]


class RadarScene(CastScene, Protocol):
    """What a radar needs of the scene: a camera's, and the bodies' cones and instance ids
    for the fill of thin bodies (radar_fill.py)."""

    @property
    def instances(self) -> NDArray[np.int32]: ...

    def cones(self, origin: F64, max_range: float) -> Cones: ...


def fan(p: RadarParams) -> F64:
    """Down-looking elevations (rad) whose sea ranges D_i grow by 1 / (1 - H / h): then any
    target at least H tall between two of them is hit (ray i + 1 passes it at height
    h (1 - D / D_(i+1)) < H), from `fan_min_range_m` to the maximum range."""
    h, target = p.antenna_height_m, p.fan_target_height_m
    if target <= 0.0 or h <= target:
        return np.empty(0)
    ratio = 1.0 / (1.0 - target / h)
    count = math.ceil(math.log(p.range_m / p.fan_min_range_m) / math.log(ratio)) + 1
    sea_range = p.fan_min_range_m * ratio ** np.arange(count)
    return -np.arctan(h / sea_range)


class RadarModel:
    """One radar on one vessel; deterministic for a seed and name."""

    message: ClassVar[type[Message]] = RadarSweep

    def __init__(self, params: RadarParams, mount: Mount) -> None:
        scene: RadarScene | None = mount.scene
        noise, seed, name, period_ns = mount.noise, mount.seed, mount.name, mount.period_ns
        if period_ns <= 0:
            raise SensorError(f"radar {name!r} needs its sample period (got {period_ns} ns)")
        if scene is None:
            raise SensorError(f"radar {name!r} needs the ray-casting scene")
        self.params, self.scene, self.noise = params, scene, noise
        self.period_ns = int(period_ns)
        self.turn_ns = round(params.rotation_period_s * NS_PER_S)
        self.beams_per_turn = max(1, round(720.0 / params.beam_width_deg))
        self.step_rad = 2 * math.pi / self.beams_per_turn
        width = math.radians(params.beam_width_deg)
        self.offsets = ((np.arange(params.sub_rays) + 0.5) / params.sub_rays - 0.5) * width
        self.elevations = np.concatenate([fan(params), np.radians(params.elevations_deg)])
        if self.elevations.size == 0:
            raise SensorError(f"radar {name!r} has no rays: give elevations_deg or a fan")
        self._rng = seeding.rng(seed, name)
        self._fill_rng = seeding.rng(seed, f"{name}/fill")  # radar_fill.py: its own stream

    def beam_indices(self, stamp_ns: int) -> NDArray[np.int64]:
        """Beams emitted in [stamp - period, stamp): j with j T / n in that interval."""
        n, t = self.beams_per_turn, self.turn_ns
        first = -(-(stamp_ns - self.period_ns) * n // t)
        last = -(-stamp_ns * n // t)
        return np.arange(first, last, dtype=np.int64)

    def sample(self, state: VesselState, *, tick: int, stamp_ns: int) -> RadarSweep:
        rot = rotation_from_quaternion(state.orientation)
        heading = rotations.yaw_of_matrix(rot)
        origin = np.asarray(state.position, dtype=np.float64) + rot @ (
            0.0,
            0.0,
            self.params.antenna_height_m,
        )
        beams = self.beam_indices(stamp_ns)
        azimuth = -self.step_rad * (beams % self.beams_per_turn).astype(np.float64)
        intensity, ranges = self.sweep(origin, heading + azimuth)
        start = float(azimuth[0] % (2 * math.pi)) if beams.size else 0.0
        return RadarSweep(
            tick=tick,
            stamp_ns=stamp_ns,
            azimuth_start_rad=start,
            azimuth_end_rad=start - self.step_rad * max(beams.size - 1, 0),
            heading_rad=heading,
            range_m=self.params.range_m,
            beams=int(beams.size),
            intensity=intensity,
            ranges=ranges,
        )

    def rays(self, bearings: F64) -> F64:
        """Unit directions (beams x sub-rays x elevations, 3) of beams at map bearings."""
        b = bearings[:, None, None] + self.offsets[None, :, None]
        return directions(b, self.elevations[None, None, :])

    def sweep(self, origin: F64, bearings: F64) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        """Echo profiles (beams, range_bins) uint8 and first-return ranges (beams,) float32."""
        p = self.params
        nb = bearings.size
        dirs = self.rays(bearings)
        per_beam = dirs.shape[1] * dirs.shape[2]
        flat = dirs.reshape(-1, 3)
        hits = self.scene.cast(origin, flat, p.range_m) if nb else None
        draws = self._rng.standard_normal(flat.shape[0])  # drawn for every ray: aligned stream
        ranges = np.full(nb, np.inf, dtype=np.float32)
        intensity = np.zeros((nb, p.range_bins), dtype=np.uint8)
        if hits is None:
            return intensity, ranges
        beam_of = np.arange(flat.shape[0]) // per_beam
        echoes = [self._echoes(hits, flat, draws, beam_of)]
        echoes.append(self._fill(origin, bearings, hits.instance.reshape(nb, per_beam)))
        beam, strength, clean, noisy = (np.concatenate(part) for part in zip(*echoes, strict=True))
        bins = np.minimum((noisy / p.range_m * p.range_bins).astype(np.intp), p.range_bins - 1)
        echo = np.bincount(beam * p.range_bins + bins, strength, minlength=nb * p.range_bins)
        intensity[:] = np.rint(255.0 * (1.0 - np.exp(-echo))).reshape(nb, p.range_bins)
        ranges[:] = _first_returns(nb, beam, clean, noisy)
        return intensity, ranges

    def _echoes(
        self,
        hits: Hits,
        dirs: F64,
        draws: F64,
        beam_of: Ints,
        body: NDArray[np.int32] | None = None,
    ) -> Echoes:
        """(beam, strength, true range, noisy range) of the rays that return an echo; `body`:
        only those that met that instance (a fill's rays)."""
        p = self.params
        r = hits.range.astype(np.float64)
        if self.noise:
            r = r + p.range_noise_sigma_m * draws
        ok = (hits.cls != CLASS_NONE) & np.isfinite(r) & (r >= 0.0) & (r < p.range_m)
        if not p.sea_clutter:
            ok &= hits.cls != CLASS_WATER
        if body is not None:
            ok &= hits.instance == body
        idx = np.flatnonzero(ok)
        strength = 0.3 + 0.7 * np.abs(np.sum(hits.normal[idx] * dirs[idx], axis=1))
        return beam_of[idx], strength, hits.range[idx], r[idx]

    def _fill(self, origin: F64, bearings: F64, met: NDArray[np.int32]) -> Echoes:
        """The echoes of thin bodies within a beam's width that its rays missed
        (radar_fill.py)."""
        p = self.params
        width = math.radians(p.beam_width_deg)
        beams = Beams(bearings, width, width / p.sub_rays, self.elevations, met)
        scene = self.scene
        cones = scene.cones(origin, p.range_m)
        rays = fill(origin, cones, scene.corners(), scene.instances, beams,
                    near_m=p.fan_min_range_m)  # fmt: skip
        if rays.dirs.shape[0] == 0:
            return _NO_ECHO
        hits = scene.cast(origin, rays.dirs, p.range_m)
        draws = self._fill_rng.standard_normal(size=(rays.dirs.shape[0],))
        return self._echoes(hits, rays.dirs, draws, rays.beam, rays.instance)


Ints = NDArray[np.intp]
Echoes = tuple[Ints, F64, NDArray[np.float32], F64]
_NO_ECHO: Echoes = (np.empty(0, np.intp), np.empty(0), np.empty(0, np.float32), np.empty(0))


def _first_returns(
    beams: int, beam: NDArray[np.intp], clean: NDArray[np.float32], noisy: F64
) -> F64:
    """Each beam's first return: its nearest ray by the true range, reported with that
    ray's own noise. The nearest of the noisy ranges was biased short (0.2 m low at sigma
    0.2 over a beam's rays: a sensor check found the reading -0.215 +- 0.151 m, not
    N(0, 0.2) as the paper's "Gaussian noise on this distance reading" is)."""
    nearest = np.full(beams, np.inf, dtype=clean.dtype)
    np.minimum.at(nearest, beam, clean)
    first = np.flatnonzero(clean == nearest[beam])[::-1]  # reversed: of ties, the first wins
    out = np.full(beams, np.inf)
    out[beam[first]] = noisy[first]
    return out
