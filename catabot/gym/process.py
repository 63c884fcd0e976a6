"""The run behind an episode: `catabot run` as a child process, on its own loopback port.

The env writes the episode's scenario to a file, starts `python -m catabot run FILE
--listen tcp/127.0.0.1:PORT` (embedded Zenoh, no router: each world its own port and its
own key prefix), and joins it as the ego's controller. Ending an episode early stops the
run the way Ctrl-C does (SIGTERM to `catabot run`, which ends the conductor and every
service cleanly); a run that does not end in time is killed with its whole process tree.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from catabot.bus.session import free_port
from catabot.config.scenario import Scenario
from catabot.errors import CataBotError

STOP_S = 10.0  # a clean stop takes well under a second; after this, kill
FAILURE_WAIT_S = 3.0  # for a failing run to print its cause


class RunError(CataBotError, RuntimeError):
    """The run behind the env could not start or ended badly; the message holds its log."""


class SimProcess:
    """One `catabot run` of one episode's scenario, in a temporary folder of its own."""

    def __init__(self, scenario: Scenario, *, out: str | None = None) -> None:
        self.folder = Path(tempfile.mkdtemp(prefix=f"catabot-{scenario.name}-"))
        self.failed = False  # a failed run's folder is kept: its error names its log
        self.out = Path(out) if out is not None else self.folder / "runs"
        self.name = scenario.name
        self.file = self.folder / "episode.json"
        self.file.write_text(scenario.model_dump_json(indent=1) + "\n")
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        self.log = self.folder / "run.log"
        cmd = [sys.executable, "-m", "catabot", "run", str(self.file), "--quiet",
               "--listen", self.endpoint, "--out", str(self.out.resolve())]  # fmt: skip
        with self.log.open("w") as log:
            self.proc = subprocess.Popen(
                cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                cwd=self.folder, env=_child_env(), start_new_session=True,
            )  # fmt: skip

    @property
    def alive(self) -> bool:
        return self.proc.poll() is None

    def failure(self) -> str:
        """Why the run stopped, from its console (the launcher's summary names the cause:
        its `run failed:` line alone where there is one; a run still ending is given a few
        seconds to say it, where its start's lines had been quoted instead); its folder is
        kept from now on, so the log named here is still there to read."""
        self.failed = True
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.proc.wait(timeout=FAILURE_WAIT_S)
        code = self.proc.poll()
        try:
            lines = self.log.read_text(errors="replace").strip().splitlines()
        except OSError:  # its folder removed already
            lines = ["(its log is gone)"]
        tail = [line for line in lines if line.startswith("run failed:")] or lines[-8:]
        status = "still running" if code is None else f"exit code {code}"
        return f"catabot run ({status}, log {self.log}, kept): " + " | ".join(tail)

    def run_dir(self) -> Path | None:
        """The run folder `catabot run` made for this run (None before it has)."""
        if not self.out.is_dir():
            return None
        mine = [p for p in self.out.iterdir() if p.name.startswith(f"{self.name}-2")]
        return mine[0] if len(mine) == 1 else None

    def stop(self, *, ended: bool = False) -> None:
        """Wait for every process of the run (`ended`: it is ending by itself), ending it
        as Ctrl-C does if it has not; kill on a hang."""
        if ended:
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.proc.wait(timeout=STOP_S)
        if self.alive:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=STOP_S)
            except subprocess.TimeoutExpired:
                _kill_tree(self.proc.pid)
                self.proc.wait()
        if not self.failed:
            self.discard()

    def discard(self) -> None:
        """Its temporary folder goes, failed or not (a port clash the env tried again)."""
        shutil.rmtree(self.folder, ignore_errors=True)


def _child_env() -> dict[str, str]:
    """The run imports the same `catabot` and `services` as the env (a source checkout on
    PYTHONPATH as well as an installed package)."""
    env = dict(os.environ)
    root = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    return env


def _kill_tree(pid: int) -> None:
    """SIGKILL `pid` and every descendant (the services run in sessions of their own)."""
    for victim in [*reversed(_descendants(pid)), pid]:
        with contextlib.suppress(ProcessLookupError):
            os.kill(victim, signal.SIGKILL)


def _descendants(pid: int) -> list[int]:
    """Every descendant of `pid`, parents first, from /proc (Linux)."""
    parents: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        parents.setdefault(ppid, []).append(int(entry.name))
    out, todo = [], [pid]
    while todo:
        kids = parents.get(todo.pop(), [])
        out += kids
        todo += kids
    return out


def wait_started(run: SimProcess, deadline: float) -> None:
    """Fail early when the run exits before the env could join it (a bad scenario: exit 2)."""
    if not run.alive:
        raise RunError(run.failure())
    if time.monotonic() > deadline:
        raise RunError(f"the run did not start in time; {run.failure()}")
