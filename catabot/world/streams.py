"""The streams of a world: every key with its message type, producer and period in ticks.

Every process derives the same table from the same resolved world, so producers, consumers
and the recorder agree on periods without a negotiation round on the bus (DESIGN.md §8).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from catabot.bus import checks
from catabot.bus.clock import Stream
from catabot.bus.messages import (
    BodyStates,
    ThrustCmd,
    TwistBatch,
    TwistCmd,
    VesselState,
    WaypointsCmd,
)
from catabot.config.rates import guidance_period_ticks, rate_in_ticks
from catabot.config.sensors import SENSOR_TYPES

if TYPE_CHECKING:
    from catabot.world.world import Body, World

EXTERNAL = "external"  # the producer of commands from outside the lockstep


@dataclass(frozen=True)
class Streams:
    states: Stream  # every body in one `BodyStates` a tick: what lockstep services read
    vessel_states: tuple[Stream, ...]  # each vessel's own state, for observers only
    sensors: tuple[Stream, ...]
    commands: tuple[Stream, ...]  # thrust and twist of every vessel from outside (tick -1)
    controls: tuple[Stream, ...]  # the commands of vessels' controllers (lockstep stacks)
    waypoints: tuple[Stream, ...]  # high-level commands from outside
    twists: tuple[Stream, ...]  # the traffic service's set-points, one per shard (or none)
    guidance_states: Stream  # the states the traffic service reads (see `_guidance_states`)

    @classmethod
    def of(cls, world: World) -> Streams:
        keys, vessels = world.keys, world.vessels
        commands = [s for v in vessels for s in _commands(world, v)]
        owner = world.sensor_owners
        states = Stream(
            keys.world_states(),
            BodyStates,
            "physics",
            stamp_ticks=1,  # the state at the end of the tick
            check=checks.body_states(world.body_ids),
        )
        return cls(
            states=states,
            vessel_states=tuple(
                Stream(keys.vessel_state(v.id), VesselState, "physics") for v in vessels
            ),
            sensors=tuple(
                Stream(s.key, SENSOR_TYPES[s.config.type].message, owner[s.key], s.period)
                for s in world.sensors
            ),
            commands=tuple(s for s in commands if s.period is None),
            controls=tuple(s for s in commands if s.period is not None),
            waypoints=tuple(_waypoints(world, v) for v in vessels),
            twists=_twist_batches(world),
            guidance_states=_guidance_states(world, states),
        )

    def lockstep(self) -> list[Stream]:
        """Every clocked stream of the world (what the recorder waits for)."""
        return [self.states, *self.sensors, *self.twist_batches(), *self.controls]

    def twist_batches(self, *, lag: int = 0) -> list[Stream]:
        """The traffic set-points (empty without traffic), read `lag` ticks late."""
        return [replace(s, lag=lag) for s in self.twists]


def _commands(world: World, vessel: Body) -> list[Stream]:
    """A vessel's thrust and twist keys: free-running (tick -1, from anyone), except the one
    its controller drives, which is clocked (the controller is its producer)."""
    keys, c = world.keys, vessel.controller
    out = []
    for kind, key, message, check in (
        (
            "thrust",
            keys.cmd_thrust(vessel.id),
            ThrustCmd,
            checks.thrust(len(vessel.model.thrusters)),
        ),
        ("twist", keys.cmd_twist(vessel.id), TwistCmd, checks.twist),
    ):
        if c is not None and c.command == kind:
            period = rate_in_ticks(c.rate_hz, world.scenario.dt_ns, where=key)
            out.append(Stream(key, message, c.participant, period, check=check))
        else:
            out.append(Stream(key, message, EXTERNAL, None, check=_free(vessel, check, kind)))
    return out


def _waypoints(world: World, vessel: Body) -> Stream:
    key = world.keys.cmd_waypoints(vessel.id)
    check = checks.waypoints if vessel.kind == "boat" else checks.release_only(vessel.id)
    return Stream(key, WaypointsCmd, EXTERNAL, None, check=_free(vessel, check, "waypoints"))


def _free(vessel: Body, check: checks.Check, kind: str) -> checks.Check:
    """A free-running command's check, or `checks.driven` for a vessel a controller drives."""
    c = vessel.controller
    return check if c is None else checks.driven(vessel.id, c.participant, c.command, kind=kind)


def _twist_batches(world: World) -> tuple[Stream, ...]:
    """The traffic service's set-points, one batch a guidance period from each shard for its
    block of boats (one shard: every boat, on `world/cmd/twist`)."""
    blocks = world.traffic_blocks
    period = guidance_period_ticks(world.scenario) if blocks else 0
    return tuple(
        Stream(_twist_key(world, i), TwistBatch, name, period, check=checks.twist_batch(ids))
        for i, (name, ids) in enumerate(blocks.items())
    )


def _guidance_states(world: World, states: Stream) -> Stream:
    """The states traffic guidance reads at tick k (a multiple of its period P) are those
    tagged k - 1: physics also puts them, the same bytes, on their own key at ticks
    k % P == P - 1, so the traffic service receives and decodes one batch a guidance period,
    not one a tick (and waits for physics only at guidance ticks). With P = 1 it is the
    states stream itself."""
    if not world.traffic_blocks:
        return states
    period = guidance_period_ticks(world.scenario)
    if period == 1:
        return states
    return replace(states, key=world.keys.guidance_states(), period=period, phase=period - 1)


def _twist_key(world: World, shard: int) -> str:
    return world.keys.world_twists(shard if world.scenario.traffic.shards > 1 else None)
