"""The streams and participants of a world, derived from the scenario alone.

Every process computes the same table from the same scenario, so producers, consumers
and the recorder agree on periods without a negotiation round on the bus.
"""

from __future__ import annotations

from catabot.clock import Stream, period_in_ticks
from catabot.keys import Keys
from catabot.messages import ThrustCmd, TwistCmd, VesselState
from catabot.scenario import Scenario
from catabot.sensor_types import SENSOR_TYPES

EXTERNAL = "external"


def state_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    return [Stream(keys.vessel_state(v.id), VesselState, "physics") for v in scenario.vessels]


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
    """Commands from outside the lockstep: applied at the next tick boundary."""
    out: list[Stream] = []
    for v in scenario.vessels:
        out.append(Stream(keys.cmd_thrust(v.id), ThrustCmd, EXTERNAL, None))
        out.append(Stream(keys.cmd_twist(v.id), TwistCmd, EXTERNAL, None))
    return out


def world_streams(scenario: Scenario, keys: Keys) -> list[Stream]:
    """Every lockstep stream of the world (what the recorder waits for)."""
    return state_streams(scenario, keys) + sensor_streams(scenario, keys)


def participants(scenario: Scenario) -> list[str]:
    """Every stepping participant of the run: services, then external ones."""
    return services(scenario) + list(scenario.clock.external_participants)


def services(scenario: Scenario) -> list[str]:
    """The CataBot services a scenario needs, in start order."""
    names = ["physics"]
    if any(v.sensors for v in scenario.vessels):
        names.append("sensors")
    if scenario.recording.csv or scenario.recording.mcap:
        names.append("recorder")
    return names
