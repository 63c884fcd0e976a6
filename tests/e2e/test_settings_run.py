"""`catabot set rain 25` during a run: the LiDAR sees rain from the tick the change took
effect on, the change is recorded (config.changes.csv, run.extra.mcap, the run folder's
scenario.json), and running that scenario.json again records the same bytes; a bad key or
value is refused with exit 2 naming what is allowed, and the run goes on."""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

from conftest import basic_scenario, catabot, csv_rows, files_of, only_run_dir, scenario_file, start
from PIL import Image

from catabot.bus.session import free_port
from services.recorder.mcap_read import read_mcap_messages


def _scenario(tmp: Path) -> Path:
    """25 s of wall clock: on a loaded machine each CLI process below takes seconds to start
    (at 15 s, the last `get` found the run over)."""
    data = basic_scenario("settings", duration_s=10.0, clock={"realtime_factor": 0.4})
    data["vessels"][0]["sensors"] = [
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
        {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 64, "height": 48}},
    ]
    return scenario_file(tmp, data)


def _granted(endpoint: str) -> int:
    """The last tick granted, once the run answers (-2 while it does not)."""
    got = catabot("get", "--json", "-e", endpoint, "--mode", "client", "--timeout", "1")
    return int(json.loads(got.stdout)["granted"]) if got.returncode == 0 else -2


def _wait_ticking(endpoint: str) -> None:
    limit = time.monotonic() + 60
    while _granted(endpoint) < 60:
        assert time.monotonic() < limit, "the run never got going"
        time.sleep(0.2)


def _while_it_runs(endpoint: str, png: Path) -> int:
    """At once, while the run goes on: `set rain 25`, a bad key and a bad value (exit 2
    naming what is allowed), the Space key (the camera's next colour image as a PNG); then
    `get rain`. Returns the tick the change took effect at. All at once because each CLI
    process takes seconds to start on a loaded machine: one after another, the last ones
    found the run over (CI rehearsal, three workers)."""
    flags = ("-e", endpoint, "--mode", "client", "--timeout", "20")
    calls = {
        "set": start("set", "rain", "25", *flags),
        "key": start("set", "snow", "3", *flags),
        "value": start("set", "rain", "80", *flags),
        "shot": start("snapshot", "-o", str(png), *flags),
    }
    done = {name: (proc.communicate(timeout=60), proc.returncode) for name, proc in calls.items()}
    (out, err), code = done["set"]
    assert code == 0, err
    match = re.search(r"rain = 25\.0 from tick (\d+)", out)
    assert match, out
    got = catabot("get", "rain", *flags)
    assert got.returncode == 0 and got.stdout.strip() == "25.0", got.stderr
    (_, err), code = done["key"]
    assert code == 2 and "Traceback" not in err
    assert "unknown setting 'snow'" in err and "rain" in err
    assert "sensor.ego.lidar.enabled" in err  # the keys this run offers
    (_, err), code = done["value"]
    assert code == 2 and "Traceback" not in err and "from 0 to 50" in err, err
    (out, err), code = done["shot"]
    assert code == 0 and "ego/cam" in out, err
    with Image.open(png) as image:
        assert image.size == (64, 48) and image.mode == "RGB"
    return int(match.group(1))


def test_no_simulation_is_a_clear_error(tmp_path: Path) -> None:
    gone = f"tcp/127.0.0.1:{free_port()}"
    refused = catabot("set", "rain", "1", "-e", gone, "--mode", "client", "--timeout", "1")
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert f"catabot set: nothing answers at {gone} (Connection refused)" in refused.stderr
    assert refused.stderr.count("\n") == 1  # one line, not Zenoh's error from orchestrator.rs
    words = catabot("set", "current", "[0.1,", "0.0]", "-e", gone, "--timeout", "1")
    assert words.returncode == 2 and "nothing answers" in words.stderr  # read as one value
    bad = catabot("set", "current", "[nan, 0]", "--timeout", "1")
    assert bad.returncode == 2 and "catabot set: '[nan, 0]' is not JSON" in bad.stderr
    alone = catabot("get", "--world", "nobody", "--timeout", "1")
    assert alone.returncode == 2 and "Traceback" not in alone.stderr
    assert "no running simulation of world 'nobody' answered within 1 s" in alone.stderr


def test_set_rain_mid_run_is_recorded_and_replays_to_the_same_bytes(tmp_path: Path) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    out = tmp_path / "live"
    run = start("run", str(_scenario(tmp_path)), "--out", str(out), "--quiet",
                "--listen", endpoint)  # fmt: skip
    try:
        _wait_ticking(endpoint)
        effect = _while_it_runs(endpoint, tmp_path / "snap.png")
        stdout, stderr = run.communicate(timeout=120)
    finally:
        run.kill()
    assert run.returncode == 0, stderr
    assert "setting refused 2" in stderr  # counted like any refused input
    told = f"conductor: setting rain = 25.0 from tick {effect} (t = {effect / 100:g} s)"
    assert told in stdout + stderr  # the run's own console says what changed
    folder = only_run_dir(out)
    scans = [(int(r[1]), int(r[3])) for r in csv_rows(folder / "sensor.ego.lidar.csv")[1:]]
    assert len(scans) == 100 and 60 < effect < 1000
    assert all(rain == 0 for tick, rain in scans if tick < effect)
    assert all(rain > 100 for tick, rain in scans if tick >= effect)
    assert any(tick >= effect for tick, _ in scans)
    rows = csv_rows(folder / "config.changes.csv")
    assert rows == [["stamp_ns", "tick", "key", "value"],
                    [str(effect * 10_000_000), str(effect), "rain", "25.0"]]  # fmt: skip
    extra = [
        m for m in read_mcap_messages(folder / "run.extra.mcap") if m.topic == "/config/changes"
    ]
    assert len(extra) == 1 and extra[0].log_time == effect * 10_000_000
    recorded = json.loads((folder / "scenario.json").read_text())["settings"]
    assert recorded == [{"t_s": effect / 100, "key": "rain", "value": 25.0}]
    replay_out = tmp_path / "replay"
    again = catabot("run", str(folder / "scenario.json"), "--out", str(replay_out), "--quiet",
                    "--realtime", "1000")  # the pace is not in the bytes  # fmt: skip
    assert again.returncode == 0, again.stderr
    assert files_of(only_run_dir(replay_out)) == files_of(folder)
