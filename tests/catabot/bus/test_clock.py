"""The lockstep rules without I/O: due samples, tick counts, Jacobi release (DESIGN.md §4)."""

from __future__ import annotations

import pytest

from catabot.bus import checks, codec
from catabot.bus import inbox as inbox_module
from catabot.bus.clock import ClockError, Policy, Stream, period_in_ticks, ticks_for
from catabot.bus.identity import Roster
from catabot.bus.inbox import Conflict, Inbox
from catabot.bus.messages import GpsFix, ImuSample, ThrustCmd, TwistBatch, TwistCmd, VesselState
from catabot.bus.rejections import Rejected
from tests.catabot.bus.inbox_samples import (
    CMD,
    GPS,
    KEYS,
    STATE,
    ZIDS,
    _add,
    _cmd,
    _gps,
    _inbox,
    _state,
)

# -- Stream -------------------------------------------------------------------------------


def test_due_before_period_1() -> None:
    s = Stream("k", VesselState, "p", 1)
    assert [s.due_before(k) for k in range(5)] == [-1, 0, 1, 2, 3]
    assert [s.due_through(k) for k in range(5)] == [0, 1, 2, 3, 4]


def test_due_before_period_3() -> None:
    s = Stream("k", VesselState, "p", 3)
    assert [s.due_before(k) for k in range(9)] == [-1, 0, 0, 0, 3, 3, 3, 6, 6]
    assert [s.due_through(k) for k in range(9)] == [0, 0, 0, 3, 3, 3, 6, 6, 6]


def test_due_before_period_10() -> None:
    s = Stream("k", GpsFix, "p", 10)
    assert s.due_before(0) == -1
    assert all(s.due_before(k) == 0 for k in range(1, 11))
    assert s.due_before(11) == 10
    assert s.due_before(20) == 10
    assert s.due_before(21) == 20
    assert s.due_through(9) == 0
    assert s.due_through(10) == 10
    assert s.due_through(19) == 10


def test_free_running_stream_is_never_due() -> None:
    s = Stream("k", ThrustCmd, "external", None)
    assert all(s.due_before(k) == -1 for k in range(0, 50))
    assert all(s.due_through(k) == -1 for k in range(0, 50))


def test_due_before_negative_tick() -> None:
    assert Stream("k", VesselState, "p", 1).due_before(-3) == -1


def test_default_period_is_one_tick() -> None:
    assert Stream("k", VesselState, "p").period == 1


def test_policy_values() -> None:
    assert Policy("abort") is Policy.ABORT
    assert Policy("drop") is Policy.DROP
    with pytest.raises(ValueError):
        Policy("ignore")


# -- tick arithmetic ----------------------------------------------------------------------


def test_ticks_for() -> None:
    assert ticks_for(60_000_000_000, 10_000_000) == 6000
    assert ticks_for(10_000_000, 10_000_000) == 1
    assert ticks_for(25_000_000, 10_000_000) == 2  # a partial last tick is not run


def test_ticks_for_errors() -> None:
    with pytest.raises(ClockError, match="dt must be a positive number of nanoseconds"):
        ticks_for(1_000, 0)
    with pytest.raises(ClockError, match=r"got -5"):
        ticks_for(1_000, -5)
    with pytest.raises(ClockError, match="shorter than one tick"):
        ticks_for(9_999_999, 10_000_000)


def test_period_in_ticks() -> None:
    assert period_in_ticks(10_000_000, 10_000_000, what="imu") == 1
    assert period_in_ticks(100_000_000, 10_000_000, what="gps") == 10


@pytest.mark.parametrize("period", [33_333_333, 5_000_000, 0, -10_000_000])
def test_period_in_ticks_errors(period: int) -> None:
    with pytest.raises(ClockError) as info:
        period_in_ticks(period, 10_000_000, what="ego/cam")
    msg = str(info.value)
    assert msg.startswith("ego/cam: ")
    assert f"period {period} ns is not a whole number of ticks" in msg
    assert "multiples of 10000000 ns" in msg and "100 Hz divided by a whole number" in msg


# -- Inbox --------------------------------------------------------------------------------


def test_jacobi_release() -> None:
    inbox = _inbox()
    _add(inbox, STATE, _state(0))
    assert inbox.release(0) == {}  # tagged 0: not for the step of tick 0
    out = inbox.release(1)
    assert list(out) == [STATE] and [m.tick for m in out[STATE]] == [0]
    assert inbox.release(1) == {}  # released once only


def test_release_holds_samples_of_the_current_and_later_ticks() -> None:
    inbox = _inbox()
    for k in (0, 1, 2, 3):
        _add(inbox, STATE, _state(k))
    assert [m.tick for m in inbox.release(2)[STATE]] == [0, 1]  # oldest first
    assert [m.tick for m in inbox.release(4)[STATE]] == [2, 3]


def test_free_samples_are_released_at_the_next_step() -> None:
    inbox = _inbox()
    _add(inbox, CMD, _cmd(0.5))
    _add(inbox, CMD, _cmd(0.7))
    assert inbox.missing(0) == []
    out = inbox.release(0)
    assert [m.thrust for m in out[CMD]] == [(0.5, 0.5), (0.7, 0.7)]  # arrival order
    assert inbox.release(1) == {}


def test_missing_follows_the_periods() -> None:
    inbox = _inbox()
    assert inbox.missing(0) == []  # nothing is due before tick 0
    assert inbox.missing(1) == [STATE, GPS]
    _add(inbox, STATE, _state(0))
    assert inbox.missing(1) == [GPS]
    _add(inbox, GPS, _gps(0))
    assert inbox.missing(1) == []
    _add(inbox, STATE, _state(1))
    assert inbox.missing(2) == []  # gps is next due at 10
    for k in range(2, 10):
        _add(inbox, STATE, _state(k))
    assert inbox.missing(10) == []
    assert inbox.missing(11) == [STATE, GPS]
    _add(inbox, STATE, _state(10))
    _add(inbox, GPS, _gps(10))
    assert inbox.missing(11) == []


def test_a_lagged_stream_is_due_and_released_lag_ticks_later() -> None:
    lagged = Stream(STATE, VesselState, "physics", 1, lag=3)
    assert [lagged.due_before(k) for k in (0, 3, 4, 5, 10)] == [-1, -1, 0, 1, 6]
    inbox = Inbox([lagged], roster=Roster(ZIDS))
    assert inbox.missing(3) == []  # nothing due yet: the consumer steps ahead of physics
    assert inbox.missing(4) == [STATE]
    for k in range(6):
        _add(inbox, STATE, _state(k))
    assert inbox.release(3) == {}
    assert [m.tick for m in inbox.release(5)[STATE]] == [0, 1]  # tagged < 5 - 3
    assert [m.tick for m in inbox.release(9)[STATE]] == [2, 3, 4, 5]


def test_a_phased_stream_is_due_the_tick_before_each_period() -> None:
    """The traffic's copy of the states (period 10, phase 9): its step at a guidance tick k
    waits for the batch tagged k - 1 and, between guidance ticks, for nothing new."""
    s = Stream(STATE, VesselState, "physics", 10, phase=9)
    due = [s.due_before(k) for k in (0, 9, 10, 11, 19, 20, 21, 30)]
    assert due == [-1, -1, 9, 9, 9, 19, 19, 29]
    assert [k for k in range(-1, 31) if s.is_due(k)] == [9, 19, 29]
    inbox = Inbox([s], roster=Roster(ZIDS))
    assert inbox.missing(10) == [STATE] and inbox.missing(9) == []
    with pytest.raises(Rejected, match="tag out of the window"):
        _add(inbox, STATE, _state(10))  # not a tick of its phase
    _add(inbox, STATE, _state(9))
    assert inbox.missing(20) == [STATE] and inbox.missing(19) == []
    assert [m.tick for m in inbox.release(10)[STATE]] == [9]


@pytest.mark.parametrize("phase, period", [(-1, 10), (10, 10), (1, None)])
def test_a_phase_lies_within_a_clocked_period(phase: int, period: int | None) -> None:
    with pytest.raises(ValueError, match="phase"):
        Stream(STATE, VesselState, "physics", period, phase=phase)


@pytest.mark.parametrize("lag, period", [(-1, 1), (2, None)])
def test_a_lag_must_be_non_negative_and_on_a_clocked_stream(lag: int, period: int | None) -> None:
    with pytest.raises(ValueError, match="lag"):
        Stream(STATE, VesselState, "physics", period, lag=lag)


def test_a_late_or_repeated_sample_is_refused_and_keeps_the_mark() -> None:
    """One producer publishes a key in tick order: an older or repeated tag is a forgery or
    a replay, never data."""
    inbox = _inbox()
    for k in range(6):
        _add(inbox, STATE, _state(k))
    with pytest.raises(Rejected, match="tag out of the window"):
        _add(inbox, STATE, _state(2))
    with pytest.raises(Rejected, match="second sample for one tick: tick 5: one a tick at most"):
        _add(inbox, STATE, _state(5))
    assert inbox.latest[STATE] == 5
    assert STATE not in inbox.missing(6)


def test_a_different_second_sample_for_a_tick_is_a_conflict() -> None:
    """A trial copied physics's session id and sent its own states for each tick: whichever
    came first was recorded. Two different samples for one tick are a `Conflict`, which
    ends the run (the same bytes twice stay a plain refusal)."""
    inbox = _inbox()
    _add(inbox, STATE, _state(0))
    forged = codec.encode(
        VesselState(0, 0, (600.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), *[(0.0,) * 3] * 4)
    )
    said = "in physics's session's name: one is forged, or physics sent two"
    with pytest.raises(Conflict, match=f"two different samples for one tick: tick 0 of .*{said}"):
        _add(inbox, STATE, forged)
    assert [m.position for m in inbox.release(1)[STATE]] == [(0.0, 0.0, 0.0)]


def test_dropped_producers_are_not_waited_for() -> None:
    inbox = _inbox()
    assert inbox.missing(1) == [STATE, GPS]
    inbox.drop_producers(["sensors"])
    assert inbox.missing(1) == [STATE]
    inbox.drop_producers(("physics",))
    assert inbox.missing(100) == []


def test_a_dropped_producer_stalled_at_the_first_tick_that_waited_for_it() -> None:
    """Where a dropped stack's vessel is handed back: a tick the samples alone decide, so a
    stack failing at one tick is handed back at one tick on every run (the grant naming the
    drop came at 5.2 s on one run and 5.4 s on another)."""
    inbox = _inbox()
    assert inbox.stalled("sensors") == 1  # nothing heard: tag 0 is due, tick 1 waits for it
    _add(inbox, GPS, _gps(0))
    _add(inbox, GPS, _gps(10))
    assert inbox.stalled("sensors") == 21  # the next due tag is 20
    lagged = Inbox([Stream(GPS, GpsFix, "sensors", 10, lag=3)], roster=Roster(ZIDS))
    _add(lagged, GPS, _gps(0))
    assert lagged.stalled("sensors") == 14  # read 3 ticks later
    assert inbox.stalled("external") is None and inbox.stalled("nobody") is None  # not clocked
    inbox.drop_producers(["sensors"])
    assert inbox.stalled_by(20) == [] and inbox.stalled_by(21) == ["sensors"]  # once
    assert inbox.stalled_by(30) == [] and inbox.handed == {"sensors"}


def test_malformed_payloads_raise_and_leave_the_inbox_unchanged() -> None:
    inbox = _inbox()
    _add(inbox, STATE, _state(0))
    before = ({k: list(v) for k, v in inbox.held.items()}, dict(inbox.latest))
    for payload in (b"\xc1junk", b"", _gps(3), _state(4)[:-3]):
        with pytest.raises(Rejected, match="malformed"):
            _add(inbox, STATE, payload)
    with pytest.raises(Rejected, match="malformed"):
        _add(inbox, GPS, codec.encode(ImuSample(1, 1, (0, 0, 0, 1), (0, 0, 0), (0, 0, 0))))
    assert ({k: list(v) for k, v in inbox.held.items()}, dict(inbox.latest)) == before
    assert inbox.missing(1) == [GPS]


def test_inbox_refuses_two_streams_on_one_key() -> None:
    with pytest.raises(ValueError, match="share one key"):
        Inbox([Stream("k", VesselState, "a"), Stream("k", VesselState, "b")])


def test_inbox_keys() -> None:
    assert _inbox().keys == [STATE, GPS, CMD]


# -- streams of a scenario ----------------------------------------------------------------


def test_a_free_command_over_64_kib_is_refused_before_it_is_decoded() -> None:
    """An 83 MB map of unknown keys took physics past its deadline decoding it."""
    inbox = _inbox()
    with pytest.raises(Rejected, match=r"too large.*70000 bytes; a command: 65536 at most"):
        inbox.add(CMD, b"\x00" * 70_000)
    assert inbox.release(0) == {}


def test_samples_held_for_an_unknown_producer_are_bounded_in_bytes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Junk sent on a stack's key before it joined was held whole: 2,500 x 1 MB, 3.2 GB."""
    monkeypatch.setattr(inbox_module, "MAX_PENDING_BYTES", 3_000_000)
    inbox = Inbox([Stream(CMD, ThrustCmd, "stack", 10)], roster=Roster(ZIDS))
    inbox.add(CMD, b"\x00" * 1_000_000, sender="x")
    inbox.add(CMD, b"\x00" * 1_000_000, sender="x")
    with pytest.raises(Rejected, match="producer unknown"):
        inbox.add(CMD, b"\x00" * 1_500_000, sender="x")
    assert len(inbox.pending) == 2
    inbox.add(CMD, b"\x00" * 900_000, sender="x")  # what fits is still held
    assert len(inbox.pending) == 3


def test_a_lockstep_order_refused_for_its_content_still_answers_its_tick() -> None:
    """A stack's NaN twist for tick 10 held physics (and the recorder) until the deadline,
    which then blamed physics: it is refused, and tick 10 goes on without it for every
    consumer alike; a refused reading of a sensor or a state is still waited for."""
    twist_key = KEYS.cmd_twist("ego")
    stream = Stream(twist_key, TwistCmd, "p", 10, check=checks.twist)
    inbox = Inbox([stream], roster=Roster(ZIDS))
    bad = codec.encode(TwistCmd(float("nan"), 0.0, 0, 0))
    with pytest.raises(Rejected, match=r"invalid content: surge nan .*tick 0 goes on without it"):
        inbox.add(twist_key, bad, sender=ZIDS["p"])
    assert inbox.missing(1) == [] and inbox.release(1) == {}
    inbox.add(twist_key, codec.encode(TwistCmd(1.0, 0.0, 10, 100)), sender=ZIDS["p"])
    assert inbox.release(11) == {twist_key: [TwistCmd(1.0, 0.0, 10, 100)]}
    fixes = Stream("f", GpsFix, "p", 10, check=_refuse)
    inbox = Inbox([fixes], roster=Roster(ZIDS))
    with pytest.raises(Rejected, match="invalid content: no"):
        inbox.add("f", codec.encode(GpsFix(0, 0, 0.0, 0.0, 0.0, 0.0, 0.0)), sender=ZIDS["p"])
    assert inbox.missing(1) == ["f"]


def _refuse(_msg: object) -> None:
    raise ValueError("no")


def test_a_free_command_to_a_vessel_driven_in_lockstep_is_refused_saying_so() -> None:
    """It said only `sender ? is not nav`; the twist's check says it in words, so does this."""
    inbox = Inbox([Stream(CMD, ThrustCmd, "p", 10)], roster=Roster(ZIDS))
    with pytest.raises(Rejected) as info:
        inbox.add(CMD, _cmd(0.5), sender="")
    assert (info.value.reason, info.value.detail) == (
        "not from its producer",
        "sender unsaid (no Zenoh source info) is not p (the vessel's thrust is driven in "
        "lockstep by it: a free command would change the run)",
    )
    with pytest.raises(Rejected, match=r"^not from its producer: sender x is not physics$"):
        _inbox().add(STATE, _state(0), sender="x")  # not a command: no such words
    batch = KEYS.world_twists()  # the traffic's set-points: no one vessel's
    inbox = Inbox([Stream(batch, TwistBatch, "p", 10)], roster=Roster(ZIDS))
    with pytest.raises(Rejected, match=r"is not p \(the fleet's twist is driven in"):
        inbox.add(batch, b"", sender="")
