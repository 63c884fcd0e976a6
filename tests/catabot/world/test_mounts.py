"""A camera, LiDAR or radar inside its own vessel's shape is refused before the run starts
(`catabot run`, `catabot scenario validate`); a mount above the deck, between a catamaran's
hulls, or an IMU inside the boat is not."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from catabot.config.load import parse_scenario
from catabot.config.vessel import load_vessel_model
from catabot.run.cli import main
from catabot.world.mounts import MountInsideError, check_mounts, inside
from catabot.world.shapes import vessel_mesh
from catabot.world.world import World


def _world(model: str, sensor: dict[str, Any]) -> World:
    vessel = {"id": "ego", "model": model, "sensors": [sensor]}
    return World.resolve(parse_scenario({"name": "m", "vessels": [vessel]}))


@pytest.mark.parametrize(
    ("model", "point", "within"),
    [
        ("catabot", (0.0, 0.0, 0.35), True),  # in its electronics box
        ("catabot", (0.0, 0.5, 0.1), True),  # in a hull
        ("catabot", (0.0, 0.4, 0.1), True),  # on a hull's centreline: a ray along x met the
        ("wamv", (0.0, 1.03, 0.124), True),  # bow's apex edge twice and said "outside"
        ("monohull", (-0.301, 0.0, 0.295), True),
        ("catabot", (0.0, 0.0, 0.1), False),  # between the hulls, under the deck box
        ("catabot", (0.5, 0.0, 1.5), False),  # the camera's default, above it all
        ("monohull", (0.0, 0.0, 1.0), True),  # in the cabin
        ("wamv", (0.0, 0.0, 0.35), False),  # between the hulls
    ],
)
def test_ray_parity_finds_the_inside_of_the_bundled_shapes(
    model: str, point: tuple[float, float, float], within: bool
) -> None:
    mesh = vessel_mesh(load_vessel_model(model), source=model)
    assert mesh is not None and inside(mesh, point) is within


def test_a_camera_inside_its_hull_is_refused_naming_it_and_where_the_deck_is() -> None:
    cam = {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"mount_xyz": [0, 0, 0.35]}}
    with pytest.raises(MountInsideError) as info:
        check_mounts(_world("catabot", cam))
    said = str(info.value)
    assert said.startswith("vessels.0.sensors.0 (cam): its rays start at [0.0, 0.0, 0.35] ")
    assert "inside ego's own shape (model 'catabot', up to z = 0.46 m)" in said


@pytest.mark.parametrize(("model", "height"), [("monohull", 1.0), ("catabot", 0.05)])
def test_a_radar_antenna_below_its_shapes_top_is_refused_and_an_imu_is_not(
    model: str, height: float
) -> None:
    """Inside the cabin, or between a catamaran's hulls (not inside the shape, yet 205 of
    240 beams hit its own hulls there)."""
    params = {"antenna_height_m": height, "fan_target_height_m": 0.0}  # no fan: a mount test
    radar = {"name": "r", "type": "radar", "rate_hz": 10.0, "params": params}
    said = f"antenna_height_m {height:g} is not above ego's own shape \\(model '{model}'"
    with pytest.raises(MountInsideError, match=said):
        check_mounts(_world(model, radar))
    check_mounts(_world(model, radar | {"params": {"antenna_height_m": 3.0}}))
    check_mounts(_world("monohull", {"name": "imu", "type": "imu", "rate_hz": 100.0}))
    check_mounts(_world("catabot", {"name": "l", "type": "lidar", "rate_hz": 10.0}))


def test_scenario_validate_refuses_it_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lidar = {"name": "l", "type": "lidar", "rate_hz": 10, "params": {"mount_xyz": [0, 0.5, 0.1]}}
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"name": "m", "vessels": [{"id": "ego", "sensors": [lidar]}]}))
    assert main(["scenario", "validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "(l): its rays start at [0.0, 0.5, 0.1] (mount_xyz)" in err


@pytest.mark.parametrize("kind", ["lidar", "camera"])
def test_a_sensor_under_the_water_is_refused(kind: str) -> None:
    """A LiDAR 1 m down was taken without a word: its scans held rain and the seabed."""
    sensor = {"name": "s", "type": kind, "rate_hz": 5.0, "params": {"mount_xyz": [0, 0, -1.0]}}
    with pytest.raises(MountInsideError, match=r"\(s\): its rays start at \[0.0, 0.0, -1.0\] "
                                               r"\(mount_xyz\), under water"):  # fmt: skip
        check_mounts(_world("catabot", sensor))
