"""A command from outside the lockstep (tick -1) is recorded at the tick physics took it, so
the recording never shows a command after (or long before) the state it changed.

The recorder used to stamp it at its own tick when it heard it, up to a window of ticks
away from physics: a twist sent while a stack held tick 50 was recorded at 0.41-0.43 s in
three runs whose states were the same bytes. Physics now names the commands it took in
that tick's `BodyStates.commands` (catabot/bus/taken.py), and the recorder writes them
from there. Which tick that is depends on the wall clock (how far physics ran ahead within
the window when the command came), so two runs need not agree: only a lockstep command does.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from conftest import only_run_dir
from test_client import Run

from catabot.client import Client, Observation, Thrust, Twist

pytestmark = pytest.mark.timeout(180)
SCENARIO = {
    "name": "taken", "seed": 2, "duration_s": 2.0,
    "clock": {"external_participants": ["hold"]},
    "vessels": [{"id": "ego"}],
}  # fmt: skip


def _run(tmp: Path) -> Path:
    """`hold` steps every tick; at tick 50 it sends ego a free twist and holds the clock
    half a second, so physics runs to the window's end and takes it there."""
    run = Run(tmp, SCENARIO)
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            ego = sim.vessel("ego")

            def step(obs: Observation) -> None:
                if obs.tick == 50:  # send does not wait for a state here: physics, held at
                    ego.send(Twist(1.0, 0.0))  # the window's end by this step, sends none
                    time.sleep(0.5)

            sim.run_lockstep("hold", step)
        return run.finish()
    finally:
        run.kill()


def test_a_free_command_is_recorded_at_the_tick_its_state_changes(tmp_path: Path) -> None:
    folder = _run(tmp_path / "a")
    twist = np.loadtxt(folder / "vessel.ego.cmd.twist.csv", delimiter=",", skiprows=1, ndmin=2)
    assert twist.shape[0] == 1 and tuple(twist[0, 2:]) == (1.0, 0.0)
    stamp = int(twist[0, 0])
    states = np.loadtxt(folder / "vessel.ego.state.csv", delimiter=",", skiprows=1)
    moving = states[np.abs(states[:, 9]) > 1e-6]  # linear_velocity_x: surge
    assert int(moving[0, 0]) == stamp + 10_000_000  # the end of the tick it took effect
    assert twist[0, 1] > 50  # physics ran on, within the window, while the stack held 50


def test_a_stale_outside_command_hands_the_vessel_back(tmp_path: Path) -> None:
    """`command_timeout_s`: a stack that sent one thrust and went quiet stops steering the
    vessel after that long (it kept its last order to the run's end); physics applies it and
    the recorder writes the rest it goes back to, at the same tick."""
    data = SCENARIO | {"name": "stale", "duration_s": 2.5}
    data["vessels"] = [{"id": "ego", "command_timeout_s": 0.4}]
    run = Run(tmp_path, data)
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            ego = sim.vessel("ego")

            def step(obs: Observation) -> None:
                if obs.tick == 20:
                    ego.send(Thrust([0.8, 0.8]))

            sim.run_lockstep("hold", step)
        out, err = run.proc.communicate(timeout=120)
        assert run.proc.returncode == 0, out + err
        folder = only_run_dir(run.out)
    finally:
        run.kill()
    thrust = np.loadtxt(folder / "vessel.ego.cmd.thrust.csv", delimiter=",", skiprows=1)
    (taken, back), (sent, rest) = thrust[:, 1].astype(int), thrust[:, 2:]
    assert tuple(sent) == (0.8, 0.8) and tuple(rest) == (0.0, 0.0)
    assert back - (taken + 1) == 40  # 0.4 s after the tick physics took it (a row's tick + 1)
    states = np.loadtxt(folder / "vessel.ego.state.csv", delimiter=",", skiprows=1)
    surge = states[:, 9]  # linear_velocity_x
    peak = int(np.argmax(surge))  # the thrusters' lag drives it on a little after `back`
    assert back <= states[peak, 1] < back + 100 and surge[-1] < 0.95 * surge[peak]
    assert "ego: no outside command for 0.4 s (command_timeout_s): handed back" in err
