"""What `catabot` refuses before anything starts, with one line naming why (exit 2): a
script that does not fit its vessel's thrusters or gives one time two steps, a controller's
missing program (validate says what run would), an output file in a folder that is not
there, an endpoint nobody listens on or that cannot be listened on."""

from __future__ import annotations

import json
import math
import socket
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from catabot.config.vessel import BUNDLED_DIR as BUNDLED_VESSELS
from catabot.config.vessel import bundled_vessel_names
from catabot.run.cli import main
from catabot.run.launcher import RunOptions, prepare
from catabot.run.service import service_parser


def _scenario(folder: Path, **vessel: Any) -> str:
    data = {"name": "refused", "duration_s": 1.0, "vessels": [{"id": "ego", **vessel}]}
    path = folder / "refused.json"
    path.write_text(json.dumps(data))
    return str(path)


def _both_refuse(path: str, out: Path, capsys: pytest.CaptureFixture[str]) -> str:
    """validate and run both exit 2 with the same line, and run makes no run folder."""
    errs = []
    for argv in (["scenario", "validate", path], ["run", path, "--out", str(out)]):
        assert main(argv) == 2
        errs.append(capsys.readouterr().err.split(": ", 1)[1])
    assert errs[0] == errs[1] and "Traceback" not in errs[0]
    assert not out.exists()
    return errs[0]


def test_a_thrust_step_needs_one_value_per_thruster(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = [{"t_s": 0.0, "thrust": [0.5, 0.5]}, {"t_s": 2.0, "thrust": [0.5]}]
    err = _both_refuse(_scenario(tmp_path, script=script), tmp_path / "runs", capsys)
    assert "vessels.0.script.1.thrust: 1 value(s), but model 'catabot' has 2 thruster(s)" in err


def test_two_script_steps_at_one_time_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = [{"t_s": 2.0, "thrust": [0.5, 0.5]}, {"t_s": 0.0, "thrust": [1.0, 1.0]},
              {"t_s": 2.0, "twist": {"surge_mps": 1.0, "yaw_rate_radps": 0.0}}]  # fmt: skip
    err = _both_refuse(_scenario(tmp_path, script=script), tmp_path / "runs", capsys)
    assert "vessels.0.script.2.t_s: step 0 is also at 2 s; give each time one step" in err


def test_a_flag_that_breaks_the_scenario_is_named_with_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    assert main(["run", path, "--duration", "1.005", "--out", str(tmp_path / "runs")]) == 2
    err = capsys.readouterr().err
    assert f"scenario {path} with --duration 1.005: duration_s: 1.005 s is not a whole" in err
    assert main(["run", path, "--seed", "-3", "--duration", "1", "--out", str(tmp_path)]) == 2
    said = f"scenario {path} with --duration 1 --seed -3: seed: must be >= 0 (got -3)"
    assert said in capsys.readouterr().err


def test_validate_refuses_a_missing_program_as_run_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    controller = {"participant": "stack", "rate_hz": 10.0, "program": "nope.py"}
    err = _both_refuse(_scenario(tmp_path, controller=controller), tmp_path / "runs", capsys)
    assert "vessels.0.controller.program: 'nope.py' is not a file" in err


@pytest.mark.parametrize(
    ("argv", "why"),
    [
        (["scenario", "schema", "-o", "{missing}/s.json"], "folder {missing} does not exist"),
        (["scenario", "schema", "-o", "{tmp}"], "is a folder; give a file name"),
        (["scenario", "generate", "-o", "{missing}/g.json"], "folder {missing} does not exist"),
    ],
)
def test_an_output_file_that_cannot_be_written_is_refused_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], why: str
) -> None:
    names = {"missing": str(tmp_path / "no" / "such"), "tmp": str(tmp_path)}
    assert main([a.format(**names) for a in argv]) == 2
    err = capsys.readouterr().err
    assert why.format(**names) in err and "Traceback" not in err


def test_the_schema_is_written_where_asked(tmp_path: Path) -> None:
    assert main(["scenario", "schema", "-o", str(tmp_path / "s.json")]) == 0
    assert json.loads((tmp_path / "s.json").read_text())["title"] == "CataBot scenario"


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_a_router_that_does_not_answer_is_refused_before_any_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    endpoint = f"tcp/127.0.0.1:{_closed_port()}"
    assert main(["run", "--duration", "1", "--connect", endpoint, "--out", str(tmp_path)]) == 2
    assert f"nothing answers at {endpoint}" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_a_listen_port_in_use_is_refused_before_any_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        endpoint = f"tcp/127.0.0.1:{taken.getsockname()[1]}"
        assert main(["run", "--duration", "1", "--listen", endpoint, "--out", str(tmp_path)]) == 2
    assert f"cannot listen on {endpoint}: Address already in use" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_validate_checks_a_sweeps_changes_before_any_run(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A sweep's grid, checked whole before its first run starts."""
    assert main(["scenario", "validate", "--set", "seed=3", "--set", "name=lab3"]) == 0
    assert main(["scenario", "validate", "--set", "water.current=3"]) == 2
    assert "with --set water.current=3: water.current: must be an object" in capsys.readouterr().err


def test_validate_notes_a_participant_given_two_vessels(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Allowed (a stack on the bus may drive both), but a catabot.client stack cannot join
    it: validate said "valid" and the run waited out its start timeout."""
    stack = {"participant": "pair", "rate_hz": 10.0}
    vessels = [{"id": "a", "controller": stack},
               {"id": "b", "pose": {"x_m": 20.0, "y_m": 0.0}, "controller": stack}]  # fmt: skip
    path = tmp_path / "pair.json"
    path.write_text(json.dumps({"name": "pair", "vessels": vessels}))
    assert main(["scenario", "validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "valid" in out and "note: participant 'pair' controls vessels a, b: a " in out


def test_validate_notes_a_field_of_view_that_looks_like_radians(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial user's `hfov_deg: 1.5708` (a 90-degree camera in radians) validated silently
    as a 1.6-degree one; a 60-degree camera is not noted."""
    cams = [{"name": n, "type": "camera", "rate_hz": 10.0, "params": {"hfov_deg": fov}}
            for n, fov in (("tele", 1.5708), ("wide", 60.0))]  # fmt: skip
    path = tmp_path / "cams.json"
    path.write_text(json.dumps({"name": "cams", "vessels": [{"id": "ego", "sensors": cams}]}))
    assert main(["scenario", "validate", str(path)]) == 0
    notes = [line for line in capsys.readouterr().out.splitlines() if line.startswith("note")]
    assert notes == ["note: vessels.0.sensors.0.params.hfov_deg (ego/tele) is 1.5708 degrees; "
                     "if it is radians, that is 90 degrees: give that"]  # fmt: skip


def test_the_vessel_model_schema_checks_every_bundled_model(tmp_path: Path) -> None:
    assert main(["scenario", "model-schema", "-o", str(tmp_path / "m.json")]) == 0
    schema = json.loads((tmp_path / "m.json").read_text())
    assert schema["title"] == "CataBot vessel model"
    for name in bundled_vessel_names():
        jsonschema.validate(json.loads((BUNDLED_VESSELS / f"{name}.json").read_text()), schema)
    with pytest.raises(jsonschema.ValidationError, match="mass_kg"):
        jsonschema.validate({"name": "x", "hulls": []}, schema)
    shape = {"mesh": {"file": "boat.obj", "scale": 0.01}}  # the README's: one factor
    model = json.loads((BUNDLED_VESSELS / "catabot.json").read_text()) | {"shape": shape}
    jsonschema.validate(model, schema)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(model | {"shape": {"mesh": {"file": "b.obj", "scale": [1, 2]}}}, schema)


def test_validate_checks_a_vessel_model_file_as_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A model file given to `validate` was read as a scenario: 15 unknown fields."""
    assert main(["scenario", "validate", str(BUNDLED_VESSELS / "wamv.json")]) == 0
    assert (
        "a valid vessel model 'wamv' (211 kg, 2 hull(s), 2 thruster(s))" in capsys.readouterr().out
    )
    heavy = json.loads((BUNDLED_VESSELS / "catabot.json").read_text()) | {"mass_kg": 400.0}
    (tmp_path / "heavy.json").write_text(json.dumps(heavy))
    assert main(["scenario", "validate", str(tmp_path / "heavy.json")]) == 2
    assert "cannot float: its mass 400 kg" in capsys.readouterr().err
    typo = {k: v for k, v in heavy.items() if k != "damping"} | {"dampng": heavy["damping"]}
    (tmp_path / "typo.json").write_text(json.dumps(typo))
    assert main(["scenario", "validate", str(tmp_path / "typo.json")]) == 2
    assert "damping: required field missing; dampng: unknown field" in capsys.readouterr().err
    hull = {k: v for k, v in heavy.items() if k != "hulls"} | {"hull": heavy["hulls"]}
    (tmp_path / "hull.json").write_text(json.dumps(hull))  # no `hulls`: still a model
    assert main(["scenario", "validate", str(tmp_path / "hull.json")]) == 2
    assert "hulls: required field missing; hull: unknown field" in capsys.readouterr().err


def test_realtime_zero_undoes_a_files_pace_and_a_negative_one_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--realtime 0` (or inf) is as fast as possible, the default a scenario's
    clock.realtime_factor replaces: it was refused as not > 0."""
    data = {"name": "paced", "duration_s": 1.0, "clock": {"realtime_factor": 1.0},
            "vessels": [{"id": "ego"}]}  # fmt: skip
    path = tmp_path / "paced.json"
    path.write_text(json.dumps(data))
    for fast in (0.0, math.inf):
        world = prepare(RunOptions(scenario=str(path), realtime=fast))
        assert world.scenario.clock.realtime_factor is None
    assert prepare(RunOptions(scenario=str(path), realtime=4.0)).scenario.clock.realtime_factor == 4
    assert main(["run", str(path), "--realtime", "-1", "--out", str(tmp_path)]) == 2
    said = "catabot run: --realtime -1: a pace is 0 or more (1: the wall clock, 0: as fast as"
    assert said in capsys.readouterr().err  # it said "must be > 0", while 0 is taken


def test_a_service_without_a_run_dir_records_under_runs_not_where_it_was_started() -> None:
    """`catabot service recorder` without --run-dir wrote its CSVs and MCAP into the current
    folder, whatever it was."""
    args = service_parser("recorder").parse_args(["--scenario", "harbour"])
    assert args.run_dir is None  # resolved against the scenario: runs/<its name>
    assert "runs/<the scenario's name>" in service_parser("recorder").format_help()


def test_validate_takes_run_s_seed_and_duration_and_refuses_what_run_refuses(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A sweep script validated `--seed 3 --set seed=4` (valid) and then ran it (refused):
    validate had ignored --seed, a flag it shares with `scenario generate`."""
    assert main(["scenario", "validate", "--seed", "3", "--set", "seed=4"]) == 2
    assert "seed is given by --seed too" in capsys.readouterr().err
    assert main(["scenario", "validate", "--duration", "5"]) == 0
    assert "500 ticks" in capsys.readouterr().out
    assert main(["scenario", "validate", "--boats", "5", "--name", "x"]) == 2
    said = "catabot scenario validate: --boats, --name: only for `scenario generate`\n"
    assert capsys.readouterr().err == said
