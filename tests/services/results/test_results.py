"""`catabot results`: a sweep's runs in one table, from hand-made run folders (the files
`catabot run` writes: scenario.json, log/run.json, metrics.json)."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from services.results import cli

GOAL = {"reached": True, "time_to_goal_s": 12.5, "path_length_m": 31.0, "final_distance_m": 1.0}


def vessel(**more: Any) -> dict[str, Any]:
    near = {"distance_m": 8.0, "id": "b"}
    base = {"distance_m": 31.0, "max_speed_mps": 2.0, "collisions": 0, "groundings": 0,
            "thrust_impulse_Ns": 400.0, "nearest_vessel": near}  # fmt: skip
    return base | more


def make_run(
    folder: Path,
    *,
    gain: float = 1.0,
    seed: int = 1,
    metrics: bool = True,
    reason: str = "completed",
) -> Path:
    (folder / "log").mkdir(parents=True)
    other = {"id": "b", "pose": {"x_m": 20.0, "y_m": 0.0}}
    scenario = {"name": "sweep", "seed": seed, "rain": {"rate_mm_h": gain},
                "vessels": [{"id": "ego"}, other]}  # fmt: skip
    (folder / "scenario.json").write_text(json.dumps(scenario))
    run = {"reason": reason, "error": "" if reason == "completed" else "stack crashed",
           "sim_s": 20.0, "wall_s": 4.0}  # fmt: skip
    (folder / "log" / "run.json").write_text(json.dumps(run))
    if metrics:
        boats = {"boat_000": {"distance_m": 9.0, "max_speed_mps": 1.0}}  # traffic: no row
        vessels = {"ego": vessel(goal=GOAL), "b": vessel(collisions=1), **boats}
        record = {"end_reason": reason, "vessels": vessels, "traffic_collisions": [],
                  "closest_approach": {"distance_m": 8.0, "vessels": ["b", "ego"]}}  # fmt: skip
        (folder / "metrics.json").write_text(json.dumps(record))
    return folder


@pytest.fixture
def sweep(tmp_path: Path) -> Path:
    make_run(tmp_path / "sweep" / "sweep-1", gain=0.0)
    make_run(tmp_path / "sweep" / "sweep-2", gain=25.0)
    make_run(tmp_path / "sweep" / "sweep-3", gain=25.0, seed=2, metrics=False, reason="fault")
    (tmp_path / "sweep" / "notes").mkdir()  # not a run: passed over
    return tmp_path / "sweep"


def test_a_folder_of_runs_is_a_row_per_run_and_scenario_vessel(
    sweep: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert cli.main([str(sweep), "--csv", str(sweep / "table.csv")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].split() == ["run", "vessel", "rain.rate_mm_h", "seed", "reason", "goal_reached",
                              "time_to_goal_s", "nearest_vessel_m", "collisions", "groundings",
                              "thrust_impulse_Ns"]  # fmt: skip
    assert out[1].split() == ["sweep-1", "ego", "0.0", "1", "completed", "yes", "12.50", "8.00",
                              "0", "0", "400.00"]  # fmt: skip
    assert out[3].split()[:3] == ["sweep-2", "ego", "25.0"]
    assert out[5].split() == ["sweep-3", "-", "25.0", "2", "fault", *["-"] * 6]  # not measured
    assert out[-1] == f"3 runs, 5 rows; every column in {sweep / 'table.csv'}"


def test_the_csv_has_every_column_and_pandas_reads_numbers_as_numbers(sweep: Path) -> None:
    assert cli.main([str(sweep), "--csv", str(sweep / "table.csv")]) == 0
    table = pd.read_csv(sweep / "table.csv")
    assert len(table) == 5 and list(table["vessel"].fillna("-")) == ["ego", "b", "ego", "b", "-"]
    for column in ("rain.rate_mm_h", "sim_s", "wall_s", "time_to_goal_s", "nearest_vessel_m"):
        assert table[column].dtype == "float64", column
    assert table["error"].fillna("").tolist() == ["", "", "", "", "stack crashed"]
    assert table["closest_approach_m"].tolist()[:4] == [8.0] * 4
    assert table.loc[1, "collisions"] == 1 and table.loc[0, "goal_reached"]


def test_csv_dash_is_the_csv_on_stdout(
    sweep: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """It wrote a file named "-"; now a pipe gets the CSV alone, the count on stderr."""
    monkeypatch.chdir(sweep)
    assert cli.main([str(sweep), "--csv", "-"]) == 0
    said = capsys.readouterr()
    table = pd.read_csv(io.StringIO(said.out))
    assert len(table) == 5 and "time_to_goal_s" in table.columns
    assert said.err == "3 runs, 5 rows\n" and not (sweep / "-").exists()


def test_runs_of_two_code_versions_are_said_and_the_csv_says_which(
    sweep: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial's sweep spanned a commit, and nothing in the table or the CSV told."""
    for name, commit in (("sweep-1", "d9b360c0ffee+dirty"), ("sweep-2", "e3863f0c0ffee")):
        path = sweep / name / "log" / "run.json"
        path.write_text(json.dumps(json.loads(path.read_text()) | {"git_commit": commit}))
    assert cli.main([str(sweep), "--csv", str(sweep / "t.csv")]) == 0
    err = capsys.readouterr().err
    assert "runs of 3 versions of the code (None, d9b360c0ffee, e3863f0c0ffe)" in err
    commits = pd.read_csv(sweep / "t.csv")["git_commit"].fillna("").tolist()
    assert commits == ["d9b360c0ffee+dirty"] * 2 + ["e3863f0c0ffee"] * 2 + [""]


def test_runs_named_one_by_one_keep_their_order_and_count_once(
    sweep: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    runs = [str(sweep / "sweep-2"), str(sweep), str(sweep / "sweep-2")]
    assert cli.main(runs) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines[1:-1]] == ["sweep-2"] * 2 + ["sweep-1"] * 2 + [
        "sweep-3"
    ]
    assert lines[-1] == "3 runs, 5 rows"


def test_runs_that_differ_in_nothing_have_no_swept_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    make_run(tmp_path / "a")
    make_run(tmp_path / "b")
    assert cli.main([str(tmp_path / "a"), str(tmp_path / "b")]) == 0
    assert capsys.readouterr().out.split()[2] == "seed"


@pytest.mark.parametrize(
    ("make", "said"),
    [
        (lambda p: p / "missing", "no such folder"),
        (lambda p: (p / "f.txt").write_text("x") and p / "f.txt", "a file; give a run folder"),
        (
            lambda p: (p / "empty").mkdir() or p / "empty",
            "not a run folder (it has no scenario.json), and no run folder",
        ),
    ],
)
def test_what_is_not_a_run_is_named_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], make: Any, said: str
) -> None:
    assert cli.main([str(make(tmp_path))]) == 2
    err = capsys.readouterr().err
    assert err.startswith("catabot results: ") and said in err and len(err.splitlines()) == 1


def test_a_run_whose_scenario_does_not_read_is_left_out_and_named(
    sweep: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (sweep / "sweep-2" / "scenario.json").write_text('{"name": "x", "duration_s": -1}')
    assert cli.main([str(sweep)]) == 0
    captured = capsys.readouterr()
    assert "left out " + str(sweep / "sweep-2") in captured.err
    assert captured.out.splitlines()[-1] == "2 runs, 3 rows"
    for run in ("sweep-1", "sweep-3"):
        (sweep / run / "scenario.json").write_text("not json")
    assert cli.main([str(sweep)]) == 2
    assert "no run to tabulate" in capsys.readouterr().err


def test_an_unwritable_csv_is_refused_before_any_run_is_read(
    sweep: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (sweep / "sweep-1" / "scenario.json").write_text("not json")  # would be named if read
    assert cli.main([str(sweep), "--csv", str(sweep / "no" / "t.csv")]) == 2
    csv = sweep / "no" / "t.csv"
    said = f"catabot results: --csv {csv}: folder {csv.parent} does not exist\n"
    assert capsys.readouterr().err == said


def test_one_run_reads_in_the_singular_and_its_unmeasured_thrust_is_a_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A vessel under velocity control has no thrust impulse for that time: 0 alone read as
    a real zero in pandas (metrics.json's thrust_unknown_s says how long)."""
    run = make_run(tmp_path / "one")
    record = json.loads((run / "metrics.json").read_text())
    record["vessels"]["ego"] |= {"thrust_impulse_Ns": 0.0, "thrust_unknown_s": 19.99}
    (run / "metrics.json").write_text(json.dumps(record))
    assert cli.main([str(run), "--csv", str(tmp_path / "t.csv")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[-2:] == ["thrust_impulse_Ns", "thrust_unknown_s"]
    assert lines[1].split()[-2:] == ["0.00", "19.99"] and lines[2].split()[-1] == "-"
    assert lines[-1] == f"1 run, 2 rows; every column in {tmp_path / 't.csv'}"
    assert pd.read_csv(tmp_path / "t.csv")["thrust_unknown_s"].tolist()[0] == 19.99


def test_runs_of_different_scenarios_are_said_to_be(
    sweep: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = json.loads((sweep / "sweep-2" / "scenario.json").read_text())
    (sweep / "sweep-2" / "scenario.json").write_text(json.dumps(data | {"name": "gain2"}))
    assert cli.main([str(sweep)]) == 0  # a sweep that names its runs (--set name=gain2)
    assert "scenarios" not in capsys.readouterr().err
    sensors = [{"name": f"s{k}", "type": "imu", "rate_hz": 50.0} for k in range(4)]
    other = {"name": "other", "duration_s": 9.0, "rain": {"rate_mm_h": 3.0},
             "vessels": [{"id": "ego", "model": "wamv", "sensors": sensors}]}  # fmt: skip
    (sweep / "sweep-2" / "scenario.json").write_text(json.dumps(other))
    assert cli.main([str(sweep)]) == 0
    assert "runs of 2 scenarios (other, sweep)" in capsys.readouterr().err


def test_a_swept_list_is_a_numeric_column_per_item_that_differs(tmp_path: Path) -> None:
    """A sweep over the current's north component needed json.loads of "[0.0, 0.3]"."""
    for k, north in enumerate((0.0, 0.3, 0.6)):
        run = make_run(tmp_path / "sweep" / f"run-{k}")
        data = json.loads((run / "scenario.json").read_text())
        data["water"] = {"current": {"velocity_mps": [0.5, north]}}
        (run / "scenario.json").write_text(json.dumps(data))
    assert cli.main([str(tmp_path / "sweep"), "--csv", str(tmp_path / "t.csv")]) == 0
    table = pd.read_csv(tmp_path / "t.csv")
    assert "water.current.velocity_mps" not in table and "water.current.velocity_mps.0" not in table
    assert table["water.current.velocity_mps.1"].tolist() == [0.0, 0.0, 0.3, 0.3, 0.6, 0.6]


def test_a_sweep_over_the_timeline_has_its_column(tmp_path: Path) -> None:
    """Two onsets of a current looked like repeats of one run: no column told them apart."""
    for k, onset in enumerate((2.0, 6.0)):
        run = make_run(tmp_path / "onset" / f"run-{k}")
        data = json.loads((run / "scenario.json").read_text())
        data["settings"] = [{"t_s": onset, "key": "current", "value": [0.0, 0.5]}]
        (run / "scenario.json").write_text(json.dumps(data))
    assert cli.main([str(tmp_path / "onset"), "--csv", str(tmp_path / "t.csv")]) == 0
    settings = pd.read_csv(tmp_path / "t.csv")["settings"].tolist()
    assert settings == ["current=[0.0, 0.5] at 2 s"] * 2 + ["current=[0.0, 0.5] at 6 s"] * 2


def test_runs_from_two_folders_are_named_by_their_folder(tmp_path: Path) -> None:
    """`catabot results tl live` had two rows named `a`."""
    for where in ("tl", "live"):
        make_run(tmp_path / where / "a")
    assert cli.main([str(tmp_path / "tl"), str(tmp_path / "live"), "--csv",
                     str(tmp_path / "t.csv")]) == 0  # fmt: skip
    assert set(pd.read_csv(tmp_path / "t.csv")["run"]) == {"tl/a", "live/a"}


def test_one_folder_spelled_two_ways_counts_once(tmp_path: Path) -> None:
    make_run(tmp_path / "tl" / "a")
    twice = [str(tmp_path / "tl"), str(tmp_path / "tl" / ".." / "tl")]
    assert cli.main([*twice, "--csv", str(tmp_path / "t.csv")]) == 0
    assert pd.read_csv(tmp_path / "t.csv")["run"].tolist() == ["a", "a"]  # ego and b, once
