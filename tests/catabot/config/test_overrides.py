"""`catabot run --set FIELD=VALUE`: one scenario field changed for one run, checked as the file
is, and every mistake named with the flag that made it."""

from __future__ import annotations

import copy
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.overrides import OverrideError
from catabot.config.overrides import apply as apply_to
from catabot.run.launcher import RunOptions, prepare


def apply(data: dict[str, Any], items: list[str], **kw: Any) -> list[str]:
    """A file's data whose resolved form has the same shape (these tests' own)."""
    return apply_to(data, items, resolved=copy.deepcopy(data), **kw)


def test_fields_lists_and_bare_words_are_set_in_order() -> None:
    data = {"name": "x", "water": {"current": {"velocity_mps": [0.0, 0.0]}},
            "vessels": [{"id": "ego", "controller": {"args": []}}]}  # fmt: skip
    flags = apply(data, ["water.current.velocity_mps=[0.5, 0]", "name=lab3",
                         'vessels.0.controller.args=["--gain", "2"]', "name=lab4"])  # fmt: skip
    assert data["water"]["current"]["velocity_mps"] == [0.5, 0]
    assert data["name"] == "lab4" and data["vessels"][0]["controller"]["args"] == ["--gain", "2"]
    assert flags[0] == "--set water.current.velocity_mps=[0.5, 0]" and len(flags) == 4


@pytest.mark.parametrize(
    ("item", "said"),
    [
        ("water.curent=1", "no field water.curent (did you mean 'current'?)"),
        ("zzz=1", "no field zzz (its fields: name, vessels, water)"),
        ("water.current.velocity_mps=[0.5", "the value is not JSON (Expecting ',' delimiter"),
        ("vessels.3.id=x", "vessels.3: a list of 1, so an index from 0 to 0"),
        ("vessels.ego.id=x", "a list of 1, so an index from 0 to 0: 'ego' is vessels.0"),
        ("vessels.0.task.goal=1", "vessels.0.task is not set in the scenario: set it whole"),
        ("name.first=x", "name is a value, not a section"),
        ("seed", "give FIELD=VALUE"),
        ("=3", "give FIELD=VALUE"),
    ],
)
def test_a_mistake_is_named_with_its_flag(item: str, said: str) -> None:
    data = {"name": "x", "water": {"current": {"velocity_mps": [0.0, 0.0]}},
            "vessels": [{"id": "ego", "task": None}]}  # fmt: skip
    with pytest.raises(OverrideError) as err:
        apply(data, [item])
    assert str(err.value).startswith((f"--set {item!r}: ", f"--set {item}: "))
    assert said in str(err.value)


def test_a_string_field_takes_the_text_as_it_is() -> None:
    """A run named after a swept value: `name=2024-lab` had been malformed JSON, `name=0.5`
    a number where a string belongs."""
    data = {"name": "x", "seed": 0}
    apply(data, ["name=2024-lab"])
    assert data["name"] == "2024-lab"
    apply(data, ["name=0.5", "seed=7"])
    assert data == {"name": "0.5", "seed": 7}


def test_a_field_its_own_flag_gives_is_refused() -> None:
    with pytest.raises(OverrideError, match=r"--set seed=3: seed is given by --seed too"):
        apply({"seed": 0}, ["seed=3"], flagged={"seed": "--seed"})
    with pytest.raises(OverrideError, match=r"--duration too"):
        prepare(RunOptions(duration_s=2.0, sets=("duration_s=3",)))


def test_a_preset_set_fills_what_the_file_left_to_it() -> None:
    """`--set water.waves.preset=medium` gave flat water (the resolved calm sea's height,
    filled in, beat the preset) while scenario.json and the report said "medium"."""
    waves = prepare(RunOptions(sets=("water.waves.preset=medium",))).scenario.water.waves
    assert (waves.preset, waves.significant_height_m) == ("medium", 1.24)
    task = ('vessels.0.task={"route": [[0, 0], [30, 5]]}', "vessels.0.task.route.1.0=40")
    route = prepare(RunOptions(sets=task)).scenario.vessels[0].task
    assert route is not None and route.route is not None and list(route.route[1]) == [40.0, 5.0]


def test_a_run_takes_the_changed_scenario_and_checks_it_whole() -> None:
    world = prepare(RunOptions(sets=("water.current.velocity_mps=[0.5,0]", "name=lab3")))
    assert world.scenario.name == "lab3"
    assert world.scenario.water.current.velocity_mps == (0.5, 0.0)
    with pytest.raises(ScenarioError, match=r"with --set water\.current=fast: water\.current"):
        prepare(RunOptions(sets=("water.current=fast",)))


def test_a_sensor_param_the_file_left_to_its_default_can_be_set() -> None:
    """A radar sweep over range_m was refused ("its fields: ") unless the file listed it:
    params hold only what the file gave; the sensor type's model checks the key."""
    radar = {"name": "radar", "type": "radar", "rate_hz": 10.0, "params": {}}
    camera = {"name": "cam", "type": "camera", "rate_hz": 10.0, "params": {}}
    data = {"vessels": [{"id": "ego", "sensors": [radar, camera]}]}
    apply(data, ["vessels.0.sensors.0.params.range_m=300",
                 "vessels.0.sensors.1.params.outputs.depth=false"])  # fmt: skip
    assert data["vessels"][0]["sensors"][0]["params"] == {"range_m": 300}
    assert data["vessels"][0]["sensors"][1]["params"] == {"outputs": {"depth": False}}
    gps = prepare(RunOptions(sets=("vessels.0.sensors.1.params.horizontal_sigma=2.5",)))
    assert gps.scenario.vessels[0].sensors[1].typed_params().horizontal_sigma == 2.5
    with pytest.raises(ScenarioError, match=r"params\.horizontal_sigm: unknown field \(allowed"):
        prepare(RunOptions(sets=("vessels.0.sensors.1.params.horizontal_sigm=1",)))
