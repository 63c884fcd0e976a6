"""Loading a scenario file (catabot/config/load.py): paths relative to the file, bundled
elevation images by bare name, and the one-line answers for what is not a scenario file."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import (
    BUNDLED,
    TERRAINS,
    json_schema,
    load_scenario,
    parse_scenario,
    scenario_json,
)
from catabot.config.notes import scenario_notes
from tests.paths import BAY


def _base() -> dict[str, Any]:
    sensors = [{"name": "imu", "type": "imu", "rate_hz": 100.0}]
    return {"name": "test", "duration_s": 1.0, "vessels": [{"id": "ego", "sensors": sensors}]}


def _refusal(data: Any) -> str:
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(data)
    return str(caught.value)


def test_a_copied_bundled_scenario_still_finds_its_terrain(tmp_path: Path) -> None:
    copy = Path(shutil.copy(BUNDLED / "harbour.json", tmp_path))
    assert load_scenario(copy).terrain is not None
    assert load_scenario(copy).terrain.elevation_image == str(TERRAINS / "bay.png")  # type: ignore[union-attr]


@pytest.mark.parametrize("image", ["bay.png", str(TERRAINS / "bay.png")])
def test_the_bundled_image_brings_its_own_heights_and_scale(tmp_path: Path, image: str) -> None:
    """`"bay.png"` alone made a 1500 m bay (the defaults: 5 m a pixel, -35 to 60 m), while
    `scenario generate --terrain bay.png` made the harbour's 600 m one (bay.json)."""
    path = tmp_path / "s.json"
    terrain = {"elevation_image": image, "metres_per_pixel": 3.0}  # what it gives stays
    path.write_text(json.dumps({"name": "s", "terrain": terrain, "vessels": [{"id": "ego"}]}))
    got = load_scenario(path).terrain
    assert got is not None
    assert (got.min_elevation_m, got.max_elevation_m, got.metres_per_pixel) == (-15.0, 25.0, 3.0)


def test_an_image_beside_the_scenario_comes_before_the_bundled_one(tmp_path: Path) -> None:
    shutil.copy(BAY, tmp_path / "bay.png")
    path = tmp_path / "s.json"
    terrain = {"elevation_image": "bay.png", "min_elevation_m": -15.0, "max_elevation_m": 25.0}
    path.write_text(json.dumps({"name": "s", "terrain": terrain, "vessels": [{"id": "ego"}]}))
    assert load_scenario(path).terrain.elevation_image == str(tmp_path / "bay.png")  # type: ignore[union-attr]


def _copied_bay(tmp_path: Path, **scale: float) -> list[str]:
    shutil.copy(BAY, tmp_path / "bay.png")
    path = tmp_path / "s.json"
    terrain = {"elevation_image": "bay.png", **scale}
    path.write_text(json.dumps({"name": "s", "terrain": terrain, "vessels": [{"id": "ego"}]}))
    return scenario_notes(load_scenario(path))


def test_a_copy_of_the_bundled_image_without_its_scale_is_said(tmp_path: Path) -> None:
    """A copy (to edit it) takes the defaults, a bay 2.5 times wider than the bundled
    one's: said, with the scale bay.json gives the bundled image."""
    (note,) = _copied_bay(tmp_path)
    assert "is a copy of the bundled bay.png" in note
    assert "metres_per_pixel 2, min_elevation_m -15, max_elevation_m 25" in note
    assert "this run's is metres_per_pixel 5, min_elevation_m -35, max_elevation_m 60" in note


def test_a_copy_given_the_bundled_scale_or_an_edited_copy_is_not_said(tmp_path: Path) -> None:
    bundled = {"metres_per_pixel": 2.0, "min_elevation_m": -15.0, "max_elevation_m": 25.0}
    assert _copied_bay(tmp_path, **bundled) == []
    (tmp_path / "s.json").write_text(
        json.dumps(
            {"name": "s", "terrain": {"elevation_image": "bay.png"}, "vessels": [{"id": "e"}]}
        )
    )
    assert len(scenario_notes(load_scenario(tmp_path / "s.json"))) == 1
    (tmp_path / "bay.png").write_bytes((tmp_path / "bay.png").read_bytes() + b"edited")
    assert scenario_notes(load_scenario(tmp_path / "s.json")) == []  # its own image now
    (tmp_path / "s.json").write_text(json.dumps(
        {"name": "s", "terrain": {"elevation_image": str(BAY), "metres_per_pixel": 3.0},
         "vessels": [{"id": "e"}]}
    ))  # fmt: skip
    assert scenario_notes(load_scenario(tmp_path / "s.json")) == []  # the bundled one itself


def test_relative_paths_are_written_without_dot_dot(tmp_path: Path) -> None:
    (tmp_path / "maps").mkdir()
    shutil.copy(BAY, tmp_path / "maps" / "coast.png")
    (tmp_path / "scenarios").mkdir()
    path = tmp_path / "scenarios" / "s.json"
    terrain = {"elevation_image": "../maps/coast.png", "min_elevation_m": -1.0}
    path.write_text(json.dumps({"name": "s", "terrain": terrain, "vessels": [{"id": "ego"}]}))
    image = load_scenario(path).terrain.elevation_image  # type: ignore[union-attr]
    assert image == str(tmp_path / "maps" / "coast.png")


def test_a_folder_is_not_a_scenario_file_and_a_run_folder_gets_a_hint(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=r"is a folder$"):
        load_scenario(tmp_path)
    (tmp_path / "scenario.json").write_text("{}")
    with pytest.raises(ScenarioError, match=r"a run folder.s scenario is .*/scenario\.json"):
        load_scenario(tmp_path)


def test_an_empty_list_says_how_many_items_it_needs(tmp_path: Path) -> None:
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"name": "s", "vessels": []}))
    with pytest.raises(ScenarioError, match=r"vessels: needs at least 1 item\(s\), got 0"):
        load_scenario(path)


def test_a_sensors_unknown_parameter_lists_that_types_parameters(tmp_path: Path) -> None:
    imu = {"name": "imu", "type": "imu", "rate_hz": 100.0, "params": {"gyro_noise": 1.0}}
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"name": "s", "vessels": [{"id": "ego", "sensors": [imu]}]}))
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    message = str(caught.value)
    assert "vessels.0.sensors.0.params.gyro_noise: unknown field" in message
    assert "(allowed: gyro_sigma, accel_sigma" in message and "rate_hz" not in message


def test_json_schema_is_valid_and_accepts_every_bundled_scenario() -> None:
    schema = json_schema()
    validator_cls = jsonschema.validators.validator_for(schema)
    validator_cls.check_schema(schema)
    assert validator_cls is jsonschema.Draft202012Validator
    bundled = sorted(BUNDLED.glob("*.json"))
    assert {p.stem for p in bundled} >= {"default", "harbour", "navigate", "perception"}
    for path in bundled:
        validator_cls(schema).validate(json.loads(path.read_text()))
        assert scenario_notes(load_scenario(path.stem)) == [], path.name  # nothing to warn of
    validator_cls(schema).validate(_base())
    assert schema["title"] == "CataBot scenario"
    assert "vessels" in schema["required"]


def test_json_schema_refuses_what_the_loader_refuses() -> None:
    validator = jsonschema.Draft202012Validator(json_schema())
    for mutate in (
        lambda d: d.update(extra=1),
        lambda d: d.update(duration_s=-1),
        lambda d: d.update(clock={"policy": "ignore"}),
        lambda d: d["vessels"][0]["sensors"][0].update(type="sonar"),
        lambda d: d.pop("vessels"),
    ):
        data = _base()
        mutate(data)
        assert not validator.is_valid(data)
        with pytest.raises(ScenarioError):
            parse_scenario(data)


def test_json_schema_checks_each_sensor_types_params_and_allows_a_schema_hook() -> None:
    """An editor completes and checks `params` by the sensor's type, and a scenario may
    name its schema (`"$schema"`, the usual editor hook) without being refused."""
    validator = jsonschema.Draft202012Validator(json_schema())
    data = _base()
    data["vessels"][0]["sensors"] = [
        {"name": "lidar", "type": "lidar", "rate_hz": 10, "params": {"chanels": 16}}
    ]
    (error,) = validator.iter_errors(data)
    assert "'chanels' was unexpected" in error.message
    assert "params.chanels: unknown field" in _refusal(data)
    data["vessels"][0]["sensors"][0]["params"] = {"channels": 16}
    data["$schema"] = "../scenario.schema.json"
    assert validator.is_valid(data)
    assert parse_scenario(data).vessels[0].sensors[0].params["channels"] == 16


def test_a_scenario_read_once_is_written_as_resolved_as_one_read_twice() -> None:
    """A sensor without `params` had {} in a split run's scenario.json (each service reads
    the file once) and every default in `catabot run`'s (which parses its own dump again)."""
    once = parse_scenario(_base())
    assert once.vessels[0].sensors[0].params["gyro_sigma"] == 0.009
    assert scenario_json(once) == scenario_json(parse_scenario(once.model_dump()))


def test_unknown_fields_of_one_place_are_said_together() -> None:
    """20 misnamed keys repeated the allowed names 20 times, 4 kB on one line."""
    data = {**_base(), "foo": 1, "bar": 2}
    data["vessels"][0].update(colour=1, speed=2)
    message = _refusal(data)
    assert "vessels.0.colour, vessels.0.speed: unknown fields (allowed: id, model," in message
    assert "foo, bar: unknown fields (allowed: name, seed," in message
    assert message.count("allowed:") == 2


def test_degrees_given_to_a_bounded_radians_field_are_named_as_such() -> None:
    """`yaw_rad: 90` had the hint; `roll_rad: 30` only heard its bound."""
    data = _base()
    data["vessels"][0]["pose"] = {"x_m": 0.0, "y_m": 0.0, "roll_rad": 30}
    assert "roll_rad: must be <= 3.14159 (got 30) (degrees? 30° is 0.5236 rad)" in _refusal(data)
