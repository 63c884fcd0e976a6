"""The README's client example, taken from the README itself and run against live runs:
free-running on the default scenario, and in lockstep as examples/stack.json's program."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from tests.examples.test_examples import Run
from tests.paths import REPO

pytestmark = pytest.mark.timeout(180)


@pytest.fixture
def live(tmp_path: Path) -> Iterator[Callable[..., Run]]:
    """`catabot run` in the background (test_examples.Run), killed if a test fails."""
    runs: list[Run] = []

    def start(scenario: str, *flags: str) -> Run:
        runs.append(Run(tmp_path / f"runs{len(runs)}", scenario, *flags))
        return runs[-1]

    yield start
    for r in runs:
        if r.proc.poll() is None:
            r.proc.kill()
            r.proc.wait()


def readme_stack(folder: Path) -> Path:
    """The first Python block of "Plugging in your autonomy stack", as a file."""
    text = (REPO / "README.md").read_text()
    section = text.split("## Plugging in your autonomy stack", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert blocks, "the README section has no python example"
    assert len(blocks[0].splitlines()) <= 35, "the README example should stay short"
    path = folder / "my_stack.py"
    path.write_text(blocks[0])
    return path


def _stack(path: Path, *args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, str(path), *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, cwd=REPO)


def test_the_readme_stack_runs_free_and_in_lockstep(
    tmp_path: Path, live: Callable[..., Run]
) -> None:
    stack = readme_stack(tmp_path)
    sim = live("default", "--duration", "10", "--realtime", "2")
    free = _stack(stack, "--connect", sim.endpoint)
    assert free.returncode == 0, free.stderr
    assert "default catabot ['imu', 'gps'] traffic: 0" in free.stdout
    assert "run ended at tick 999: completed" in free.stdout
    thrust = (sim.finish() / "vessel.ego.cmd.thrust.csv").read_text().splitlines()
    pairs = [[float(v) for v in r.split(",")[2:]] for r in thrust[1:]]
    assert pairs and all(a + b <= 1.6 + 1e-9 for a, b in pairs)  # ahead -+ turn, ahead <= 0.8

    # in lockstep as the run's own program: `catabot run` passes --world, --vessel and
    # --participant, which a stack with only the connection flags refused
    scenario = json.loads((REPO / "examples" / "stack.json").read_text())
    scenario["vessels"][0]["controller"]["program"] = str(stack)
    (tmp_path / "stack.json").write_text(json.dumps(scenario))
    run = subprocess.run([sys.executable, "-m", "catabot", "run", str(tmp_path / "stack.json"),
                          "--quiet", "--out", str(tmp_path / "runs")], capture_output=True,
                         text=True, timeout=120, cwd=REPO)  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    folder = Path(run.stdout.split("run folder: ")[-1].strip())
    assert "run ended at tick 2999: completed" in (folder / "log" / "stack.log").read_text()
    rows = (folder / "vessel.ego.state.csv").read_text().splitlines()
    x, y = (float(v) for v in rows[-1].split(",")[2:4])
    assert abs(x - 40) < 3 and abs(y - 20) < 3, (x, y)  # it steered to its goal
