"""Every Zenoh key expression of a world (DESIGN.md §3).

No other module spells a key by hand: a typo in a key is a silent loss of data on a
pub/sub bus, so keys are built in exactly one place and names are checked here.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from catabot.errors import CataBotError

ROOT = "catabot"
_NAME = re.compile(r"^[A-Za-z0-9_.\-]{1,64}$")  # one chunk of a key, and part of file names


class KeyNameError(CataBotError, ValueError):
    """A name that cannot be one chunk of a Zenoh key expression."""


def check_name(kind: str, name: str) -> str:
    """Refuse names that would change a key's meaning ('/', wildcards, '$', spaces) or not fit
    in a file name (the recorder names files after streams)."""
    if not isinstance(name, str) or not _NAME.match(name):
        shown = repr(name) if len(repr(name)) <= 80 else repr(name)[:77] + "..."
        raise KeyNameError(
            f"{kind} name {shown} is not allowed in a key: use 1-64 letters, digits, '_', '-' "
            "or '.'"
        )
    return name


def lives_of(participant: str) -> str:
    """A participant's liveliness tokens in any world (a container's health check)."""
    return f"{ROOT}/*/live/{check_name('participant', participant)}/*"


def world_infos() -> str:
    """Every running world's `world/info` queryable: how a client finds the worlds."""
    return f"{ROOT}/*/world/info"


@dataclass(frozen=True)
class Keys:
    """The key expressions of one world: `catabot/<world>/...`."""

    world: str

    def __post_init__(self) -> None:
        check_name("world", self.world)

    @property
    def prefix(self) -> str:
        return f"{ROOT}/{self.world}"

    def all(self) -> str:
        return f"{self.prefix}/**"

    def tick(self) -> str:
        return f"{self.prefix}/clock/tick"

    def ack(self, participant: str) -> str:
        return f"{self.prefix}/clock/ack/{check_name('participant', participant)}"

    def acks(self) -> str:
        return f"{self.prefix}/clock/ack/*"

    def end(self) -> str:
        return f"{self.prefix}/clock/end"

    def live(self, participant: str, zid: str) -> str:
        """A participant's liveliness token: its name and its session's zid (identity.py);
        zid "*": every token of that name (who holds `physics`?)."""
        return f"{self.prefix}/live/{check_name('participant', participant)}/{zid}"

    def lives(self) -> str:
        return f"{self.prefix}/live/*/*"

    def vessel_state(self, vessel: str) -> str:
        return f"{self.prefix}/vessel/{check_name('vessel', vessel)}/state"

    def vessel_states(self) -> str:
        return f"{self.prefix}/vessel/*/state"

    def world_states(self) -> str:
        """Every body's state in one `BodyStates` per tick (what lockstep services read)."""
        return f"{self.prefix}/world/states"

    def guidance_states(self) -> str:
        """The same `BodyStates` only at the tick before each traffic guidance tick: what
        the traffic service reads (it would otherwise receive ten batches to use one)."""
        return f"{self.prefix}/world/states/guidance"

    def world_twists(self, shard: int | None = None) -> str:
        """Every traffic boat's twist set-point in one `TwistBatch` per tick (lockstep); with
        `traffic.shards`, each shard's block of boats on a key of its own."""
        base = f"{self.prefix}/world/cmd/twist"
        return base if shard is None else f"{base}/{shard:02d}"  # sorted = shard order

    def vessel_commands(self) -> str:
        """Every command key of every vessel, named or not (physics' watch for strays)."""
        return f"{self.prefix}/vessel/*/cmd/*"

    def cmd_thrust(self, vessel: str) -> str:
        return f"{self.prefix}/vessel/{check_name('vessel', vessel)}/cmd/thrust"

    def cmd_twist(self, vessel: str) -> str:
        return f"{self.prefix}/vessel/{check_name('vessel', vessel)}/cmd/twist"

    def cmd_waypoints(self, vessel: str) -> str:
        return f"{self.prefix}/vessel/{check_name('vessel', vessel)}/cmd/waypoints"

    def cmds(self) -> str:
        return f"{self.prefix}/vessel/*/cmd/*"

    def sensor(self, vessel: str, sensor: str) -> str:
        return f"{self.prefix}/sensor/{check_name('vessel', vessel)}/{check_name('sensor', sensor)}"

    def env_state(self) -> str:
        return f"{self.prefix}/env/state"

    def world_info(self) -> str:
        """Queryable of the conductor: the resolved world as JSON (catabot/run/world_info.py)."""
        return f"{self.prefix}/world/info"

    def config(self, name: str) -> str:
        return f"{self.prefix}/config/{check_name('config', name)}"

    def configs(self) -> str:
        """What the conductor's settings desk answers (catabot/run/settings_desk.py)."""
        return f"{self.prefix}/config/**"

    def config_changes(self) -> str:
        """The recorded stream of run-time setting changes (`SettingsChange`)."""
        return self.config("changes")

    def relative(self, key: str) -> str:
        """The part of a key after `catabot/<world>/`, used to name files and topics."""
        head = self.prefix + "/"
        if not key.startswith(head):
            raise KeyNameError(f"key {key!r} is not in world {self.world!r}")
        return key[len(head) :]

    def vessel_of(self, key: str) -> str:
        """The vessel id of a `vessel/<id>/...` or `sensor/<id>/...` key of this world."""
        parts = self.relative(key).split("/")
        if len(parts) < 3 or parts[0] not in ("vessel", "sensor"):
            raise KeyNameError(f"key {key!r} names no vessel")
        return parts[1]

    def participant_of(self, key: str) -> str:
        """The participant named by the last chunk of an ack key."""
        return key.rsplit("/", 1)[-1]

    def member_of(self, key: str) -> tuple[str, str]:
        """(name, zid) of a liveliness token key `live/<name>/<zid>`; KeyNameError if not one."""
        parts = self.relative(key).split("/")
        if len(parts) != 3 or parts[0] != "live":
            raise KeyNameError(f"key {key!r} is not a liveliness token of world {self.world!r}")
        return parts[1], parts[2]
