"""A participant that stops on a fault of its own tells the conductor why (`Ack.fault`), so
the run's error quotes it on every host; a bad or forged fault text changes nothing."""

from __future__ import annotations

import time

import pytest

from catabot.bus.clock import Policy
from catabot.bus.conductor import GONE_GRACE_S, SILENT, WORDS_S
from catabot.bus.inbox import Inputs
from catabot.bus.messages import Ack, Tick
from tests.catabot.bus.lockstep_world import Step, World

WHY = "No space left on device: runs/x/vessel.ego.state.csv"


def _tells_at(world: World, tick: int, why: str) -> Step:
    """At `tick` it reports `why` and leaves, as a service's exit path does."""

    def step(t: Tick, _inputs: Inputs) -> None:
        if t.tick == tick:
            world.members["teller"].participant.report_fault(why)
            world.members["teller"].session.close()

    return step


def _members(world: World, why: str) -> list[str]:
    names = ["a", "teller"]
    world.member("a", peers=names)
    world.member("teller", _tells_at(world, 10, why), peers=names)
    return names


def test_the_run_error_quotes_the_participants_own_words(world: World) -> None:
    names = _members(world, WHY)
    result = world.run(names, 50, deadline_s=5.0, start_timeout_s=5.0)
    assert result.error == f"participant 'teller' stopped at tick 10: {WHY}"
    assert result.ticks_done == 10
    a = world.members["a"]
    a.join()
    assert a.end is not None and a.end.error == result.error


def test_a_long_or_unprintable_fault_is_clipped_to_one_line(world: World) -> None:
    names = _members(world, "Traceback:\n" + "x" * 500)
    result = world.run(names, 50, deadline_s=5.0, start_timeout_s=5.0)
    said = result.error.removeprefix("participant 'teller' stopped at tick 10: ")
    assert said.startswith("Traceback: xxx") and len(said) == 200, result.error


def test_policy_drop_goes_on_without_the_participant_that_failed(world: World) -> None:
    names = _members(world, WHY)
    result = world.run(names, 30, deadline_s=1.0, start_timeout_s=5.0, policy=Policy.DROP)
    assert (result.error, result.dropped, result.ticks_done) == ("", ["teller"], 30)
    a = world.members["a"]
    a.join()
    assert a.ticks == list(range(30))


def _late_words(world: World, *, after_s: float) -> list[str]:
    """A teller whose token goes at tick 10 and whose fault comes `after_s` later."""
    names = ["a", "teller"]

    def step(t: Tick, _inputs: Inputs) -> None:
        if t.tick == 10:
            teller = world.members["teller"]
            teller.participant._token.undeclare()  # the token first, as if its words came late
            time.sleep(after_s)
            teller.participant.report_fault(WHY)
            teller.session.close()

    world.member("a", peers=names)
    world.member("teller", step, peers=names)
    return names


def test_words_that_come_after_the_token_went_still_name_the_drop(world: World) -> None:
    """A loaded machine delivered a crashed stack's fault after its token had gone: the
    drop said "left the run at tick 120", not the stack's ZeroDivisionError."""
    names = _late_words(world, after_s=4 * GONE_GRACE_S)
    paced = {"realtime_factor": 1.0}  # 1.5 s: its words come 0.8 s after tick 10
    result = world.run(names, 150, deadline_s=5.0, start_timeout_s=5.0, policy=Policy.DROP, **paced)
    assert (result.dropped, result.ticks_done) == (["teller"], 150)
    assert result.why_dropped == {"teller": f"participant 'teller' stopped at tick 10: {WHY}"}


@pytest.mark.parametrize("after_s", [2 * GONE_GRACE_S, 2 * WORDS_S], ids=["late", "never"])
def test_under_abort_late_words_name_the_fault_and_none_say_it_left(
    world: World, after_s: float
) -> None:
    """Under abort the run ends when the token goes, so it waits WORDS_S for the fault:
    "left the run at tick 10" alone had hidden a crash whose words came 0.4 s late."""
    names = _late_words(world, after_s=after_s)
    result = world.run(names, 150, deadline_s=5.0, start_timeout_s=5.0)
    told = f"participant 'teller' stopped at tick 10: {WHY}"
    left = f"participant 'teller' left the run at tick 10{SILENT}"
    assert result.error == (told if after_s < WORDS_S else left), result.error


@pytest.mark.parametrize("fault", ["\x00" * 10, "y" * 201], ids=["unprintable", "too-long"])
def test_a_fault_with_a_bad_text_is_refused_and_the_run_completes(world: World, fault: str) -> None:
    """A client's own fault ack (no `report_fault` clipping it) is refused and counted."""
    names = ["a", "b"]

    def step(t: Tick, _inputs: Inputs) -> None:
        if t.tick == 3:
            ack = Ack(t.run, 3, fault=fault)
            world.members["b"].participant.publish(world.keys.ack("b"), ack)

    world.member("a", peers=names)
    world.member("b", step, peers=names)
    result = world.run(names, 20, deadline_s=5.0, start_timeout_s=5.0)
    assert (result.error, result.ticks_done) == ("", 20)
    assert world.conductor.rejections.totals.get("fault with a bad reason") == 1
