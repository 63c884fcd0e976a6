"""The longest physics step each model stays stable at (catabot/world/step_limits.py), and
the refusal of a scenario whose step is longer. The physics behind the limit, stable under
it and diverging beyond it: tests/services/physics/test_step_limits.py."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.vessel import BUNDLED_DIR, load_vessel_model
from catabot.world import step_limits
from catabot.world.world import World


def _world(dt_s: float, model: str = "wamv", **more: Any) -> World:
    data = {"dt_ns": round(dt_s * 1e9), "vessels": [{"id": "ego", "model": model}], **more}
    return World.resolve(parse_scenario(data))


def test_the_limit_is_juries_conditions_for_one_degree_of_freedom() -> None:
    """b < 2 and a + 2b < 4 with a = k dt^2/m, b = c dt/m: at the limit a + 2b = 4 exactly
    (or b = 2 with no stiffness), MARGIN of it given."""
    k, c, m = 4000.0, 300.0, 50.0
    limit = step_limits._limit("heave", k, c, m)
    dt = limit.dt_s / step_limits.MARGIN
    assert k * dt**2 / m + 2 * c * dt / m == pytest.approx(4.0, rel=1e-12)
    assert limit.period_s == pytest.approx(2 * math.pi * math.sqrt(m / k))
    damped = step_limits._limit("surge", 0.0, c, m)
    assert damped.dt_s / step_limits.MARGIN == pytest.approx(2 * m / c)
    assert math.isinf(damped.period_s)


def test_the_wamv_rolls_fastest_and_the_schemas_longest_step_is_refused_for_it() -> None:
    limit = step_limits.step_limit(load_vessel_model("wamv"), 1025.0)
    assert limit.dof == "roll" and 0.08 < limit.dt_s < 0.09
    assert limit.period_s == pytest.approx(0.365, abs=0.002)
    _world(0.08)  # under it: runs
    with pytest.raises(ScenarioError) as err:
        _world(0.1)
    text = str(err.value)
    assert text.startswith("vessels.0.model: model 'wamv' is stable only with a physics step")
    assert "up to 0.0864 s (roll: natural period 0.365 s" in text and "dt_ns 100000000" in text


@pytest.mark.parametrize("model", ["catabot", "monohull", "buoy"])
def test_the_other_bundled_models_take_every_step_the_schema_allows(model: str) -> None:
    assert step_limits.step_limit(load_vessel_model(model), 1025.0).dt_s > 0.1


def test_a_light_model_on_heavy_damping_is_refused_at_the_default_step(tmp_path: Path) -> None:
    """An audit's 0.3 kg model on the catamaran's hulls: thrown 17 m up on its first step."""
    data = json.loads((BUNDLED_DIR / "catabot.json").read_text())
    data.update(mass_kg=0.3, added_mass=[0.0] * 6)
    data.pop("shape", None)
    path = tmp_path / "light.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ScenarioError, match=r"model '.*light.json' is stable only .*\(heave"):
        _world(0.01, model=str(path))


def test_the_buoy_and_traffic_models_count_only_with_buoys_and_traffic(tmp_path: Path) -> None:
    """The buoy's model is loaded for every scenario; a run without buoys has no buoy body."""
    data = json.loads((BUNDLED_DIR / "buoy.json").read_text())
    data.update(mass_kg=0.05, added_mass=[0.0] * 6)
    light = tmp_path / "light_buoy.json"
    light.write_text(json.dumps(data))
    models = {"catabot": load_vessel_model("catabot"), "buoy": load_vessel_model(str(light))}
    scenario = parse_scenario({"vessels": [{"id": "ego"}]})
    step_limits.check_step(scenario, models)  # no buoy: fine
    with_buoy = parse_scenario(
        {"vessels": [{"id": "ego"}], "buoys": [{"id": "b", "x_m": 9, "y_m": 0}]}
    )
    with pytest.raises(ScenarioError, match=r"^buoys: model 'buoy'"):
        step_limits.check_step(with_buoy, models)
