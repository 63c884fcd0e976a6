"""The waterplane factors F_j = sum_c w_c exp(i k_j . r_c) (services/physics/hull_average.py):
the split sum over a hull's grid of stations is the plain sum, and a hull short against the
waves sees its origin's velocity."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.vessel import load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.physics.hull_average import HullAverage, _factor
from services.physics.hydro import build_columns

WAVES = np.random.default_rng(1).normal(0.0, 1.5, (2, 6, 9))  # kx, ky (B, M), rad/m


def _direct(plan: np.ndarray, w: np.ndarray) -> np.ndarray:
    kx, ky = WAVES
    return np.exp(1j * (kx[..., None] * plan[:, 0] + ky[..., None] * plan[:, 1])) @ w


@pytest.mark.parametrize("name", ["catabot", "monohull", "wamv", "buoy"])
def test_the_split_sum_over_stations_is_the_plain_sum(name: str) -> None:
    cols = build_columns([load_vessel_model(name)])
    real = cols.area_m2[0] > 0
    plan, w = cols.bottom_m[0][:2][:, real].T, cols.area_m2[0, real] / cols.area_m2[0].sum()
    np.testing.assert_allclose(_factor(plan, w, *WAVES), _direct(plan, w), atol=1e-9)


def test_columns_on_no_grid_take_the_plain_sum() -> None:
    plan = np.random.default_rng(2).uniform(-2.0, 2.0, (30, 2))  # 30 x 30 stations: no grid
    w = np.full(30, 1 / 30)
    np.testing.assert_allclose(_factor(plan, w, *WAVES), _direct(plan, w), atol=1e-12)


def test_a_hull_short_against_the_waves_sees_its_origins_velocity() -> None:
    """A 0.8 m buoy in a swell of 50-100 m waves: factors within 1 % of 1, at any heading."""
    cols = build_columns([load_vessel_model("buoy")])
    hulls = HullAverage(cols.bottom_m.transpose(0, 2, 1), cols.area_m2)
    hulls.use(WaveField(WaveConfig(preset="heavy"), 3))
    assert hulls._re is not None and hulls._im is not None
    assert np.abs(hulls._re - 1.0).max() < 0.01 and np.abs(hulls._im).max() < 0.01


def test_the_stages_of_a_change_of_sea_share_one_table() -> None:
    """A change of sea rescales the same components 40 times in 10 s (sea_change.py): built
    at every stage, the table cost 0.1 s each and a paced run fell behind."""
    cols = build_columns([load_vessel_model("wamv")])
    hulls = HullAverage(cols.bottom_m.transpose(0, 2, 1), cols.area_m2)
    medium, heavy = (
        WaveField(WaveConfig(preset="medium"), 1),
        WaveField(WaveConfig(preset="heavy"), 1),
    )
    hulls.use(WaveField.blend(medium, heavy, 0.025))
    first = hulls._re
    hulls.use(WaveField.blend(medium, heavy, 0.5))
    assert hulls._re is first  # the same components, only rescaled: the same table
    hulls.use(heavy)
    assert hulls._re is not first and hulls._re is not None
    assert hulls._re.shape == (1, 512, heavy.amplitudes_m.size)
