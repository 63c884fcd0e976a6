"""`catabot run` tells on its console (stderr, with refusals) what a service advises: a
twist beyond reach, a script step or a setting after the run's end, a LiDAR that mostly
sees its own vessel."""

from __future__ import annotations

from pathlib import Path

from conftest import catabot, only_run_dir, scenario_file


def test_a_scripted_twist_beyond_reach_is_told_on_the_console(tmp_path: Path) -> None:
    def twist(surge: float) -> list[dict[str, object]]:
        return [{"t_s": 0.0, "twist": {"surge_mps": surge, "yaw_rate_radps": 0.0}}]

    data = {"name": "advice", "duration_s": 0.5,
            "settings": [{"t_s": 2.0, "key": "rain", "value": 5}], "vessels": [
        {"id": "fast", "script": twist(3.0)},
        {"id": "slow", "pose": {"x_m": 10.0, "y_m": 0.0},
         "script": [*twist(1.0), {"t_s": 2.0, "thrust": [0.0, 0.0]}],
         "sensors": [{"name": "low", "type": "lidar", "rate_hz": 10.0, "params": {
             "channels": 8, "columns": 64, "mount_xyz": [0.0, 0.0, 0.2]}}]},
    ]}  # fmt: skip
    out, file = tmp_path / "runs", str(scenario_file(tmp_path, data))
    checked = catabot("scenario", "validate", file).stdout  # said before any run, too
    assert "note: settings.0 (rain at 2 s) comes after the run's last tick (0.49 s)" in checked
    assert "note: slow: its script step at 2 s comes after the run's last tick" in checked
    result = catabot("run", file, "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    told = [line for line in result.stderr.splitlines() if "beyond its thrusters" in line]
    assert len(told) == 1, result.stderr  # the console notes, as refusals
    assert told[0].startswith("physics: fast: the scripted twist 3 m/s at 0 rad/s is beyond")
    assert "about 1.87 m/s straight ahead" in told[0]
    assert told[0].split("physics: ", 1)[1] in (only_run_dir(out) / "log/physics.log").read_text()
    late = "physics: slow: its script step at 2 s comes after the run's last tick (0.49 s), so it"
    assert late in result.stderr
    assert "sensors: slow/low: " in result.stderr  # between its hulls: it sees them
    assert "settings.0 (rain at 2 s) comes after the run's last tick (0.49 s)" in result.stderr
    assert "of its first sample's returns are its own vessel: mount it where" in result.stderr
