"""`catabot run --set FIELD=VALUE`: one scenario field changed for one run, checked as the file
is, and every mistake named with the flag that made it."""

from __future__ import annotations

import pytest

from catabot.config.base import ScenarioError
from catabot.config.overrides import OverrideError, apply
from catabot.run.launcher import RunOptions, prepare


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


def test_a_run_takes_the_changed_scenario_and_checks_it_whole() -> None:
    world = prepare(RunOptions(sets=("water.current.velocity_mps=[0.5,0]", "name=lab3")))
    assert world.scenario.name == "lab3"
    assert world.scenario.water.current.velocity_mps == (0.5, 0.0)
    with pytest.raises(ScenarioError, match=r"with --set water\.current=fast: water\.current"):
        prepare(RunOptions(sets=("water.current=fast",)))
