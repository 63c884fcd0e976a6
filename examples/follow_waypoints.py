"""A line-of-sight path follower on GPS and IMU alone: the fix in the local frame (the world's
GPS origin, guidance.LocalFrame), the heading from the IMU, a lookahead point on the current
leg to steer at, and the cross-track error reported as it goes and summed up at the end.

catabot run examples/follow_waypoints.json    # the scenario starts this stack
# or by hand, free-running beside any run (a vessel with no controller):
python examples/follow_waypoints.py --connect tcp/127.0.0.1:7447 --waypoints 0 0 20 0 20 15
"""

from __future__ import annotations

import math

from common import clear_errors, parser, report
from guidance import Catamaran, LocalFrame, line_of_sight, next_leg, route_of, steer, wrap, yaw_of

from catabot.client import Client, End, Observation, Thrust, Twist


class Follower:
    """Where the vessel is on its path, and the cross-track errors so far."""

    def __init__(self, frame: LocalFrame, path: list[tuple[float, float]], kind: str,
                 speed: float, lookahead_m: float, accept_m: float) -> None:  # fmt: skip
        self.frame, self.path, self.kind = frame, path, kind
        self.speed, self.lookahead_m, self.accept_m = speed, lookahead_m, accept_m
        self.leg = 0
        self.errors: list[float] = []
        self.done_s: float | None = None
        self.boat = Catamaran()
        self.position = (math.nan, math.nan)
        self.said_s = -math.inf  # a progress line every 5 s of simulated time

    def step(self, obs: Observation) -> Thrust | Twist | None:
        fix, imu = obs.sensors["gps"], obs.sensors["imu"]
        if fix is None or imu is None:
            return None
        self.position = self.frame.to_local(fix.latitude, fix.longitude)
        self.leg = next_leg(self.position, self.path, self.leg, self.accept_m)
        surge = rate = 0.0
        if self.leg < len(self.path) - 1:
            a, b = self.path[self.leg], self.path[self.leg + 1]
            wanted, cross, _ = line_of_sight(self.position, a, b, self.lookahead_m)
            heading = yaw_of(imu.orientation)
            rate = steer(wanted, heading, gain=0.8, max_rate=0.5)
            surge = self.speed * max(0.3, math.cos(wrap(wanted - heading)))  # turn, then go
            self.errors.append(cross)
            if obs.time_s - self.said_s >= 5.0:  # free-running steps fall anywhere
                self.said_s = obs.time_s
                x, y = self.position
                print(f"t={obs.time_s:6.1f} s  ({x:6.1f}, {y:6.1f})  leg {self.leg}  "
                      f"cross-track {cross:+5.2f} m", flush=True)  # fmt: skip
        elif self.done_s is None:
            self.done_s = obs.time_s
            print(f"t={obs.time_s:6.1f} s  path done", flush=True)
        if self.kind == "twist":
            return Twist(surge, rate)
        return Thrust(self.boat.thrust(surge, rate, imu.angular_velocity[2]))

    def summary(self) -> str:
        e = [abs(v) for v in self.errors] or [math.nan]
        done = f"done at t={self.done_s:.1f} s" if self.done_s is not None else "not done"
        rms = math.sqrt(sum(v * v for v in e) / len(e))
        return (f"path {done} (leg {self.leg} of {len(self.path) - 1}); cross-track error "
                f"mean {sum(e) / len(e):.2f} m, rms {rms:.2f} m, max {max(e):.2f} m")  # fmt: skip


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--waypoints", type=float, nargs="+", metavar="X Y",
                   help="the path in map (m); default: the vessel's task.route")  # fmt: skip
    p.add_argument("--speed", type=float, default=1.2, help="m/s along the path")
    p.add_argument("--lookahead", type=float, default=4.0, help="m down the path to aim at")
    p.add_argument("--accept", type=float, default=2.5, help="m from a waypoint to take the next")
    p.add_argument(
        "--command",
        choices=["twist", "thrust"],
        default="twist",
        help="what to send when free-running (in lockstep: the controller's kind)",
    )
    p.add_argument("--rate", type=float, default=10.0, help="Hz when free-running")  # fmt: skip
    args = p.parse_args()
    with clear_errors("follow_waypoints.py"), Client.from_args(args) as sim:
        vessel = sim.vessel(args.vessel).info
        control = vessel.controller
        frame, scenario = LocalFrame.of_scenario(sim.info.scenario), sim.info.scenario
        path = route_of(args.waypoints, scenario, vessel.id)
        kind = control.command if control is not None else args.command
        if kind == "thrust" and vessel.model != "catabot":
            raise SystemExit(f"follow_waypoints.py mixes thrust for the catabot model only "
                             f"({vessel.id!r} is a {vessel.model!r}): use twist")  # fmt: skip
        follower = Follower(frame, path, kind, args.speed, args.lookahead, args.accept)
        end: End | None
        if control is not None:
            name = args.participant or control.participant
            end = sim.run_lockstep(name, follower.step, vessel=vessel.id, sensors=["gps", "imu"])
        else:
            end = sim.run_free(follower.step, rate_hz=args.rate, vessel=vessel.id,
                               sensors=["gps", "imu"])  # fmt: skip
    report(end, follower.summary())


if __name__ == "__main__":
    main()
