"""What the figures draw from a run's scenario: the rain rate as the run had it, the
vessels' tasks, the boats' numbers."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle

from catabot.config.load import parse_scenario
from catabot.world.world import World
from services.plots.compare import run_labels
from services.plots.figures import (
    _changes,
    _in_force,
    _view,
    draw_task,
    rain_steps,
    task_points,
)
from services.plots.marks import boat_names
from services.plots.series import _thruster_names, own_pairs


def test_the_rain_rate_follows_the_settings_timeline() -> None:
    """`catabot set rain 25` (written back into the run's scenario.json as a timeline entry)
    was drawn as the scenario's starting rate for the whole run."""
    scenario = parse_scenario({
        "name": "wet", "duration_s": 10.0, "rain": {"rate_mm_h": 5.0},
        "vessels": [{"id": "ego"}],
        "settings": [{"t_s": 6.0, "key": "rain", "value": 0}, {"t_s": 2.5, "key": "rain",
                     "value": 25}, {"t_s": 3.0, "key": "waves", "value": "heavy"}],
    })  # fmt: skip
    t, rate = rain_steps(scenario, 10.0)
    assert t.tolist() == [0.0, 2.5, 6.0, 10.0] and rate.tolist() == [5.0, 25.0, 0.0, 0.0]
    at = rate[np.searchsorted(t, [0.0, 2.4, 2.5, 7.0], side="right") - 1]
    assert at.tolist() == [5.0, 5.0, 25.0, 0.0]


def test_without_changes_the_rain_is_the_scenarios() -> None:
    scenario = parse_scenario({"name": "dry", "duration_s": 4.0, "vessels": [{"id": "ego"}]})
    t, rate = rain_steps(scenario, 4.0)
    assert t.tolist() == [0.0, 4.0] and rate.tolist() == [0.0, 0.0]


def test_trajectories_mark_the_task_and_number_the_boats() -> None:
    """A scenario author checks a vessel's goal and route against its track, and which
    white track is which boat."""
    world = World.resolve(parse_scenario({
        "name": "task", "vessels": [{"id": "ego", "task": {
            "goal": {"x_m": 60.0, "y_m": 20.0, "radius_m": 4.0}, "route": [[0, 0], [30, 5]]}}],
        "traffic": {"count": 12, "region": {"center_m": [0.0, 300.0], "size_m": [200.0, 200.0]}},
    }))  # fmt: skip
    assert task_points(world, ["ego"]).tolist() == [
        [56.0, 16.0],
        [64.0, 24.0],
        [0.0, 0.0],
        [30.0, 5.0],
    ]
    fig, ax = plt.subplots()
    draw_task(ax, world.scenario.vessels[0].task, "#ff8c00", "ego")
    xy = np.zeros((2, len(world.bodies), 2))
    boat_names(ax, world, xy)
    (goal,) = [p for p in ax.patches if isinstance(p, Circle)]
    assert goal.center == (60.0, 20.0) and goal.radius == 4.0 and goal.get_label() == "ego goal"
    assert [line.get_label() for line in ax.lines] == ["ego route"]
    assert [t.get_text() for t in ax.texts] == [str(i) for i in range(12)]  # boat_000 -> "0"
    plt.close(fig)


def test_a_thrust_is_drawn_until_a_twist_takes_over_and_back() -> None:
    """The default run's thrust plot held 0.3/0.9 from 40 s to the end while its twist
    controller drove (a newcomer's reading of plots/thrust.png)."""
    thrust_t, thrust = np.array([0.0, 10.0]), np.array([[0.5, 0.5], [0.3, 0.9]])
    t, held = _in_force(thrust_t, thrust, np.array([40.0]), 60.0)
    assert t.tolist() == [0.0, 10.0, 40.0, 60.0]
    assert held[:2].tolist() == thrust.tolist() and np.isnan(held[2:]).all()
    t, held = _in_force(np.array([40.0]), np.array([[1.0, 0.0]]), thrust_t, 60.0)
    assert t.tolist() == [0.0, 10.0, 40.0, 60.0] and held[2:].tolist() == [[1.0, 0.0]] * 2


def test_the_own_view_holds_the_scenario_vessels_and_the_full_view_the_traffic() -> None:
    """A fleet of three filled a corner of a 300 m frame spread by the traffic: the own
    vessels get a figure of their own, cropped to their tracks and tasks."""
    world = World.resolve(parse_scenario({
        "name": "fleet", "vessels": [{"id": "a"}, {"id": "b", "pose": {"x_m": 20.0}}],
        "traffic": {"count": 2, "region": {"center_m": [0.0, 300.0], "size_m": [100.0, 100.0]}},
    }))  # fmt: skip
    position = np.zeros((2, len(world.bodies), 3))
    position[:, 1, 0] = 20.0
    position[:, 2:4, :2] = [[-50.0, 250.0], [50.0, 350.0]]
    data = SimpleNamespace(run=SimpleNamespace(world=world), own=["a", "b"],
                           states=SimpleNamespace(position=position))  # fmt: skip
    lo, hi = _view(data, everyone=True)  # type: ignore[arg-type]
    assert lo.tolist() == [-90.0, -40.0] and hi.tolist() == [90.0, 390.0]
    lo, hi = _view(data, everyone=False)  # type: ignore[arg-type]
    assert lo.tolist() == [-10.0, -10.0] and hi.tolist() == [30.0, 10.0]


def test_thrusters_are_named_by_their_side() -> None:
    """ "thruster 0" left a student to find in the model file which one is port."""
    world = World.resolve(parse_scenario({"name": "t", "vessels": [{"id": "ego"}]}))
    thrusters = world.body("ego").model.thrusters
    assert _thruster_names(thrusters, 2) == ("thruster 0 (port)", "thruster 1 (starboard)")
    assert _thruster_names(thrusters, 3)[2] == "thruster 2"  # more values than thrusters


def test_setting_changes_are_marked_where_they_took_effect() -> None:
    """A current set mid-run bent the track, and the plots did not say when."""
    scenario = parse_scenario({
        "name": "set", "duration_s": 10.0, "vessels": [{"id": "ego"}],
        "settings": [{"t_s": 5.5, "key": "current", "value": [0.0, -1.0]}],
    })  # fmt: skip
    fig, ax = plt.subplots()
    _changes(ax, scenario)
    (line,) = ax.lines
    assert list(line.get_xdata()) == [5.5, 5.5]
    assert [t.get_text() for t in ax.texts] == ["current = [0.0, -1.0]"]
    plt.close(fig)


def test_compared_runs_are_named_by_what_differs_from_the_first() -> None:
    """Two lab runs differ in their current: the legend says so, not only their folders; a
    change made while it ran is named with its time, whole, and a run that did not
    complete says how it ended (a value had been cut mid-list, an end left out)."""
    calm = {"name": "lab", "vessels": [{"id": "ego", "script": [{"t_s": 0, "thrust": [1, 1]}]}]}
    drift = {**calm, "water": {"current": {"velocity_mps": [0.0, 0.5]}}}
    live = {**calm, "settings": [{"t_s": 1.26, "key": "current", "value": [0.3, 0.0]}]}
    other = {
        "name": "harbour",
        "vessels": [{"id": "boat", "model": "wamv"}],
        "seed": 3,
        "duration_s": 9.0,
        "traffic": {"count": 2},
        "buoys": [{"id": "b", "x_m": 30, "y_m": 0}],
    }
    ends = ("completed", "completed", "fault", "completed")
    runs = [SimpleNamespace(run=SimpleNamespace(folder=Path(f"runs/{n}"),
                                                world=World.resolve(parse_scenario(d)),
                                                end_reason=lambda e=e: e))
            for n, d, e in zip("abcd", (calm, drift, live, other), ends, strict=True)]  # fmt: skip
    assert run_labels(runs) == [  # type: ignore[arg-type]
        "a (water.current.velocity_mps=[0.0, 0.0])", "b (water.current.velocity_mps=[0.0, 0.5])",
        "c (water.current.velocity_mps=[0.0, 0.0], current=[0.3, 0.0] at 1.26 s, ended: fault)",
        "d (scenario harbour)"]  # fmt: skip


def test_each_pair_of_own_vessels_has_its_distance() -> None:
    """The closest approach of any two flattened after a pile-up: a fleet's pairs apart."""
    xy = np.zeros((2, 3, 2))
    xy[:, 1, 0], xy[:, 2, 1] = [3.0, 6.0], [4.0, 8.0]
    pairs = own_pairs(xy, ["a", "b", "c"])
    assert {k: v.tolist() for k, v in pairs.items()} == {
        "a-b": [3.0, 6.0], "a-c": [4.0, 8.0], "b-c": [5.0, 10.0]}  # fmt: skip
    assert (
        own_pairs(xy[:, :1], ["a"]) == {} and own_pairs(np.zeros((2, 7, 2)), list("abcdefg")) == {}
    )
