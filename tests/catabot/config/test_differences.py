"""The fields a sweep's runs differ in, named as `--set` names them."""

from __future__ import annotations

from catabot.config.differences import (
    differences,
    flat_fields,
    flatten,
    one_scenario,
    swept_fields,
)
from catabot.config.load import parse_scenario
from catabot.config.scenario import Scenario


def scenario(**changes: object) -> Scenario:
    data: dict[str, object] = {"name": "s", "vessels": [{"id": "ego"}]}
    return parse_scenario(data | changes)


def test_a_tree_flattens_to_dotted_leaves_and_plain_lists_stay_whole() -> None:
    tree = {"water": {"current": {"velocity_mps": [0.0, 0.5]}}, "vessels": [{"id": "a"}]}
    assert flatten(tree) == {"water.current.velocity_mps": [0.0, 0.5], "vessels.0.id": "a"}


def test_the_name_and_the_settings_timeline_are_not_fields_of_a_sweep() -> None:
    keys = flat_fields(scenario(settings=[{"t_s": 1.0, "key": "rain", "value": 5}]))
    assert not any(k == "name" or k.startswith("settings") for k in keys)
    assert keys["vessels.0.id"] == "ego" and keys["seed"] == 0


def test_differences_give_the_other_runs_values() -> None:
    first, other = scenario(), scenario(seed=3, rain={"rate_mm_h": 25.0})
    assert differences(first, other) == {"rain.rate_mm_h": 25.0, "seed": 3}
    assert differences(first, scenario(name="renamed")) == {}


def test_swept_fields_count_a_field_any_run_changes() -> None:
    runs = [scenario(), scenario(seed=2), scenario(rain={"rate_mm_h": 5.0})]
    assert swept_fields(runs) == ["rain.rate_mm_h", "seed"]
    assert swept_fields(runs[:1]) == []
    two = scenario(vessels=[{"id": "ego"}, {"id": "b", "pose": {"x_m": 9.0, "y_m": 0.0}}])
    assert "vessels.1.id" in swept_fields([two, scenario()])  # a field only the first has


def test_runs_a_few_fields_apart_are_one_scenario_whatever_their_names() -> None:
    """A sweep names each run (`--set name=gain2`): still one scenario's runs."""
    assert one_scenario(scenario(), scenario(name="gain2", seed=5))
    other = scenario(name="other", vessels=[{"id": f"v{k}"} for k in range(3)])
    assert not one_scenario(scenario(), other) and one_scenario(scenario(), scenario(seed=9))
