"""One process of a run, its output relayed into its log by a thread.

When the log cannot be written (a full disk), its lines go to the console instead of being
lost; a process's CRITICAL line (its own fatal fault) is kept as a cause, the first refusal
of each kind and its advice become console notes.
"""

from __future__ import annotations

import contextlib
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import IO

from catabot.bus.participant import WAITED
from catabot.bus.rejections import report_of
from catabot.run.advice import advice_of

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
            self.notes.append(f"{self.name} refused more kinds of input: see {self.log_path}")
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

    def left_before_joining(self) -> None:
        """A program that exited cleanly before the run's clock started: it never joined."""
        if not self.fatal:
            self.fatal, self.fatal_at = (f"the program {self.what} ended (exit code 0) before "
                "the run started: a controller program joins the run and steps it to its end "
                "(run_lockstep, README \"Plugging in\")"), time.monotonic()  # fmt: skip

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
