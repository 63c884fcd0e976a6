"""The physics service: a DART world stepped once per tick, states published every tick.

At tick k it applies the orders in force (scripted, or the latest from the bus, which
arrived before tick k), advances t_k → t_(k+1) and publishes each vessel's state at
t_(k+1) tagged k: consumers see it from tick k+1 on (DESIGN.md §4's one-tick delay).
"""

from __future__ import annotations

import logging
import sys

from catabot.inbox import Inputs
from catabot.messages import Tick, VesselState
from catabot.participant import Participant
from catabot.service import Built, ServiceContext, run_service
from catabot.streams import command_streams
from services.physics.commands import CommandBook
from services.physics.control import TwistController
from services.physics.setup import build_world

log = logging.getLogger("physics")


class PhysicsService:
    def __init__(self, ctx: ServiceContext) -> None:
        scenario = ctx.scenario
        self.world, models = build_world(scenario)
        self.keys = ctx.keys
        self.dt_ns = scenario.dt_ns
        self.controllers = {
            vid: TwistController(m, dt_s=self.dt_ns / 1e9) for vid, m in models.items()
        }
        self.book = CommandBook(
            scenario.vessels, {vid: len(m.thrusters) for vid, m in models.items()}
        )
        self.streams = command_streams(scenario, ctx.keys)
        self.vessel_of = {s.key: s.key.split("/")[-3] for s in self.streams}
        self.participant = Participant(
            ctx.session, ctx.keys, ctx.name, inputs=self.streams, peers=ctx.peers
        )

    def step(self, tick: Tick, inputs: Inputs) -> None:
        for key, msgs in inputs.items():
            self.book.take(self.vessel_of[key], key, msgs)
        self._apply_orders(tick.stamp_ns)
        self.world.step()
        self._publish(tick)

    def _apply_orders(self, stamp_ns: int) -> None:
        states = self.world.states()
        for vid in self.world.vessel_ids:
            order = self.book.order(vid, stamp_ns)
            if order.twist is not None:
                s = states[vid]
                measured = (float(s.linear_velocity[0]), float(s.angular_velocity[2]))
                command = tuple(self.controllers[vid].command(order.twist, measured))
            else:
                command = order.thrust or ()
            if command:
                try:
                    self.world.set_thrust(vid, command)
                except ValueError as exc:
                    log.error("vessel %s: refused thrust command: %s", vid, exc)

    def _publish(self, tick: Tick) -> None:
        stamp = tick.stamp_ns + self.dt_ns
        for vid, s in self.world.states().items():
            self.participant.publish(
                self.keys.vessel_state(vid),
                VesselState(
                    tick.tick,
                    stamp,
                    _t(s.position),
                    _t(s.orientation),
                    _t(s.linear_velocity),
                    _t(s.angular_velocity),
                    _t(s.linear_acceleration),
                    _t(s.angular_acceleration),
                ),
            )


def _t(values: object) -> tuple[float, ...]:
    return tuple(float(v) for v in values)  # type: ignore[attr-defined]


def build(ctx: ServiceContext) -> Built:
    service = PhysicsService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("physics", build, argv)


if __name__ == "__main__":
    sys.exit(main())
