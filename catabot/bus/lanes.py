"""A participant's events in lanes by sender, so that a stranger's flood cannot hold up a run.

One FIFO held everything a process heard: a trial's flood of 64 KB junk commands (2000 a
second, each refused after 1.5 ms of decoding) queued the traffic's set-points behind it,
physics grew to 1.4 GB and the run ended with physics "hung"; 158 000 one-byte puts a second
on `clock/tick` made a run four times slower. Now the events of the run's own sessions (the
roster's: the conductor and the participants) and the process's own go on one FIFO, as
before. Every other sender (a client's commands, a stranger's junk) has a lane of its own,
bounded in events and bytes; what overflows is dropped where it arrives, unread and
counted. Lanes are served in turn, one event between every few of the run's own and when
nothing else waits, within a time budget (a tenth of the wall clock), so a flood costs the
run at most that. A sender that joins the run after its first samples were laned (a
participant's token seen late) has its lane's events taken first, in order."""

from __future__ import annotations

import queue
import threading
import time
from collections import deque
from collections.abc import Callable

Event = tuple[str, str, bytes, str]  # kind, key, payload, sender zid
OWN = frozenset(("join", "leave", "stop", "digest"))  # the process's own events
POKE: Event = ("poke", "", b"", "")  # wakes the loop for a lane: never handed out
LANE_EVENTS = 256  # events one stranger may have waiting
LANE_BYTES = 8 << 20  # ... and bytes (a command is 64 KiB at most: inbox.py)
LANES = 64  # strangers with events waiting at once: more are dropped as they come
EVERY = 4  # one lane event after this many of the run's own, when both wait
BUDGET = 0.1  # share of the wall clock lane events may take, over each second


class Lanes:
    def __init__(self, *, trusted: Callable[[str], bool]) -> None:
        """`trusted(zid)`: whether a sender is one of the run's sessions (the roster)."""
        self.trusted = trusted
        self.main: queue.SimpleQueue[Event] = queue.SimpleQueue()
        self._lanes: dict[str, deque[Event]] = {}  # insertion order: whose turn is next
        self._bytes: dict[str, int] = {}
        self._front: deque[Event] = deque()  # a joined sender's laned events, first
        self._lock = threading.Lock()
        self.dropped: dict[str, tuple[int, str]] = {}  # sender: (count, last key), to report
        self._own_since, self._served = 0, POKE  # the run's events since a lane's; the last
        self._window, self._spent = 0.0, 0.0  # the budget's second, and lane time in it

    def admits(self, kind: str, sender: str, size: int) -> bool:
        """Whether an event may be queued (checked before its payload is copied); a refusal
        is counted as dropped."""
        if kind in OWN or self.trusted(sender):
            return True
        lane = self._lanes.get(sender)
        if lane is None:
            full = len(self._lanes) >= LANES
        else:
            full = len(lane) >= LANE_EVENTS or self._bytes[sender] + size > LANE_BYTES
        return not full

    def offer(
        self, kind: str, key: str, sender: str, size: int, payload: Callable[[], bytes]
    ) -> None:
        """A Zenoh callback's event: `payload()` (a copy, or work) is called only if `admits`
        takes it; a refused one is counted, unread."""
        if self.admits(kind, sender, size):
            self.put((kind, key, payload(), sender))
        else:
            self.refuse(key, sender)

    def put(self, event: Event) -> None:
        kind, key, payload, sender = event
        if kind in OWN or self.trusted(sender):
            self.main.put(event)
            return
        with self._lock:
            if self.trusted(sender):  # bound meanwhile: its lane was moved to the front
                self.main.put(event)
            elif not self.admits(kind, sender, len(payload)):
                self._drop(key, sender)
            else:
                self._lanes.setdefault(sender, deque()).append(event)
                self._bytes[sender] = self._bytes.get(sender, 0) + len(payload)
                if len(self._lanes) == 1 and len(self._lanes[sender]) == 1:
                    self.main.put(POKE)  # the loop may be asleep on the FIFO

    def refuse(self, key: str, sender: str) -> None:
        """Count an event `admits` refused (its payload never copied)."""
        with self._lock:
            self._drop(key, sender)

    def _drop(self, key: str, sender: str) -> None:
        count, _ = self.dropped.get(sender, (0, ""))
        self.dropped[sender] = (count + 1, key)

    def take_dropped(self) -> dict[str, tuple[int, str]]:
        with self._lock:
            dropped, self.dropped = self.dropped, {}
        return dropped

    def joined(self, zid: str) -> None:
        """`zid` is now one of the run's (the roster bound it): its laned events come first."""
        with self._lock:
            lane = self._lanes.pop(zid, None)
            self._bytes.pop(zid, None)
            if lane:
                self._front.extend(lane)

    def get(self, timeout: float) -> Event:
        """The next event; queue.Empty after `timeout` s without one."""
        until = time.monotonic() + timeout
        while True:
            if self._front:
                return self._front.popleft()
            if self._lane_due():
                return self._from_lane()
            left = until - time.monotonic()
            if left <= 0:
                raise queue.Empty
            try:
                event = self.main.get(timeout=min(left, self._budget_back()))
            except queue.Empty:
                continue
            if event is not POKE:
                self._own_since += 1
                return event

    def spent(self, event: Event, seconds: float) -> None:
        """Time the participant took over `event`: a lane's counts against the budget."""
        if event is self._served:
            self._spent += seconds

    def empty(self) -> bool:
        return self.main.empty() and not self._lanes and not self._front

    def _lane_due(self) -> bool:
        if not self._lanes or self._over_budget():
            return False
        return self._own_since >= EVERY or self.main.empty()

    def _from_lane(self) -> Event:
        with self._lock:
            sender = next(iter(self._lanes))
            lane = self._lanes.pop(sender)
            event = lane.popleft()
            self._bytes[sender] -= len(event[2])
            if lane:
                self._lanes[sender] = lane  # to the back: the next sender's turn
            else:
                del self._bytes[sender]
        self._own_since, self._served = 0, event
        return event

    def _over_budget(self) -> bool:
        now = time.monotonic()
        if now - self._window >= 1.0:
            self._window, self._spent = now, 0.0
        return self._spent >= BUDGET

    def _budget_back(self) -> float:
        """How long to wait on the FIFO alone: until the budget's next second if lanes
        wait on it, else as long as the caller allows."""
        if self._lanes and self._over_budget():
            return max(self._window + 1.0 - time.monotonic(), 0.001)
        return 3600.0
