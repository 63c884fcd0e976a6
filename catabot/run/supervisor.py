"""Watching the processes of one run until all have ended, and saying truthfully how it ended.

- Each process's stderr comes through `catabot run` into its log (`Child`): when the log
  cannot be written (a full disk), its lines go to the console instead of being lost, and
  a process's CRITICAL line (its own fatal fault: a disk full, a crash) is kept as a cause.
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
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

from catabot.bus.participant import WAITED
from catabot.bus.rejections import report_of
from catabot.run.advice import advice_of

HANG_S = 3.0  # the conductor's heartbeat is every 0.5 s
START_S = 60.0  # until its first line (Python's imports on a loaded machine take seconds)
FAULT_REAP_S = 2.0  # after a fault: End carries the error, services drain for 1 s
MAX_ECHOED = 10  # kinds of refusal echoed to the console per process
HINTED = ("malformed", "invalid content")  # refusals of a payload's content


class Child:
    """One process of the run, its stderr relayed into its log by a thread.

    A service (`python -m MODULE ...`) states its own fatal fault in a CRITICAL line; a
    `program` (a controller's stack, catabot/run/programs.py: `command` is its whole command
    line) need not: its stdout goes into the log too, and an exit with an error while the
    run goes is its fatal fault, named with its last line (a traceback's exception)."""

    def __init__(
        self,
        name: str,
        command: list[str],
        log_path: Path,
        *,
        stdout: bool,
        program: bool = False,
        env: dict[str, str] | None = None,
    ) -> None:
        self.name, self.log_path, self.program = name, log_path, program
        self.what = command[1] if program else ""  # the program's file
        self.proc = subprocess.Popen(
            command if program else [sys.executable, "-m", *command],
            stdout=subprocess.PIPE if stdout or program else subprocess.DEVNULL,
            stderr=subprocess.STDOUT if program else subprocess.PIPE,  # a program's: one stream
            text=True,
            env=env,
            start_new_session=True,  # Ctrl-C reaches the launcher only; it ends the run cleanly
        )
        self.fatal = ""  # the first CRITICAL line: the process's own fatal fault
        self.fatal_at = 0.0
        self.last_line = ""  # a program's last line, for its fatal fault
        self.waited = ""  # whose data it waited for when the run failed (Participant._waited)
        self.notes: list[str] = []  # console lines: the first refusal of each kind, advice
        self._advised = 0
        self._refusals: set[tuple[str, str, str]] = set()
        self._relay = threading.Thread(target=self._copy_stderr, daemon=True)
        self._relay.start()

    def _copy_stderr(self) -> None:
        lines = self.proc.stdout if self.program else self.proc.stderr
        assert lines is not None
        log = _open(self.log_path)
        for line in lines:
            if " CRITICAL " in line and not self.fatal:
                self.fatal, self.fatal_at = line.split(" CRITICAL ", 1)[1].strip(), time.monotonic()
            self.last_line = line.strip() or self.last_line
            if f" {WAITED} " in line and not self.waited:
                self.waited = line.split(" ERROR ", 1)[-1].strip()
            self._note_refusal(line)
            self._note_advice(line)
            log = _write(log, line, self)

    def _note_refusal(self, line: str) -> None:
        """The first refusal of each (key, reason), for the console (`Supervisor.wait`): a
        client whose commands are dropped learns why without reading `log/`; at most
        `MAX_ECHOED` kinds, so a client spraying keys cannot flood the console."""
        report = report_of(line)
        if report is None or report in self._refusals or len(self._refusals) > MAX_ECHOED:
            return
        key, reason, detail = (_printable(part) for part in report)
        self._refusals.add(report)
        if len(self._refusals) > MAX_ECHOED:
            self.notes.append(f"{self.name} refused more kinds of samples: see {self.log_path}")
            return
        hint = " (messages: docs/MESSAGES.md)" if reason in HINTED else ""
        said = f"{reason}: {detail}" if detail else reason
        counts = self.log_path.with_name(f"{self.name}.rejected.json")
        self.notes.append(f"{self.name} refused {key}: {said}{hint}; first of its kind, all "
                            f"counted in {counts}")  # fmt: skip

    def _note_advice(self, line: str) -> None:
        """A service's advice (catabot/run/advice.py), at most `MAX_ECHOED` a process."""
        text = advice_of(line)
        if text is not None and self._advised < MAX_ECHOED:
            self._advised += 1
            self.notes.append(f"{self.name}: {_printable(text)}")

    def waited_line(self) -> str:
        """Whose data it waited for at the fault (`Participant._waited`), once an exited
        process's last lines are read."""
        if self.proc.poll() is not None:
            self._relay.join(timeout=1.0)
        return self.waited

    def crashed(self) -> None:
        """A program that ended with an error while the run went: that is its fatal fault."""
        code = self.proc.returncode
        if not self.program or self.fatal or code is None or code == 0:
            return
        self._relay.join(timeout=1.0)  # its last lines
        how = f"exit code {code}" if code > 0 else f"killed by signal {-code}"
        said = f": {self.last_line}" if self.last_line else ""
        self.fatal = f"the program {self.what} ended ({how}){said}"
        self.fatal_at = time.monotonic()

    def state(self) -> str:
        """The Linux scheduler's state letter of the process ('T': stopped), or ''."""
        with contextlib.suppress(OSError, IndexError):
            return Path(f"/proc/{self.proc.pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        return ""

    def join(self) -> None:
        self._relay.join(timeout=2.0)


def _printable(text: str) -> str:
    """A client's key or field names shown safely: no control characters on a terminal."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _exits(proc: subprocess.Popen[str], *, within_s: float) -> bool:
    try:
        proc.wait(timeout=within_s)
    except subprocess.TimeoutExpired:
        return False
    return True


def _open(path: Path) -> IO[str] | None:
    try:
        return path.open("a", encoding="utf-8")
    except OSError as exc:
        print(f"catabot run: cannot write {path} ({exc.strerror}); its lines follow here",
              file=sys.stderr)  # fmt: skip
        return None


def _write(log: IO[str] | None, line: str, child: Child) -> IO[str] | None:
    """Into the log while it can be written, else to the console (named)."""
    if log is not None:
        try:
            log.write(line)
            log.flush()
            return log
        except OSError as exc:
            print(f"catabot run: {child.log_path}: {exc.strerror}; {child.name}'s lines follow "
                  "here", file=sys.stderr)  # fmt: skip
    sys.stderr.write(f"[{child.name}] {line}")
    return None


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

    def __init__(self, conductor: Child, services: dict[str, Child], stops: Stops) -> None:
        self.conductor, self.services, self.stops = conductor, services, stops
        self.result: dict[str, object] = {}
        self.progress: dict[str, object] = {}
        self.stopped: set[str] = set()  # services stopped before they joined an interrupted run
        self.hung: list[str] = []  # processes found hung and killed
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
            if died and not asked_to_stop and self.conductor.proc.poll() is None:
                for child in died:
                    child.crashed()
                self.conductor.proc.send_signal(signal.SIGTERM)
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
            elif kind == "progress" and callable(on_progress):
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
            left = child.program and f"participant {name!r}" in error
            if left and _exits(child.proc, within_s=1.0):
                child.crashed()

    def _kill_hung_participants(self) -> None:
        """Participants the conductor reports as gone or late, whose process still exists a
        second later (one that is only closing its session is not hung)."""
        error = str(self.result.get("error", ""))
        for name, child in self.services.items():
            if f"participant {name!r}" in error and not _exits(child.proc, within_s=1.0):
                state = {"T": "stopped by a signal", "t": "stopped by a debugger"}.get(
                    child.state(), "alive but not stepping"
                )
                self._kill(child, f"participant {name!r} hung ({state}): {self._waited(error)}")

    def _reap(self) -> None:
        """Services end by themselves after the conductor's End (15 s allows the recorder's
        last flush of a clean end; a second or two after a fault); one still starting when an
        interrupted run ended never heard the End: stopped at once, and not blamed."""
        ticks = int(self.result.get("ticks_done", 0))  # type: ignore[call-overload]
        unjoined = self.result.get("reason") == "interrupted" and ticks == 0
        faulted = bool(self.result.get("error")) or bool(self.hung) or not self.result
        timeout = 1.0 if unjoined else FAULT_REAP_S if faulted else 15.0
        limit = time.monotonic() + timeout
        for name, child in self.services.items():
            try:
                child.proc.wait(timeout=max(limit - time.monotonic(), 0.1))
            except subprocess.TimeoutExpired:
                if unjoined:
                    self.stopped.add(name)
                ended(child.proc, grace_s=1.0)

    def cause(self) -> str:
        """The first fault: a process's own fatal error, a hung process, else the conductor's."""
        fatal = [c for c in (self.conductor, *self.services.values()) if c.fatal]
        if fatal:
            first = min(fatal, key=lambda c: c.fatal_at)
            return f"{first.name}: {first.fatal}"
        if self.hung:
            return self.hung[0]
        return self._waited(str(self.result.get("error", "") or ""))

    def _waited(self, error: str) -> str:
        """The conductor's fault, and whose data the participant it names waited for."""
        for name, child in self.services.items():
            if f"participant {name!r}" in error:
                waited = child.waited_line()
                if waited:
                    return f"{error}; {waited}"
        return error


def ended(proc: subprocess.Popen[str], *, grace_s: float) -> None:
    """SIGTERM, `grace_s` to exit, then SIGKILL: a process that must go, gone."""
    proc.terminate()
    try:
        proc.wait(timeout=grace_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
