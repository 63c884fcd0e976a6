"""The runs behind one env: the episode's run and its seat, the next one started early, and
old ones ending in the background.

A reset always gets a fresh run of the episode's own scenario (the episode is a function of
its seed, so is the run). What can be saved is waiting: with `prelaunch`, the run of the
episode a seedless reset will draw next is started while the current one plays (its
processes import and resolve the world, then wait for the env to join), and an episode that
ends stops its run in the background while the agent goes on.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

from catabot.gym.episode import Draw, Episode
from catabot.gym.link import ClientLink, Command, Frame, LinkError, LinkTimeout, not_forked
from catabot.gym.options import EnvOptions
from catabot.gym.process import RunError, SimProcess
from catabot.world.world import World

JOIN_POLL_S = 0.5
PORT_TRIES = 3
PORT_TAKEN = "Address already in use"  # the run could not bind the port picked for it


@dataclass
class Live:
    episode: Episode
    world: World
    run: SimProcess
    link: ClientLink | None = None


class Runner:
    def __init__(self, options: EnvOptions, draw: Draw, world: str) -> None:
        self.options, self.draw, self.world = options, draw, world
        self.live: Live | None = None
        self.next: Live | None = None
        self._ending: list[threading.Thread] = []
        self._launched = 0

    def start(self, seed: int, upcoming: int | None) -> Live:
        """The episode of `seed` joined at tick 0 (its frame taken: act next); with
        `upcoming`, that episode's run starts now in the background."""
        not_forked()
        self.end("reset before the episode ended")
        early, self.next = self.next, None
        if early is not None and early.episode.seed == seed and early.run.alive:
            try:
                self._join(early)  # started early; it may have given up waiting meanwhile
            except RunError:
                early = None
        else:
            self._retire(early)
            early = None
        live = early or self._fresh(seed)
        if upcoming is not None:
            self.next = self._launch(upcoming)
        return live

    def _fresh(self, seed: int) -> Live:
        """A new run of `seed`, joined. A port another process took between the pick and the
        run's bind (a parallel env or test: "Address already in use") is tried again."""
        for attempt in range(PORT_TRIES):
            live = self._launch(seed)
            try:
                return self._join(live)
            except RunError as exc:
                if PORT_TAKEN not in str(exc) or attempt == PORT_TRIES - 1:
                    raise
                live.run.discard()  # tried again: no error names its log
        raise AssertionError("unreachable")

    def _join(self, live: Live) -> Live:
        """Take the controller's seat in `live` and its tick-0 frame; RunError if the run
        does not get there (its console's last lines say why)."""
        self.live = live
        try:
            live.link = ClientLink(
                live.world, self.draw.vessel, self.draw.sensor_names(), live.run.endpoint,
                alive=lambda: live.run.alive, timeout_s=self.options.start_timeout_s,
            )  # fmt: skip
            self._first(live)
        except LinkError as exc:
            why = live.run.failure()  # before `end`, which removes the run's folder
            self.end()
            raise RunError(f"the episode's run did not start ({exc}): {why}") from None
        return live

    def _launch(self, seed: int) -> Live:
        """A run of the episode of `seed`, named `<world>-<n>` (n counts this env's runs):
        its keys, its run folder and its port are its own, whatever else still runs."""
        self._launched += 1
        episode = self.draw.episode(seed, f"{self.world}-{self._launched}")
        world = World.resolve(episode.scenario)
        return Live(episode, world, SimProcess(episode.scenario, out=self.options.runs_dir))

    def _first(self, live: Live) -> None:
        """Tick 0's frame, waiting as long as the run starts up (and failing if it exits)."""
        assert live.link is not None
        limit = time.monotonic() + self.options.start_timeout_s
        while True:
            try:
                live.link.observe(JOIN_POLL_S)
                return
            except LinkTimeout:
                if not live.run.alive or time.monotonic() > limit:
                    raise

    def observe(self) -> Frame:
        live = self._current()
        assert live.link is not None
        try:
            return live.link.observe(self.options.step_timeout_s)
        except LinkError as exc:
            raise LinkError(f"{exc}; {live.run.failure()}") from exc

    def act(self, command: Command) -> None:
        live = self._current()
        assert live.link is not None
        live.link.act(command)

    def _current(self) -> Live:
        if self.live is None:
            raise LinkError("no episode is running: call reset()")
        return self.live

    def end(self, reason: str = "") -> None:
        """Stop the episode's run in the background (the next reset does not wait for it):
        ended after the last period observed when a `reason` is given (its recording stops
        there on every run), else stopped as Ctrl-C does."""
        live, self.live = self.live, None
        self._retire(live, reason)

    def _retire(self, live: Live | None, reason: str = "") -> None:
        if live is None:
            return
        thread = threading.Thread(target=_finish, args=(live, reason), name="catabot-stop",
                                  daemon=True)  # fmt: skip
        thread.start()
        self._ending = [t for t in self._ending if t.is_alive()] + [thread]

    def close(self) -> None:
        """Every run of this env stopped, every process gone."""
        self.end("the env was closed before the episode ended")
        self._retire(self.next)
        self.next = None
        for thread in self._ending:
            thread.join()
        self._ending = []


def _finish(live: Live, reason: str) -> None:
    """End `live`'s run (by its seat when there is a reason), leave it, wait for its
    processes; a run that does not end by itself is stopped."""
    link = live.link
    ended = bool(reason) and link is not None and link.end(reason)
    if link is not None:
        link.close()
    live.run.stop(ended=ended)
