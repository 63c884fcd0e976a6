"""Run-time setting changes on the clock (DESIGN.md §4): when each one takes effect.

A change is scheduled by the conductor at a tick nobody has been granted yet and travels
inside the `Tick` that grants it, so every participant holds it before it steps that tick,
whatever the route or the window: a change at tick k is applied at the start of step k, by
every participant, on every run. A sparse clocked stream could not do this (a consumer of a
stream cannot tell a change that is not due from one that is late). What a key means and
whether a value is allowed is the config layer's business (catabot/config/live.py): here a
change is a tick, a key and the value's canonical JSON text.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from catabot.errors import CataBotError

MAX_PER_TICK = 8  # live changes that may take effect at one tick
MAX_LIVE = 1000  # live changes in one run: a flood is refused, not queued
MAX_WIRE_CHARS = 2048  # one change on the wire (keys and values are short)


class SettingsError(CataBotError, ValueError):
    """A change the clock cannot schedule (the run is ending, too many changes)."""


def switch_key(vessel: str, sensor: str) -> str:
    """The live key that switches a sensor off or on (ids and names hold no '.')."""
    return f"sensor.{vessel}.{sensor}.enabled"


def sensor_switch(key: str) -> tuple[str, str] | None:
    """(vessel, sensor) a change of `key` switches; None for any other key."""
    parts = key.split(".")
    ok = len(parts) == 4 and parts[0] == "sensor" and parts[3] == "enabled"
    return (parts[1], parts[2]) if ok else None


@dataclass(frozen=True)
class Change:
    tick: int
    key: str
    value: str  # canonical JSON text of the validated value

    @property
    def decoded(self) -> Any:
        return json.loads(self.value)

    def wire(self) -> str:
        return json.dumps([self.tick, self.key, self.value], separators=(",", ":"))


def from_wire(text: str) -> Change:
    """A change as a Tick carries it; ValueError if it is not one."""
    if not isinstance(text, str) or len(text) > MAX_WIRE_CHARS:
        raise ValueError("a setting change must be a short JSON text")
    try:
        tick, key, value = json.loads(text)
        json.loads(value)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"malformed setting change {text[:80]!r}: {exc}") from None
    if type(tick) is not int or not isinstance(key, str) or not key:
        raise ValueError(f"malformed setting change {text[:80]!r}")
    return Change(tick, key, value)


def settings_problem(settings: Iterable[str], last: int, *, after: int) -> str:
    """A grant's changes must fall in the ticks it adds (`after` + 1 to `last`): one for a
    tick already granted could reach a participant that has stepped it, and the run would
    fork. Empty when every change does."""
    for text in settings:
        try:
            at = from_wire(text).tick
        except ValueError as exc:
            return str(exc)
        if not after < at <= last:
            return f"a setting change at tick {at} outside the grant's {after + 1}..{last}"
    return ""


def changes_of(settings: Iterable[str]) -> list[Change]:
    """The changes a step's Tick carries, in the order they apply."""
    return [from_wire(text) for text in settings]


class Schedule:
    """The run's changes by tick, owned by the conductor: the scenario's timeline from the
    start, live ones (`propose`, from the settings desk's thread) at the first tick above
    every grant. One lock makes "the first tick not granted" and "what this grant carries"
    agree: no change can land on a tick some participant has already been granted."""

    def __init__(
        self,
        timeline: Iterable[Change] = (),
        *,
        ticks: int,
        grace_s: Callable[[str], float] = lambda _key: 0.0,
    ) -> None:
        """`grace_s(key)`: how much longer than the tick's deadline a change of `key` may
        take to apply (catabot/config/live.py's `apply_grace_s`)."""
        self.ticks, self.grace_of = ticks, grace_s
        self._lock = threading.Lock()
        self._granted = -1
        self._by_tick: dict[int, list[Change]] = {}
        self._live = 0
        self._live_at: dict[int, int] = {}
        self.beyond: list[Change] = []  # a timeline past the run's end never applies
        for change in timeline:
            if 0 <= change.tick < ticks:
                self._by_tick.setdefault(change.tick, []).append(change)
            else:
                self.beyond.append(change)

    def propose(self, key: str, value: str) -> Change:
        """Schedule a live change at the first tick not granted; SettingsError if the run
        is over or too many changes came."""
        with self._lock:
            tick = self._granted + 1
            if tick >= self.ticks:
                raise SettingsError("the run is ending: no tick is left to change it at")
            if self._live >= MAX_LIVE:
                raise SettingsError(f"this run has taken its {MAX_LIVE} live changes")
            if self._live_at.get(tick, 0) >= MAX_PER_TICK:
                raise SettingsError(f"{MAX_PER_TICK} changes already wait for tick {tick}")
            change = Change(tick, key, value)
            self._by_tick.setdefault(tick, []).append(change)
            self._live += 1
            self._live_at[tick] = self._live_at.get(tick, 0) + 1
            return change

    def grant(self, last: int) -> tuple[str, ...]:
        """The changes a grant up to `last` carries (those after the previous grant)."""
        with self._lock:
            first, self._granted = self._granted + 1, max(self._granted, last)
            return tuple(c.wire() for k in range(first, last + 1) for c in self._by_tick.get(k, ()))

    def grace(self, first: int, last: int) -> float:
        """The most grace any change at ticks `first`..`last` has (0 with none)."""
        with self._lock:
            keys = {c.key for k in range(first, last + 1) for c in self._by_tick.get(k, ())}
        return max(map(self.grace_of, keys), default=0.0)

    def applied(self) -> list[Change]:
        """Every change granted so far, in the order it applied: the run's timeline."""
        with self._lock:
            done = sorted(k for k in self._by_tick if k <= self._granted)
            return [c for k in done for c in self._by_tick[k]]

    def asked(self) -> list[Change]:
        """Every change the run was asked for, in tick order: granted, waiting, or past its
        end (the run folder's scenario.json: an interrupted run's had lost its later ones)."""
        return self.in_force() + sorted(self.beyond, key=lambda c: c.tick)

    def in_force(self) -> list[Change]:
        """Every change granted or waiting, in order (what `catabot get` shows)."""
        with self._lock:
            return [c for k in sorted(self._by_tick) for c in self._by_tick[k]]

    @property
    def granted(self) -> int:
        return self._granted
