"""A table of bad scenarios, one or two per config section: `catabot run` refuses each before
anything starts, with exit 2, the field named and no traceback; `scenario validate` agrees."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from conftest import catabot, in_process

from catabot.run.cli import main
from tests.paths import BAY

VESSEL = {"id": "ego"}


def scenario(**top: Any) -> dict[str, Any]:
    return {"name": "bad", "duration_s": 1.0, "vessels": [VESSEL], **top}


def vessel(**fields: Any) -> dict[str, Any]:
    return scenario(vessels=[{"id": "ego", **fields}])


def sensor(type_: str, **fields: Any) -> dict[str, Any]:
    return vessel(sensors=[{"name": "s", "type": type_, "rate_hz": 10.0, **fields}])


CASES: list[tuple[str, Any, str]] = [
    ("seed negative", scenario(seed=-3), "seed: must be >= 0"),
    ("seed too big", scenario(seed=2**63), "seed: must be <"),
    ("seed not integer", scenario(seed=3.5), "seed: must be an integer"),
    ("seed a string", scenario(seed="3"), "seed: must be an integer"),
    ("name with slash", scenario(name="a/b"), "world name 'a/b' is not allowed"),
    ("duration zero", scenario(duration_s=0), "duration_s: must be > 0"),
    ("duration shorter than a tick", scenario(duration_s=0.001), "duration_s:"),
    ("duration astronomical", scenario(duration_s=1e300), "duration_s: must be <= 1e+07"),
    ("dt too long", scenario(dt_ns=10**9), "dt_ns: must be <= 100000000"),
    ("name too long", scenario(name="x" * 10_000), "use 1-64 letters"),
    ("dt not integer", scenario(dt_ns=1.5), "dt_ns: must be an integer"),
    ("unknown top-level field", scenario(speed=3), "speed: unknown field"),
    ("no vessels", scenario(vessels=[]), "vessels:"),
    ("clock policy", scenario(clock={"policy": "retry"}), "clock.policy: must be one of"),
    ("clock window", scenario(clock={"window_ticks": 0}), "clock.window_ticks: must be >= 1"),
    ("clock deadline", scenario(clock={"deadline_s": -1}), "clock.deadline_s: must be > 0"),
    ("origin latitude", scenario(origin={"latitude_deg": 91}), "origin.latitude_deg: must be <="),
    ("water density", scenario(water={"density_kg_m3": 2000}), "water.density_kg_m3: must be <"),
    ("waves preset", scenario(water={"waves": {"preset": "stormy"}}), "water.waves.preset:"),
    ("waves breaking", scenario(water={"waves": {"significant_height_m": 9, "peak_period_s": 3}}),
     "significant steepness"),
    ("current map missing",
     scenario(water={"current": {"map": {"path": "nope.npy", "spacing_m": 5}}}), "nope.npy"),
    ("wind negative", scenario(wind={"speed_mps": -1}), "wind.speed_mps: must be >= 0"),
    ("rain too heavy", scenario(rain={"rate_mm_h": 80}), "rain.rate_mm_h: must be <= 50"),
    ("terrain missing", scenario(terrain={"elevation_image": "nope.png"}), "nope.png"),
    ("terrain heights", scenario(terrain={"elevation_image": str(BAY), "min_elevation_m": 5,
                                          "max_elevation_m": 1}), "max_elevation_m"),
    ("buoy id clash", scenario(buoys=[{"id": "ego", "x_m": 20, "y_m": 0}]), "'ego' is used twice"),
    ("vessel model unknown", vessel(model="submarine"), "vessels.0.model: vessel model 'submari"),
    ("vessel model file missing", vessel(model="boats/missing.json"), "missing.json"),
    ("vessel ids", scenario(vessels=[VESSEL, VESSEL]), "vessel ids must be unique"),
    ("script thrust", vessel(script=[{"t_s": 0, "thrust": [2.0, 0.0]}]),
     "script.0.thrust: commands are normalised: each in [-1, 1] (got [2.0, 0.0])"),
    ("controller rate", vessel(controller={"participant": "p", "rate_hz": 30}), "controller"),
    ("sensor type", sensor("sonar"), "unknown sensor type 'sonar'"),
    ("sensor rate", sensor("imu", rate_hz=30.0), "whole number of ticks"),
    ("sensor params", sensor("lidar", params={"channels": 0}), "channels"),
    ("camera size", sensor("camera", params={"width": 1}), "width"),
    ("camera memory", sensor("camera", params={"width": 4096, "height": 4096}),
     "needs about 3.4 GB a frame"),
    ("current too fast", scenario(water={"current": {"velocity_mps": [1e9, 0]}}),
     "at most 10 m/s"),
    ("wind too strong", scenario(wind={"speed_mps": 1e6}), "wind.speed_mps: must be <= 80"),
    ("waypoint buoys crowd", scenario(traffic={"count": 500, "behaviour_mix": {"waypoints": 1},
                                               "waypoints": {"count": 50}}), "at most 5%"),
    ("traffic count", scenario(traffic={"count": 1000}), "traffic.count: must be <= 500"),
    ("traffic behaviour", scenario(traffic={"count": 1, "behaviour_mix": {"zigzag": 1}}),
     "traffic.behaviour_mix"),
    ("traffic guidance", scenario(traffic={"count": 1, "guidance_hz": 30}), "traffic.guidance_hz"),
    ("traffic model", scenario(traffic={"count": 1, "models": [{"model": "yacht"}]}),
     "traffic.models.0.model: vessel model 'yacht'"),
    ("recording flag", scenario(recording={"csv": "yes"}), "recording.csv: must be true or false"),
    ("settings file", {"rainIntensity": 80}, "rainIntensity: must be a number in [0.0, 50.0]"),
    ("not UTF-8", b'{"name": "\xff\xfe"}', "not UTF-8 text"),
    ("nested too deeply", b"[" * 100_000 + b"]" * 100_000, "JSON nested too deeply"),
    ("not JSON", b"{vessels: []}", "not valid JSON"),
    ("a list, not an object", [VESSEL], "must be an object"),
]  # fmt: skip


def test_the_table_spans_every_config_section() -> None:
    sections = {"seed", "name", "duration_s", "dt_ns", "clock", "origin", "water", "wind",
                "rain", "terrain", "buoys", "vessels", "traffic", "recording"}  # fmt: skip
    base = scenario()
    dicts = [data for _, data, _ in CASES if isinstance(data, dict)]
    covered = {key for data in dicts for key, value in data.items() if base.get(key) != value}
    assert sections <= covered, sections - covered
    assert len(CASES) >= 30


AS_A_PROCESS = {"seed negative", "not UTF-8", "nested too deeply", "camera memory"}


@pytest.mark.parametrize(("what", "data", "message"), CASES, ids=[c[0] for c in CASES])
def test_run_and_validate_refuse_it_with_exit_2_and_no_traceback(
    tmp_path: Path,
    out: Path,
    capsys: pytest.CaptureFixture[str],
    what: str,
    data: Any,
    message: str,
) -> None:
    """`catabot run` as a process for a few (the exit code and stderr a shell sees), in this
    one for the rest, like `scenario validate`, which shares its checks (launcher.prepare):
    45 cases of two process start-ups each cost CI's 15 minutes a minute of a core."""
    path = tmp_path / "bad.json"
    path.write_bytes(data if isinstance(data, bytes) else json.dumps(data).encode())
    if what in AS_A_PROCESS:
        run = catabot("run", str(path), "--out", str(out))
        code, said_out, said_err = run.returncode, run.stdout, run.stderr
    else:
        code, said_out, said_err = in_process(["run", str(path), "--out", str(out)], capsys)
    assert code == 2, (what, said_out, said_err)
    assert message in said_err, (what, said_err)
    assert "Traceback" not in said_err + said_out, what
    assert list(out.iterdir()) == [], "nothing may start"
    assert main(["scenario", "validate", str(path)]) == 2, what
    said = capsys.readouterr()
    assert message in said.err and "Traceback" not in said.err + said.out, (what, said.err)
