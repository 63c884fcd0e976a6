"""The env's seat in the lockstep: the client API's pull-style join, observe, act.

`observe()` blocks until the next control tick is granted and every input due before it is
in (catabot.client.Joined: the bus Participant on a thread of its own, Jacobi inputs, acks,
End); `act(command)` is the command for that tick, applied by physics from the next tick on
every run (DESIGN.md §4). What the env knows beyond that (terrain, hull boxes, rows) it
takes from its own resolved World of the episode's scenario, checked against the world the
run describes (`world/info`).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import zenoh

from catabot.bus.messages import BodyStates, Message
from catabot.bus.session import Connection
from catabot.client import (
    Client,
    ClientError,
    NoData,
    RunEnded,
    SimulatorNotFound,
    Thrust,
    Twist,
    WorldInfo,
)
from catabot.client.discover import find_world
from catabot.errors import CataBotError
from catabot.world.world import World

Command = Thrust | Twist
ASK_S = 0.5  # how long one look for the run's world/info waits before the run is checked
END_WAIT_S = 5.0  # an ended run's End comes in milliseconds; past this, the run is stopped
RETRY = {"period_init_ms": 20, "period_max_ms": 100, "period_increase_factor": 1.5}
# a port clash met a listener that never answers the handshake: closing the session waited
# out Zenoh's 10 s open timeout before reset could try a fresh port (loopback takes ms)
OPEN_TIMEOUT_MS = 3000
_zenoh = {"opened": False, "forked": False}  # this process opened a session; then forked


def _forked() -> None:
    _zenoh["forked"] = _zenoh["opened"]


os.register_at_fork(after_in_child=_forked)


class LinkError(CataBotError, RuntimeError):
    """The run behind the env failed or ended while the env waited for it."""


class LinkTimeout(LinkError):
    """Nothing came from the run within the time allowed."""


@dataclass(frozen=True)
class Frame:
    """What the stack sees at a control tick: every body's state at the start of the tick
    (tagged tick - 1; the start states at tick 0) and the newest sample of each sensor."""

    tick: int
    stamp_ns: int
    bodies: BodyStates
    sensors: Mapping[str, Message] = field(default_factory=dict)


class ClientLink:
    """The env as the participant that controls `vessel` at its controller's rate."""

    def __init__(
        self,
        world: World,
        vessel: str,
        sensors: Sequence[str],
        endpoint: str,
        *,
        alive: Callable[[], bool],
        timeout_s: float,
    ) -> None:
        me = world.body(vessel)
        if me.controller is None:
            raise LinkError(f"vessel {vessel!r} has no controller to take the seat of")
        session = _session(endpoint)
        try:
            info = _find(session, world.scenario.name, endpoint, alive, timeout_s)
            if info.body_ids != world.body_ids:
                raise LinkError(f"the run at {endpoint} has other bodies than the episode's "
                                f"scenario: {list(info.body_ids)[:6]}...")  # fmt: skip
            self._client = Client(session, info, f"connect {endpoint}", timeout_s)
            self._joined = self._client.join(
                me.controller.participant, vessel=vessel, sensors=list(sensors)
            )
        except ClientError as exc:
            session.close()
            raise LinkError(str(exc)) from None
        except BaseException:
            session.close()
            raise

    def observe(self, timeout_s: float) -> Frame:
        """The next control tick's frame; LinkTimeout when nothing comes within
        `timeout_s`, LinkError when the run ends or fails first."""
        try:
            obs = self._joined.observe(timeout_s)
        except NoData as exc:
            raise LinkTimeout(str(exc)) from None
        except (RunEnded, ClientError) as exc:
            raise LinkError(str(exc)) from None
        newest = {name: s for name, s in obs.sensors.items() if s is not None}
        return Frame(obs.tick, obs.stamp_ns, obs.bodies, newest)

    def act(self, command: Command) -> None:
        """The command of the tick last observed."""
        try:
            self._joined.act(command)
        except ClientError as exc:
            raise LinkError(str(exc)) from None

    def end(self, reason: str) -> bool:
        """End the run after the last period observed (the episode is over), so its
        recording stops there on every run; False if the run was over or did not end."""
        try:
            self._joined.end_run(reason, timeout_s=END_WAIT_S)
        except ClientError:  # RunEnded and NoData included: the run's own end, or a kill
            return False
        return True

    def close(self) -> None:
        self._client.close()


def not_forked() -> None:
    """LinkError in a child forked after this process opened Zenoh: asked before a run is
    started for it (a forked vector env's worker left a run's folder and "still running")."""
    if _zenoh["forked"]:
        raise LinkError(
            "this process was forked from one that had opened Zenoh sessions, and Zenoh does "
            "not run in such a child (it hangs): make vector envs with "
            "AsyncVectorEnv(..., context='spawn') or gymnasium.make_vec(..., "
            "vector_kwargs={'context': 'spawn'})"
        )


def _session(endpoint: str) -> zenoh.Session:
    """A peer connecting to the run's conductor, which may not listen yet: Zenoh retries
    every 20 ms (its default waits 1 s, then 2 s, ...: a reset took a whole retry longer),
    and opens at once (a peer's default is to scout for 0.5 s first; the env knows its one
    endpoint and waits for the run's tokens anyway)."""
    not_forked()
    _zenoh["opened"] = True
    config = Connection(connect=(endpoint,), open_timeout_ms=OPEN_TIMEOUT_MS).config()
    config.insert_json5("connect/retry", json.dumps(RETRY))
    config.insert_json5("scouting/delay", "0")
    # every episode's run offered its shared-memory segments, which this process mapped and
    # kept: ≈1.3 files and 2-10 MB a reset, never released; loopback TCP is enough here
    config.insert_json5("transport/shared_memory/enabled", "false")
    try:
        return zenoh.open(config)
    except Exception as exc:
        raise LinkError(f"cannot open zenoh to the run at {endpoint}: {exc}") from None


def _find(
    session: zenoh.Session, world: str, endpoint: str, alive: Callable[[], bool], timeout_s: float
) -> WorldInfo:
    """The run's world/info, asked until it answers; LinkError as soon as the run is gone."""
    limit = time.monotonic() + timeout_s
    while True:
        try:
            return find_world(session, world, ASK_S, f"connect {endpoint}")
        except SimulatorNotFound:
            if not alive():
                raise LinkError("the run exited before it answered") from None
            if time.monotonic() > limit:
                raise LinkTimeout(f"the run did not answer within {timeout_s:g} s") from None
