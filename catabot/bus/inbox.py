"""Samples a participant has received, released in Jacobi order.

A sample tagged tick j is released to the step of tick k only when j < k (j < k - lag
for a stream read with a lag: `Stream.released_before`); free-running
samples (tick -1, from clients outside the lockstep) are released at the next step
after they arrive. Releasing by tick rather than by arrival is what keeps a run
deterministic when producers race each other on different routes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.messages import Message

Inputs = Mapping[str, list[Message]]


class Inbox:
    def __init__(self, streams: Sequence[Stream]) -> None:
        self.streams = {s.key: s for s in streams}
        if len(self.streams) != len(streams):
            raise ValueError("two input streams share one key")
        self.latest = {key: -1 for key in self.streams}
        self.held: dict[str, list[Message]] = {key: [] for key in self.streams}
        self.dropped: set[str] = set()
        # Only clocked streams can be due (physics has ~300 free-running command keys with
        # 100 boats); only keys holding samples need a look at release.
        self._clocked = [s for s in self.streams.values() if s.period is not None]
        self._holding: set[str] = set()
        self._order = {key: i for i, key in enumerate(self.streams)}  # release in stream order

    @property
    def keys(self) -> list[str]:
        return list(self.streams)

    def add(self, key: str, payload: bytes) -> None:
        """Decode and hold a sample; raises CodecError for a malformed payload."""
        stream = self.streams[key]
        msg = codec.decode(payload, stream.message)
        tick = _tick_of(msg)
        self.held[key].append(msg)
        self._holding.add(key)
        if tick > self.latest[key]:
            self.latest[key] = tick

    def drop_producers(self, names: Iterable[str]) -> None:
        """Stop waiting for streams of participants the conductor dropped."""
        self.dropped.update(names)

    def missing(self, tick: int) -> list[str]:
        """Keys whose last sample due before `tick` has not arrived yet."""
        return [
            s.key
            for s in self._clocked
            if s.producer not in self.dropped and self.latest[s.key] < s.due_before(tick)
        ]

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


def _tick_of(msg: Message) -> int:
    return int(getattr(msg, "tick", -1))
