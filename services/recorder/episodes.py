"""Contact and encounter episodes: when a condition on a pair (or a vessel) starts and ends.

A collision, a grounding or an encounter is reported once per episode, not once per tick:
an episode starts at the first tick the condition holds and ends at the last tick it held
before it stayed false for `gap_ns` (a hull bouncing off a quay is one collision). While an
episode lasts its smallest value and when it occurred are kept (an encounter's closest point
of approach). All of it is arrays over every slot at once; Python runs per episode only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Episode:
    slot: tuple[int, ...]  # its index in the tracked array (vessel, or vessel and body)
    start_ns: int
    end_ns: int | None  # None: still going on when the run ended
    least: float  # the smallest value seen during it (inf when none was given)
    least_ns: int


class Episodes:
    def __init__(self, shape: tuple[int, ...], gap_ns: int) -> None:
        self.gap_ns = gap_ns
        self.active = np.zeros(shape, dtype=bool)
        self.start = np.zeros(shape, dtype=np.int64)
        self.seen = np.zeros(shape, dtype=np.int64)  # the last tick it held
        self.least = np.full(shape, np.inf)
        self.least_at = np.zeros(shape, dtype=np.int64)
        self.done: list[Episode] = []
        self.going = False  # any episode active

    def update(self, holds: NDArray[np.bool_], stamp_ns: int, value: Array | None = None) -> None:
        """This tick's condition per slot, and the value to minimise (e.g. a distance)."""
        if not self.going and not holds.any():
            return  # the usual tick: nothing in contact, nothing near
        differ = holds != self.active
        if differ.any():  # something starts or lapses: rare, so the steady state stays cheap
            new = differ & holds
            self.start[new] = stamp_ns
            self.least[new] = np.inf
            self.active |= new
            over = differ & ~holds & (stamp_ns - self.seen > self.gap_ns)
            for slot in zip(*np.nonzero(over), strict=True):
                self.done.append(self._episode(slot, int(self.seen[slot])))
            self.active &= ~over
        np.copyto(self.seen, stamp_ns, where=holds)
        if value is not None:
            better = holds & (value < self.least)
            np.copyto(self.least, value, where=better)
            np.copyto(self.least_at, stamp_ns, where=better)
        self.going = bool(self.active.any())

    def all(self) -> list[Episode]:
        """Every episode, ended or not, by start time then slot (deterministic)."""
        going = [self._episode(s, None) for s in zip(*np.nonzero(self.active), strict=True)]
        return sorted([*self.done, *going], key=lambda e: (e.start_ns, e.slot))

    def _episode(self, slot: tuple[np.intp, ...], end_ns: int | None) -> Episode:
        return Episode(
            tuple(int(i) for i in slot),
            int(self.start[slot]),
            end_ns,
            float(self.least[slot]),
            int(self.least_at[slot]),
        )
