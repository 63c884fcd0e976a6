"""Whom the cause of a missed deadline names (Supervisor._waited): the participant that held
the run up, not one that waited for its data."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from catabot.run.supervisor import Stops, Supervisor

THRUST = "catabot/w/vessel/ego/cmd/thrust"


def supervisor(**waited: str) -> Supervisor:
    children: Any = {n: SimpleNamespace(waited_line=lambda w=w: w) for n, w in waited.items()}
    return Supervisor(SimpleNamespace(), children, Stops())  # type: ignore[arg-type]


def test_the_stack_the_recorder_waited_for_is_named_first() -> None:
    """A stack asleep in its step for longer than the deadline had the recorder blamed."""
    sup = supervisor(recorder=f"recorder waited at tick 301 for {THRUST} from 'stack'", stack="")
    error = "participant 'recorder' missed the 1 s deadline of tick 300"
    assert sup._waited(error) == (
        f"participant 'stack' held the run up: recorder waited at tick 301 for {THRUST} from "
        "'stack' (the conductor: participant 'recorder' missed the 1 s deadline of tick 300)"
    )


def test_a_late_stacks_own_wait_afterwards_is_left_out() -> None:
    """Named itself, its wait for physics after its long step read as physics' fault."""
    sup = supervisor(
        recorder=f"recorder waited at tick 301 for {THRUST} from 'stack'",
        stack="stack waited at tick 302 for catabot/w/world/states from 'physics'",
    )
    error = "participant 'stack' missed the 2 s deadline of tick 301"
    assert sup._waited(error) == f"{error}; recorder waited at tick 301 for {THRUST} from 'stack'"


def test_a_wait_for_no_other_participant_is_quoted_as_it_was() -> None:
    sup = supervisor(physics="physics waited at tick 5 for catabot/w/x from 'outside'")
    error = "participant 'physics' missed the 10 s deadline of tick 5"
    assert sup._waited(error) == f"{error}; physics waited at tick 5 for catabot/w/x from 'outside'"
    assert supervisor(physics="")._waited(error) == error


def test_the_earliest_wait_is_the_root_of_a_wait_on_each_other() -> None:
    """A stack that acked tick 101 without its command held physics there, then waited at 102
    for physics' states: the stack held the run up, not physics."""
    sup = supervisor(
        physics=f"physics waited at tick 101 for {THRUST} from 'stack'",
        stack="stack waited at tick 102 for catabot/w/world/states from 'physics'",
    )
    error = "participant 'physics' missed the 2 s deadline of tick 101"
    assert sup._waited(error).startswith(
        f"participant 'stack' held the run up: physics waited at tick 101 for {THRUST}"
    )
