"""A run-time change of sea builds up over `RAMP_S` instead of in one tick.

Replaced in one tick, the surface under a boat jumped by up to a wave height: from a medium
to a heavy swell a boat fell 1.2 m for 0.4 s and landed at 26 m/s^2, and from heavy to calm
one fell freely; its IMU and its metrics recorded a drop no sea makes. Now the old sea fades
and the new one builds up in `STAGES` even steps (`WaveField.blend`), each a small fraction of
a wave: what a boat meets when the wind gets up, only faster.

Physics and the sensors each keep one `SeaChange` and ask it every tick: both hold the same
rule and the same ticks, so both see the same surface at every tick, as they did before.
"""

from __future__ import annotations

from catabot.bus.clock import NS_PER_S
from catabot.world.waves import WaveField

RAMP_S = 10.0  # from the tick of the change to the new sea whole
STAGES = 40  # steps of the way: 2.5 % of the difference each, every quarter of a second


class SeaChange:
    """The sea of a run, which a change sends from where it is now towards a new one."""

    def __init__(self, now: WaveField, *, dt_ns: int) -> None:
        self.now = now
        self.every = max(1, round(RAMP_S / STAGES * NS_PER_S / dt_ns))  # ticks between stages
        self._from: WaveField | None = None
        self._to: WaveField | None = None
        self._start = 0

    def begin(self, to: WaveField, *, tick: int) -> None:
        """Head for `to` from the sea as it is at `tick` (part of the way to another, too):
        its first step is taken at `tick` itself."""
        self._from, self._to, self._start = self.now, to, tick

    def at(self, tick: int) -> WaveField | None:
        """The sea from `tick` on, where it changes at `tick`; None where it does not."""
        if self._from is None or self._to is None or tick < self._start:
            return None
        done, part = divmod(tick - self._start, self.every)
        if part:
            return None
        share = (done + 1) / STAGES
        if share >= 1.0:
            self.now, self._from, self._to = self._to, None, None
        else:
            self.now = WaveField.blend(self._from, self._to, share)
        return self.now
