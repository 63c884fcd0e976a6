"""A split run's `log/run.json`, written by its recorder.

Why: `catabot run` writes `log/run.json` before it starts any service and rewrites it at the
end; a run whose processes are started one by one (`catabot service ...` on several hosts,
a compose file) had none, so `catabot results` showed its rows without a wall time or a
commit, and a recorder killed mid-run left nothing saying what had run. The recorder is the
process that owns the run folder there, so where no launcher wrote one first, it writes the
same record: `running` with the provenance as it starts, how the run ended at the End.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

from catabot.bus.messages import End
from catabot.config.scenario import Scenario
from catabot.run.provenance import provenance, write_started

log = logging.getLogger("recorder")
BY = "recorder (a split run: no catabot run launched it)"


class SplitRecord:
    def __init__(self, run_dir: Path, scenario: Scenario) -> None:
        self.path = run_dir / "log" / "run.json"
        self.scenario = scenario
        self.own = not self.path.exists()  # `catabot run` writes its own before any service
        self.started = time.monotonic()
        if self.own:
            self.path.parent.mkdir(exist_ok=True)
            write_started(run_dir, scenario, writer="recorder")

    def end(self, end: End) -> None:
        """How the run ended, where the recorder wrote the start (else the launcher does)."""
        if not self.own:
            return
        ticks = max(end.tick + 1, 0)
        record = {
            "ticks": ticks,
            "sim_s": ticks * self.scenario.dt_ns / 1e9,
            "wall_s": time.monotonic() - self.started,
            "error": end.error,
            "reason": end.reason,
            "written_by": BY,
            **provenance(self.scenario),
        }
        try:
            self.path.write_text(json.dumps(record, indent=2) + "\n")
        except OSError as exc:  # the recording is whole without it: said, not fatal
            log.error("cannot write %s: %s", self.path, exc.strerror or exc)
