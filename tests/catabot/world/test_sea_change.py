"""A run-time change of sea builds up in stages (catabot/world/sea_change.py)."""

from __future__ import annotations

import numpy as np

from catabot.config.waves import WaveConfig
from catabot.world.sea_change import STAGES, SeaChange
from catabot.world.waves import WaveField

X, Y = np.meshgrid(np.linspace(-50.0, 50.0, 11), np.linspace(-30.0, 30.0, 7))


def _sea(preset: str) -> WaveField:
    return WaveField(WaveConfig(preset=preset), seed=4)


def test_a_blend_is_the_weighted_sum_of_the_two_seas() -> None:
    medium, heavy = _sea("medium"), _sea("heavy")
    mixed = WaveField.blend(medium, heavy, 0.25)
    expected = 0.75 * medium.height(X, Y, 3.0) + 0.25 * heavy.height(X, Y, 3.0)
    assert np.allclose(mixed.height(X, Y, 3.0), expected, atol=1e-5)
    at = (X, Y, 10.0, 3.0)  # above the surface: the surface's own orbital velocity
    speed = 0.75 * medium.velocity(*at) + 0.25 * heavy.velocity(*at)
    assert np.allclose(mixed.velocity(*at), speed, atol=1e-5)
    assert not mixed.is_calm and mixed.amplitudes_m.size == 2 * heavy.amplitudes_m.size


def test_from_calm_only_the_new_sea_builds_up() -> None:
    heavy = _sea("heavy")
    part = WaveField.blend(_sea("calm"), heavy, 0.5)
    assert part.amplitudes_m.size == heavy.amplitudes_m.size  # no calm components carried
    assert np.allclose(part.height(X, Y, 1.0), 0.5 * heavy.height(X, Y, 1.0), atol=1e-5)
    assert abs(part.sigma_m - heavy.sigma_m / 2) < 1e-9


def test_the_stages_come_at_their_ticks_and_end_on_the_new_sea() -> None:
    medium, heavy = _sea("medium"), _sea("heavy")
    sea = SeaChange(medium, dt_ns=10_000_000)
    assert sea.every == 25 and sea.at(0) is None  # a quarter of a second; nothing under way
    sea.begin(heavy, tick=100)
    seen = {t: sea.at(t) for t in range(99, 100 + STAGES * 25 + 30)}
    stages = [t for t, field in seen.items() if field is not None]
    assert stages == [100 + 25 * k for k in range(STAGES)]
    last = seen[stages[-1]]
    assert last is heavy and sea.now is heavy  # the new sea itself, not a blend of it
    first = seen[100]
    assert first is not None and np.allclose(
        first.height(X, Y, 1.0),
        (1 - 1 / STAGES) * medium.height(X, Y, 1.0) + heavy.height(X, Y, 1.0) / STAGES,
        atol=1e-5,
    )


def test_a_change_part_of_the_way_starts_from_the_sea_as_it_is() -> None:
    calm, heavy = _sea("calm"), _sea("heavy")
    sea = SeaChange(calm, dt_ns=10_000_000)
    sea.begin(heavy, tick=0)
    for t in range(0, 20 * 25 + 1):
        sea.at(t)  # half way: 21 stages taken
    halfway = sea.now.height(X, Y, 2.0)
    sea.begin(calm, tick=501)
    back = sea.at(501)
    assert back is not None
    assert np.allclose(back.height(X, Y, 2.0), (1 - 1 / STAGES) * halfway, atol=1e-5)
