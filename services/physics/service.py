"""The physics service: a DART world stepped once per tick, states published every tick.

At tick k it applies the orders in force (scripted, or the latest from the bus, which
arrived before tick k), advances t_k → t_(k+1) and publishes every body's state at
t_(k+1) tagged k: consumers see it from tick k+1 on (DESIGN.md §4's one-tick delay).
"""

from __future__ import annotations

import logging
import sys

import numpy as np

from catabot.bus.inbox import Inputs
from catabot.bus.messages import BodyStates, Message, Tick, TwistBatch, VesselState
from catabot.bus.settings import changes_of
from catabot.bus.strays import watch_strays
from catabot.bus.taken import entry
from catabot.config import live
from catabot.config.notes import late_steps
from catabot.run.advice import advise
from catabot.run.service import Built, ServiceContext, run_service
from catabot.world.sea_change import SeaChange
from services.physics import settings
from services.physics.commands import CommandBook, some
from services.physics.control import TwistControllerBank
from services.physics.reach import Reach
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
        world = ctx.world
        self.world = build_world(world)
        self.keys = ctx.keys
        self.dt_ns = world.scenario.dt_ns
        self.controllers = TwistControllerBank(
            [v.model for v in world.vessels], dt_s=self.dt_ns / 1e9
        )
        self.book = CommandBook(world.vessels)
        self.driven_by = world.driven_by  # clock.policy drop: the vessels a participant drove
        self.reach = Reach(world.vessels, self.controllers.single)  # says a twist is too much
        for text in late_steps(world.scenario):
            advise(log, text)
        streams = world.streams
        self.streams = [*streams.commands, *streams.controls, *streams.waypoints]
        self.vessel_of = {s.key: ctx.keys.vessel_of(s.key) for s in self.streams}
        self.blocks = {s.key: ids for s, ids in zip(streams.twists, world.traffic_blocks.values(),
                                                      strict=True)}  # fmt: skip
        delay = world.scenario.traffic.setpoint_delay_ticks  # physics steps ahead of traffic
        self.streams += streams.twist_batches(lag=delay)
        self.body_ids = world.body_ids
        self.state_keys = [s.key for s in streams.vessel_states]
        guidance = streams.guidance_states  # the traffic's copy of the states, when it has one
        self.guidance = guidance if guidance.key != streams.states.key else None
        self.scenario, self.specs = world.scenario, live.keys_of(world.scenario)
        self.sea = SeaChange(world.waves, dt_ns=self.dt_ns)
        self.participant = ctx.participant(self.streams)
        watch_strays(self.participant, ctx.keys.vessel_commands(), self._stray)

    def _stray(self, key: str) -> str:
        """Why a command key physics does not take is none: no such vessel, or command."""
        _, vessel, _, command = self.keys.relative(key).split("/")
        if vessel not in self.book.row:
            return f"no vessel {vessel!r} in this world (its vessels: {some(self.book.ids)})"
        return f"no command {command!r} (a vessel takes thrust, twist, waypoints)"

    def step(self, tick: Tick, inputs: Inputs) -> None:
        changes = changes_of(tick.settings)
        settings.take(self.world, self.scenario, self.specs, changes, tick=tick.tick, sea=self.sea)
        inbox = self.participant.inbox
        for name in inbox.stalled_by(tick.tick):  # a dropped stack's vessels handed back
            self.book.drop(name, self.driven_by([name]), tick.stamp_ns)
        taken: list[str] = []  # free commands (tick -1), for the recorder (taken.py)
        for key, msgs in inputs.items():
            if inbox.streams[key].producer in inbox.handed:
                continue  # a dropped stack's late sample: its vessel was handed back
            if key in self.blocks:
                self._take_twists(msgs[-1], self.blocks[key])
                continue
            self.book.take(self.vessel_of[key], msgs, tick.stamp_ns)
            self.reach.heard(self.vessel_of[key], msgs)
            rel = self.keys.relative(key)
            taken += [entry(rel, m) for m in msgs if getattr(m, "tick", 0) == -1]
        self._apply_orders(tick.stamp_ns)
        self.world.step()
        self._publish(tick, tuple(taken))

    def _take_twists(self, batch: Message, boats: tuple[str, ...]) -> None:
        assert isinstance(batch, TwistBatch)  # the inbox decodes each stream as its type
        self.book.take_batch(batch, boats)

    def _apply_orders(self, stamp_ns: int) -> None:
        """Thrust orders as given; twist orders through one controller pass for all vessels."""
        thrust, rows, target = self.book.orders(stamp_ns)
        for row, values in thrust.items():
            try:
                self.world.set_thrust(self.world.vessel_ids[row], values)
            except ValueError as exc:
                log.error("vessel %s: refused thrust command: %s", self.world.vessel_ids[row], exc)
        if rows.size:
            measured = self.world.surge_and_yaw_rate(rows)
            try:
                self.world.set_thrusts(rows, self.controllers.command(rows, target, measured))
            except ValueError as exc:
                log.error("refused controller output: %s", exc)

    def _publish(self, tick: Tick, taken: tuple[str, ...]) -> None:
        """One batch of every body for the lockstep services, then each vessel's own state
        for observers (buoys only in the batch: nobody outside follows a buoy). A vessel's
        own state is encoded only while someone subscribes to it: with 100 boats and no
        viewer that is 100 encodes a tick for nobody."""
        stamp = tick.stamp_ns + self.dt_ns
        v, b = self.world.state_arrays(), self.world.buoy_state_arrays()
        cols = [np.concatenate((getattr(v, f), getattr(b, f))) for f in FIELDS]
        also = [self.guidance.key] if self.guidance and self.guidance.is_due(tick.tick) else []
        pos, quat, vel, rate, acc, spin = cols
        batch = BodyStates(tick.tick, stamp, self.body_ids, pos, quat, vel, rate, acc, spin, taken)
        self.participant.publish(self.keys.world_states(), batch, also=also)
        for i in self.participant.watched_among(self.state_keys):
            row = (tuple(getattr(v, f)[i].tolist()) for f in FIELDS)
            self.participant.publish(self.state_keys[i], VesselState(tick.tick, stamp, *row))


def build(ctx: ServiceContext) -> Built:
    service = PhysicsService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("physics", build, argv)


if __name__ == "__main__":
    sys.exit(main())
