"""Hundreds of bad scenario files, made from one rich valid scenario by breaking one thing at a
time (an unknown key in every section, the wrong type, NaN, a list in every value): `catabot
scenario validate` and `catabot run` both refuse each with exit 2, the field named, and no
traceback. (tests/e2e/test_bad_scenarios.py runs a hand-picked table as real processes.)"""

from __future__ import annotations

import copy
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from catabot.run.cli import main
from tests.paths import BAY

RICH: dict[str, Any] = {
    "name": "rich", "seed": 4, "duration_s": 2.0, "dt_ns": 10_000_000,
    "clock": {"deadline_s": 5.0, "window_ticks": 20, "external_participants": ["p"]},
    "origin": {"latitude_deg": 40.7, "longitude_deg": -74.0, "altitude_m": 0.0},
    "water": {"density_kg_m3": 1025.0, "waves": {"significant_height_m": 0.3},
              "current": {"velocity_mps": [0.2, 0.1]}},
    "wind": {"speed_mps": 3.0, "toward_rad": 1.0, "gust_std_mps": 0.5,
             "zones": [{"shape": "circle", "center_m": [300.0, 300.0], "radius_m": 40.0,
                        "speed_mps": 1.0, "toward_rad": 0.0}]},
    "rain": {"rate_mm_h": 5.0},
    "terrain": {"elevation_image": str(BAY), "min_elevation_m": -15.0, "max_elevation_m": 25.0,
                "metres_per_pixel": 2.0},
    "buoys": [{"id": "mark", "x_m": 330.0, "y_m": 300.0}],
    "vessels": [{
        "id": "ego", "model": "catabot", "pose": {"x_m": 300.0, "y_m": 300.0, "yaw_rad": 0.0},
        "script": [{"t_s": 0.5, "thrust": [0.5, 0.5]},
                   {"t_s": 1.0, "twist": {"surge_mps": 1.0, "yaw_rate_radps": 0.1}}],
        "controller": {"participant": "stack", "rate_hz": 10.0, "command": "twist"},
        "sensors": [
            {"name": "imu", "type": "imu", "rate_hz": 50.0, "params": {"gyro_sigma": 0.01}},
            {"name": "lidar", "type": "lidar", "rate_hz": 10.0,
             "params": {"channels": 16, "columns": 256, "mount_xyz": [0.0, 0.0, 1.0]}},
            {"name": "cam", "type": "camera", "rate_hz": 5.0,
             "params": {"width": 64, "height": 48, "outputs": {"normals": False}}},
        ],
    }],
    "traffic": {"count": 3, "models": [{"model": "monohull", "weight": 1.0}],
                "behaviour_mix": {"circle": 0.5, "hold": 0.5},
                "circle": {"radius_m": [15.0, 20.0], "speed_mps": 3.0},
                "hold": {"gain": 0.5, "max_speed_mps": 1.0}},
    "recording": {"csv": True, "mcap": True},
}  # fmt: skip


def _leaves(node: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[tuple[Any, ...], Any]]:
    if isinstance(node, dict):
        yield path, node
        for key, value in node.items():
            yield from _leaves(value, (*path, key))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _leaves(value, (*path, i))
    else:
        yield path, node


def _set(data: dict[str, Any], path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    out = copy.deepcopy(data)
    node = out
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return out


def _cases() -> list[tuple[str, dict[str, Any], str]]:
    """(id, scenario, the field path the error must name), every one invalid by construction."""
    cases = []
    for path, value in _leaves(RICH):
        where = ".".join(map(str, path))
        if isinstance(value, dict):  # every section refuses a key it does not know
            bad = _set(RICH, (*path, "bogus"), 1) if path else {**RICH, "bogus": 1}
            cases.append((f"{where or 'top'}+bogus", bad, f"{where}.bogus" if path else "bogus"))
            continue
        if isinstance(value, bool):
            cases.append((f"{where}=text", _set(RICH, path, "yes"), where))
        elif isinstance(value, int | float):
            cases.append((f"{where}=text", _set(RICH, path, "ten"), where))
            cases.append((f"{where}=NaN", _set(RICH, path, float("nan")), where))
            cases.append((f"{where}=list", _set(RICH, path, [1.0]), where))
        elif isinstance(value, str):
            cases.append((f"{where}=number", _set(RICH, path, 7), where))
    return cases


CASES = _cases()


def test_the_rich_scenario_is_valid_and_the_table_is_large(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert len(CASES) >= 100
    assert main(["scenario", "validate", _file(Path("/tmp"), "rich-ok", RICH)]) == 0, (
        capsys.readouterr().err
    )


def _file(folder: Path, name: str, data: dict[str, Any]) -> str:
    path = folder / f"{name}.json"
    path.write_text(json.dumps(data))  # NaN goes in as JSON's NaN literal, as a user may write
    return str(path)


@pytest.mark.parametrize(("what", "data", "field"), CASES, ids=[c[0] for c in CASES])
def test_validate_and_run_refuse_it_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], what: str, data: Any, field: str
) -> None:
    path = _file(tmp_path, "bad", data)
    for argv in (["scenario", "validate", path], ["run", path, "--out", str(tmp_path / "runs")]):
        assert main(argv) == 2, what
        err = capsys.readouterr().err
        assert field in err, (what, err)
        assert "Traceback" not in err
    assert not (tmp_path / "runs").exists(), "nothing may start"
