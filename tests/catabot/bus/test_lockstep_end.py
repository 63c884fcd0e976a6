"""A participant ends the run (`EndRun` from its step, an `Ack` with `end`; DESIGN.md §4).

A controller whose episode is over ends the run after the last tick it stepped: nothing
more is granted, everyone steps up to that tick and no further than its data allows, and
the End names who ended it and why. Real Conductor and Participants over real Zenoh.
"""

from __future__ import annotations

import threading
import time

import pytest

from catabot.bus.clock import MAX_END_REASON, EndRun, Stream
from catabot.bus.inbox import Inputs
from catabot.bus.messages import Ack, GpsFix, Tick
from tests.catabot.bus.lockstep_world import World, _fix


def _ender(at: int, reason: str = "episode over") -> object:
    def step(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == at:
            raise EndRun(reason)

    return step


@pytest.mark.parametrize("window", [1, 8, 40])
def test_a_participant_ends_the_run_after_the_tick_before_its_request(
    world: World, window: int
) -> None:
    names = ["ctl", "physics", "recorder"]
    world.member("ctl", _ender(37), peers=names)  # type: ignore[arg-type]
    world.member("physics", peers=names)
    world.member("recorder", peers=names)
    result = world.run(names, 1000, deadline_s=2.0, start_timeout_s=5.0, window_ticks=window)
    assert result.error == "" and result.ticks_done == 37
    assert result.reason == "ended by 'ctl' after tick 36: episode over"
    assert result.wall_s < 0.9  # neither the deadline nor an idle second waited for
    ctl = world.members["ctl"]
    ctl.join()
    assert ctl.ticks == list(range(38))  # it stepped 37, which raised: not acked, not done
    for name in names:
        m = world.members[name]
        m.join()
        assert m.error is None and m.end is not None
        assert (m.end.tick, m.end.reason, m.end.error) == (36, result.reason, "")
        assert m.ticks[:37] == list(range(37))  # physics may run ahead: no one needs it


def test_a_consumer_records_exactly_up_to_the_end(world: World) -> None:
    """The controller's own stream ends the consumer's steps: whatever the window, the
    consumer is handed the producer's samples of every tick up to the end and no more."""
    key = world.keys.sensor("ego", "gps")
    names = ["ctl", "cons"]

    def produce(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 27:
            raise EndRun("done")
        world.members["ctl"].participant.publish(key, _fix(tick.tick))

    world.member("ctl", produce, peers=names)
    cons = world.member("cons", inputs=[Stream(key, GpsFix, "ctl", 1)], peers=names)
    result = world.run(names, 500, deadline_s=2.0, start_timeout_s=5.0, window_ticks=40)
    cons.join()
    assert result.error == "" and result.ticks_done == 27
    assert result.wall_s < 0.9  # cons acked 26 as it got there, not after an idle second
    assert cons.ticks == list(range(28))  # tick 27 needs the samples of 26: it has them
    assert cons.end_inputs is not None
    seen = [m.tick for k in cons.released for m in cons.released[k].get(key, ())]
    seen += [m.tick for m in cons.end_inputs.get(key, ())]
    assert seen == list(range(27))


def test_a_participant_that_ended_the_run_may_leave_before_the_end(world: World) -> None:
    names = ["ctl", "slow"]
    world.member("ctl", _ender(5), peers=names)  # type: ignore[arg-type]
    world.member("slow", lambda t, _i: time.sleep(0.02), peers=names)
    ctl = world.members["ctl"]

    def leave_soon() -> None:  # its token gone: the conductor sees it leave
        time.sleep(0.05)
        ctl.participant.stop()
        ctl.join()
        ctl.participant.close()

    threading.Thread(target=leave_soon, daemon=True).start()
    result = world.run(names, 300, deadline_s=2.0, start_timeout_s=5.0, window_ticks=40)
    assert result.error == "", result.error  # not "participant 'ctl' left the run"
    assert result.ticks_done == 5 and result.reason.startswith("ended by 'ctl'")


@pytest.mark.parametrize(
    "reason", ["x" * (MAX_END_REASON + 1), "bell\x07"], ids=["too long", "unprintable"]
)
def test_an_end_request_with_a_bad_reason_is_refused_and_the_run_goes_on(
    world: World, reason: str
) -> None:
    sent = []

    def forge(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 3 and not sent:
            ack = Ack(tick.run, 2, end=reason)
            world.members["ctl"].participant.publish(world.keys.ack("ctl"), ack)
            sent.append(True)

    world.member("ctl", forge)
    result = world.run(["ctl"], 30, deadline_s=2.0, start_timeout_s=5.0)
    assert (result.error, result.reason, result.ticks_done) == ("", "completed", 30)
    assert world.conductor is not None
    assert world.conductor.rejections.totals.get("end request with a bad reason") == 1


def test_the_first_end_wins(world: World) -> None:
    names = ["a", "b"]
    world.member("a", _ender(12, "a's reason"), peers=names)  # type: ignore[arg-type]
    world.member("b", _ender(30, "b's reason"), peers=names)  # type: ignore[arg-type]
    result = world.run(names, 300, deadline_s=2.0, start_timeout_s=5.0, window_ticks=1)
    assert result.error == "" and result.ticks_done == 12
    assert result.reason == "ended by 'a' after tick 11: a's reason"
