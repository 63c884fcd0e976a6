"""Every example runs against a live simulation (zenoh-python's examples check, our shape):
a real `catabot run` listening on loopback, the example as its own process connecting to it."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from catabot.bus.session import free_port
from tests.paths import REPO

pytestmark = pytest.mark.timeout(180)
EXAMPLES = REPO / "examples"


def example(name: str, *args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, str(EXAMPLES / name), *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=REPO)


class Run:
    """`catabot run` in the background, listening on its own port."""

    def __init__(self, out: Path, scenario: str, *flags: str) -> None:
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.out = out
        cmd = [sys.executable, "-m", "catabot", "run", scenario, "--quiet", "--out", str(out)]
        self.proc = subprocess.Popen(
            [*cmd, "--listen", self.endpoint, *flags],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO,
        )  # fmt: skip

    def finish(self, timeout: float = 120) -> Path:
        stdout, stderr = self.proc.communicate(timeout=timeout)
        assert self.proc.returncode == 0, stdout + stderr
        (run_dir,) = [p for p in self.out.iterdir() if p.is_dir()]
        return run_dir


@pytest.fixture
def run(tmp_path: Path) -> Iterator[type[Run]]:
    runs: list[Run] = []

    def start(scenario: str, *flags: str) -> Run:
        r = Run(tmp_path / f"runs{len(runs)}", scenario, *flags)
        runs.append(r)
        return r

    yield start  # type: ignore[misc]
    for r in runs:
        if r.proc.poll() is None:
            r.proc.kill()
            r.proc.wait()


def test_every_example_has_a_main_and_is_checked_here() -> None:
    source = Path(__file__).read_text()
    for path in sorted(EXAMPLES.glob("*.py")):
        if path.name != "common.py":
            assert 'if __name__ == "__main__":\n    main()' in path.read_text(), path.name
            assert f'"{path.name}"' in source, f"{path.name} has no test here"


def test_watch_state_prints_the_vessel_moving(run: type[Run]) -> None:
    sim = run("default", "--duration", "8", "--realtime", "2")
    shown = example("watch_state.py", "--connect", sim.endpoint, "--count", "5", "--every", "20")
    assert shown.returncode == 0, shown.stderr
    lines = [ln for ln in shown.stdout.splitlines() if ln.startswith("t=")]
    assert len(lines) == 5 and "x=" in lines[0] and "u=" in lines[0]
    sim.finish()


def test_send_thrust_is_recorded_and_applied(run: type[Run]) -> None:
    sim = run("default", "--duration", "6", "--realtime", "2")
    sent = example("send_thrust.py", "--connect", sim.endpoint, "--thrust", "0.5", "-0.25",
                   "--repeat", "3")  # fmt: skip
    assert sent.returncode == 0, sent.stderr
    rows = (sim.finish() / "vessel.ego.cmd.thrust.csv").read_text().splitlines()
    assert rows[0] == "stamp_ns,tick,thrust_0,thrust_1"
    assert [r.split(",")[2:] for r in rows[1:]] == [["0.5", "-0.25"]] * 3


def test_send_thrust_says_when_no_simulation_listens() -> None:
    lonely = f"tcp/127.0.0.1:{free_port()}"
    sent = example("send_thrust.py", "--listen", lonely, "--thrust", "0.1", "0.1", "--wait", "2",
                   timeout=30)  # fmt: skip
    assert sent.returncode != 0 and "no simulation subscribes" in sent.stderr


def test_lockstep_stack_reaches_its_goal_and_records_the_same_bytes_twice(
    run: type[Run],
) -> None:
    recorded = []
    for _ in range(2):
        sim = run("examples/stack.json")
        stack = example("lockstep_stack.py", "--connect", sim.endpoint, "--goal", "40", "20",
                        timeout=120)  # fmt: skip
        assert stack.returncode == 0, stack.stderr
        assert "run ended at tick 2999 (completed)" in stack.stdout
        run_dir = sim.finish()
        recorded.append({p.name: p.read_bytes() for p in sorted(run_dir.glob("*.csv"))})
        recorded[-1]["run.mcap"] = (run_dir / "run.mcap").read_bytes()
    assert recorded[0] == recorded[1]
    last = recorded[0]["vessel.ego.state.csv"].decode().splitlines()[-1].split(",")
    x, y = float(last[2]), float(last[3])
    assert abs(x - 40.0) < 2.0 and abs(y - 20.0) < 2.0, (x, y)
    commands = recorded[0]["vessel.ego.cmd.thrust.csv"].decode().splitlines()
    assert len(commands) == 1 + 300  # 10 Hz for 30 s, each tagged with its tick
    assert [c.split(",")[1] for c in commands[1:4]] == ["0", "10", "20"]
