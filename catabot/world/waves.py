"""The water surface: seeded, directional, linear (Airy) deep-water waves from a spectrum.

Shared by physics (buoyancy follows the moving surface), sensors and visualisation, so that
every service sees the same sea from the same `(config, seed)`.

Model. The surface elevation is a sum of M = frequency_components x direction_components
regular waves (the "double summation" model),

    eta(x, y, t) = sum_m a_m cos(k_m . (x, y) - omega_m t + phi_m),   omega_m^2 = g |k_m|,

with k_m pointing along theta_m, the direction the component travels TO (ENU, radians
counter-clockwise from +x = east). Amplitudes follow a_m^2 / 2 = integral of S(omega) D(theta)
over the component's bin (a_m = sqrt(2 S(omega_m) d_omega D(theta_m) d_theta)). The bins are
chosen with EQUAL ENERGY, in frequency from the spectrum and in direction from the spreading
function, so every component has the same amplitude a = sqrt(2 m0 / M), m0 = Hs^2 / 16, and no
component is wasted on the spectrum's empty tails. Inside its bin each component's frequency
and direction are jittered with the seeded generator: no two components share a frequency, so
the surface never repeats exactly and is ergodic (a time average at one point gives the
ensemble statistics, which the double summation with shared frequencies does not).

The spectrum is truncated to [0.5, 4] x omega_p (the part outside holds ~0.5% of the energy
for Pierson-Moskowitz) and the amplitudes are scaled to the full m0, so the realised
significant height is the configured one.

Randomness (DESIGN.md section 2): the generator is `seeding.rng(seed, "waves")`, the scenario
seed plus the source's own name.

Cost. The hot path is (points x components) phases; they are computed in float64 in "cycles",
reduced to one turn, and only then handed to float32 cos/sin, which NumPy vectorises with SIMD
(float64 cos is not: ~10x slower). The reduction keeps the float32 error at the level of its
rounding (~1e-7 of an amplitude), whatever the distance from the origin or the time. Points are
processed in blocks that stay in cache.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from catabot.config.waves import GRAVITY, WaveConfig, WaveError
from catabot.world import seeding

Array = NDArray[np.float64]

BAND = (0.5, 4.0)  # spectrum truncation, in multiples of the peak frequency
_GRID = 4097  # points of the tables that invert the cumulative spectrum / spreading
_BLOCK = 256  # points per block: (block x components) scratch arrays stay in L2 cache


# --- spectrum and spreading -------------------------------------------------------------


def spectral_density(config: WaveConfig, omega: ArrayLike) -> Array:
    """One-sided spectrum S(omega) (m^2 s / rad) of the configured sea, untruncated.

    Pierson-Moskowitz in its (Hs, Tp) form, which integrates to exactly Hs^2/16; JONSWAP is
    PM times the peak enhancement gamma^r, normalised numerically to the same m0 (the usual
    closed-form factor 1 - 0.287 ln(gamma) is only an approximation).
    """
    w = np.asarray(omega, dtype=np.float64)
    m0 = config.significant_height_m**2 / 16.0
    return m0 * _shape(w, config) / _shape_integral(config)


def _shape(omega: Array, config: WaveConfig) -> Array:
    """Unnormalised spectral shape; PM part integrates to 1 over (0, inf)."""
    wp = config.peak_frequency_radps
    safe = np.where(omega > 0.0, omega, 1.0)
    ratio = wp / safe
    pm = np.where(omega > 0.0, 5.0 * ratio**4 / safe * np.exp(-1.25 * ratio**4), 0.0)
    if config.spectrum == "pierson-moskowitz" or config.gamma == 1.0:
        return pm
    sigma = np.where(omega <= wp, 0.07, 0.09)
    r = np.exp(-((omega - wp) ** 2) / (2.0 * sigma**2 * wp**2))
    return pm * config.gamma**r


def _shape_integral(config: WaveConfig) -> float:
    """Integral of `_shape` over (0, inf): 1 for PM, a quadrature for JONSWAP."""
    if config.spectrum == "pierson-moskowitz" or config.gamma == 1.0:
        return 1.0
    wp = config.peak_frequency_radps
    w = np.linspace(0.2 * wp, 20.0 * wp, 40001)
    tail = 1.25 / 20.0**4  # integral of the PM shape's 5 wp^4 / w^5 beyond 20 wp
    return float(np.trapezoid(_shape(w, config), w)) + tail


def _inverse_cdf(density: Array, grid: Array, quantiles: Array) -> Array:
    """Values of `grid` at which the cumulative of `density` reaches `quantiles` (in [0, 1])."""
    steps = 0.5 * (density[1:] + density[:-1]) * np.diff(grid)
    cdf = np.concatenate([[0.0], np.cumsum(steps)])
    return np.interp(quantiles, cdf / cdf[-1], grid)


# --- the field ------------------------------------------------------------------------------


class WaveField:
    """The sea surface of one (config, seed): heights, normals and orbital velocities.

    Every method takes NumPy arrays (or scalars) of any mutually broadcastable shapes, time
    included, and returns the broadcast shape (plus a trailing 3 for vectors). Component
    tables are read-only. Thread-safe: the methods keep no state between calls.

    The same call gives the same bits in any process on the same machine (DESIGN.md section 4
    needs no more: physics alone feeds the surface into the recorded state). A point's value
    may differ by a few float32 roundings (~1e-8 m) with the size of the batch it is in,
    because BLAS picks kernels by shape; errors of the float32 path are ~1e-7 of Hs.
    """

    def __init__(self, config: WaveConfig, seed: int, *, gravity: float = GRAVITY) -> None:
        if not isinstance(config, WaveConfig):
            raise WaveError(f"WaveField needs a WaveConfig (got {type(config).__name__})")
        try:
            seeding.check_seed(seed)
        except seeding.SeedError as exc:
            raise WaveError(f"wave {exc}") from None
        if not (math.isfinite(gravity) and gravity > 0.0):
            raise WaveError(f"gravity must be a finite number > 0 (got {gravity})")
        self.config, self.seed, self.gravity = config, int(seed), float(gravity)
        omega, theta, phase = _components(config, self.seed)
        amp = 0.0 if config.is_calm else config.significant_height_m / math.sqrt(8.0 * omega.size)
        self._tables(omega, theta, phase, np.full(omega.size, amp))  # a = sqrt(2 m0 / M)
        self._calm, self.sigma_m = config.is_calm, config.significant_height_m / 4.0

    @classmethod
    def blend(cls, old: WaveField, new: WaveField, share: float) -> WaveField:
        """`old` fading and `new` building up: the components of both, the old ones'
        amplitudes times 1 - share and the new ones' times share (a calm side has none).
        A run-time change of sea part of the way (catabot/world/sea_change.py)."""
        parts = [(f, w) for f, w in ((old, 1.0 - share), (new, share)) if w > 0 and not f.is_calm]
        if not parts:
            return new
        field = cls.__new__(cls)
        field.config, field.seed, field.gravity = new.config, new.seed, new.gravity
        omega, theta, phase, amp = (
            np.concatenate([getattr(f, name) for f, _ in parts])
            for name in ("frequencies_radps", "directions_rad", "phases_rad", "amplitudes_m")
        )
        amp = amp * np.concatenate([np.full(f.amplitudes_m.size, w) for f, w in parts])
        field._tables(omega, theta, phase, amp)
        field._calm, field.sigma_m = False, float(np.sqrt(np.sum(amp**2) / 2.0))
        return field

    def _tables(self, omega: Array, theta: Array, phase: Array, amp: Array) -> None:
        """The components' read-only tables and the float32 weights the sums use."""
        self.frequencies_radps = _frozen(omega)
        self.directions_rad = _frozen(theta)
        self.phases_rad = _frozen(phase)
        self.amplitudes_m = _frozen(amp)
        k = omega**2 / self.gravity
        self.wavenumbers_radpm = _frozen(k)
        kx, ky = k * np.cos(theta), k * np.sin(theta)
        # Phase in cycles = [x, y, t, 1] @ _cycles: one small matmul per block of points.
        self._cycles = np.stack([kx, ky, -omega, phase]) / (2.0 * math.pi)
        self._k32 = k.astype(np.float32)
        self._height_w = self.amplitudes_m[:, None].astype(np.float32)
        self._slope_w = np.stack([amp * kx, amp * ky], axis=1).astype(np.float32)
        self._orbital_w = np.stack(
            [amp * omega * np.cos(theta), amp * omega * np.sin(theta), amp * omega], axis=1
        ).astype(np.float32)

    @property
    def is_calm(self) -> bool:
        return self._calm

    def height(self, x: ArrayLike, y: ArrayLike, t: ArrayLike = 0.0) -> Array:
        """Surface elevation eta (m, world z) at horizontal points (x, y), time t (s)."""
        if self.is_calm:  # no tables to evaluate: the physics' calm path stays as cheap as before
            return np.zeros(np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(t)))
        cols, shape = _columns(x, y, t)
        out = np.empty((cols.shape[0], 1))
        for s, block in self._blocks(cols):
            np.cos(block, out=block)
            out[s : s + block.shape[0]] = block @ self._height_w
        return out.reshape(shape)

    def normal(self, x: ArrayLike, y: ArrayLike, t: ArrayLike = 0.0) -> Array:
        """Unit upward surface normal (..., 3) from the analytic gradient of eta."""
        cols, shape = _columns(x, y, t)
        n = np.zeros((cols.shape[0], 3))
        n[:, 2] = 1.0
        if not self.is_calm:
            for s, block in self._blocks(cols):
                np.sin(block, out=block)  # -d(eta)/dx = sum a kx sin(phase)
                n[s : s + block.shape[0], :2] = block @ self._slope_w
            n /= np.linalg.norm(n, axis=1, keepdims=True)
        return n.reshape((*shape, 3))

    def velocity(self, x: ArrayLike, y: ArrayLike, z: ArrayLike, t: ArrayLike = 0.0) -> Array:
        """Orbital velocity of the water (..., 3), m/s, world frame, at points (x, y, z).

        Linear deep-water kinematics, decaying as exp(k z'), with Wheeler stretching: the depth
        z' = min(z - eta, 0) is measured from the local surface, so a point on the surface
        moves with the surface (w = d(eta)/dt) in a trough as on a crest, where plain linear
        theory would under- or overshoot. Points above the surface get the surface's value.
        """
        x, y, z, t = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, z, t)))
        cols, shape = _columns(x, y, t)
        out = np.zeros((cols.shape[0], 3))
        if not self.is_calm:
            z_flat = z.ravel()
            for s, block in self._blocks(cols):
                e = s + block.shape[0]
                cos = np.cos(block)
                out[s:e] = self.orbital(cos, np.sin(block, out=block), z_flat[s:e])
        return out.reshape((*shape, 3))

    def orbital(
        self, cos: NDArray[np.float32], sin: NDArray[np.float32], z: Array, *,
        eta: NDArray[np.float32] | None = None,
    ) -> Array:  # fmt: skip
        """`velocity` at points whose phases' cosines and sines are given, (P, M) float32
        each (overwritten): for a caller that has them already (physics' sea sampler, which
        gives them averaged over each hull with the surface height `eta` at its origin)."""
        height = self.height_of(cos) if eta is None else eta
        depth = np.minimum(z - height, 0.0).astype(np.float32)
        decay = np.exp(depth[:, None] * self._k32)
        cos *= decay
        sin *= decay
        out = np.empty((cos.shape[0], 3))
        out[:, :2] = cos @ self._orbital_w[:, :2]
        out[:, 2] = sin @ self._orbital_w[:, 2]
        return out

    def height_of(self, cos: NDArray[np.float32]) -> NDArray[np.float32]:
        """The surface height at points whose phases' cosines are given (P, M): `height`
        for a caller that has them (`orbital`; physics' sea sampler)."""
        return (cos @ self._height_w)[:, 0]

    def phases(self, x: ArrayLike, y: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float32]:
        """Every component's phase k . (x, y) - omega t + phi at each point, (P, M) float32
        radians within half a turn: the one reduction rule of `height`, for callers that
        build their own sums from the phases (physics' Taylor patches)."""
        cols, _ = _columns(x, y, t)
        cycles = cols @ self._cycles
        cycles -= np.rint(cycles)
        return np.multiply(cycles, 2.0 * math.pi, dtype=np.float32, casting="same_kind")

    def _blocks(self, cols: Array) -> Iterator[tuple[int, NDArray[np.float32]]]:
        """Yield (start, phases) per block of points: float32 radians within one turn.

        The phases buffer is reused for the next block: use it before asking for the next.
        Buffers are allocated once per call, not per block: fresh arrays of this size cost
        page faults on every block.
        """
        n, m = min(cols.shape[0], _BLOCK), self._cycles.shape[1]
        cycles, turns = np.empty((n, m)), np.empty((n, m))
        phases = np.empty((n, m), dtype=np.float32)
        for s in range(0, cols.shape[0], _BLOCK):
            rows = cols[s : s + _BLOCK]
            c, r, p = cycles[: len(rows)], turns[: len(rows)], phases[: len(rows)]
            np.matmul(rows, self._cycles, out=c)  # float64, any magnitude
            np.subtract(c, np.rint(c, out=r), out=c)  # within half a turn
            np.multiply(c, 2.0 * math.pi, out=p, casting="same_kind")
            yield s, p


def _components(config: WaveConfig, seed: int) -> tuple[Array, Array, Array]:
    """Frequencies, directions and phases of all components, flattened (freq-major)."""
    nf, nd = config.frequency_components, config.direction_components
    rng = seeding.rng(seed, "waves")
    jitter_f, jitter_d, phase = rng.random((3, nf, nd))
    wp = config.peak_frequency_radps
    w_grid = np.linspace(BAND[0] * wp, BAND[1] * wp, _GRID)
    u = (np.arange(nf)[:, None] + jitter_f) / nf
    omega = _inverse_cdf(_shape(w_grid, config), w_grid, u)
    if config.spreading is None:
        offset = np.zeros((nf, nd))
    else:
        t_grid = np.linspace(-math.pi, math.pi, _GRID)
        spread = np.cos(t_grid / 2.0) ** (2.0 * config.spreading)
        v = (np.arange(nd)[None, :] + jitter_d) / nd
        offset = _inverse_cdf(spread, t_grid, v)
    theta = config.direction_rad + offset
    return omega.ravel(), theta.ravel(), 2.0 * math.pi * phase.ravel()


def _columns(x: ArrayLike, y: ArrayLike, t: ArrayLike) -> tuple[Array, tuple[int, ...]]:
    """Broadcast x, y, t and stack them as the rows [x, y, t, 1] of a (P, 4) array.
    Points of one shape at one time (physics' every step) skip the broadcast, half the cost
    for a hundred points."""
    same = isinstance(x, np.ndarray) and isinstance(y, np.ndarray) and x.shape == y.shape
    if same and isinstance(t, float | int):
        cols = np.empty((np.size(x), 4))
        cols[:, 0], cols[:, 1], cols[:, 2:] = np.ravel(x), np.ravel(y), ((float(t), 1.0),)
        return _finite(cols), np.shape(x)
    bx, by, bt = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, t)))
    cols = np.empty((bx.size, 4))
    for i, v in enumerate((bx, by, bt)):
        cols[:, i] = v.ravel()
    cols[:, 3] = 1.0
    return _finite(cols), bx.shape


def _finite(cols: Array) -> Array:
    if not np.isfinite(cols).all():
        raise WaveError("wave field evaluated at a non-finite position or time")
    return cols


def _frozen(values: Array) -> Array:
    out = np.array(values, dtype=np.float64)
    out.flags.writeable = False
    return out
