"""The real Conductor and Participants over real Zenoh sessions on loopback (DESIGN.md §4).

Each test builds a small world: the conductor's session listens on a free port, every
participant's session connects to it, the conductor runs in one thread and each
participant's `run()` in its own. Deadlines are short so that faults show in well
under a second; every session is closed at the end (zenoh leaks threads otherwise).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import pytest

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.inbox import Inputs
from catabot.bus.messages import Ack, GpsFix, Tick
from catabot.bus.participant import Participant
from tests.catabot.bus.lockstep_world import DT_NS, Member, Step, World, _fix

# -- (a) the happy path -------------------------------------------------------------------


def test_three_participants_step_every_tick_in_lockstep(world: World) -> None:
    names = ["physics", "sensors", "recorder"]
    for name in names:
        world.member(name, peers=names)
    result = world.run(names, 50, deadline_s=2.0, start_timeout_s=5.0)

    assert result.error == ""
    assert result.ticks_done == 50
    assert result.dropped == []
    assert result.reason == "completed"
    assert world.conductor is not None
    for name in names:
        m = world.members[name]
        m.join()
        assert m.error is None
        assert m.ticks == list(range(50))  # each tick once, in order
        assert m.end is not None
        assert (m.end.run, m.end.tick, m.end.reason, m.end.error) == (
            world.conductor.run_id,
            49,
            "completed",
            "",
        )
    # lockstep: nobody starts tick k before everybody has finished tick k - 1
    finished: dict[int, int] = {}
    for what, _name, tick in world.events:
        if what == "start" and tick > 0:
            assert finished.get(tick - 1, 0) == len(names), f"tick {tick} started early"
        elif what == "done":
            finished[tick] = finished.get(tick, 0) + 1


def test_ticks_carry_time(world: World) -> None:
    stamps: list[tuple[int, int, int]] = []
    world.member("solo", lambda t, _i: stamps.append((t.tick, t.stamp_ns, t.dt_ns)))
    result = world.run(["solo"], 5, deadline_s=2.0, start_timeout_s=5.0)
    world.members["solo"].join()
    assert result.error == ""
    assert stamps == [(k, k * DT_NS, DT_NS) for k in range(5)]


# -- (b) Jacobi inputs --------------------------------------------------------------------


def _producer_consumer(
    world: World, produce: Step, consume: Step | None = None
) -> tuple[str, Member]:
    key = world.keys.sensor("ego", "gps")
    names = ["prod", "cons"]
    world.member("prod", produce, peers=names)
    stream = Stream(key, GpsFix, "prod", 2)
    cons = world.member("cons", consume, inputs=[stream], peers=names)
    return key, cons


def _check_jacobi(cons: Member, key: str, ticks: int) -> None:
    assert cons.ticks == list(range(ticks))
    for k in range(ticks):
        got = [m.tick for m in cons.released[k].get(key, [])]
        # the sample of tick j (j even) is handed over at tick j + 1: never earlier, never later
        expected = [k - 1] if k >= 1 and (k - 1) % 2 == 0 else []
        assert got == expected, f"tick {k}: released {got}, expected {expected}"
    assert cons.end_inputs == {}  # nothing left over for the end


def test_consumer_gets_exactly_the_samples_of_earlier_ticks(world: World) -> None:
    key = world.keys.sensor("ego", "gps")
    participant: dict[str, Participant] = {}

    def produce(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick % 2 == 0:
            time.sleep(0.004)  # a slow producer
            participant["p"].publish(key, _fix(tick.tick))

    key, cons = _producer_consumer(world, produce)
    participant["p"] = world.members["prod"].participant
    result = world.run(["prod", "cons"], 30, deadline_s=2.0, start_timeout_s=5.0)
    for m in world.members.values():
        m.join()
        assert m.error is None
    assert result.error == "" and result.ticks_done == 30
    _check_jacobi(cons, key, 30)


def test_consumer_waits_for_a_late_sample(world: World) -> None:
    """A producer whose sample trails its ack: the consumer must wait, not step without it."""
    key = world.keys.sensor("ego", "gps")
    sent: dict[int, float] = {}
    timers: list[threading.Timer] = []

    def send_late(tick: int) -> None:
        sent[tick] = time.monotonic()
        world.members["prod"].participant.publish(key, _fix(tick))  # signed, as its producer

    def produce(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick % 2 == 0:
            timer = threading.Timer(0.03, send_late, args=(tick.tick,))
            timers.append(timer)
            timer.start()

    key, cons = _producer_consumer(world, produce)
    step_at: dict[int, float] = {}
    cons.user_step = lambda tick, _inputs: step_at.__setitem__(tick.tick, time.monotonic())
    result = world.run(["prod", "cons"], 12, deadline_s=2.0, start_timeout_s=5.0)
    for timer in timers:
        timer.join()
    for m in world.members.values():
        m.join()
        assert m.error is None
    assert result.error == "" and result.ticks_done == 12
    _check_jacobi(cons, key, 12)
    for j, t in sent.items():
        if j + 1 < 12:
            assert step_at[j + 1] >= t, f"tick {j + 1} stepped before the sample of tick {j}"


# -- stop and pacing ----------------------------------------------------------------------


def test_stop_ends_the_run_at_the_tick_boundary(world: World) -> None:
    def step(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 5:
            assert world.conductor is not None
            world.conductor.stop("interrupted")  # before this tick's ack goes out

    solo = world.member("solo", step)
    result = world.run(["solo"], 50, deadline_s=2.0, start_timeout_s=5.0)
    solo.join()
    # the tick in progress is completed (everyone acked it), then the run stops
    assert (result.error, result.reason, result.ticks_done) == ("", "interrupted", 6)
    assert solo.ticks == list(range(6))
    assert solo.end is not None and (solo.end.reason, solo.end.tick) == ("interrupted", 5)


@pytest.mark.parametrize("window", [1, 8])
def test_realtime_factor_paces_the_clock(world: World, window: int) -> None:
    started: dict[int, float] = {}
    solo = world.member("solo", lambda t, _i: started.setdefault(t.tick, time.monotonic()))
    result = world.run(
        ["solo"], 20, deadline_s=2.0, start_timeout_s=5.0, realtime_factor=2.0, window_ticks=window
    )
    solo.join()
    assert result.error == "" and result.ticks_done == 20
    assert result.wall_s >= 19 * DT_NS / 1e9 / 2.0  # tick 19 starts 95 ms after tick 0
    t0 = world.conductor._t0  # the pace's origin: tick k is granted at t0 + k dt / factor
    for k in range(20):  # a window never lets a paced tick start before its time (a loaded
        assert started[k] >= t0 + k * DT_NS / 1e9 / 2.0, k  # machine only makes it later)


def test_watched_follows_subscribers_coming_and_going(world: World) -> None:
    """Outputs for observers only are skipped while nobody subscribes (physics' per-vessel
    states); the answer must follow a subscriber in another session within a moment."""
    part = Participant(world.open(), world.keys, "physics")
    key = world.keys.vessel_state("ego")
    other = world.keys.vessel_state("boat_000")
    assert not part.watched(key)
    assert part.watched_among([other, key]) == []
    sub = world.open().declare_subscriber(key, lambda _: None)
    assert _eventually(lambda: part.watched(key))
    assert part.watched_among([other, key]) == [1]
    sub.undeclare()
    assert _eventually(lambda: not part.watched(key))
    assert part.watched_among([other, key]) == []


def _eventually(check: Callable[[], bool], timeout_s: float = 3.0) -> bool:
    limit = time.monotonic() + timeout_s
    while not check():
        if time.monotonic() > limit:
            return False
        time.sleep(0.01)
    return True


# -- the window -----------------------------------------------------------------------------


def _slow_consumer_run(world: World, window: int, ticks: int) -> tuple[str, Member]:
    participant: dict[str, Participant] = {}

    def produce(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick % 2 == 0:
            participant["p"].publish(key, _fix(tick.tick))

    key, cons = _producer_consumer(world, produce, lambda t, i: time.sleep(0.01))
    participant["p"] = world.members["prod"].participant
    result = world.run(
        ["prod", "cons"], ticks, deadline_s=2.0, start_timeout_s=5.0, window_ticks=window
    )
    assert result.error == "" and result.ticks_done == ticks
    for m in world.members.values():
        m.join()
        assert m.error is None
    return key, cons


def test_a_window_lets_the_fast_run_ahead_of_the_slow_but_no_further(world: World) -> None:
    """Within the window a producer steps ahead of a slow consumer (their steps overlap),
    never more than `window_ticks` ahead, and the consumer still gets exactly the samples
    of earlier ticks."""
    window, ticks = 4, 24
    key, cons = _slow_consumer_run(world, window, ticks)
    _check_jacobi(cons, key, ticks)
    assert world.members["prod"].ticks == list(range(ticks))
    order = {(what, who, t): i for i, (what, who, t) in enumerate(world.events)}
    ahead = [order[("start", "prod", k + 1)] < order[("done", "cons", k)] for k in range(ticks - 1)]
    assert any(ahead), "the producer never stepped ahead of the consumer"
    for k in range(window, ticks):
        assert order[("done", "cons", k - window)] < order[("start", "prod", k)], (
            f"the producer started tick {k} before the consumer finished tick {k - window}"
        )


def test_a_window_of_one_is_strict_lockstep(world: World) -> None:
    _key, _cons = _slow_consumer_run(world, 1, 10)
    order = {(what, who, t): i for i, (what, who, t) in enumerate(world.events)}
    for k in range(1, 10):
        assert order[("done", "cons", k - 1)] < order[("start", "prod", k)]


def test_a_stop_in_a_window_ends_everyone_on_the_same_tick(world: World) -> None:
    def step(tick: Tick, _inputs: Inputs) -> None:
        if tick.tick == 5:
            assert world.conductor is not None
            world.conductor.stop("interrupted")

    names = ["a", "b"]
    world.member("a", step, peers=names)
    world.member("b", lambda t, i: time.sleep(0.005), peers=names)
    result = world.run(names, 200, deadline_s=2.0, start_timeout_s=5.0, window_ticks=8)
    assert result.error == "" and result.reason == "interrupted"
    assert 6 <= result.ticks_done <= 6 + 8  # what was granted when the stop came completes
    for name in names:
        m = world.members[name]
        m.join()
        assert m.ticks == list(range(result.ticks_done))
        assert m.end is not None and m.end.tick == result.ticks_done - 1


def test_acks_come_every_half_window(world: World) -> None:
    """Half the window between acks: a tenth of the acks a strict lockstep needs."""
    acks: list[int] = []
    sub = world.open().declare_subscriber(
        world.keys.ack("solo"), lambda s: acks.append(codec.decode(s.payload.to_bytes(), Ack).tick)
    )
    world.member("solo")
    result = world.run(["solo"], 100, deadline_s=2.0, start_timeout_s=5.0, window_ticks=20)
    world.members["solo"].join()
    assert result.error == "" and result.ticks_done == 100
    assert _eventually(lambda: len(acks) >= 10), f"acks seen: {acks}"  # still in flight
    sub.undeclare()
    assert acks == list(range(9, 100, 10))
