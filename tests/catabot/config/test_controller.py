"""A controller's program: where its file is found, and the names and args it may have."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import load_scenario, parse_scenario


def _data(*controllers: dict[str, Any]) -> dict[str, Any]:
    vessels = [{"id": f"v{i}", "controller": c} for i, c in enumerate(controllers)]
    return {"vessels": vessels}


def _write(folder: Path, data: dict[str, Any]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "scenario.json").write_text(json.dumps(data))
    return folder / "scenario.json"


def test_the_program_is_found_next_to_the_scenario_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for folder in (tmp_path / "scen", tmp_path / "cwd"):
        folder.mkdir()
        (folder / "stack.py").write_text("")
    monkeypatch.chdir(tmp_path / "cwd")
    path = _write(tmp_path / "scen", _data({"participant": "s", "program": "stack.py"}))
    controller = load_scenario(path).vessels[0].controller
    assert controller is not None and controller.program == str(tmp_path / "scen" / "stack.py")


def test_then_in_the_current_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "cwd" / "examples").mkdir(parents=True)
    (tmp_path / "cwd" / "examples" / "nav.py").write_text("")
    monkeypatch.chdir(tmp_path / "cwd")
    path = _write(tmp_path / "scen", _data({"participant": "s", "program": "examples/nav.py"}))
    controller = load_scenario(path).vessels[0].controller
    assert controller is not None
    assert controller.program == str(tmp_path / "cwd" / "examples" / "nav.py")


def test_a_program_found_nowhere_is_left_as_written(tmp_path: Path) -> None:
    path = _write(tmp_path, _data({"participant": "s", "program": "gone.py", "args": ["-v"]}))
    controller = load_scenario(path).vessels[0].controller
    assert controller is not None and controller.program == "gone.py"
    assert controller.args == ["-v"]


@pytest.mark.parametrize(
    ("controllers", "message"),
    [
        ([{"participant": "s", "args": ["-v"]}], "vessels.0.controller.args: needs a program"),
        ([{"participant": "physics", "program": "a.py"}], "vessels.0.controller: participant "
         "'physics' is a CataBot process's name"),
        ([{"participant": "s", "program": "a.py"}, {"participant": "s", "program": "b.py"}],
         "vessels.1.controller: participant 's' is named with another program"),
        ([{"participant": "s", "program": "a.py"}, {"participant": "s"}],
         "vessels.1.controller: participant 's' is named with another program"),
        ([{"participant": "s", "program": ""}], "vessels.0.controller.program"),
        ([{"participant": "physics"}], "vessels.0.controller: participant 'physics' is a "
         "CataBot process's name"),  # without a program: physics waited for its own commands
        ([{"participant": "sensors.1"}], "participant 'sensors.1' is a CataBot process's name"),
    ],
)  # fmt: skip
def test_bad_controller_programs_are_named(controllers: list[dict[str, Any]], message: str) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(_data(*controllers))
    assert message in str(info.value)


def test_one_program_may_drive_several_vessels() -> None:
    same = {"participant": "s", "program": "a.py", "args": ["x"]}
    scenario = parse_scenario(_data(same, same))
    assert [v.controller.program for v in scenario.vessels if v.controller] == ["a.py", "a.py"]


@pytest.mark.parametrize(
    ("names", "message"),
    [
        (["s", "s"], "clock.external_participants: each name once (got ['s', 's'])"),
        (["recorder"], "clock.external_participants: 'recorder' is a CataBot process's name"),
    ],
)
def test_external_participants_are_named_once_and_not_as_a_service(
    names: list[str], message: str
) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario({"clock": {"external_participants": names}, "vessels": [{"id": "ego"}]})
    assert message in str(info.value)


def test_numbers_in_args_are_taken_as_their_text() -> None:
    """A sweep over a gain wrote ["--gain", 2]: refused as "must be a string"."""
    program = {"participant": "s", "program": "x.py", "args": ["--gain", 2, 0.5]}
    scenario = parse_scenario({"vessels": [{"id": "ego", "controller": program}]})
    assert scenario.vessels[0].controller is not None
    assert scenario.vessels[0].controller.args == ["--gain", "2", "0.5"]
    with pytest.raises(ScenarioError, match="must be a string"):
        parse_scenario({"vessels": [{"id": "ego", "controller": {**program, "args": [True]}}]})
