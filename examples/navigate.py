"""An obstacle-avoiding navigator: takes its vessel to a goal through traffic on LiDAR, GPS and
IMU alone (no simulator state). Each control period it bins the scan into a local occupancy
grid (raindrops dropped by their reflectivity), groups the cells into objects and tracks their
velocities (tracking.py), and picks the arc of a dynamic window that best trades progress,
clearance from the predicted obstacles and speed (planning.py); it sends a twist or
differential thrust, whichever its vessel's controller takes, and stops within --tolerance of
the goal.

catabot run examples/navigate.json      # the scenario starts this stack (controller.program)
# or by hand, beside a run whose vessel has a controller but no program:
python examples/navigate.py --connect tcp/127.0.0.1:7447 --goal 80 0
"""

from __future__ import annotations

import math
import time

import numpy as np
from common import clear_errors, parser, report
from guidance import Catamaran, LocalFrame, goal_of, yaw_of
from planning import GridSpec, Planner, choose, reflectivity, world_offsets
from tracking import Obstacles, Tracker

from catabot.client import Client, Observation, SensorInfo, Thrust, Twist


class Navigator:
    """The stack's state between control periods: the last command (the dynamic window's
    centre) and what it has seen, for the summary."""

    def __init__(self, frame: LocalFrame, goal: tuple[float, float], lidar: SensorInfo,
                 kind: str, period_s: float, tolerance_m: float) -> None:  # fmt: skip
        self.frame, self.goal, self.kind = frame, np.array(goal), kind
        self.mount = np.array(lidar.mount_xyz), np.array(lidar.mount_rpy)
        self.period_s, self.tolerance_m = period_s, tolerance_m
        self.obstacles = Obstacles(GridSpec(), Tracker())
        self.plan, self.boat = Planner(), Catamaran()
        self.surge = self.yaw_rate = 0.0
        self.scanned_ns = -1
        self.seen: tuple[np.ndarray, np.ndarray] = (np.empty((0, 2)), np.empty((0, 2)))
        self.arrived_s: float | None = None
        self.busy_s, self.steps = 0.0, 0  # wall-clock cost of the stack (the log only)
        self.closest_m = math.inf  # nearest occupied cell seen
        self.position = (math.nan, math.nan)

    def step(self, obs: Observation) -> Thrust | Twist | None:
        started = time.perf_counter()
        try:
            return self._step(obs)
        finally:
            self.busy_s += time.perf_counter() - started
            self.steps += 1

    def _step(self, obs: Observation) -> Thrust | Twist | None:
        fix, imu, scan = (obs.sensors[n] for n in ("gps", "imu", "lidar"))
        if fix is None or imu is None:
            return None  # the first period: nothing measured yet, keep still
        self.position = self.frame.to_local(fix.latitude, fix.longitude)
        to_goal = self.goal - self.position
        if scan is not None and scan.stamp_ns != self.scanned_ns:  # a new scan: update the map
            dt = (scan.stamp_ns - self.scanned_ns) / 1e9 if self.scanned_ns >= 0 else self.period_s
            offsets = world_offsets(scan.points, *self.mount, np.array(imu.orientation))
            power = reflectivity(scan.points, scan.intensity)
            self.seen = self.obstacles.update(offsets, power, np.array(self.position), dt)
            self.scanned_ns = scan.stamp_ns
            if len(self.seen[0]):
                self.closest_m = min(self.closest_m, float(np.hypot(*self.seen[0].T).min()))
        cells, velocities = self.seen
        if self.arrived_s is None and math.hypot(*to_goal) < self.tolerance_m:
            self.arrived_s = obs.time_s
            print(f"t={obs.time_s:6.1f} s  reached the goal at {self.where()}", flush=True)
        if self.arrived_s is not None:
            self.surge = self.yaw_rate = 0.0
        else:
            heading = yaw_of(np.array(imu.orientation))
            self.surge, self.yaw_rate = choose(self.surge, self.yaw_rate, heading, to_goal, cells,
                                               velocities, self.period_s, self.plan)  # fmt: skip
        if self.kind == "twist":
            return Twist(self.surge, self.yaw_rate)
        return Thrust(self.boat.thrust(self.surge, self.yaw_rate, imu.angular_velocity[2]))

    def where(self) -> str:
        return f"({self.position[0]:.1f}, {self.position[1]:.1f})"


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--goal", type=float, nargs=2, metavar=("X", "Y"),
                   help="in map (m); default: the vessel's task.goal in the scenario")  # fmt: skip
    p.add_argument("--tolerance", type=float, default=3.0, help="m from the goal to stop")
    args = p.parse_args()
    with clear_errors("navigate.py"), Client.from_args(args) as sim:
        vessel = sim.vessel(args.vessel).info
        if vessel.controller is None:
            raise SystemExit(f"vessel {vessel.id!r} has no controller: nothing to join as")
        lidar = vessel.sensor("lidar")
        vessel.sensor("gps"), vessel.sensor("imu")  # UnknownSensor now rather than later
        scenario, control = sim.info.scenario, vessel.controller
        if control.command == "thrust" and vessel.model != "catabot":
            raise SystemExit(f"navigate.py mixes thrust for the catabot model only "
                             f"({vessel.id!r} is a {vessel.model!r}): use twist")  # fmt: skip
        nav = Navigator(
            LocalFrame.of_scenario(scenario), goal_of(args.goal, scenario, vessel.id), lidar,
            control.command, control.period_ticks * sim.info.dt_ns / 1e9, args.tolerance,
        )  # fmt: skip
        name = args.participant or control.participant
        end = sim.run_lockstep(name, nav.step, vessel=vessel.id, sensors=["gps", "imu", "lidar"])
    arrived = f"arrived at t={nav.arrived_s:.1f} s" if nav.arrived_s is not None else "not arrived"
    report(
        end,
        f"{vessel.id} at {nav.where()}, {arrived}, nearest obstacle seen "
        f"{nav.closest_m:.1f} m; {1e3 * nav.busy_s / max(nav.steps, 1):.1f} ms a period",
    )


if __name__ == "__main__":
    main()
