"""Samples and an inbox of three streams (states every tick, a GPS every 10, a free command),
shared by the inbox's tests."""

from __future__ import annotations

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.identity import Roster
from catabot.bus.inbox import Inbox
from catabot.bus.keys import Keys
from catabot.bus.messages import GpsFix, ThrustCmd, VesselState

KEYS = Keys("w")
STATE = KEYS.vessel_state("ego")
GPS = KEYS.sensor("ego", "gps")
CMD = KEYS.cmd_thrust("ego")


def _state(tick: int) -> bytes:
    zero3 = (0.0, 0.0, 0.0)
    return codec.encode(
        VesselState(tick, tick * 10, (float(tick), 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), *[zero3] * 4)
    )


def _gps(tick: int) -> bytes:
    return codec.encode(GpsFix(tick, tick * 10, 40.0, -74.0, 0.0, 0.0, 0.0))


def _cmd(value: float) -> bytes:
    return codec.encode(ThrustCmd(thrust=(value, value)))


ZIDS = {"physics": "a1", "sensors": "b2", "p": "c3"}  # each producer's session


def _inbox() -> Inbox:
    return Inbox(
        [
            Stream(STATE, VesselState, "physics", 1),
            Stream(GPS, GpsFix, "sensors", 10),
            Stream(CMD, ThrustCmd, "external", None),
        ],
        roster=Roster(ZIDS),
    )


def _add(inbox: Inbox, key: str, payload: bytes) -> None:
    """Add a sample as its producer's session sends it."""
    inbox.add(key, payload, sender=ZIDS.get(inbox.streams[key].producer, ""))
