"""The LiDAR rain model against the paper's equations and the original code's numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from services.sensors.rain import (
    RainModelError,
    RainParams,
    apply_rain,
    drop_density,
    mean_drops,
)

ORIGINAL = RainParams(drop_diameter_mm=2.75)  # the original code's D (anchors.md)


def test_drop_density_and_mean_drops_match_the_original_code() -> None:
    # to the digits anchors.md gives: eq. (1) in drops/m^3, eq. (2) in a 50 m beam of r = 2 cm
    assert round(drop_density(1.0, 2.75), 4) == 0.1015
    assert round(drop_density(50.0, 2.75), 3) == 56.199
    assert round(float(mean_drops(1.0, 50.0, ORIGINAL)), 5) == 0.00638
    assert round(float(mean_drops(50.0, 50.0, ORIGINAL)), 3) == 3.531
    assert drop_density(0.0, 3.25) == 0.0


def test_poisson_drop_count_has_the_mean_of_eq_2() -> None:
    z = np.full(1_000_000, 50.0)
    rng = np.random.default_rng(1)
    n = rng.poisson(mean_drops(50.0, z, ORIGINAL))
    assert n.mean() == pytest.approx(3.531, rel=0.01)


class _Fixed:
    """A generator stub: given drop counts and uniforms, so one beam is computed by hand."""

    def __init__(self, n: list[int], u: list[float]) -> None:
        self.n, self.u = np.array(n), np.array(u)

    def poisson(self, lam: np.ndarray) -> np.ndarray:
        return self.n

    def random(self, shape: tuple[int, ...]) -> np.ndarray:
        return self.u


def test_one_beam_by_hand_follows_equations_4_to_7_and_step_three() -> None:
    p = RainParams()
    z, n, u = 40.0, 3, 0.5
    z_drop = z * (1 - u ** (1 / n))
    area, beam = math.pi * (3.25e-3) ** 2 / 4, math.pi * 0.02**2
    rio = 0.9 / math.pi / z**2 * math.exp(-2 * (n * 2 * area / (beam * z)) * z)
    rird = (n * 2 * area / (beam * z_drop)) / z_drop**2
    out = apply_rain(np.array([z]), 100.0, 10.0, p, _Fixed([n], [u]))  # type: ignore[arg-type]
    if rio >= rird:
        assert out.range[0] == z and out.intensity[0] == pytest.approx(rio)
    else:
        assert out.range[0] == pytest.approx(z_drop) and out.intensity[0] == pytest.approx(rird)
    # a drop right in front of the sensor beats the object; none beyond the threshold: no return
    near = apply_rain(np.array([z]), 100.0, 10.0, p, _Fixed([1], [0.99999]))  # type: ignore[arg-type]
    assert near.is_rain[0] and near.range[0] < 0.01
    far = apply_rain(np.array([np.inf]), 100.0, 10.0, p, _Fixed([1], [0.0]))  # type: ignore[arg-type]
    assert not far.is_rain[0] and far.range[0] == np.inf and far.intensity[0] == 0.0


def _plain_monte_carlo(distance: float, rate: float, p: RainParams, beams: int) -> float:
    """The paper's steps written plainly, one beam at a time: the fraction of beams whose
    object return is lost or replaced by a raindrop."""
    rng = np.random.default_rng(99)
    hit = math.isfinite(distance)
    z = distance if hit else 100.0
    n_mean = math.pi * p.beam_radius_m**2 * z * drop_density(rate, p.drop_diameter_mm)
    area = math.pi * (p.drop_diameter_mm / 1000) ** 2 / 4
    beam = math.pi * p.beam_radius_m**2
    changed = 0
    for _ in range(beams):
        n = int(rng.poisson(n_mean))
        if n == 0:
            continue  # the object (or nothing) as without rain
        z_drop = min(rng.uniform(0.0, z, n))
        rio = (p.reflectivity / math.pi) / z**2 * math.exp(-2 * n * p.q_ext * area / (beam * z) * z)
        rird = n * p.q_back * area / (beam * z_drop) / z_drop**2
        if hit and rio > rird:
            changed += rio <= p.detection_threshold
        else:
            changed += 1 if hit else rird > p.detection_threshold
    return changed / beams


@pytest.mark.parametrize("distance", [30.0, 80.0, np.inf])
def test_rain_effect_grows_with_rate_and_matches_a_plain_monte_carlo(distance: float) -> None:
    p, rng = RainParams(), np.random.default_rng(5)
    fractions = []
    for rate in (0.0, 10.0, 25.0, 50.0):
        out = apply_rain(np.full(200_000, distance), 100.0, rate, p, rng)
        seen = np.isfinite(distance) & (out.range == distance)
        fraction = float(np.mean(~seen)) if np.isfinite(distance) else float(out.is_rain.mean())
        plain = _plain_monte_carlo(distance, rate, p, 4000)
        assert fraction == pytest.approx(plain, abs=0.025), (rate, fraction, plain)
        fractions.append(fraction)
    assert fractions[0] == 0.0
    assert fractions[1] < fractions[2] < fractions[3]


def test_no_rain_no_rain_returns_and_objects_kept() -> None:
    d = np.array([5.0, 50.0, 99.0, np.inf])
    out = apply_rain(d, 100.0, 0.0, RainParams(), np.random.default_rng(0))
    assert not out.is_rain.any()
    assert np.array_equal(out.range, d)
    assert out.intensity[0] == pytest.approx(0.9 / math.pi / 25.0)


def test_a_gated_receiver_drops_a_dim_object_in_dry_air_as_in_rain() -> None:
    """The paper's step three applies the threshold only with a drop in the beam; `gated`
    (reflection "lambertian") applies it to every return, at the paper's threshold."""
    d, rho = np.array([5.0, 5.0]), np.array([1e-4, 1e-3])  # RIO 4e-6 and 4e-5 at 5 m
    paper = apply_rain(d, 100.0, 0.0, RainParams(), np.random.default_rng(0), rho=rho)
    gated = apply_rain(d, 100.0, 0.0, RainParams(), np.random.default_rng(0), rho=rho, gated=True)
    assert np.array_equal(paper.range, d)  # below the threshold and still seen: dry air
    assert np.array_equal(gated.range, [np.inf, 5.0])
    assert gated.intensity[1] == pytest.approx(1e-3 / 25.0) and gated.intensity[0] == 0.0


def test_bad_parameters_are_refused() -> None:
    with pytest.raises(RainModelError, match="drop_diameter_mm must be > 0"):
        RainParams(drop_diameter_mm=0.0)
    with pytest.raises(RainModelError, match="rain rate must be a finite number >= 0"):
        drop_density(-1.0, 3.25)
