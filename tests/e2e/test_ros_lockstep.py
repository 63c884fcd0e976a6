"""`ros.lockstep: true`: a ROS 2 stack that answers each controller tick's /clock with a
Twist drives the vessel deterministically: the same commands give byte-identical runs, in
either convention, and each command is applied at the tick whose clock it answered."""

from __future__ import annotations

import queue
import threading
from pathlib import Path
from typing import Any

import zenoh
from conftest import catabot, files_of, only_run_dir, scenario_file, start
from ros_client import ROSBAGS, RosClient, bridge_key, rmw_key, twist

from catabot.bus.session import free_port
from services.recorder.mcap_read import read_mcap_messages

PERIOD_NS = 100_000_000  # the controller's 10 Hz


def _scenario() -> dict[str, Any]:
    return {
        "name": "roslock",
        "seed": 9,
        "duration_s": 3.0,
        "vessels": [
            {
                "id": "ego",
                "controller": {"participant": "ros", "rate_hz": 10.0, "command": "twist"},
                "sensors": [{"name": "imu", "type": "imu", "rate_hz": 50.0}],
            }
        ],
        "ros": {"lockstep": True, "mode": "both"},
    }


def surge(stamp_ns: int) -> float:
    """The stack's decision at a clock: any deterministic function of what it saw."""
    return 0.4 + 0.3 * (stamp_ns // PERIOD_NS % 7)


class Stack:
    """Replies to every /clock on a controller tick with one Twist, from its own thread
    (no Zenoh call in a callback)."""

    def __init__(self, client: RosClient, rmw: bool) -> None:
        self.client, self.rmw = client, rmw
        self.clocks: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        key = rmw_key("/clock", "rosgraph_msgs/msg/Clock") if rmw else bridge_key("/clock")
        self.sub = client.session.declare_subscriber(key, self._on_clock)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._reply, daemon=True)
        self.thread.start()

    def _on_clock(self, sample: zenoh.Sample) -> None:
        self.clocks.put(sample.payload.to_bytes())

    def _reply(self) -> None:
        key = (
            rmw_key("/ego/cmd_vel", "geometry_msgs/msg/Twist")
            if self.rmw
            else bridge_key("/ego/cmd_vel")
        )
        while not self.stop.is_set():
            try:
                payload = self.clocks.get(timeout=0.1)
            except queue.Empty:
                continue
            clock = ROSBAGS.deserialize_cdr(payload, "rosgraph_msgs/msg/Clock").clock
            stamp = int(clock.sec) * 10**9 + int(clock.nanosec)
            if stamp % PERIOD_NS == 0:  # tick 0's too
                self.client.put(key, twist(surge(stamp), 0.05), rmw=self.rmw)

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=2)
        self.sub.undeclare()


def _run(tmp: Path, tag: str, *, rmw: bool) -> Path:
    out = tmp / tag
    out.mkdir()
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    client = RosClient(endpoint)
    stack = Stack(client, rmw)
    try:
        proc = start("run", str(scenario_file(tmp, _scenario())), "--out", str(out), "--quiet",
                     "--listen", endpoint)  # fmt: skip
        _, err = proc.communicate(timeout=120)
    finally:
        stack.close()
        client.close()
    assert proc.returncode == 0, err
    return only_run_dir(out)


def test_the_same_commands_give_byte_identical_runs(tmp_path: Path) -> None:
    """Two runs, the stack on the bridge's keys and on rmw_zenoh's: the same bytes, so the
    same commands give the same run whichever way they come."""
    runs = [_run(tmp_path, "a", rmw=False), _run(tmp_path, "b", rmw=True)]
    files = [files_of(run) for run in runs]
    assert {"run.mcap", "vessel.ego.state.csv", "vessel.ego.cmd.twist.csv"} <= set(files[0])
    assert files[0] == files[1]
    commands = [m for m in read_mcap_messages(runs[0] / "run.mcap") if m.topic == "/ego/cmd_vel"]
    assert [m.log_time for m in commands] == [k * PERIOD_NS for k in range(30)]
    for m in commands:  # each tick's command is the answer to that tick's /clock, 0's too
        assert (m.decoded.linear.x, m.decoded.angular.z) == (surge(m.log_time), 0.05)
    log = (runs[0] / "log" / "ros.log").read_text()
    assert "no longer reproducible" not in log


def test_with_no_stack_the_run_goes_on_with_the_vessel_at_rest(tmp_path: Path) -> None:
    """The wait for a /clock subscriber and the wait for its reply had each a reply timeout
    at tick 0: together past the deadline, so a ROS node started a few seconds late found
    the run failed (blaming physics). Now they share one timeout, and with nobody on /clock
    nobody can reply: the last command (at first: rest) holds at once, as documented."""
    data = _scenario() | {"duration_s": 1.0, "clock": {"deadline_s": 2.0}}
    data["ros"] = {"lockstep": True, "mode": "bridge", "reply_timeout_s": 1.5}
    out = tmp_path / "runs"
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    assert "nobody subscribes to /clock" in (run / "log" / "ros.log").read_text()
    twist = (run / "vessel.ego.cmd.twist.csv").read_text().splitlines()
    assert len(twist) == 1 + 10 and all(line.endswith(",0.0,0.0") for line in twist[1:])
