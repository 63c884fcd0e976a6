"""The scenario's `settings` timeline through `catabot run`: each kind of change takes effect
in the service that owns it at its tick (a LiDAR off and on again, camera outputs off, a
traffic boat told to hold, the sea, wind and current), and every change is recorded."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import basic_scenario, catabot, csv_rows, only_run_dir, scenario_file

from services.recorder.mcap_read import read_mcap_messages

CHANGES = [
    {"t_s": 0.3, "key": "traffic.boat_000.behaviour", "value": "hold"},
    {"t_s": 0.4, "key": "sensor.ego.cam.outputs.color", "value": False},
    {"t_s": 0.4, "key": "sensor.ego.cam.outputs.depth", "value": False},
    {"t_s": 0.5, "key": "sensor.ego.lidar.enabled", "value": False},
    {"t_s": 1.0, "key": "sensor.ego.lidar.enabled", "value": True},
    {"t_s": 1.2, "key": "waves", "value": "heavy"},
    {"t_s": 1.2, "key": "wind.speed_mps", "value": 10},
    {"t_s": 1.2, "key": "current", "value": [1.0, 0.0]},
]


def test_a_settings_timeline_changes_each_service_at_its_tick(tmp_path: Path) -> None:
    late = {"t_s": 5.0, "key": "rain", "value": 20.0}  # after the end: kept, never applied
    data = basic_scenario("timeline", duration_s=1.6, settings=[*CHANGES, late])
    data["vessels"][0]["sensors"] = [
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
        {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 64, "height": 48}},
    ]
    data["traffic"] = {"count": 1, "behaviour_mix": {"circle": 1.0}}
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(tmp_path / "o"),
                     "--quiet")  # fmt: skip
    assert result.returncode == 0, result.stderr
    run = only_run_dir(tmp_path / "o")
    scans = [int(r[1]) for r in csv_rows(run / "sensor.ego.lidar.csv")[1:]]
    assert scans == [0, 10, 20, 30, 40, 100, 110, 120, 130, 140, 150]  # off from 50 to 99
    stamps = _stamps(run / "run.mcap")
    tick = 10_000_000
    assert stamps["/ego/cam/image_raw"] == [0, 20 * tick]  # colour off from tick 40
    assert stamps["/ego/cam/depth"] == [0, 20 * tick]
    assert len(stamps["/ego/cam/segmentation"]) == 8  # still on
    twists = np.loadtxt(run / "vessel.boat_000.cmd.twist.csv", delimiter=",", skiprows=1)
    surge = dict(zip(twists[:, 1].astype(int).tolist(), twists[:, 2].tolist(), strict=True))
    assert surge[20] > 4.0 and all(abs(v) <= 2.0 for k, v in surge.items() if k >= 30)
    changes = csv_rows(run / "config.changes.csv")[1:]
    assert [(int(r[1]), r[2]) for r in changes] == [
        (round(c["t_s"] * 100), str(c["key"])) for c in CHANGES
    ]
    # the timeline as asked: an interrupted run's had lost what was still to come
    assert (run / "scenario.json").read_text().count('"key"') == len(CHANGES) + 1


def _stamps(path: Path) -> dict[str, list[int]]:
    out: dict[str, list[int]] = {}
    for m in read_mcap_messages(path):
        out.setdefault(m.topic, []).append(m.log_time)
    return out


STACK = """
from catabot.client import Client, Thrust, add_stack_args
import argparse
p = argparse.ArgumentParser()
add_stack_args(p)
args = p.parse_args()
seen = []
def step(obs):
    seen.append(obs.sensors["gps"] is not None and obs.sensors["gps"].tick)
    return Thrust([0.3, 0.3])
with Client.from_args(args) as sim:
    end = sim.run_lockstep(args.participant, step, vessel=args.vessel, sensors=["gps"])
print("gps ticks", sorted(set(seen) - {False}), end.reason)
"""


def test_a_lockstep_stack_reading_a_sensor_switched_off_is_not_held(tmp_path: Path) -> None:
    """The services were told of a switch and the client was not: a stack that read the GPS
    waited for samples that never came, and the run ended at the deadline, blaming it."""
    (tmp_path / "stack.py").write_text(STACK)
    off_on = [{"t_s": 0.5, "key": "sensor.ego.gps.enabled", "value": False},
              {"t_s": 1.0, "key": "sensor.ego.gps.enabled", "value": True}]  # fmt: skip
    data = basic_scenario("switch", duration_s=1.5, settings=off_on)
    data["clock"] = {"deadline_s": 3.0}
    gps = {"name": "gps", "type": "gps", "rate_hz": 10.0}
    data["vessels"][0] |= {"controller": {"participant": "stack", "program": "stack.py"},
                           "sensors": [gps]}  # fmt: skip
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(tmp_path / "o"),
                     "--quiet")  # fmt: skip
    assert result.returncode == 0, result.stderr
    said = (only_run_dir(tmp_path / "o") / "log" / "stack.log").read_text()
    assert "gps ticks [10, 20, 30, 40, 100, 110, 120, 130] completed" in said, said  # off 50-99
