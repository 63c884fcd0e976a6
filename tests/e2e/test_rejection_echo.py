"""A command dropped by physics is said on the console once, with what it should have been."""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path

from conftest import (
    basic_scenario,
    matched_publisher,
    only_run_dir,
    scenario_file,
    start,
    wait_for_line,
)

from catabot.bus import codec
from catabot.bus.keys import Keys
from catabot.bus.session import Connection, free_port, open_session


def _listening_run(
    tmp: Path, name: str, *, duration_s: float
) -> tuple[subprocess.Popen[str], str, Path]:
    """`catabot run` at half real time, listening for a client: (process, endpoint, out)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    data = basic_scenario(name, duration_s=duration_s)
    data["clock"] = {"realtime_factor": 2.0}
    out = tmp / "out"
    proc = start("run", str(scenario_file(tmp, data)), "--out", str(out), "--quiet",
                 "--listen", endpoint)  # fmt: skip
    wait_for_line(proc, "zenoh:")
    return proc, endpoint, out


def test_the_first_refusal_of_each_kind_reaches_the_console_once(tmp_path: Path) -> None:
    proc, endpoint, out = _listening_run(tmp_path, "echo", duration_s=6.0)
    key = Keys("echo").cmd_twist("ego")
    wrong = codec.pack({"v": 1, "type": "twist_cmd", "surge_mps": 1.0, "yaw_rate_radps": 0.1})
    with open_session(Connection(connect=(endpoint,))) as session:
        pub = matched_publisher(session, key)
        for _ in range(5):
            pub.put(wrong)
            time.sleep(0.3)  # over a second: the log repeats the refusal, the console not
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    said = [line for line in (stdout + stderr).splitlines() if line.startswith("physics refused")]
    assert len(said) == 1, stdout + stderr
    assert said[0].startswith(
        f"physics refused {key}: malformed: twist_cmd: unknown field(s) 'surge_mps', "
        "'yaw_rate_radps' (fields: surge, yaw_rate; optional: tick, stamp_ns)"
    ), said[0]
    log = (only_run_dir(out) / "log" / "physics.log").read_text()
    assert log.count(f"refused a sample on {key}: malformed") >= 2  # the log says it again


def test_a_command_to_no_vessel_or_of_no_kind_is_said_not_dropped_unheard(tmp_path: Path) -> None:
    """`vessel/ghost/cmd/thrust` and `vessel/ego/cmd/pose` reached no subscriber: a typo in
    an id was silent. Physics watches every command key and names what is wrong."""
    proc, endpoint, out = _listening_run(tmp_path, "stray", duration_s=4.0)
    keys = Keys("stray")
    ghost, pose = keys.cmd_thrust("ghost"), f"{keys.prefix}/vessel/ego/cmd/pose"
    wild = f"{keys.prefix}/vessel/**"  # of any depth: physics logged a traceback per put
    with open_session(Connection(connect=(endpoint,))) as session:
        for key in (ghost, pose, wild, f"{keys.prefix}/vessel/ego/cmd/thrust/**"):
            matched_publisher(session, key).put(b"anything")  # once physics' watch is there
            time.sleep(0.3)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    said = stdout + stderr
    assert f"physics refused {ghost}: no such stream: no vessel 'ghost' in this world " in said
    assert "(its vessels: ego)" in said
    assert f"physics refused {pose}: no such stream: no command 'pose' (a vessel takes" in said
    assert (
        f"physics refused {wild}: no such stream: a put on a key expression with wildcards" in said
    )
    rejected = json.loads((only_run_dir(out) / "log" / "run.json").read_text())["rejected"]
    assert rejected == {"physics": {"no such stream": 4}}  # once a put: the streams it reached
    # under the wildcard (the ego's) left it to the watch over every command key
    assert "Traceback" not in (only_run_dir(out) / "log" / "physics.log").read_text()
