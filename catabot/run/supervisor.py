"""Watching the processes of one run until all have ended, and saying truthfully how it ended.

- Each process's stderr comes through `catabot run` into its log (child.py), a process's
  CRITICAL line (its own fatal fault: a disk full, a crash) kept as a cause.
- The conductor says it is alive every half second (`catabot/run/conduct.py`); silence for
  `HANG_S` means it hangs (stopped, wedged): it is killed, and the run reported as such.
- A participant the conductor reports as gone or late whose process still exists hangs: it
  is killed at once (a stopped process ignores SIGTERM), and named as hung.
- After a fault, services get `End` with the error and a second or two to flush; whatever
  is left is killed, so `catabot run` returns within the deadline plus a couple of seconds.
"""

from __future__ import annotations

import contextlib
import json
import re
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Iterator

from catabot.bus import clock
from catabot.bus.participant import WAITED
from catabot.run.child import Child

HANG_S = 3.0  # the conductor's heartbeat is every 0.5 s
START_S = 60.0  # until its first line (Python's imports on a loaded machine take seconds)
FAULT_REAP_S = 2.0  # after a fault: End carries the error, services drain for 1 s
END_REAP_S = 15.0  # after a clean end: the recorder's last flush
PROGRAM_REAP_S = 5.0  # a controller program's, after a clean end
GONE_S = 2.0  # a program gone before the clock started, and the run not ending: a fault


def _exits(proc: subprocess.Popen[str], *, within_s: float) -> bool:
    try:
        proc.wait(timeout=within_s)
    except subprocess.TimeoutExpired:
        return False
    return True


class Stops:
    """Ctrl-C, SIGTERM and SIGHUP all end the run cleanly through the conductor (a launcher
    killed by its shell or a process manager must leave no orphans ticking). A request is
    held until the conductor says it is ready: a signal before its handlers are set would
    kill it outright."""

    def __init__(self) -> None:
        self.requested = False
        self.ready = threading.Event()
        self.conductor: subprocess.Popen[str] | None = None

    @contextlib.contextmanager
    def installed(self) -> Iterator[None]:
        signals = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
        previous = {sig: signal.signal(sig, self._on_signal) for sig in signals}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)

    def _on_signal(self, *_: object) -> None:
        self.requested = True
        self.forward()

    def forward(self) -> None:
        """Pass a held request to the conductor once it takes signals."""
        if self.requested and self.ready.is_set() and self.conductor is not None:
            self.conductor.send_signal(signal.SIGINT)


class Supervisor:
    """Follows the conductor's lines, watches every process, ends hung ones, finds the cause."""

    def __init__(
        self, conductor: Child, services: dict[str, Child], stops: Stops, *, goes_on: bool = False
    ) -> None:
        """`goes_on`: the scenario's clock.policy is drop, so a process that dies once the
        clock has started is the conductor's to drop, and the run goes on without it."""
        self.conductor, self.services, self.stops = conductor, services, stops
        self.goes_on = goes_on
        self.result: dict[str, object] = {}
        self.progress: dict[str, object] = {}  # the conductor's last progress line
        self.stopped: set[str] = set()  # services stopped before they joined an interrupted run
        self.hung: list[str] = []  # processes found hung and killed
        self.lingered: set[str] = set()  # programs stopped, still running after a clean end
        self.after_fault: set[str] = set()  # services stopped, still running after a fault
        self._ticking = False  # a progress line came: the run's clock has started
        self._gone: dict[str, float] = {}  # programs that exited 0 before it had, and when
        self._started = time.monotonic()
        self._heard: float | None = None  # when the conductor last said anything
        self._echoed: dict[str, int] = {}  # refusal lines echoed, per process

    def wait(self, on_progress: object = None, on_note: Callable[[str], None] = print) -> None:
        """Until every process has ended (`on_progress(event)` for the progress lines,
        `on_note(line)` for the first refusal of each kind)."""
        reader = threading.Thread(target=self._follow, args=(on_progress,), daemon=True)
        reader.start()
        asked_to_stop = False
        while reader.is_alive():
            reader.join(timeout=0.1)
            self._echo(on_note)
            died = [c for c in self.services.values() if c.proc.poll() not in (None, 0)]
            died += self._gone_before_joining()
            if died and not asked_to_stop and self.conductor.proc.poll() is None:
                for child in died:
                    child.crashed()
                if not (self.goes_on and self._ticking):
                    self.conductor.proc.send_signal(signal.SIGUSR1)  # a stop for a fault
                    asked_to_stop = True
            silent = self._silent()
            if silent and self.conductor.proc.poll() is None:
                self._kill(self.conductor, f"the conductor hung (nothing from it for {silent:g} s)")
        self.conductor.proc.wait()
        self._programs_that_left()
        self._kill_hung_participants()
        self._reap()
        for child in (self.conductor, *self.services.values()):
            child.join()
        self._echo(on_note)

    def _gone_before_joining(self) -> list[Child]:
        """Programs that exited cleanly before the clock started and stayed gone for
        GONE_S: the run would wait out `clock.start_timeout_s` for them (a program that
        ended the run itself exits 0 too, but the conductor ends within that)."""
        now, gone = time.monotonic(), []
        for child in self.services.values():
            if self._ticking or not child.program or child.proc.poll() != 0:
                continue
            if now - self._gone.setdefault(child.name, now) > GONE_S:
                child.left_before_joining()
                gone.append(child)
        return gone

    def _echo(self, on_note: Callable[[str], None]) -> None:
        for child in (self.conductor, *self.services.values()):
            done = self._echoed.get(child.name, 0)
            for line in child.notes[done:]:
                on_note(line)
            self._echoed[child.name] = done + len(child.notes[done:])

    def _silent(self) -> float:
        """How long the conductor has been silent, once that means it hangs (else 0)."""
        now = time.monotonic()
        if self._heard is None:
            return START_S if now - self._started > START_S else 0.0
        return HANG_S if now - self._heard > HANG_S else 0.0

    def _follow(self, on_progress: object) -> None:
        assert self.conductor.proc.stdout is not None
        for line in self.conductor.proc.stdout:
            self._heard = time.monotonic()
            try:
                event = json.loads(line)
            except json.JSONDecodeError:
                continue
            kind = event.get("kind")
            if kind == "ready":
                self.stops.ready.set()
                self.stops.forward()
            elif kind == "progress":
                self._ticking, self.progress = True, event
                if callable(on_progress):
                    on_progress(event)
            elif kind == "result":
                self.result = event

    def _kill(self, child: Child, why: str) -> None:
        child.proc.kill()  # SIGKILL: a stopped process does not take SIGTERM
        self.hung.append(why)

    def _programs_that_left(self) -> None:
        """A program the conductor saw leave (often before this loop saw it end) and that
        ended with an error: its own crash is the cause, not merely its leaving."""
        error = str(self.result.get("error", ""))
        for name, child in self.services.items():
            left = child.program and clock.blames(error, name)
            if left and _exits(child.proc, within_s=1.0):
                child.crashed()

    def _kill_hung_participants(self) -> None:
        """Participants the conductor reports as gone or late, whose process still exists a
        second later (one that is only closing its session is not hung). One that said
        whose data it waited for is not hung but starved: the cause is that data's sender."""
        error = str(self.result.get("error", ""))
        for name, child in self.services.items():
            if clock.blames(error, name) and not _exits(child.proc, within_s=1.0):
                state = {"T": "stopped by a signal", "t": "stopped by a debugger"}.get(
                    child.state(), "alive but not stepping"
                )
                hung = "" if child.waited_line() else f"participant {name!r} hung ({state}): "
                self._kill(child, hung + self._waited(error))

    def _reap(self) -> None:
        """Services end by themselves after the conductor's End (15 s allows the recorder's
        last flush of a clean end; a second or two after a fault); one still starting when an
        interrupted run ended never heard the End: stopped at once, and not blamed. A
        controller program has PROGRAM_REAP_S: it has no files of the run to close."""
        ticks = int(self.result.get("ticks_done", 0))  # type: ignore[call-overload]
        unjoined = self.result.get("reason") == "interrupted" and ticks == 0
        faulted = bool(self.result.get("error")) or bool(self.hung) or not self.result
        timeout = 1.0 if unjoined else FAULT_REAP_S if faulted else END_REAP_S
        start = time.monotonic()
        for name, child in self.services.items():
            limit = start + (min(timeout, PROGRAM_REAP_S) if child.program else timeout)
            try:
                child.proc.wait(timeout=max(limit - time.monotonic(), 0.1))
            except subprocess.TimeoutExpired:
                if unjoined:
                    self.stopped.add(name)
                elif child.program and not faulted:  # its own loop (a spin, a plot window)
                    self.lingered.add(name)
                elif faulted and child.proc.poll() is None:
                    self.after_fault.add(name)
                ended(child.proc, grace_s=1.0)

    def cause(self) -> str:
        """The first fault: a process's own fatal error, a hung process, else the conductor's."""
        gone_on = self.dropped()  # the run went on without them: their faults end nothing
        fatal = [c for c in (self.conductor, *self.services.values())
                 if c.fatal and c.name not in gone_on]  # fmt: skip
        if fatal:
            first = min(fatal, key=lambda c: c.fatal_at)
            return f"{first.name}: {first.fatal}"
        if self.hung:
            return self.hung[0]
        return self._waited(str(self.result.get("error", "") or ""))

    def dropped(self) -> dict[str, str]:
        """Participants the conductor dropped (clock.policy drop), each with why: the
        conductor's words, and a program's own last words when it died."""
        why = dict(self.result.get("why_dropped") or {})  # type: ignore[call-overload]
        for name, child in self.services.items():
            if name in why and child.fatal:
                why[name] = f"{why[name]}; {child.fatal}"
        return why

    def _waited(self, error: str) -> str:
        """The conductor's fault, and whose data held the run. When several miss a deadline
        the conductor names one; the wait at the earliest tick is the root (a stack that
        skipped its command held physics at tick 101, then waited at 102 for physics), so
        the cause leads with that wait's sender when another participant was the one named
        (a stack asleep in its step had the recorder blamed)."""
        named = [n for n in self.services if clock.blames(error, n)]
        waits = sorted((_tick_of(line), n != named[0], n, line)
                       for n, line in self._waits()) if named else []  # fmt: skip
        if not waits:
            return error
        _, _, waiter, line = waits[0]
        late = [p for p in _producers(line) if p != waiter and p in self.services]
        if waiter == named[0] and late:
            return f"participant {late[0]!r} held the run up: {line} (the conductor: {error})"
        return f"{error}; {line}"

    def _waits(self) -> list[tuple[str, str]]:
        lines = [(n, c.waited_line()) for n, c in self.services.items()]  # each read once
        return [(n, line) for n, line in lines if line]


def _tick_of(waited: str) -> int:
    """The tick of a waited line as `Participant._waited` writes it."""
    found = re.search(rf" {WAITED} (\d+) ", waited)
    return int(found.group(1)) if found else 1 << 62


def _producers(waited: str) -> list[str]:
    """The senders a waited line names (`... for KEY from 'stack', KEY from 'physics'`)."""
    return re.findall(r" from '([^']+)'", waited)


def ended(proc: subprocess.Popen[str], *, grace_s: float) -> None:
    """SIGTERM, `grace_s` to exit, then SIGKILL: a process that must go, gone."""
    proc.terminate()
    try:
        proc.wait(timeout=grace_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
