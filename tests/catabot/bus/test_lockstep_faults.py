"""Faults in the real lockstep: deadline, drop policy, crash, bad input (the start: its file)."""

from __future__ import annotations

import logging
import threading
import time

import pytest

from catabot.bus import codec, start_wait
from catabot.bus.clock import ClockLimits, Policy, Stream
from catabot.bus.conductor import SILENT
from catabot.bus.inbox import Inputs
from catabot.bus.messages import Tick, VesselState
from catabot.bus.participant import Participant, Stopped
from tests.catabot.bus.lockstep_world import DT_NS, Step, World, _fix, _state

# -- (c) deadline -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("window", "hang_at", "done"),
    [(1, 3, 3), (8, 13, 12)],  # a window of 8 acks every 4 ticks: 3, 7, 11
    ids=["barrier", "window"],
)
def test_a_step_past_the_deadline_ends_the_run_naming_it(
    world: World, window: int, hang_at: int, done: int
) -> None:
    """The fault names the participant holding the oldest unacknowledged tick."""
    release = threading.Event()

    def hang(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == hang_at:
            release.wait(5.0)

    world.member("fast")
    world.member("stuck", hang)
    try:
        result = world.run(
            ["fast", "stuck"], 100, deadline_s=0.5, start_timeout_s=5.0, window_ticks=window
        )
    finally:
        release.set()
    assert result.error == f"participant 'stuck' missed the 0.5 s deadline of tick {done}"
    assert (result.reason, result.ticks_done) == ("fault", done)
    fast = world.members["fast"]
    fast.join()
    assert fast.ticks[: done + 1] == list(range(done + 1))
    assert len(fast.ticks) <= done + window  # never past the window
    assert fast.end is not None and fast.end.error == result.error
    assert fast.end.tick == done - 1  # the last complete tick
    world.members["stuck"].join()


@pytest.mark.parametrize(("deadline_s", "junk"), [(2.5, False), (0.5, False), (2.5, True)])
def test_a_participant_waiting_for_a_late_ones_data_is_not_named(
    world: World, deadline_s: float, junk: bool
) -> None:
    """`cons` needs `slow`'s output of each tick before; `slow` sleeps in tick 13. Acks come
    every half window, so `cons` had stepped 12 and 13 unacknowledged and looked as late as
    `slow`: the deadline named it, the first in the list (as physics for a slow stack). A
    quarter of the deadline (at most a second) without events, it acks what it has stepped
    (a second, under a trial's 1 s deadline: physics was named for the stack), junk on its
    input from a stranger (refused samples, `junk`) coming faster or not."""
    release = threading.Event()
    key = world.keys.vessel_state("ego")
    names = ["cons", "slow"]
    holder: dict[str, Participant] = {}

    def slow(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 13:
            release.wait(6.0)
        holder["p"].publish(key, _state(tick.tick))

    limits = ClockLimits(DT_NS, 100, 8, deadline_s=deadline_s)
    world.member("cons", inputs=[Stream(key, VesselState, "slow", 1)], peers=names, limits=limits)
    holder["p"] = world.member("slow", slow, peers=names).participant
    stranger = world.open().declare_publisher(key)

    def spam_it() -> None:
        while junk and not release.is_set():
            stranger.put(b"x")  # refused: not from `slow`'s session
            time.sleep(0.05)

    spam = threading.Thread(target=spam_it)
    spam.start()
    try:
        result = world.run(names, 100, deadline_s=deadline_s, start_timeout_s=5.0, window_ticks=8)
    finally:
        release.set()
        spam.join()
    assert result.error == f"participant 'slow' missed the {deadline_s:g} s deadline of tick 12"


def test_the_late_one_does_not_blame_whom_it_waited_for(
    world: World, caplog: pytest.LogCaptureFixture
) -> None:
    """A stack past its deadline logged "stack waited at tick 14 for world/states from
    'physics'" as the run ended: physics had waited for it, not the other way round."""
    release = threading.Event()
    names, holder = ["cons", "slow"], {}
    out = {name: world.keys.vessel_state(name) for name in names}

    def stepper(name: str, hang_at: int | None) -> Step:
        def step(tick: Tick, _inputs: Inputs) -> None:
            if tick.tick == hang_at:
                release.wait(6.0)
            holder[name].publish(out[name], _state(tick.tick))

        return step

    for name, other, hang_at in (("cons", "slow", None), ("slow", "cons", 13)):
        stream = Stream(out[other], VesselState, other, 1)
        member = world.member(name, stepper(name, hang_at), inputs=[stream], peers=names)
        holder[name] = member.participant
    try:
        with caplog.at_level("WARNING", logger="catabot.bus.participant"):
            result = world.run(names, 100, deadline_s=2.5, start_timeout_s=5.0, window_ticks=8)
            world.members["cons"].join()  # before `slow` steps on: its sample had raced the End
            release.set()  # the End is out: the late one steps on, then finds it
            world.members["slow"].join()
    finally:
        release.set()
    assert result.error == "participant 'slow' missed the 2.5 s deadline of tick 12"
    said = [r.getMessage() for r in caplog.records]
    assert [m for m in said if m.startswith("slow ")] == [], said
    assert [m for m in said if m.startswith("cons waited at tick ")], said  # the one held


# -- (d) policy drop ----------------------------------------------------------------------


def test_policy_drop_goes_on_without_the_hanging_participant(world: World) -> None:
    release = threading.Event()
    key = world.keys.vessel_state("ego")
    names = ["hang", "cons", "other"]
    holder: dict[str, Participant] = {}

    def hang(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 5:
            release.wait(5.0)
        holder["p"].publish(key, _state(tick.tick))

    holder["p"] = world.member("hang", hang, peers=names).participant
    cons = world.member("cons", inputs=[Stream(key, VesselState, "hang", 1)], peers=names)
    world.member("other", peers=names)
    try:
        result = world.run(names, 20, deadline_s=0.3, start_timeout_s=5.0, policy=Policy.DROP)
    finally:
        release.set()
    assert result.error == ""
    assert result.dropped == ["hang"]
    assert result.ticks_done == 20
    assert result.reason == "completed"
    for m in world.members.values():
        m.join()
        assert m.error is None
    assert cons.ticks == list(range(20))
    assert world.members["other"].ticks == list(range(20))
    hung = world.members["hang"]  # told, it stops: it had stepped on to 19 and heard "completed"
    assert hung.end is not None and (hung.end.reason, hung.end.tick) == ("dropped", 5), hung.end
    assert hung.end.error == "hang was dropped (clock.policy drop): the run goes on without it"
    assert hung.ticks == list(range(6))
    for k in range(1, 6):  # before the drop, the consumer had every state
        assert [m.tick for m in cons.released[k][key]] == [k - 1]


# -- (f) a crash mid-run ------------------------------------------------------------------


def _crash_at(world: World, tick: int, crashed_at: list[float]) -> Step:
    def step(t: Tick, _inputs: Inputs) -> None:
        if t.tick == tick:
            crashed_at.append(time.monotonic())
            world.members["crash"].session.close()

    return step


def _with_a_crash_at_tick_10(world: World) -> tuple[list[str], list[float]]:
    """Members a, b and one that closes its session at tick 10; when it did is recorded."""
    crashed_at: list[float] = []
    names = ["a", "b", "crash"]
    world.member("a", peers=names)
    world.member("b", peers=names)
    world.member("crash", _crash_at(world, 10, crashed_at), peers=names)
    return names, crashed_at


def test_a_participant_that_crashes_is_named_within_a_second(world: World) -> None:
    names, crashed_at = _with_a_crash_at_tick_10(world)
    result = world.run(names, 50, deadline_s=5.0, start_timeout_s=5.0)
    assert crashed_at, "the crash never happened"
    assert result.error == f"participant 'crash' left the run at tick 10{SILENT}"
    assert SILENT == (
        " without a word: its process ended, or stopped answering for 1.5 s (killed, frozen, "
        "or its link lost)"
    )  # a stack frozen 2 s (SIGSTOP) read as gone for good
    assert world.result_at - crashed_at[0] < 1.0
    assert result.ticks_done == 10
    for name in ("a", "b"):
        m = world.members[name]
        m.join()
        assert m.error is None
        assert m.end is not None and "crash" in m.end.error
    world.members["crash"].join()


def test_policy_drop_goes_on_without_a_crashed_participant(world: World) -> None:
    names, crashed_at = _with_a_crash_at_tick_10(world)
    result = world.run(names, 30, deadline_s=1.0, start_timeout_s=5.0, policy=Policy.DROP)
    assert crashed_at
    assert result.error == ""
    assert result.dropped == ["crash"]
    assert result.ticks_done == 30
    for name in ("a", "b"):
        m = world.members[name]
        m.join()
        assert m.error is None
        assert m.ticks == list(range(30))
    world.members["crash"].join()


# -- (g) malformed input ------------------------------------------------------------------


def test_malformed_input_is_logged_and_the_participant_goes_on(
    world: World, caplog: pytest.LogCaptureFixture
) -> None:
    key = world.keys.vessel_state("ego")
    names = ["inj", "cons"]
    holder: dict[str, Participant] = {}

    def inject(tick: Tick, _inputs: Inputs) -> None:
        p = holder["p"]
        if tick.tick == 3:  # signed as the producer's: refused for what they hold
            raw = p.session.declare_publisher(key)
            p.put(raw, b"\xc1 not msgpack")
            p.put(raw, codec.encode(_fix(3)))  # a valid message of the wrong type
        p.publish(key, _state(tick.tick))

    holder["p"] = world.member("inj", inject, peers=names).participant
    cons = world.member("cons", inputs=[Stream(key, VesselState, "inj", 1)], peers=names)
    with caplog.at_level(logging.WARNING, logger="catabot.bus.participant"):
        result = world.run(names, 20, deadline_s=2.0, start_timeout_s=5.0)
        for m in world.members.values():
            m.join()
            assert m.error is None
    assert result.error == "" and result.ticks_done == 20
    assert cons.ticks == list(range(20))
    for k in range(1, 20):
        assert [m.tick for m in cons.released[k][key]] == [k - 1]
    warnings = [r.getMessage() for r in caplog.records if r.name == "catabot.bus.participant"]
    malformed = [w for w in warnings if "malformed" in w]
    assert len(malformed) == 2, warnings  # each different detail once (rejections.py)
    assert key in malformed[0] and malformed[0].startswith("cons:")
    assert "not a msgpack payload" in malformed[0]
    assert cons.participant.rejections.totals == {"malformed": 2}


def test_a_participant_stopped_from_another_thread_leaves_the_run(world: World) -> None:
    """`Participant.stop()` (a client stack leaving): run() raises Stopped, and the
    conductor names the participant when its token goes."""

    def step(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 5:
            threading.Thread(target=world.members["a"].participant.stop).start()

    world.member("a", step, peers=["a", "b"])
    world.member("b", peers=["a", "b"])
    closer = threading.Thread(target=_close_when_stopped, args=(world,), daemon=True)
    closer.start()
    result = world.run(["a", "b"], 10_000, deadline_s=5.0, start_timeout_s=5.0)
    a = world.members["a"]
    a.join()
    assert isinstance(a.error, Stopped) and "a left the run at tick" in str(a.error)
    assert 5 <= result.ticks_done < 10_000 and "a" in result.error
    world.members["b"].join()
    assert world.members["b"].end is not None and world.members["b"].end.reason == "fault"


def _close_when_stopped(world: World) -> None:
    a = world.members["a"]
    while a.error is None:
        time.sleep(0.01)
    a.participant.close()  # its token goes: the conductor notices at once


def test_a_participant_without_a_conductor_says_what_it_waits_for(
    world: World, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """A service started alone (or in the wrong world) said nothing, however long."""
    monkeypatch.setattr(start_wait, "NOTE_EVERY_S", 0.3)
    lonely = world.member("lonely")
    with caplog.at_level(logging.WARNING, logger="catabot.bus.participant"):
        lonely.thread.start()
        time.sleep(2.5)  # idle events come every second
    notes = [
        r.getMessage() for r in caplog.records if "no tick from the conductor" in r.getMessage()
    ]
    assert notes and f"of world {world.keys.world!r} after " in notes[0], notes
    assert notes[0].endswith("is its conductor on this router (--connect), or has its run ended?")


def test_participants_gone_at_once_are_named_together_as_a_lost_link(world: World) -> None:
    """A router that died took every token with it, and the error blamed physics alone."""
    names = ["a", "b", "c"]

    def cut(t: Tick, _inputs: Inputs) -> None:
        if t.tick == 10:
            for name in ("b", "c"):
                world.members[name].participant._token.undeclare()

    world.member("a", cut, peers=names)
    world.member("b", peers=names)
    world.member("c", peers=names)
    result = world.run(names, 500, deadline_s=5.0, start_timeout_s=5.0, window_ticks=1)
    assert result.error.startswith("participants 'b', 'c' left the run at once at tick "), result
    assert "the conductor lost its link to them" in result.error
