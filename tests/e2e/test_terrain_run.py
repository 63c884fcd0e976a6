"""Terrain through `catabot run`: start poses checked before anything starts, auto placement."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import basic_scenario, catabot, csv_rows, only_run_dir, scenario_file

from catabot.config.load import load_scenario
from catabot.config.terrain import TerrainConfig
from catabot.gym.paths import PATH_MARGIN_M, path_points
from catabot.world.terrain import load_terrain
from tests.paths import BAY, SHARED_DATA

SHARED = SHARED_DATA / "elevation"
RIVER = SHARED / "new-york-river.png"


def _bay(**vessel: object) -> dict[str, object]:
    data = basic_scenario("terrain", duration_s=2.0)
    data["terrain"] = {"elevation_image": str(BAY), "min_elevation_m": -15.0,
                       "max_elevation_m": 25.0, "metres_per_pixel": 2.0}  # fmt: skip
    data["vessels"][0].update(vessel)  # type: ignore[index]
    return data


def test_pose_on_land_is_refused_before_anything_starts(tmp_path: Path, out: Path) -> None:
    data = _bay(pose={"x_m": 420.0, "y_m": 250.0})  # the island's summit
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out))
    assert result.returncode == 2
    assert "vessels.0.pose (ego)" in result.stderr and "on land" in result.stderr
    assert list(out.iterdir()) == []


def test_pose_in_too_shallow_water_is_refused(tmp_path: Path, out: Path) -> None:
    data = _bay(pose={"x_m": 300.0, "y_m": 470.0})  # on the north shore's slope
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out))
    assert result.returncode == 2
    assert "vessels.0.pose (ego)" in result.stderr
    assert "shallow" in result.stderr or "on land" in result.stderr


def test_bundled_harbour_scenario_runs(out: Path) -> None:
    """Also: its WAM-V follows the path the gym envs keep their starts clear of (arcs of its
    twist script, carried by the current: catabot/gym/paths.py) within PATH_MARGIN_M."""
    result = catabot("run", "harbour", "--duration", "60.3", "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    poses = [v["pose"] for v in json.loads((run / "scenario.json").read_text())["vessels"]]
    assert all(p is not None for p in poses), "missing poses are resolved into the run folder"
    world = load_scenario(run / "scenario.json")
    path = path_points(world.vessels[1], world, seconds=60.3)[:, :2]
    track = np.loadtxt(run / "vessel.wamv.state.csv", delimiter=",", skiprows=1, usecols=(2, 3))
    off = np.hypot(track[:, None, 0] - path[None, :, 0], track[:, None, 1] - path[None, :, 1])
    assert len(track) == 6031 and off.min(axis=1).max() < PATH_MARGIN_M  # measured 1.45 m


@pytest.mark.skipif(not RIVER.is_file(), reason="needs ../shared/data/elevation")
def test_vessel_without_pose_starts_in_the_new_york_river(tmp_path: Path, out: Path) -> None:
    data = basic_scenario("river", duration_s=2.0)
    data["terrain"] = {"elevation_image": str(RIVER)}  # the original's defaults
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    pose = json.loads((run / "scenario.json").read_text())["vessels"][0]["pose"]
    terrain = load_terrain(TerrainConfig(elevation_image=str(RIVER)))
    assert terrain.depth(pose["x_m"], pose["y_m"]) > 1.0
    w, h = terrain.size_m
    assert abs(pose["x_m"] - w / 2) < 400 and abs(pose["y_m"] - h / 2) < 400
    rows = csv_rows(run / "vessel.ego.state.csv")
    assert len(rows) == 202  # the header, the start state and 200 ticks


@pytest.mark.skipif(not RIVER.is_file(), reason="needs ../shared/data/elevation")
def test_an_original_settings_config_runs_on_its_terrain_with_radar(
    tmp_path: Path, out: Path
) -> None:
    """The original's SettingsConfig.json with terrainFromFile: robot_0 starts in the river
    (not at (0, 0) in open water), the radar runs and its minimap is written."""
    (tmp_path / "New York River Elevation.png").symlink_to(RIVER)
    settings = {
        "radarActive": True, "lidarActive": False, "imuActive": True, "minimapActive": True,
        "rainIntensity": 0.0, "screenshotsSaveToFile": False, "screenshotsColorActive": False,
        "screenshotsSegmentationActive": False, "screenshotsDepthActive": False,
        "screenshotsNormalActive": False, "robotControlType": "Keyboard",
        "boatControlType": "Circles", "boatsNumberActive": 0, "gpsLatitude": 40.7003,
        "gpsLongitude": -74.017, "terrainFromFile": True, "terrainHeightMin": -35.0,
        "terrainHeightMax": 60.0, "terrainPixelScale": 5.0,
        "terrainPathToElevationFile": "New York River Elevation.png",
    }  # fmt: skip
    path = scenario_file(tmp_path, settings, "SettingsConfig.json")
    result = catabot("run", str(path), "--duration", "2.1", "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    x, y = (float(v) for v in csv_rows(run / "vessel.robot_0.state.csv")[1][2:4])
    terrain = load_terrain(TerrainConfig(elevation_image=str(RIVER)))
    assert (x, y) != (0.0, 0.0) and terrain.depth(x, y) > 1.0
    assert len(csv_rows(run / "sensor.robot_0.radar.csv")) > 10
    assert list((run / "dataset" / "robot_0.radar").glob("ppi_*.png"))
