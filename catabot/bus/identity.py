"""Who sent a sample: Zenoh session ids (zids), bound to participant names.

Anything on the bus may come from a buggy or hostile client, so the lockstep believes a
clock message or a lockstep sample only from the session that owns its name: the conductor
for ticks and ends, a stream's producer for its samples, a participant for its acks.

- Every CataBot publisher puts with Zenoh `source_info` (its session id and a sequence
  number); `sender_of(sample)` reads it back. This guards against a buggy client, not a
  hostile one: a put states whatever source info its sender gives it (zenoh-python takes
  any `SourceInfo`), and every sample a client receives shows the ids to copy. So on the
  embedded mesh (loopback by default) a hostile local process can pose as any participant.
  The secure profile is what makes identities enforceable: TLS, a login per process, and a
  router whose access control lets each login put only its own keys.
- Names are bound to zids by a `Roster`: given by `catabot run`, which picks a random zid
  for every process it starts (`--zid`, `--roster`), or learnt from liveliness tokens
  `live/<name>/<zid>` (first binding wins; a second token claiming a bound name is ignored;
  a binding outlives its token, so the conductor's End is believed after its token is gone).
"""

from __future__ import annotations

import argparse
import secrets
from collections.abc import Mapping

import zenoh

from catabot.errors import CataBotError


class RosterError(CataBotError, ValueError):
    """A roster or zid that cannot be used."""


def new_zid() -> str:
    """A random Zenoh session id: 128 bits in hex, unguessable (Zenoh refuses a leading 0)."""
    return f"{secrets.randbits(124) | 1 << 124:032x}"


def check_zid(zid: str) -> str:
    """A zid as Zenoh takes it and prints it back: 1-32 lower-case hex digits, no leading 0."""
    ok = 1 <= len(zid) <= 32 and all(c in "0123456789abcdef" for c in zid)
    if not ok or zid.startswith("0"):
        raise RosterError(f"zid {zid!r} is not 1-32 lower-case hex digits without a leading 0")
    return zid


def sender_of(sample: zenoh.Sample) -> str:
    """The zid of the session that published `sample` ("" when it did not say)."""
    info = sample.source_info
    return str(info.source_id.zid) if info is not None else ""


def shown(sender: str) -> str:
    """A sender as every refusal names it: a sample without Zenoh source info was shown as
    `sender ?` by some refusals and as `sender ` (blank) by others."""
    return f"sender {sender or 'unsaid (no Zenoh source info)'}"


class Roster:
    """Participant name -> zid, fixed entries first, then bindings learnt from tokens."""

    def __init__(self, fixed: Mapping[str, str] | None = None) -> None:
        self.fixed = {name: check_zid(zid) for name, zid in (fixed or {}).items()}
        self.learnt: dict[str, str] = {}

    @classmethod
    def parse(cls, text: str) -> Roster:
        """`name=zid,name=zid` (the form `catabot run` passes with `--roster`)."""
        pairs = [p.partition("=") for p in text.split(",") if p]
        if any(not name or not zid for name, _, zid in pairs):
            raise RosterError(f"roster {text!r}: use name=zid,name=zid")
        return cls({name: zid for name, _, zid in pairs})

    def __str__(self) -> str:
        return ",".join(f"{name}={zid}" for name, zid in self.fixed.items())

    def zid(self, name: str) -> str | None:
        return self.fixed.get(name) or self.learnt.get(name)

    def knows(self, zid: str) -> bool:
        """Whether `zid` is one of the run's sessions (called for every sample: no copies)."""
        return zid in self.fixed.values() or zid in self.learnt.values()

    def bind(self, name: str, zid: str) -> bool:
        """Learn `name` from a token; False (ignore the token) if it contradicts a binding."""
        known = self.zid(name)
        if known is None:
            self.learnt[name] = zid
            return True
        return known == zid


def add_roster_args(parser: argparse.ArgumentParser) -> None:
    """The flag with which `catabot run` tells each process every participant's session id."""
    parser.add_argument(
        "--roster",
        type=Roster.parse,
        default=Roster(),
        metavar="NAME=ZID,...",
        help="each participant's Zenoh session id (default: learnt from liveliness tokens)",
    )
