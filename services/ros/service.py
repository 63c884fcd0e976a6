"""The ROS 2 gateway: the world as ROS 2 topics on Zenoh, and ROS commands back in, for a
ROS 2 stack that has no CataBot code in it (zenoh-bridge-ros2dds or rmw_zenoh on its side).

Started by `catabot run` when the scenario has a `ros` section, or alone with
`catabot service ros --scenario ... --connect ...`. By default it observes: it subscribes to
the world's streams like any client and never holds the clock. With `ros.lockstep: true` it
is a stepping participant: nothing is dropped, and vessels whose controller is "ros" take the
stack's commands at the same tick on every run (gateway.py).
"""

from __future__ import annotations

import logging
import sys
import threading

from catabot.bus.inbox import Inputs
from catabot.bus.messages import End, Tick
from catabot.bus.participant import EndFn
from catabot.bus.rejections import Rejections
from catabot.config.ros import GATEWAY, RosConfig
from catabot.run.service import Built, ServiceContext, run_service
from services.ros.gateway import Gateway
from services.ros.observer import Observer


def build(ctx: ServiceContext) -> Built:
    ros = ctx.scenario.ros or RosConfig()  # `catabot service ros` on a scenario without one
    world = ctx.world
    inputs = [world.streams.states, *world.streams.sensors]
    if ros.lockstep:
        participant = ctx.participant(inputs)
        gateway = Gateway(
            world, ros, ctx.session, publish=participant.publish, rejections=participant.rejections
        )

        def step(tick: Tick, received: Inputs) -> None:
            gateway.publish(received, clock_from_states=False)
            gateway.clocked(tick)

        return participant, step, _closer(gateway)
    wake = threading.Event()
    refused = Rejections(logging.getLogger("ros"), "ros")  # the observer's and the commands'
    gateway = Gateway(world, ros, ctx.session, on_command=wake.set, rejections=refused)
    observer = Observer(ctx.session, ctx.keys, inputs, gateway.wanted, wake, roster=ctx.roster,
                        rejections=refused)  # fmt: skip

    def observe(_: Tick, received: Inputs) -> None:
        gateway.publish(received, clock_from_states=True)
        gateway.commands()

    return observer, observe, _closer(gateway)


def _closer(gateway: Gateway) -> EndFn:
    def on_end(end: End, received: Inputs) -> None:
        gateway.close()

    return on_end


def main(argv: list[str] | None = None) -> int:
    return run_service(GATEWAY, build, argv, timestamping=True)


if __name__ == "__main__":
    sys.exit(main())
