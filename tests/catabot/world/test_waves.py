"""The wave field against its definition: seeding, spectrum, statistics, normals, kinematics."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest

from catabot.config.waves import PRESETS, WaveConfig, WaveError, parse_wave_config
from catabot.world.waves import BAND, WaveField, spectral_density

_PRINT_HEIGHTS = """
import sys
import numpy as np
from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
field = WaveField(WaveConfig(preset="heavy"), seed=int(sys.argv[1]))
x = np.array([0.0, 12.5, -300.0, 1234.5])
y = np.array([0.0, -7.25, 80.0, 999.0])
for t in (0.0, 1.5, 3599.99):
    print(" ".join(float(v).hex() for v in field.height(x, y, t)))
"""


def _heights_in_subprocess(seed: int, hash_seed: str) -> str:
    env = {**os.environ, "PYTHONHASHSEED": hash_seed}
    done = subprocess.run(
        [sys.executable, "-c", _PRINT_HEIGHTS, str(seed)],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
        check=True,
    )
    return done.stdout


def test_same_seed_same_surface_in_separate_processes() -> None:
    first = _heights_in_subprocess(7, "1")
    second = _heights_in_subprocess(7, "2")  # a different str-hash salt must not matter
    assert first == second
    assert len(first.split()) == 12 and "0x0.0p+0" not in first
    assert _heights_in_subprocess(8, "1") != first


def test_different_seed_gives_a_different_sea() -> None:
    config = WaveConfig(preset="medium")
    x, y = np.meshgrid(np.linspace(0, 200, 20), np.linspace(0, 200, 20))
    a = WaveField(config, seed=1).height(x, y, 10.0)
    b = WaveField(config, seed=2).height(x, y, 10.0)
    assert np.abs(a - b).max() > 0.1
    assert np.array_equal(a, WaveField(config, seed=1).height(x, y, 10.0))


def test_presets_match_the_paper_amplitudes() -> None:
    """Fig. 6 amplitudes 0.62 m / 1.25 m, read as significant amplitude Hs / 2."""
    assert WaveConfig(preset="medium").significant_height_m == pytest.approx(2 * 0.62)
    assert WaveConfig(preset="heavy").significant_height_m == pytest.approx(2 * 1.25)
    calm = WaveField(WaveConfig(preset="calm"), seed=3)
    assert calm.is_calm and set(PRESETS) == {"calm", "medium", "heavy"}
    assert np.array_equal(calm.height(np.ones((4, 5)), 2.0, 7.0), np.zeros((4, 5)))
    assert np.array_equal(calm.normal(1.0, 2.0, 3.0), [0.0, 0.0, 1.0])
    assert np.array_equal(calm.velocity([1.0, 2.0], 0.0, -1.0, 3.0), np.zeros((2, 3)))


@pytest.mark.parametrize("preset", ["medium", "heavy"])
def test_realised_significant_height(preset: str) -> None:
    """4 std of eta sampled over 2 km x 2 km and an hour is the configured Hs (within 10%)."""
    config = WaveConfig(preset=preset)
    field = WaveField(config, seed=11)
    rng = np.random.default_rng(5)
    x = rng.uniform(-1000, 1000, (4096, 1))
    y = rng.uniform(-1000, 1000, (4096, 1))
    t = np.linspace(0.0, 3600.0, 40)
    eta = field.height(x, y, t)
    assert eta.shape == (4096, 40)
    assert 4.0 * eta.std() == pytest.approx(config.significant_height_m, rel=0.10)
    amps = field.amplitudes_m
    assert np.sum(amps**2) / 2 == pytest.approx(config.significant_height_m**2 / 16, rel=1e-12)


@pytest.mark.parametrize(
    "config",
    [
        WaveConfig(spectrum="pierson-moskowitz", significant_height_m=1.0, peak_period_s=6.0),
        WaveConfig(spectrum="jonswap", significant_height_m=2.5, peak_period_s=10.0),
        WaveConfig(spectrum="jonswap", significant_height_m=0.4, peak_period_s=3.0, gamma=7.0),
        WaveConfig(preset="medium"),
    ],
)
def test_spectrum_integrates_to_m0(config: WaveConfig) -> None:
    omega = np.linspace(1e-3, 60.0 * config.peak_frequency_radps, 600_001)
    m0 = np.trapezoid(spectral_density(config, omega), omega)
    assert m0 == pytest.approx(config.significant_height_m**2 / 16, rel=0.01)


def test_jonswap_peak_is_sharper_than_pierson_moskowitz() -> None:
    pm = WaveConfig(spectrum="pierson-moskowitz", significant_height_m=2.0, peak_period_s=9.0)
    js = pm.model_copy(update={"spectrum": "jonswap"})
    omega = np.linspace(0.2, 3.0, 20001)
    s_pm, s_js = spectral_density(pm, omega), spectral_density(js, omega)
    assert omega[np.argmax(s_pm)] == pytest.approx(pm.peak_frequency_radps, rel=1e-3)
    assert omega[np.argmax(s_js)] == pytest.approx(js.peak_frequency_radps, rel=1e-3)
    assert s_js.max() > 1.5 * s_pm.max()

    def half_power_width(s: np.ndarray) -> float:
        above = omega[s >= s.max() / 2]
        return float(above[-1] - above[0])

    assert half_power_width(s_js) < 0.6 * half_power_width(s_pm)


def test_components_are_equal_energy_and_never_commensurate() -> None:
    config = WaveConfig(preset="heavy", frequency_components=16, direction_components=5)
    field = WaveField(config, seed=0)
    w = field.frequencies_radps
    assert w.size == 80 and np.unique(w).size == 80  # jittered: no repeated frequency
    wp = config.peak_frequency_radps
    assert w.min() >= BAND[0] * wp and w.max() <= BAND[1] * wp
    assert np.allclose(field.wavenumbers_radpm, w**2 / 9.81)  # deep-water dispersion
    spread = np.angle(np.exp(1j * (field.directions_rad - config.direction_rad)))
    assert abs(np.mean(spread)) < 0.1 and 0.1 < np.std(spread) < 0.4  # s = 25: ~0.28 rad
    assert not field.amplitudes_m.flags.writeable


def test_long_crested_waves_travel_along_the_mean_direction() -> None:
    config = WaveConfig(preset="medium", spreading=None, direction_rad=math.pi / 2)
    field = WaveField(config, seed=4)
    assert np.allclose(field.directions_rad, math.pi / 2)
    x = np.linspace(-50, 50, 11)
    heights = field.height(x, 3.0, 2.0)  # crests parallel to x: constant along x
    assert np.allclose(heights, heights[0], atol=1e-6)


def test_height_matches_a_float64_sum_of_components() -> None:
    """The float32 fast path stays within a micrometre of the exact sum, far out and late."""
    field = WaveField(WaveConfig(preset="heavy"), seed=9)
    rng = np.random.default_rng(1)
    x, y = rng.uniform(-5000, 5000, (2, 3000))
    t = 3599.37
    k, th = field.wavenumbers_radpm, field.directions_rad
    phase = np.outer(x, k * np.cos(th)) + np.outer(y, k * np.sin(th))
    phase += field.phases_rad - field.frequencies_radps * t
    exact = np.cos(phase) @ field.amplitudes_m
    assert np.abs(field.height(x, y, t) - exact).max() < 1e-6


def test_broadcasting_over_space_and_time() -> None:
    field = WaveField(WaveConfig(preset="medium"), seed=2)
    t = np.array([0.0, 1.0, 2.0])
    grid = field.height(np.array([[0.0], [5.0]]), 1.0, t)
    assert grid.shape == (2, 3)
    # BLAS picks kernels by batch size: a point's value may move in the last bits (float32).
    assert grid[1, 2] == pytest.approx(field.height(5.0, 1.0, 2.0), abs=1e-7)
    assert field.height(0.0, 0.0).shape == ()
    assert field.normal(np.zeros((2, 3)), 0.0, 0.0).shape == (2, 3, 3)
    assert field.velocity(np.zeros(4), 0.0, -1.0, t[:1]).shape == (4, 3)


def test_normal_is_unit_and_matches_finite_difference_gradient() -> None:
    config = WaveConfig(significant_height_m=0.6, peak_period_s=4.0, spectrum="jonswap")
    field = WaveField(config, seed=21)
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-300, 300, (2, 500))
    t, h = 123.4, 1e-2
    n = field.normal(x, y, t)
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-12)
    dx = (field.height(x + h, y, t) - field.height(x - h, y, t)) / (2 * h)
    dy = (field.height(x, y + h, t) - field.height(x, y - h, t)) / (2 * h)
    expected = np.stack([-dx, -dy, np.ones_like(dx)], axis=-1)
    expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
    assert np.abs(n - expected).max() < 1e-4
    assert np.abs(n[:, :2]).max() > 0.05  # the test would be vacuous on a flat sea


def test_orbital_velocity_moves_with_the_surface_and_decays_with_depth() -> None:
    """At the surface w = d(eta)/dt (kinematic condition); deep down the water is still."""
    field = WaveField(WaveConfig(preset="medium"), seed=6)
    rng = np.random.default_rng(8)
    x, y = rng.uniform(-200, 200, (2, 400))
    t, h = 50.0, 1e-3
    eta = field.height(x, y, t)
    w_surface = field.velocity(x, y, eta, t)[:, 2]
    deta_dt = (field.height(x, y, t + h) - field.height(x, y, t - h)) / (2 * h)
    assert np.abs(w_surface - deta_dt).max() < 1e-3 * np.abs(deta_dt).max() + 1e-4
    above = field.velocity(x, y, eta + 5.0, t)  # above the surface: the surface's value
    assert np.allclose(above[:, 2], w_surface, atol=1e-9)
    speed_deep = np.linalg.norm(field.velocity(x, y, eta - 60.0, t), axis=-1)
    speed_top = np.linalg.norm(field.velocity(x, y, eta, t), axis=-1)
    assert speed_deep.max() < 0.1 * speed_top.max()


def test_explicit_fields_override_the_preset() -> None:
    config = WaveConfig(preset="heavy", direction_rad=1.5, spectrum="pierson-moskowitz")
    assert config.significant_height_m == 2.5 and config.peak_period_s == 10.0
    assert config.direction_rad == 1.5 and config.spectrum == "pierson-moskowitz"
    assert WaveConfig().is_calm  # neither preset nor height: calm water


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"significant_height_m": -1.0}, r"waves\.significant_height_m: must be >= 0 \(got -1"),
        ({"peak_period_s": 0.0}, r"waves\.peak_period_s: must be > 0 \(got 0.0\)"),
        ({"peak_period_s": -3}, r"waves\.peak_period_s: must be > 0 \(got -3\)"),
        ({"preset": "stormy"}, r"waves\.preset: must be one of 'calm', 'medium' or 'heavy'"),
        ({"height": 1.0}, r"waves\.height: unknown field \(allowed: preset, spectrum, "),
        ({"direction_rad": math.inf}, r"waves\.direction_rad: "),
        ({"frequency_components": 0}, r"waves\.frequency_components: must be >= 1"),
        (
            {"significant_height_m": 5.0, "peak_period_s": 4.0},
            r"significant steepness Hs/Lp = 0\.2 exceeds 0\.1",
        ),
    ],
)
def test_bad_config_names_the_field(data: dict[str, object], message: str) -> None:
    with pytest.raises(WaveError, match=message):
        parse_wave_config(data)


def test_bad_field_arguments() -> None:
    with pytest.raises(WaveError, match="needs a WaveConfig"):
        WaveField({"preset": "heavy"}, seed=1)  # type: ignore[arg-type]
    with pytest.raises(WaveError, match="seed must be an integer"):
        WaveField(WaveConfig(), seed=1.5)  # type: ignore[arg-type]
    with pytest.raises(WaveError, match=r"seed must be in \[0, 2\*\*63\) \(got -3\)"):
        WaveField(WaveConfig(), seed=-3)  # one seeding rule: no folding of negative seeds
    field = WaveField(WaveConfig(preset="medium"), seed=3)
    with pytest.raises(WaveError, match="non-finite position or time"):
        field.height(np.nan, 0.0, 0.0)
    xs = np.array([1.0, np.inf])  # arrays of one shape at one time: the unbroadcast path
    with pytest.raises(WaveError, match="non-finite position or time"):
        field.phases(xs, np.zeros(2), 2.0)
    with pytest.raises(WaveError, match="non-finite position or time"):
        field.phases(np.zeros(2), np.zeros(2), float("nan"))


def test_both_ways_of_stacking_points_give_the_same_phases() -> None:
    """Points of one shape at one time skip the broadcast (physics' every step): the same
    phases as when the time is an array the points broadcast with."""
    field = WaveField(WaveConfig(preset="medium"), seed=3)
    x, y = np.linspace(-50.0, 900.0, 12).reshape(3, 4), np.linspace(7.0, -300.0, 12).reshape(3, 4)
    fast = field.phases(x, y, 12.5)
    broadcast = field.phases(x, y, np.full((3, 4), 12.5))
    assert fast.shape == (12, field.amplitudes_m.size)
    np.testing.assert_array_equal(fast, broadcast)
