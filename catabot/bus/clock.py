"""The lockstep protocol's shared rules (DESIGN.md §4), free of any I/O.

Jacobi stepping: at tick k every participant advances from t_k to t_(k+1) using only
samples produced in ticks < k, publishes what it produced (tagged k), then acks k.
A stream has a period in ticks and is produced at ticks k with k % period == phase (0
but for a decimated copy of another stream); a consumer steps tick k only once the last
due sample of each stream it reads has arrived. That rule, not message ordering, makes
runs deterministic across routes.
A consumer may read a stream with a lag of L ticks (a sample tagged j reaches step k
only when j < k - L): a fixed transport delay, the same on every run, that lets the
consumer step up to L ticks ahead of the producer instead of waiting for it every tick.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

from catabot.bus.messages import Message, Tick
from catabot.errors import CataBotError

NS_PER_S = 1_000_000_000
CONDUCTOR = "conductor"  # the participant name of the clock's owner
MAX_END_REASON = 200  # characters of an `Ack.end`: why the run ends, not a payload
ENDED_BY = "ended by "  # an End's reason when a participant ended the run
NEVER_JOINED = "never joined within"


class ClockError(CataBotError, RuntimeError):
    """The run cannot go on: a participant vanished, missed the deadline or never came."""


class EndRun(Exception):
    """Raised by a step at tick k: end the run after tick k - 1, the last this participant
    stepped (a controller whose episode is over); its text is the reason everyone sees."""


def end_reason_problem(reason: str) -> str:
    """Why `reason` cannot be an `Ack.end` ("" if it can): 1-200 printable characters."""
    if 0 < len(reason) <= MAX_END_REASON and reason.isprintable():
        return ""
    return f"a reason of 1-{MAX_END_REASON} printable characters, not {reason[:40]!r}"


def end_reason(text: str) -> str:
    """A valid `Ack.end` made of any text (a step's `EndRun`): printable, clipped."""
    clean = "".join(c if c.isprintable() else " " for c in text)[:MAX_END_REASON]
    return clean if not end_reason_problem(clean) else "no reason given"


def ended_by(name: str, tick: int, reason: str) -> str:
    """The End's reason when a participant ended the run (`ender_of` reads it back)."""
    return f"{ENDED_BY}{name!r} after tick {tick}: {reason}"


def ender_of(reason: str) -> str | None:
    """Who ended the run, from an End's reason; None for any other end."""
    head, found, rest = reason.partition(ENDED_BY)
    return rest.split("'", 2)[1] if found and not head and rest.startswith("'") else None


def blame(name: str, what: str) -> str:
    """A run's error that names the participant at fault (`blames` reads it back)."""
    return f"participant {name!r} {what}"


def blames(error: str, name: str) -> bool:
    """Whether a run's error names `name` as the participant at fault (a launcher's cause
    may quote it inside its own words)."""
    return f"participant {name!r} " in error


def never_joined(missing: list[str], timeout_s: float, *, came: Collection[str] = ()) -> str:
    """The conductor's fault when participants never came (`who_never_joined` reads it);
    `came`: those seen present during the wait."""
    names = ", ".join(missing)
    return f"participant(s) {NEVER_JOINED} {timeout_s:g} s: {names}{came_and_went(missing, came)}"


def came_and_went(missing: list[str], came: Collection[str]) -> str:
    """Those of `missing` that joined and left before the start, said ("" for none)."""
    gone = [name for name in missing if name in came]
    return f" ({', '.join(gone)} joined, then left before the start: ended?)" if gone else ""


def who_never_joined(error: str) -> list[str]:
    """The participants a run's error names as never joined; none for any other error."""
    _, found, rest = error.partition(NEVER_JOINED)
    return rest.partition(": ")[2].split(" (")[0].split(", ") if found else []


class Policy(StrEnum):
    """What the conductor does with a faulty participant."""

    ABORT = "abort"
    DROP = "drop"


@dataclass(frozen=True)
class Stream:
    """A key with one producer and a period in ticks; `period=None` is free-running.
    `lag`: this consumer's fixed delay in ticks on top of the one tick (clocked only).
    `phase`: samples are tagged k with k % period == phase (the traffic's copy of the states,
    tagged just before each guidance tick: streams.py).
    `stamp_ticks`: a sample tagged k is stamped (k + stamp_ticks) x dt (states: 1, the state
    at the end of the tick). `check`: raises ValueError for a sample whose content this
    world cannot take (rows of other bodies, a thrust for thrusters the vessel lacks), so a
    bad sample is refused where it arrives, never in the step."""

    key: str
    message: type[Message]
    producer: str
    period: int | None = 1
    lag: int = 0
    stamp_ticks: int = 0
    check: Callable[[Any], None] | None = field(default=None, compare=False)
    phase: int = 0

    def __post_init__(self) -> None:
        if self.lag < 0 or (self.lag and self.period is None):
            raise ValueError(
                f"{self.key}: a lag must be >= 0, on a clocked stream (got {self.lag})"
            )
        if self.phase and not (self.period is not None and 0 <= self.phase < self.period):
            raise ValueError(f"{self.key}: phase {self.phase} outside 0..period-1")

    def is_due(self, tick: int) -> bool:
        """Whether a sample is tagged `tick` (clocked streams)."""
        return self.period is not None and tick >= 0 and tick % self.period == self.phase

    def due_before(self, tick: int) -> int:
        """The last tick < `tick` - lag at which a sample is due; -1 if none is due yet."""
        tick -= self.lag
        if self.period is None or tick <= self.phase:
            return -1
        return ((tick - 1 - self.phase) // self.period) * self.period + self.phase

    def released_before(self, tick: int) -> int:
        """Samples tagged below this tick are handed to the step of `tick`."""
        return tick - self.lag

    def due_through(self, tick: int) -> int:
        """The last tick <= `tick` at which a sample is due (used at run end)."""
        return self.due_before(tick + 1)


@dataclass(frozen=True)
class ClockSpec:
    dt_ns: int
    ticks: int
    participants: tuple[str, ...]
    deadline_s: float = 10.0
    start_timeout_s: float = 60.0
    policy: Policy = Policy.ABORT
    realtime_factor: float | None = None
    window_ticks: int = 1
    digest: str = ""  # the scenario's (config/load.py), sent in every Tick

    @property
    def ack_every(self) -> int:
        """Participants ack every this many ticks (and at the end of a grant): half the
        window, so the slowest one's ack extends the grant before the fastest runs dry."""
        return max(1, self.window_ticks // 2)


@dataclass
class Progress:
    tick: int
    stamp_ns: int
    ticks_per_s: float
    realtime_factor: float


@dataclass
class RunResult:
    ticks_done: int
    wall_s: float
    error: str = ""
    dropped: list[str] = field(default_factory=list)
    reason: str = "completed"
    join_s: float = 0.0
    why_dropped: dict[str, str] = field(default_factory=dict)  # name: the fault (policy drop)


@dataclass(frozen=True)
class ClockLimits:
    """What a participant knows of the clock from its scenario, to believe a `Tick` only if
    it could have come from the conductor: the tick length, the run's length, the window."""

    dt_ns: int
    ticks: int
    window: int
    digest: str = ""  # the scenario's (config/load.py); "" checks none
    deadline_s: float = 10.0  # the conductor's per-tick deadline (a waiting participant acks
    # within a quarter of it: participant.py)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.deadline_s) and self.deadline_s > 0):  # 0: a busy loop
            raise ValueError(f"deadline_s {self.deadline_s}: must be a finite number > 0")

    @property
    def idle_s(self) -> float:
        """How long a participant waits for an event before it acks what it has stepped:
        at 1 s, a participant waiting for a slow stack's command under a 1 s deadline had not
        acked its stepped ticks yet, and the conductor named it, not the stack."""
        return min(1.0, self.deadline_s / 4)

    def acked_by_all(self, granted: int) -> int:
        """A tick every participant has acked, known from the last grant: the conductor
        grants at most a window past that. No participant can end the run before it."""
        return granted - self.window

    def check_digest(self, theirs: str, *, waiting: bool = False) -> None:
        """A conductor that runs another scenario than this process (hosts given different
        files) is fatal here, not a sample to refuse: waiting would only time out. `theirs`:
        a Tick's digest, or (`waiting`: no tick yet) its world/info's (start_wait.py)."""
        if self.digest and theirs and theirs != self.digest:
            why = " and gives no tick: it waits for the participants of its file" if waiting else ""
            raise WorldMismatch(
                f"the conductor runs another scenario (digest {theirs}, this process's "
                f"{self.digest}){why}: give every process of the run the same scenario file"
            )

    def problem(self, tick: Tick, *, next_tick: int, grant: int) -> str:
        """Why `tick` cannot be a grant of this run ("" if it can). `grant`: the last tick
        granted so far (-1: none); `next_tick`: the tick this participant steps next."""
        if tick.dt_ns != self.dt_ns:
            return f"dt {tick.dt_ns} ns, not {self.dt_ns}"
        if not 0 <= tick.tick < self.ticks:
            return f"tick {tick.tick} outside the run's 0..{self.ticks - 1}"
        if tick.stamp_ns != tick.tick * self.dt_ns:
            return f"stamp {tick.stamp_ns} ns is not tick x dt"
        if not 1 <= tick.ack_every <= self.window:
            return f"ack_every {tick.ack_every} outside 1..{self.window}"
        if tick.tick < grant:
            return f"grant {tick.tick} goes back from {grant}"
        if tick.tick >= next_tick + self.window:  # nobody may run a window ahead of us
            return f"grant {tick.tick} is past the window ({next_tick} + {self.window})"
        return ""


# A stop for a fault (SIGUSR1: `catabot run` saw a process of the run die) is one: two
# programs failing at one tick had ended the run "interrupted", as Ctrl-C does.
FAULT_STOP = "stopped by its launcher: a process of the run ended"
# The conductor's stdout gone: `catabot run` was killed outright. Said, not "interrupted"
# as for Ctrl-C, so the folder of a run nobody stopped on purpose says what happened.
LAUNCHER_GONE = "interrupted: its launcher, catabot run, was killed"


class WorldMismatch(CataBotError):
    """This process and the conductor were started on different scenarios."""


def ticks_for(duration_ns: int, dt_ns: int) -> int:
    """Number of ticks covering a duration; a duration shorter than one tick is an error."""
    if dt_ns <= 0:
        raise ClockError(f"dt must be a positive number of nanoseconds (got {dt_ns})")
    if duration_ns < dt_ns:
        raise ClockError(f"duration {duration_ns} ns is shorter than one tick ({dt_ns} ns)")
    return duration_ns // dt_ns


def period_in_ticks(period_ns: int, dt_ns: int, *, what: str) -> int:
    """A rate expressed in ticks; refuses periods that are not a whole number of ticks."""
    if period_ns <= 0 or period_ns % dt_ns:
        raise ClockError(
            f"{what}: period {period_ns} ns is not a whole number of ticks of {dt_ns} ns "
            f"(allowed: multiples of {dt_ns} ns, i.e. rates {NS_PER_S / dt_ns:g} Hz divided "
            "by a whole number)"
        )
    return period_ns // dt_ns
