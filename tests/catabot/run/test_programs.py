"""A controller's program as `catabot run` starts it: found, refused, its command line."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from catabot.config.load import load_scenario
from catabot.run import programs
from catabot.run.launcher import LaunchError, RunOptions, prepare


def _scenario(folder: Path, program: str, *args: str) -> Path:
    controller = {"participant": "stack", "program": program, "args": list(args)}
    data = {"name": "w", "vessels": [{"id": "ego", "controller": controller}]}
    (folder / "s.json").write_text(json.dumps(data))
    return folder / "s.json"


def test_the_command_line_carries_the_run_flags_then_the_programs_args(tmp_path: Path) -> None:
    (tmp_path / "stack.py").write_text("")
    path = _scenario(tmp_path, "stack.py", "--goal", "4", "2")
    (found,) = programs.programs(load_scenario(path), str(path))
    flags = ["--connect", "tcp/127.0.0.1:7447", "--zid", "abc"]
    assert programs.command(found, "w", flags) == [
        sys.executable, str(tmp_path / "stack.py"), *flags, "--world", "w", "--vessel", "ego",
        "--participant", "stack", "--goal", "4", "2",
    ]  # fmt: skip
    env = programs.environment(tmp_path / "run")
    assert env["CATABOT_SCENARIO"] == str(tmp_path / "run" / "scenario.json")


def test_a_missing_program_names_the_field_and_where_it_looked(tmp_path: Path) -> None:
    path = _scenario(tmp_path, "nowhere.py")
    with pytest.raises(programs.ProgramError) as info:
        prepare(RunOptions(scenario=str(path)))
    assert str(info.value).startswith("vessels.0.controller.program: 'nowhere.py' is not a file")
    assert str(tmp_path) in str(info.value)


def test_the_secure_profile_needs_a_login_for_the_program(tmp_path: Path) -> None:
    (tmp_path / "stack.py").write_text("")
    logins = tmp_path / "secure"
    logins.mkdir()
    for name in ("conductor", "physics", "recorder"):
        (logins / f"{name}.json5").write_text("{}")
    with pytest.raises(LaunchError, match=r"no login for stack .*--client NAME"):
        prepare(RunOptions(scenario=str(_scenario(tmp_path, "stack.py")), zenoh_configs=logins))
