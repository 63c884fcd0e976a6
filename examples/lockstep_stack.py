"""A deterministic autonomy stack: joins the lockstep, reads its vessel's state, sends thrust.

The scenario names this program as the vessel's controller (`"controller": {"participant":
"stack", "rate_hz": 10}`); the run waits for it, and every command is applied at the same
tick on every run, so two runs record the same bytes. This one steers to a goal point with
differential thrust (thruster 0 port, 1 starboard): copy it and put your stack in `decide`.

catabot run examples/stack.json --listen tcp/127.0.0.1:7447 &
python examples/lockstep_stack.py examples/stack.json --connect tcp/127.0.0.1:7447 --goal 40 20
"""

import math

from common import parser, session

from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, ThrustCmd, Tick
from catabot.bus.participant import Participant
from catabot.config.load import load_scenario
from catabot.world import rotations
from catabot.world.world import World


def decide(x: float, y: float, yaw: float, goal: tuple[float, float]) -> tuple[float, float]:
    """Port and starboard thrust (-1..1) that turn the bow to the goal and slow down near it."""
    dx, dy = goal[0] - x, goal[1] - y
    error = math.remainder(math.atan2(dy, dx) - yaw, math.tau)
    ahead = min(math.hypot(dx, dy) / 10.0, 0.8) * max(math.cos(error), 0.0)
    turn = max(-0.5, min(0.5, 1.2 * error))  # positive: turn left, starboard pushes harder
    return max(ahead - turn, -1.0), min(ahead + turn, 1.0)


def main() -> None:
    p = parser(__doc__)
    p.add_argument("scenario", help="the scenario file the run was started with")
    p.add_argument("--goal", type=float, nargs=2, default=(40.0, 20.0), metavar=("X", "Y"))
    args = p.parse_args()
    world = World.resolve(load_scenario(args.scenario))
    me = world.body(args.vessel)
    if me.controller is None:
        raise SystemExit(f"vessel {me.id!r} has no controller in {args.scenario}")
    (commands,) = [s for s in world.streams.controls if world.keys.vessel_of(s.key) == me.id]
    latest = world.start_states()

    with session(args) as s:
        stack = Participant(
            s, world.keys, me.controller.participant, inputs=[world.streams.states],
            peers=world.participants, limits=world.clock_limits,
        )  # fmt: skip

        def step(tick: Tick, inputs: Inputs) -> None:
            nonlocal latest
            for batch in inputs.get(world.streams.states.key, []):
                assert isinstance(batch, BodyStates)
                latest = batch  # the state at the start of this tick (tagged tick - 1)
            if tick.tick % commands.period:
                return
            x, y, _ = latest.position[me.row].tolist()
            yaw = float(rotations.yaw_of_quaternions(latest.orientation[me.row : me.row + 1])[0])
            thrust = decide(x, y, yaw, tuple(args.goal))
            stack.publish(commands.key, ThrustCmd(thrust, tick=tick.tick, stamp_ns=tick.stamp_ns))

        end = stack.run(step)
        x, y, _ = latest.position[me.row].tolist()
        print(f"run ended at tick {end.tick} ({end.reason}); {me.id} at ({x:.2f}, {y:.2f})")


if __name__ == "__main__":
    main()
