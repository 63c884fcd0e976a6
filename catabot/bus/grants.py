"""A participant's grants: the Ticks of DESIGN.md §4, believed only if its clock could send them.

Each Tick from the conductor's session is checked against `ClockLimits` (the run's tick
length, its length, the window) and against the grants before it; its live setting changes
are kept for the ticks they apply at; each tick the participant steps is derived from the
grant that covers it. Kept apart from participant.py, which owns the event loop, the
stepping and the acks: this is the part that decides what the clock said."""

from __future__ import annotations

from catabot.bus.clock import ClockLimits
from catabot.bus.messages import End, Tick
from catabot.bus.rejections import Rejected
from catabot.bus.settings import from_wire, settings_problem


class Grants:
    def __init__(self, *, limits: ClockLimits | None, everyone: set[str]) -> None:
        """`everyone`: the participants a tick may name as dropped (this one among them)."""
        self.limits, self.everyone = limits, everyone
        self.last: Tick | None = None
        self.run_id = ""  # the conductor's (its session checked): a fault names this run
        self.repeated = False  # the same grant again, no one dropped: the run is ending
        self._settings: dict[int, list[str]] = {}  # changes granted, by the tick they apply

    @property
    def tick(self) -> int:
        """The last tick granted so far (-1 before the first grant)."""
        return self.last.tick if self.last is not None else -1

    def take(self, tick: Tick, *, next_tick: int) -> None:
        """Adopt `tick` as the grant; Rejected if its clock cannot have sent it (`next_tick`:
        the tick this participant steps next)."""
        if self.run_id and tick.run != self.run_id:
            raise Rejected("tick of another run", tick.run)
        self.run_id = tick.run
        if self.limits is not None:
            self.limits.check_digest(tick.digest)  # raises: another scenario than the conductor's
        problem = self._problem(tick, next_tick)
        if problem:
            raise Rejected("tick the clock cannot send", problem)
        for text in tick.settings:
            self._settings.setdefault(from_wire(text).tick, []).append(text)
        was = self.last
        self.repeated |= was is not None and (was.tick, was.dropped) == (tick.tick, tick.dropped)
        self.last = tick  # grants only grow (checked); a repeat carries a new dropped list

    def tick_of(self, k: int) -> Tick:
        """Tick k as stepped: its stamp, and the changes that apply at it."""
        grant = self.last
        assert grant is not None, "a tick stepped before any grant"
        stamp = grant.stamp_ns - (grant.tick - k) * grant.dt_ns
        changes = tuple(self._settings.pop(k, ()))
        return Tick(grant.run, k, stamp, grant.dt_ns, grant.dropped, grant.ack_every, changes)

    def drops(self, name: str) -> bool:
        """Whether the grant names `name` dropped (clock.policy drop)."""
        return self.last is not None and name in self.last.dropped

    def end(self, end: End) -> End:
        """`end` if its clock could send it (this run, a tick granted); else Rejected."""
        if self.run_id and end.run != self.run_id:
            raise Rejected("end of another run", end.run)
        if not -1 <= end.tick <= self.tick:
            raise Rejected("end the clock cannot send", f"tick {end.tick}, granted {self.tick}")
        return end

    def _problem(self, tick: Tick, next_tick: int) -> str:
        grant = self.tick
        if self.limits is not None:
            problem = self.limits.problem(tick, next_tick=next_tick, grant=grant)
            if problem:
                return problem
        if tick.ack_every < 1:
            return f"ack_every {tick.ack_every}"
        unknown = set(tick.dropped) - self.everyone
        if unknown:
            return f"drops unknown participants {sorted(unknown)}"
        return settings_problem(tick.settings, tick.tick, after=max(grant, next_tick - 1))
