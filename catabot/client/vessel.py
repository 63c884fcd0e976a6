"""A vessel as a stack sees it outside the lockstep: its state, its sensors, its commands.

An observer never blocks the clock (DESIGN.md §4): states and samples are whatever physics
and the sensors publish, the newest kept; a command sent here is free-running (tick -1),
applied at the next tick boundary after it arrives. For commands applied at the same tick
on every run, join the lockstep (`Client.join`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from catabot.bus import checks
from catabot.bus.clock import Stream
from catabot.bus.messages import Message, VesselState, WaypointsCmd
from catabot.bus.outputs import Outputs
from catabot.client.commands import Command, kind_of, message
from catabot.client.errors import CommandError
from catabot.client.info import SensorInfo, VesselInfo
from catabot.client.watch import Latest, Watch


class Sensor:
    """One sensor of a vessel: `latest(timeout_s)` and `on_sample(callback)`; samples are the
    typed messages of catabot.bus.messages (LidarScan, ImuSample, GpsFix, CameraFrame,
    RadarSweep) with NumPy arrays."""

    def __init__(self, watch: Watch, vessel: str, info: SensorInfo) -> None:
        self.info = info
        stream = Stream(info.key, info.message, info.producer, None)  # observed: no tags
        self._latest = Latest(watch, stream, f"sample of sensor {vessel}/{info.name}")

    def latest(self, timeout_s: float = 2.0) -> Any:
        """The newest sample, waiting up to `timeout_s` for a first one (NoData): this Sensor
        subscribed when it was made, so keep it; a fresh one's `latest(0)` has none yet."""
        return self._latest.wait(timeout_s)

    def on_sample(self, callback: Callable[[Any], None]) -> None:
        """`callback(sample)` for every sample from now on (on a Zenoh thread: be quick)."""
        self._latest.add(callback)


class Vessel:
    def __init__(
        self, watch: Watch, outputs: Outputs, info: VesselInfo, *, ready_timeout_s: float = 5.0
    ) -> None:
        self.info, self.id = info, info.id
        self._watch, self._outputs = watch, outputs
        self._ready_timeout_s = ready_timeout_s
        self._state: Latest | None = None
        self._sensors: dict[str, Sensor] = {}

    def _states(self) -> Latest:
        if self._state is None:
            stream = Stream(self.info.state_key, VesselState, "physics", None)
            self._state = Latest(self._watch, stream, f"state of vessel {self.id!r}")
        return self._state

    def state(self, timeout_s: float = 2.0) -> VesselState:
        """The newest state (pose in `map`, body-frame twist and acceleration); waits up to
        `timeout_s` for the first one (NoData), RunEnded once the run is over."""
        msg = self._states().wait(timeout_s)
        assert isinstance(msg, VesselState)
        return msg

    def on_state(self, callback: Callable[[VesselState], None]) -> None:
        """`callback(state)` for every state from now on (on a Zenoh thread: be quick)."""
        self._states().add(callback)

    def sensor(self, name: str) -> Sensor:
        """UnknownSensor (listing this vessel's sensors) if it has none by that name."""
        if name not in self._sensors:
            self._sensors[name] = Sensor(self._watch, self.id, self.info.sensor(name))
        return self._sensors[name]

    def send(self, command: Command) -> None:
        """Send a Thrust, Twist or Waypoints now (free-running); CommandError if the vessel
        cannot take it. Before the run's first tick it waits for it (up to the client's
        timeout; NoData then): a command sent while the services were still subscribing
        reached some of them only (the recorder wrote a thrust that physics never got). Not
        from a lockstep step of this client: the run is going, and a state to wait for may
        never come while the step holds the clock."""
        kind = kind_of(command)
        controller = self.info.controller
        if controller is not None and controller.command == kind:
            raise CommandError(
                f"vessel {self.id!r}'s {kind} is driven in lockstep by participant "
                f"{controller.participant!r}: send it with act() after "
                f"join({controller.participant!r}); a free {kind} on that key would be refused"
            )
        msg: Message = message(command, self.info)
        # the bus's own rules for a free command (catabot/world/streams.py applies them)
        if controller is not None:
            _refused(
                checks.driven(self.id, controller.participant, controller.command, kind=kind), msg
            )
        if isinstance(msg, WaypointsCmd) and self.info.kind != "boat":
            _refused(checks.release_only(self.id), msg, instead=(
                f"vessel {self.id!r} follows no path from the bus (traffic boats do): send "
                "Thrust or Twist from your own guidance; Waypoints(mode='release') ends an "
                "outside order"))  # fmt: skip
        if not self._watch.ticking:  # a stack of ours steps: the run is going already
            self.state(self._ready_timeout_s)  # the run is going: every service hears it
        self._outputs.publish(self.info.command_keys[kind], msg)


def _refused(check: checks.Check, msg: Message, *, instead: str | None = None) -> None:
    """`check(msg)`, its refusal a CommandError (saying `instead`, when given)."""
    try:
        check(msg)
    except ValueError as exc:
        raise CommandError(instead or str(exc)) from None
