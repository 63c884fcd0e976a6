"""Who is in the run: liveliness tokens `live/<name>/<zid>` bound to names by a roster.

The conductor and every participant keep one: a token that contradicts a binding (a second
session claiming a name already bound, or a name the roster gives another zid) is ignored,
so a stray client cannot join as `physics`, nor make the real physics look absent.
"""

from __future__ import annotations

from catabot.bus.identity import Roster
from catabot.bus.keys import KeyNameError, Keys


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
