"""Whose liveliness tokens bind a name (catabot/bus/members.py): only the run's own names. A
client's token `live/helper/<its zid>` was bound like a participant's, so its samples skipped
the lanes that hold a stranger's flood (test_lockstep_flood has the live run)."""

from __future__ import annotations

from catabot.bus.identity import Roster
from catabot.bus.keys import Keys
from catabot.bus.members import Members

KEYS = Keys("w")


def test_a_token_of_a_name_the_run_has_binds_it() -> None:
    roster = Roster()
    members = Members(KEYS, roster, expected={"physics", "conductor"})
    assert members.token(KEYS.live("physics", "a1"), alive=True) == "physics"
    assert roster.knows("a1") and members.present == {"physics": "a1"}


def test_a_token_of_a_name_the_run_does_not_have_is_refused_and_never_trusted() -> None:
    roster = Roster()
    members = Members(KEYS, roster, expected={"physics", "conductor"})
    key = KEYS.live("helper", "b2")
    assert members.token(key, alive=True) is None
    assert not roster.knows("b2") and members.present == {}
    assert members.refusal(key) == "token of no participant of this run"
    assert members.token(key, alive=False) is None  # its leave changes nothing either


def test_a_watcher_follows_any_name() -> None:
    members = Members(KEYS, Roster())
    assert members.token(KEYS.live("helper", "b2"), alive=True) == "helper"
