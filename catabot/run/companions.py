"""Programs `catabot run` starts beside the lockstep: the live viewer, and after the run the
conversions the scenario asks for (`recording.rerun`, `recording.export`).

None of them is a participant: the conductor never waits for them. The live viewer is a
Zenoh observer started with the services (`catabot run --view`); the conversions read the
finished run folder (run.mcap, dataset/), so they see every sample and cost the lockstep
nothing: run.rrd is the replay of the recorded streams, the same that `catabot view RUN`
shows. Each is a program of its own (`python -m services.viewer`, `services.datasets`),
started by module name: the library never imports a service.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from catabot.bus.session import free_port
from catabot.config.scenario import Scenario
from catabot.run.supervisor import ended

VIEW_MODES = ("native", "web")
VIEWER = "services.viewer"
DATASETS = "services.datasets"


READY_S = 30.0  # the viewer's start-up (imports, a link to the conductor) before services start
HOLD_SIGNALS = (signal.SIGTERM, signal.SIGHUP)  # besides Ctrl-C: end a held web viewer


@dataclass
class Viewer:
    """The live viewer's process and, for the web viewer, the address to open."""

    proc: subprocess.Popen[str]
    url: str | None
    ready_file: Path

    def wait_ready(self) -> bool:
        """Until it has subscribed and reached the conductor (so it sees the run from its
        start and its End), or READY_S: the run starts either way, the view is an extra."""
        limit = time.monotonic() + READY_S
        while not self.ready_file.exists() and self.proc.poll() is None:
            if time.monotonic() > limit:
                return False
            time.sleep(0.05)
        self.ready_file.unlink(missing_ok=True)
        return self.proc.poll() is None

    def why(self) -> str:
        """Its log's last line (`catabot view`'s one-line refusal: no display, a port), else
        where its log is: the launcher said only "see log/viewer.log"."""
        log = self.ready_file.with_name("viewer.log")
        lines = log.read_text(errors="replace").strip().splitlines() if log.is_file() else []
        return lines[-1].removeprefix("catabot view: ") if lines else f"see {log}"

    def stop(self, *, wait_s: float) -> None:
        """Let it finish (it ends after the run's End), then stop it."""
        try:
            self.proc.wait(timeout=wait_s)
        except subprocess.TimeoutExpired:
            ended(self.proc, grace_s=5)

    def hold(self) -> None:
        """Serve the web viewer until Ctrl-C, SIGTERM or SIGHUP (after the run, so it can
        still be looked at). The viewer is in its own session, so a signal to the launcher
        does not reach it: the launcher stops it (on SIGTERM it was left serving, orphaned)."""
        print(f"the web viewer stays at {self.url} until Ctrl-C", flush=True)
        asked = threading.Event()
        previous = {sig: signal.signal(sig, lambda *_: asked.set()) for sig in HOLD_SIGNALS}
        try:
            while self.proc.poll() is None and not asked.wait(0.5):
                pass
        except KeyboardInterrupt:
            pass
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        self.stop(wait_s=0)


def start_viewer(mode: str, run_dir: Path, svc_flags: list[str], *, hold: bool) -> Viewer:
    """The live viewer of this run, connected like a service; its log in log/viewer.log.
    `hold`: the web viewer stays up after the run (until the launcher stops it)."""
    ready = run_dir / "log" / "viewer.ready"
    args = [sys.executable, "-m", VIEWER, str(run_dir), *svc_flags, "--ready-file", str(ready)]
    args += [] if hold else ["--no-hold"]
    url = None
    if mode == "web":
        web, grpc = free_port(), free_port()
        args += ["--web", "--web-port", str(web), "--grpc-port", str(grpc)]
        url = f"http://127.0.0.1:{web}/?url=rerun%2Bhttp://127.0.0.1:{grpc}/proxy"
    log = (run_dir / "log" / "viewer.log").open("w")
    proc = subprocess.Popen(args, stdout=log, stderr=log, text=True, start_new_session=True)
    return Viewer(proc, url, ready)


def after_run(scenario: Scenario, run_dir: Path) -> dict[str, int]:
    """The conversions the scenario asks for, each as a program; their exit codes by name
    (`rerun`, `export-<format>`, logs in `log/<name>.log`), reported like the services'."""
    rec = scenario.recording
    steps: dict[str, list[str]] = {}
    if rec.rerun:
        steps["rerun"] = ["-m", VIEWER, str(run_dir), "--save", str(run_dir / "run.rrd")]
    for fmt in rec.export:
        out = run_dir / "export" / fmt
        steps[f"export-{fmt}"] = ["-m", DATASETS, "export", str(run_dir), "-f", fmt, "-o", str(out)]
    codes = {}
    for name, args in steps.items():
        with (run_dir / "log" / f"{name}.log").open("w") as log:
            codes[name] = subprocess.run(
                [sys.executable, *args], stdout=log, stderr=log, check=False
            ).returncode
    return codes
