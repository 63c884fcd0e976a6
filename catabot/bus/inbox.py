"""Samples a participant has received: checked where they arrive, released in Jacobi order.

A sample tagged tick j is released to the step of tick k only when j < k (j < k - lag for a
stream read with a lag: `Stream.released_before`); free-running samples (tick -1, from
clients outside the lockstep) are released at the next step after they arrive. Releasing
by tick rather than by arrival is what keeps a run deterministic when producers race each
other on different routes.

Every check happens in `add`, so nothing a client sends can fail a step: the key must be
exactly one of the streams (a put on a wildcard reaches every subscriber under the wildcard),
a clocked sample must come from its producer's session (identity.py), carry a tag the
clock could have granted and the stamp of that tag, and pass its stream's content check; a
free-running sample must carry tick -1. A refused sample raises `Rejected`, which the
participant counts (rejections.py); a clocked order refused for its content still answers
its tick (`ORDERS`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.identity import Roster, shown
from catabot.bus.messages import Message, ThrustCmd, TwistCmd, WaypointsCmd
from catabot.bus.rejections import Rejected
from catabot.errors import CataBotError

Inputs = Mapping[str, list[Message]]
MAX_PENDING = 10_000  # samples held while their producer's session is not yet known
MAX_PENDING_BYTES = 64 * 2**20  # and their bytes: 2,500 junk samples of 1 MB took 3.2 GB
MAX_FREE_BYTES = 64 * 2**10  # a free-running command (a 1000-point path is 18 KB)
OPEN = 2**62  # an off interval not closed yet
WILDCARD = "a put on a key expression with wildcards; a command goes to one key"
# A lockstep stack's order that fails its check (a NaN, a thrust beyond 1) is refused like a
# free one, and its tick counts as answered: every consumer refuses it alike, so every run
# goes on the same way (the order in force stays), where waiting for a valid one held the
# run until the deadline blamed the consumer.
ORDERS = (ThrustCmd, TwistCmd, WaypointsCmd)


class Conflict(Rejected):
    """Two different samples for one tick of a stream, both from its producer's session: one
    is forged (a session's id is what a sample states: identity.py) or the producer broke the
    protocol. Taking either would make the run depend on which came first, so the participant
    ends the run saying so (a trial's forged states were recorded in place of physics's)."""


class Inbox:
    def __init__(
        self, streams: Sequence[Stream], *, roster: Roster | None = None, dt_ns: int = 0
    ) -> None:
        self.streams = {s.key: s for s in streams}
        if len(self.streams) != len(streams):
            raise ValueError("two input streams share one key")
        self.roster = roster if roster is not None else Roster()
        self.dt_ns = dt_ns  # 0: stamps are not checked (no clock limits known)
        self.latest = {key: -1 for key in self.streams}
        self._payload: dict[str, bytes] = {}  # each clocked stream's last, for `Conflict`
        self.held: dict[str, list[Message]] = {key: [] for key in self.streams}
        self.dropped: set[str] = set()
        self.handed: set[str] = set()  # dropped producers past their stall (stalled_by)
        self.pending: list[tuple[str, bytes, str]] = []
        self._pending_bytes = 0
        # Only clocked streams can be due (physics has ~300 free-running command keys with
        # 100 boats); only keys holding samples need a look at release.
        self._clocked = [s for s in self.streams.values() if s.period is not None]
        self._holding: set[str] = set()
        self._order = {key: i for i, key in enumerate(self.streams)}  # release in stream order
        self._off: dict[str, list[tuple[int, int]]] = {}  # [start, end) tags not produced
        # A wildcard put reaches every stream under it: refused once by a watch over them
        # all (strays.py) when one says so, else here, by each stream it reached.
        self.spoken_for: Callable[[str], bool] = lambda _key: False

    @property
    def keys(self) -> list[str]:
        return list(self.streams)

    def add(self, key: str, payload: bytes, *, sender: str = "", horizon: int = 2**62) -> None:
        """Check, decode and hold a sample; `Rejected` says why one is refused. `horizon`:
        no tag may reach it (the clock cannot have granted that far)."""
        stream = self.streams.get(key)
        if stream is None:
            if "*" in key and self.spoken_for(key):
                return
            raise Rejected("not a stream key", f"{key!r}: {WILDCARD}" if "*" in key else repr(key))
        if stream.period is None and len(payload) > MAX_FREE_BYTES:  # before decoding it
            raise Rejected(
                "too large", f"{len(payload)} bytes; a command: {MAX_FREE_BYTES} at most"
            )
        if stream.period is not None and not self._from_producer(stream, key, payload, sender):
            return  # held until the producer's session is known
        msg = _decoded(payload, stream)
        tick = _tick_of(msg)
        if stream.period is not None and tick == self.latest[key] >= 0:
            self._second(key, tick, payload)
        self._check_tag(stream, msg, tick, horizon)
        try:
            _check_content(stream, msg)
        except Rejected as exc:
            if stream.period is not None and isinstance(msg, ORDERS):
                self.latest[key], self._payload[key] = tick, payload  # answered, no order
                raise Rejected(
                    exc.reason, f"{exc.detail}; tick {tick} goes on without it"
                ) from None
            raise
        self.held[key].append(msg)
        self._holding.add(key)
        self.latest[key] = max(self.latest[key], tick)
        if stream.period is not None:
            self._payload[key] = payload

    def _second(self, key: str, tick: int, payload: bytes) -> None:
        """A second sample for a tick already taken: the same bytes again are refused as
        such; other bytes are a `Conflict`."""
        if payload != self._payload.get(key, payload):
            producer = self.streams[key].producer
            raise Conflict("two different samples for one tick", f"tick {tick} of {key}, both "
                           f"in {producer}'s session's name: one is forged, or {producer} sent "
                           "two (one a tick at most)")  # fmt: skip

    def _from_producer(self, stream: Stream, key: str, payload: bytes, sender: str) -> bool:
        producer = self.roster.zid(stream.producer)
        if producer is None:
            full = self._pending_bytes + len(payload) > MAX_PENDING_BYTES
            if full or len(self.pending) >= MAX_PENDING:
                raise Rejected("producer unknown", f"{stream.producer} has no session yet")
            self.pending.append((key, payload, sender))
            self._pending_bytes += len(payload)
            return False
        if sender != producer:
            kind, whose = key.rsplit("/", 1)[-1], "vessel's" if "/vessel/" in key else "fleet's"
            driven = (f" (the {whose} {kind} is driven in lockstep by it: a free command "
                      "would change the run)") if "/cmd/" in key else ""  # fmt: skip
            why = f"{shown(sender)} is not {stream.producer}{driven}"
            raise Rejected("not from its producer", why)
        return True

    def retry_pending(self, horizon: int) -> list[tuple[str, Rejected]]:
        """Samples held for a producer now known: added, or refused (returned with why)."""
        pending, self.pending, refused = self.pending, [], []
        self._pending_bytes = 0
        for key, payload, sender in pending:
            try:
                self.add(key, payload, sender=sender, horizon=horizon)
            except Rejected as exc:
                refused.append((key, exc))
        return refused

    def _check_tag(self, stream: Stream, msg: Message, tick: int, horizon: int) -> None:
        if stream.period is None:
            if tick != -1:
                raise Rejected("tick of a free-running sample", f"tick {tick}, not -1")
            return
        if tick == self.latest[stream.key] >= 0:
            raise Rejected("second sample for one tick", f"tick {tick}: one a tick at most")
        if not stream.is_due(tick) or tick >= horizon or tick <= self.latest[stream.key]:
            raise Rejected(
                "tag out of the window",
                f"tick {tick} (period {stream.period}, last {self.latest[stream.key]}, "
                f"granted below {horizon})",
            )
        skipped = self._skipped(stream, tick)
        if skipped >= 0:  # a producer sends every due tag in order: a forger's future tags
            raise Rejected(  # were taken, and the producer's own refused as late (lost rows)
                "tag skips ahead", f"tick {tick} before tick {skipped} (period {stream.period})"
            )
        stamp = getattr(msg, "stamp_ns", None)
        expected = (tick + stream.stamp_ticks) * self.dt_ns
        if self.dt_ns and stamp != expected:
            raise Rejected("stamp of another tick", f"stamp {stamp} ns, tick {tick} has {expected}")

    def _skipped(self, s: Stream, tick: int) -> int:
        """The first tag due after the last one heard and before `tick` that its producer
        was not switched off at (-1: none; a tag of an off span is never sent)."""
        due = _next_tag(s, self.latest[s.key])
        for start, end in self._off.get(s.key, ()):
            if due >= end:
                continue
            if due < start:
                break
            due = _next_tag(s, end - 1)  # the first due tag at or after the span's end
        return due if due < tick else -1

    def drop_producers(self, names: Iterable[str]) -> None:
        """Stop waiting for streams of participants the conductor dropped."""
        self.dropped.update(names)

    def stalled(self, producer: str) -> int | None:
        """The first tick whose step waited for a sample of `producer` that never came (its
        next due tag after the last one heard, through this consumer's lag); None if none of
        its streams is clocked here. Why: a dropped stack's vessel is handed back from there,
        a tick every run agrees on when the stack failed at one, where the grant the drop
        came with depended on how fast the others had acked (5.2 or 5.4 s on two runs)."""
        ticks = [_next_tag(s, self.latest[s.key]) + 1 + s.lag for s in self._clocked
                 if s.producer == producer]  # fmt: skip
        return min(ticks) if ticks else None

    def stalled_by(self, tick: int) -> list[str]:
        """Dropped producers stalled at `tick` or before, each once (the tick their vessels
        are handed back: physics and the recorder ask alike); `handed` holds them after."""
        due = [n for n in sorted(self.dropped - self.handed)
               if (stall := self.stalled(n)) is None or tick >= stall]  # fmt: skip
        self.handed.update(due)
        return due

    def switch(self, key: str, tick: int, *, on: bool) -> None:
        """A stream's producer stops (or starts again) producing from tag `tick` on: a sensor
        switched at run time. Every participant learns it with the Tick of `tick`, before any
        step can need a sample tagged `tick`, so none waits for a sample never sent."""
        spans = self._off.setdefault(key, [])
        is_off = bool(spans) and spans[-1][1] == OPEN
        if not on and not is_off:
            spans.append((tick, OPEN))
        elif on and is_off:
            spans[-1] = (spans[-1][0], tick)

    def _due(self, s: Stream, tick: int) -> int:
        """The last tag due before `tick`, skipping tags its producer was switched off at."""
        due = s.due_before(tick)
        for start, end in reversed(self._off.get(s.key, ())):
            if start <= due < end:
                due = s.due_before(start + s.lag)
        return due

    def missing(self, tick: int) -> list[str]:
        """Keys whose last sample due before `tick` has not arrived yet."""
        return [
            s.key
            for s in self._clocked
            if s.producer not in self.dropped and self.latest[s.key] < self._due(s, tick)
        ]

    def unarrived(self, tick: int) -> str:
        """The samples due before `tick` that never came, by stream and producer, with the
        last tag each did send: what a recording ends without, in one line."""
        return "; ".join(
            f"{key} from {self.streams[key].producer!r} after its tick {self.latest[key]}"
            for key in self.missing(tick)
        )

    def release(self, tick: int) -> dict[str, list[Message]]:
        """Hand over every held sample produced before `tick`, oldest tick first."""
        out: dict[str, list[Message]] = {}
        for key in sorted(self._holding, key=self._order.__getitem__):
            held, before = self.held[key], self.streams[key].released_before(tick)
            ready = [m for m in held if _tick_of(m) < before]
            if ready:
                self.held[key] = [m for m in held if _tick_of(m) >= before]
                out[key] = sorted(ready, key=_tick_of)
            if not self.held[key]:
                self._holding.discard(key)
        return out


def checked(payload: bytes, stream: Stream) -> Message:
    """A sample decoded and through its stream's content check, or `Rejected` (for an
    observer, which has no tags to check)."""
    msg = _decoded(payload, stream)
    _check_content(stream, msg)
    return msg


def _decoded(payload: bytes, stream: Stream) -> Message:
    try:
        return codec.decode(payload, stream.message)
    except codec.CodecError as exc:
        raise Rejected("malformed", str(exc)) from None


def _check_content(stream: Stream, msg: Message) -> None:
    if stream.check is None:
        return
    try:
        stream.check(msg)
    except (ValueError, CataBotError) as exc:
        raise Rejected("invalid content", str(exc)) from None


def _next_tag(s: Stream, last: int) -> int:
    """The first tag after `last` at which `s` is due."""
    assert s.period is not None
    if last < s.phase:
        return s.phase
    return s.phase + ((last - s.phase) // s.period + 1) * s.period


def _tick_of(msg: Message) -> int:
    return int(getattr(msg, "tick", -1))
