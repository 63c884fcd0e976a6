"""Moorings (services/physics/loads.py) against their law: a moored buoy held on station by
a steady current at the analytic offset, and swinging with a regular wave like a free buoy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.config.vessel import load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world.environment import CurrentField
from catabot.world.waves import WaveField
from services.physics.loads import MOORING_PERIOD_S, MOORING_SCOPE_M, mooring_force
from services.physics.world import PhysicsWorld

DT = 0.01
BUOY = load_vessel_model("buoy")


def _buoy_world(**kwargs: object) -> PhysicsWorld:
    return PhysicsWorld([], dt_s=DT, buoys=[("b0", (0.0, 0.0))], **kwargs)  # type: ignore[arg-type]


def _run(world: PhysicsWorld, seconds: float) -> np.ndarray:
    """The buoy's (x, y) at every step."""
    out = []
    for _ in range(round(seconds / DT)):
        world.step()
        out.append(world.buoy_state_arrays().position[0, :2])
    return np.array(out)


def test_the_pull_is_linear_for_small_offsets_and_hardens_at_the_scope() -> None:
    k = np.array([2.0])
    assert mooring_force(np.array([[0.01, 0.0]]), k)[0, 0] == pytest.approx(-0.02, rel=1e-4)
    far = mooring_force(np.array([[0.0, -MOORING_SCOPE_M]]), k)[0]
    assert far[0] == 0.0 and far[1] == pytest.approx(2.0 * 2.0 * MOORING_SCOPE_M)


def test_a_steady_current_holds_the_buoy_at_the_analytic_offset() -> None:
    """Drag on the water's speed past a buoy at rest = the mooring's pull, solved by hand."""
    current = 0.5
    world = _buoy_world(current=CurrentField((current, 0.0)))
    track = _run(world, 240.0)
    lin, quad = BUOY.damping.linear[0], BUOY.damping.quadratic[0]
    drag = lin * current + quad * current * current  # N
    k = (BUOY.mass_kg + BUOY.added_mass[0]) * (2.0 * math.pi / MOORING_PERIOD_S) ** 2
    roots = np.roots([k / MOORING_SCOPE_M**2, 0.0, k, -drag])
    expected = float(max(r.real for r in roots if abs(r.imag) < 1e-9))
    assert 2.5 < expected < 3.5  # the module docstring's 3.0 m
    assert track[-1, 0] == pytest.approx(expected, abs=0.05)
    assert abs(track[-1, 1]) < 1e-6
    assert np.ptp(track[-500:, 0]) < 0.02  # settled, not swinging


def test_a_moored_buoy_swings_with_a_regular_wave_like_a_free_one() -> None:
    """A 100 N/m mooring (period 4.9 s) swung the buoy 1.54 times the water in a 6 s wave."""
    config = WaveConfig(significant_height_m=0.5, peak_period_s=6.0, frequency_components=1,
                        direction_components=1, spreading=None)  # fmt: skip
    waves = WaveField(config, 1)
    moored = _buoy_world(waves=waves)
    free = PhysicsWorld([("f", BUOY, (0.0, 0.0, 0.0, 0.0))], dt_s=DT, waves=waves)
    swing = np.ptp(_run(moored, 60.0)[3000:, 0]) / 2
    free_x = []
    for _ in range(6000):
        free.step()
        free_x.append(free.state_arrays().position[0, 0])
    free_swing = np.ptp(np.array(free_x)[3000:]) / 2
    assert swing == pytest.approx(free_swing, rel=0.05)
    assert swing == pytest.approx(0.5 / 2 / math.sqrt(2), rel=0.1)  # a regular wave's a = Hs/2√2
