"""Who is in the run: liveliness tokens `live/<name>/<zid>` bound to names by a roster.

The conductor and every participant keep one: a token that contradicts a binding (a second
session claiming a name already bound, or a name the roster gives another zid) is ignored,
so a stray client cannot join as `physics`, nor make the real physics look absent. Nor is a
name the run does not have bound (`expected`): a bound session is one of the run's, whose
samples skip the lanes that keep a stranger's flood off the run (lanes.py), and a client's
token `live/helper/<its zid>` had made its 63 KB junk commands one of the run's own (an
audit's flood stalled physics until the conductor killed it as hung).
"""

from __future__ import annotations

from collections.abc import Collection

import zenoh

from catabot.bus.identity import Roster
from catabot.bus.keys import KeyNameError, Keys
from catabot.errors import CataBotError

ASK_S = 2.0  # how long a newcomer asks who holds its name (a router answers in ms)


class NameTaken(CataBotError):
    """Another session already holds this process's name in the world (a second physics, a
    second conductor): the newcomer stops, and says so, instead of failing the run later."""


class Members:
    def __init__(
        self, keys: Keys, roster: Roster, *, expected: Collection[str] | None = None
    ) -> None:
        """`expected`: the names the run has (its participants and the conductor); None:
        any name (a watcher that only follows who is present)."""
        self.keys, self.roster = keys, roster
        self.expected = None if expected is None else frozenset(expected)
        self.present: dict[str, str] = {}  # name -> zid of the live token

    def token(self, key: str, *, alive: bool) -> str | None:
        """Apply a token event; the participant name it concerns, or None if ignored."""
        try:
            name, zid = self.keys.member_of(key)
        except KeyNameError:
            return None
        if not alive:
            if self.present.get(name) != zid:
                return None
            del self.present[name]
            return name
        if self.expected is not None and name not in self.expected:
            return None
        if not self.roster.bind(name, zid):
            return None
        self.present[name] = zid
        return name

    def refusal(self, key: str) -> str:
        """Why `token` ignored the token at `key`, as its refusal names it."""
        try:
            name, _ = self.keys.member_of(key)
        except KeyNameError:
            return "not a member's token"
        if self.expected is not None and name not in self.expected:
            return "token of no participant of this run"
        return "token contradicts the roster"

    def sender_is(self, name: str, sender: str) -> bool:
        """Whether `sender` is the session bound to `name`."""
        zid = self.roster.zid(name)
        return zid is not None and sender == zid


def claim(session: zenoh.Session, keys: Keys, name: str, roster: Roster) -> None:
    """Bind `name` to this session in `roster`; NameTaken if another session holds it in
    this world now. Asked before this process declares its own token, so the newcomer stops
    and the one already there goes on (a later token of its name is only counted there).
    `catabot run` fixes every name's session in its roster: nothing to ask then."""
    own = str(session.zid())
    if name not in roster.fixed:
        _check_free(session, keys, name, own)
    roster.bind(name, own)


def _check_free(session: zenoh.Session, keys: Keys, name: str, own: str) -> None:
    for reply in session.liveliness().get(keys.live(name, "*"), timeout=ASK_S):
        if reply.ok is None:
            continue
        try:
            _, zid = keys.member_of(str(reply.ok.key_expr))
        except KeyNameError:
            continue
        if zid != own:
            raise NameTaken(
                f"another process already runs as {name!r} in world {keys.world!r} (session "
                f"{zid}): stop one of them, or give this run another scenario name"
            )
