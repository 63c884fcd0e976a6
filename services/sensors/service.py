"""The sensors service: every sensor of every vessel, each at its own whole-tick period.

At tick k it samples from the newest vessel states (tagged k-1, stamped t_k: the state
at the start of this tick) and publishes samples tagged k stamped t_k. At tick 0 no
state has been published yet, so the scenario's start pose at rest stands in: it is
exactly the state physics starts from.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

from catabot.inbox import Inputs
from catabot.messages import Tick, VesselState
from catabot.participant import Participant
from catabot.scenario import VesselConfig
from catabot.service import Built, ServiceContext, run_service
from catabot.streams import state_streams
from services.sensors.registry import Sensor, build_sensor


@dataclass
class Mounted:
    vessel: str
    key: str
    period: int
    sensor: Sensor


class SensorsService:
    def __init__(self, ctx: ServiceContext) -> None:
        scenario = ctx.scenario
        self.mounted = [
            Mounted(
                v.id,
                ctx.keys.sensor(v.id, s.name),
                s.period_ns // scenario.dt_ns,
                build_sensor(
                    s,
                    vessel_id=v.id,
                    seed=scenario.seed,
                    origin=scenario.origin,
                    dt_ns=scenario.dt_ns,
                ),
            )
            for v in scenario.vessels
            for s in v.sensors
        ]
        carriers = {m.vessel for m in self.mounted}
        self.states = {v.id: start_state(v) for v in scenario.vessels if v.id in carriers}
        self.state_key = {ctx.keys.vessel_state(vid): vid for vid in self.states}
        inputs = [s for s in state_streams(scenario, ctx.keys) if s.key in self.state_key]
        self.participant = Participant(
            ctx.session, ctx.keys, ctx.name, inputs=inputs, peers=ctx.peers
        )

    def step(self, tick: Tick, inputs: Inputs) -> None:
        for key, msgs in inputs.items():
            state = msgs[-1]
            assert isinstance(state, VesselState)
            self.states[self.state_key[key]] = state
        for m in self.mounted:
            if tick.tick % m.period == 0:
                sample = m.sensor.sample(
                    self.states[m.vessel], tick=tick.tick, stamp_ns=tick.stamp_ns
                )
                self.participant.publish(m.key, sample)


def start_state(vessel: VesselConfig) -> VesselState:
    """The vessel at rest at its start pose, as physics creates it at t = 0."""
    p = vessel.pose
    assert p is not None, "poses are resolved before services start"
    half = p.yaw_rad / 2
    zero = (0.0, 0.0, 0.0)
    quat = (0.0, 0.0, math.sin(half), math.cos(half))
    return VesselState(-1, 0, (p.x_m, p.y_m, 0.0), quat, zero, zero, zero, zero)


def build(ctx: ServiceContext) -> Built:
    service = SensorsService(ctx)
    return service.participant, service.step, None


def main(argv: list[str] | None = None) -> int:
    return run_service("sensors", build, argv)


if __name__ == "__main__":
    sys.exit(main())
