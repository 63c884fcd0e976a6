"""The streams and participants of a world, derived from the scenario alone.

Every process computes the same table from the same scenario, so producers, consumers
and the recorder agree on periods without a negotiation round on the bus.
"""

from __future__ import annotations

from catabot.bus.clock import Stream, period_in_ticks
from catabot.bus.keys import Keys
from catabot.bus.messages import (
    BodyStates,
    ThrustCmd,
    TwistBatch,
    TwistCmd,
    VesselState,
    WaypointsCmd,
    check_ids,
)
from catabot.config.scenario import Scenario, guidance_period_ticks
from catabot.config.sensors import SENSOR_TYPES
from catabot.world.traffic_plan import all_buoys, all_vessels, plan_traffic

EXTERNAL = "external"


def body_ids(scenario: Scenario) -> tuple[str, ...]:
    """The rows of `BodyStates`: vessels (traffic included), then buoys."""
    return tuple(v.id for v in all_vessels(scenario)) + tuple(b.id for b in all_buoys(scenario))


class BodyRows:
    """Which row of a `BodyStates` holds which body: mapped once, at the first batch, then
    only checked (a changed row order would silently swap bodies between consumers)."""

    def __init__(self, expected: tuple[str, ...]) -> None:
        self.expected = expected
        self.row: dict[str, int] | None = None

    def check(self, batch: BodyStates) -> dict[str, int]:
        """The id -> row map; raises ValueError when the batch's ids are not the table's."""
        check_ids("world/states", batch.tick, batch.ids, self.expected)
        if self.row is None:
            self.row = {vid: i for i, vid in enumerate(batch.ids)}
        return self.row


def states_stream(keys: Keys) -> Stream:
    """Every body's state from physics in one batch per tick: what lockstep services read."""
    return Stream(keys.world_states(), BodyStates, "physics")


def state_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    """Each vessel's own state (traffic included), for observers and external autonomy
    stacks only: no lockstep participant waits for them (they read `states_stream`)."""
    return [Stream(keys.vessel_state(v.id), VesselState, "physics") for v in all_vessels(scenario)]


def sensor_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    return [
        Stream(
            keys.sensor(v.id, s.name),
            SENSOR_TYPES[s.type].message,
            "sensors",
            period_in_ticks(s.period_ns, scenario.dt_ns, what=f"{v.id}/{s.name}"),
        )
        for v in scenario.vessels
        for s in v.sensors
    ]


def command_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    """Each vessel's commands from outside the lockstep (tick -1, applied at the next tick
    boundary): thrust and twist, traffic boats included (an outside twist takes a boat over)."""
    out: list[Stream] = []
    for v in all_vessels(scenario):
        out.append(Stream(keys.cmd_thrust(v.id), ThrustCmd, EXTERNAL, None))
        out.append(Stream(keys.cmd_twist(v.id), TwistCmd, EXTERNAL, None))
    return out


def twist_batch_streams(scenario: Scenario, keys: Keys, *, lag: int = 0) -> list[Stream]:
    """The traffic service's set-points for all its boats, one `TwistBatch` every guidance
    period (none without traffic); physics reads them `traffic.setpoint_delay_ticks` late."""
    if scenario.traffic.count == 0:
        return []
    period = guidance_period_ticks(scenario)
    return [Stream(keys.world_twists(), TwistBatch, "traffic", period, lag)]


def waypoint_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    """High-level commands from outside: the traffic service follows them, physics only
    learns from them that an external twist or thrust override has ended."""
    return [
        Stream(keys.cmd_waypoints(v.id), WaypointsCmd, EXTERNAL, None)
        for v in all_vessels(scenario)
    ]


def traffic_boat_ids(scenario: Scenario) -> tuple[str, ...]:
    """The traffic boats, in `TwistBatch` order."""
    return tuple(b.id for b in plan_traffic(scenario).boats)


def world_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    """Every lockstep stream of the world (what the recorder waits for)."""
    return [
        states_stream(keys),
        *sensor_streams(scenario, keys),
        *twist_batch_streams(scenario, keys),
    ]


def participants(scenario: Scenario) -> list[str]:
    """Every stepping participant of the run: services, then external ones."""
    return services(scenario) + list(scenario.clock.external_participants)


def services(scenario: Scenario) -> list[str]:
    """The CataBot services a scenario needs, in start order."""
    names = ["physics"]
    if any(v.sensors for v in scenario.vessels):
        names.append("sensors")
    if scenario.traffic.count > 0:
        names.append("traffic")
    if scenario.recording.csv or scenario.recording.mcap:
        names.append("recorder")
    return names
