"""Who is in the run: liveliness tokens `live/<name>/<zid>` bound to names by a roster.

The conductor and every participant keep one: a token that contradicts a binding (a second
session claiming a name already bound, or a name the roster gives another zid) is ignored,
so a stray client cannot join as `physics`, nor make the real physics look absent.
"""

from __future__ import annotations

import zenoh

from catabot.bus.identity import Roster
from catabot.bus.keys import KeyNameError, Keys
from catabot.errors import CataBotError

ASK_S = 2.0  # how long a newcomer asks who holds its name (a router answers in ms)


class NameTaken(CataBotError):
    """Another session already holds this process's name in the world (a second physics, a
    second conductor): the newcomer stops, and says so, instead of failing the run later."""


class Members:
    def __init__(self, keys: Keys, roster: Roster) -> None:
        self.keys, self.roster = keys, roster
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
        if not self.roster.bind(name, zid):
            return None
        self.present[name] = zid
        return name

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
