"""The physics service: a DART world stepped once per tick, states published every tick.

At tick k it applies the orders in force (scripted, or the latest from the bus, which
arrived before tick k), advances t_k → t_(k+1) and publishes every body's state at
t_(k+1) tagged k: consumers see it from tick k+1 on (DESIGN.md §4's one-tick delay).
"""

from __future__ import annotations

import logging
import sys

import numpy as np

from catabot.inbox import Inputs
from catabot.messages import BodyStates, Tick, VesselState
from catabot.participant import Participant
from catabot.service import Built, ServiceContext, run_service
from catabot.streams import command_streams, waypoint_streams
from catabot.traffic_plan import all_vessels
from services.physics.commands import CommandBook
from services.physics.control import TwistControllerBank
from services.physics.setup import build_world

log = logging.getLogger("physics")
FIELDS = (  # the KinematicsArrays fields, in BodyStates / VesselState order
    "position",
    "orientation",
    "linear_velocity",
    "angular_velocity",
    "linear_acceleration",
    "angular_acceleration",
)


class PhysicsService:
    def __init__(self, ctx: ServiceContext) -> None:
        scenario = ctx.scenario
        self.world, models = build_world(scenario)
        self.keys = ctx.keys
        self.dt_ns = scenario.dt_ns
        ids = self.world.vessel_ids
        self.controllers = TwistControllerBank([models[v] for v in ids], dt_s=self.dt_ns / 1e9)
        self.book = CommandBook(
            all_vessels(scenario), {vid: len(m.thrusters) for vid, m in models.items()}
        )
        self.streams = command_streams(scenario, ctx.keys) + waypoint_streams(scenario, ctx.keys)
        self.vessel_of = {s.key: ctx.keys.vessel_of(s.key) for s in self.streams}
        self.body_ids = (*ids, *self.world.buoy_ids)
        self.state_keys = [ctx.keys.vessel_state(vid) for vid in ids]
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
        """Thrust orders as given; twist orders through one controller pass for all vessels."""
        ids = self.world.vessel_ids
        orders = [self.book.order(vid, stamp_ns) for vid in ids]
        commands: list[tuple[float, ...]] = [o.thrust or () for o in orders]
        rows = np.array([i for i, o in enumerate(orders) if o.twist is not None], dtype=np.intp)
        if rows.size:
            s = self.world.state_arrays()
            measured = np.stack([s.linear_velocity[rows, 0], s.angular_velocity[rows, 2]], axis=1)
            target = np.array([orders[i].twist for i in rows], dtype=np.float64)
            out = self.controllers.command(rows, target, measured)
            for j, i in enumerate(rows):
                commands[i] = tuple(out[j, : self.controllers.count[i]])
        for vid, command in zip(ids, commands, strict=True):
            if command:
                try:
                    self.world.set_thrust(vid, command)
                except ValueError as exc:
                    log.error("vessel %s: refused thrust command: %s", vid, exc)

    def _publish(self, tick: Tick) -> None:
        """One batch of every body for the lockstep services, then each vessel's own state
        for observers (buoys only in the batch: nobody outside follows a buoy)."""
        stamp = tick.stamp_ns + self.dt_ns
        v, b = self.world.state_arrays(), self.world.buoy_state_arrays()
        cols = [np.concatenate((getattr(v, f), getattr(b, f))) for f in FIELDS]
        self.participant.publish(
            self.keys.world_states(), BodyStates(tick.tick, stamp, self.body_ids, *cols)
        )
        rows = zip(*(getattr(v, f).tolist() for f in FIELDS), strict=True)
        for key, row in zip(self.state_keys, rows, strict=True):
            self.participant.publish(key, VesselState(tick.tick, stamp, *map(tuple, row)))


def build(ctx: ServiceContext) -> Built:
    service = PhysicsService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("physics", build, argv)


if __name__ == "__main__":
    sys.exit(main())
