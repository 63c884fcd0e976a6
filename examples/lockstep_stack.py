"""A deterministic autonomy stack: joins the lockstep, reads its vessel's state, sends thrust.

The scenario names this program as the vessel's controller (`"controller": {"participant":
"stack", "rate_hz": 10}`); the run waits for it, and every command is applied at the same
tick on every run, so two runs record the same bytes. This one steers to a goal point with
differential thrust (thruster 0 port, 1 starboard): copy it and put your stack in `decide`.
It needs no scenario file: the world, the vessel and its controller come from the run.

catabot run examples/stack.json --listen tcp/127.0.0.1:7447 &
python examples/lockstep_stack.py --connect tcp/127.0.0.1:7447 --goal 40 20
"""

import math

from common import clear_errors, parser, report
from guidance import yaw_of

from catabot.client import Client, EndRun, Observation, Thrust


def decide(x: float, y: float, yaw: float, goal: tuple[float, float]) -> tuple[float, float]:
    """Port and starboard thrust (-1..1) that turn the bow to the goal and slow down near it."""
    dx, dy = goal[0] - x, goal[1] - y
    error = math.remainder(math.atan2(dy, dx) - yaw, math.tau)
    ahead = min(math.hypot(dx, dy) / 10.0, 0.8) * max(math.cos(error), 0.0)
    turn = max(-0.5, min(0.5, 1.2 * error))  # positive: turn left, starboard pushes harder
    return max(-1.0, min(ahead - turn, 1.0)), max(-1.0, min(ahead + turn, 1.0))


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--goal", type=float, nargs=2, default=(40.0, 20.0), metavar=("X", "Y"))
    p.add_argument(
        "--end-within",
        type=float,
        metavar="M",
        help="end the run once the vessel is within M metres of the goal",
    )
    p.set_defaults(world=None)  # the one world running
    args = p.parse_args()
    goal = (args.goal[0], args.goal[1])
    seen = [(0.0, 0.0)]

    def step(obs: Observation) -> Thrust:
        assert obs.state is not None  # the state at the start of this control period
        x, y, _ = obs.state.position
        seen[0] = (x, y)
        if args.end_within and math.dist((x, y), goal) < args.end_within:
            raise EndRun(f"goal reached at t = {obs.time_s:.1f} s")  # ends it for everyone
        return Thrust(decide(x, y, yaw_of(obs.state.orientation), goal))

    with clear_errors("lockstep_stack.py"), Client.from_args(args) as sim:
        end = sim.run_lockstep(args.participant, step, vessel=args.vessel)  # None: its seat
    report(end, f"{args.vessel} at ({seen[0][0]:.2f}, {seen[0][1]:.2f})")


if __name__ == "__main__":
    main()
