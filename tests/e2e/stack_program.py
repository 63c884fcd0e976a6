"""A controller program `catabot run` starts itself (`vessels[].controller.program`): takes
the flags the launcher passes (catabot/run/programs.py), joins the lockstep as its
participant and sends differential thrust toward a goal; `--crash-at T` raises at tick T,
`--nan-at T` sends a NaN thrust for tick T and `--skip-at T` none (yet acks the tick): what
a buggy stack in another language may do. `--leave` exits at once without joining, and
`--linger` keeps running after the run (a ROS spin, a plot window).
"""

import argparse
import math
import os
import time

from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, ThrustCmd, Tick
from catabot.bus.participant import Participant
from catabot.bus.session import add_connection_args, connection_from_args, open_session
from catabot.config.load import load_scenario
from catabot.world import rotations
from catabot.world.world import World


def main() -> None:
    p = argparse.ArgumentParser()
    add_connection_args(p)
    p.add_argument("--world", required=True)
    p.add_argument("--vessel", required=True)
    p.add_argument("--participant", required=True)
    p.add_argument("--goal", type=float, nargs=2, default=(30.0, 10.0))
    p.add_argument("--crash-at", type=int, default=-1)
    p.add_argument("--nan-at", type=int, default=-1)
    p.add_argument("--skip-at", type=int, default=-1)
    p.add_argument("--sleep-at", type=float, nargs=2, default=(-1, 0.0))  # tick, seconds
    p.add_argument("--leave", action="store_true")
    p.add_argument("--linger", action="store_true")
    args = p.parse_args()
    if args.leave:
        return
    world = World.resolve(load_scenario(os.environ["CATABOT_SCENARIO"]))
    assert world.scenario.name == args.world
    me = world.body(args.vessel)
    (commands,) = [s for s in world.streams.controls if world.keys.vessel_of(s.key) == me.id]
    latest = world.start_states()
    with open_session(connection_from_args(args)) as s:
        stack = Participant(
            s, world.keys, args.participant, inputs=[world.streams.states],
            peers=world.participants, limits=world.clock_limits,
        )  # fmt: skip

        def step(tick: Tick, inputs: Inputs) -> None:
            nonlocal latest
            if tick.tick == args.crash_at:
                raise ZeroDivisionError(f"the stack fell over at tick {tick.tick}")
            if tick.tick == args.sleep_at[0]:
                time.sleep(args.sleep_at[1])
            for batch in inputs.get(world.streams.states.key, []):
                assert isinstance(batch, BodyStates)
                latest = batch
            if tick.tick % commands.period or tick.tick == args.skip_at:
                return
            x, y, _ = latest.position[me.row].tolist()
            yaw = float(rotations.yaw_of_quaternions(latest.orientation[me.row : me.row + 1])[0])
            error = math.remainder(math.atan2(args.goal[1] - y, args.goal[0] - x) - yaw, math.tau)
            turn = max(-0.5, min(0.5, 1.2 * error))
            thrust = (0.6 - turn, 0.6 + turn) if tick.tick != args.nan_at else (math.nan,) * 2
            stack.publish(commands.key, ThrustCmd(thrust, tick=tick.tick, stamp_ns=tick.stamp_ns))

        end = stack.run(step)
        print(f"stack ended at tick {end.tick} ({end.reason})", flush=True)
    while args.linger:
        time.sleep(1.0)


if __name__ == "__main__":
    main()
