"""`catabot plot`'s command series against a real run: twist set-points sent from outside are
drawn with the script's (it drew the script's alone, from the scenario)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import only_run_dir, scenario_file, start

from catabot.bus.session import free_port
from catabot.client import Client, Twist
from catabot.run.recorded import RecordedRun
from services.plots.series import read

pytestmark = pytest.mark.timeout(180)


def test_sent_twists_are_plotted_with_the_scripts(tmp_path: Path) -> None:
    endpoint, out = f"tcp/127.0.0.1:{free_port()}", tmp_path / "out"
    step = {"t_s": 0.0, "twist": {"surge_mps": 1.0, "yaw_rate_radps": 0.05}}
    data = {"name": "twists", "seed": 2, "duration_s": 6.0, "clock": {"realtime_factor": 2.0},
            "vessels": [{"id": "ego", "script": [step]}]}  # fmt: skip
    proc = start("run", str(scenario_file(tmp_path, data)), "--quiet", "--out", str(out),
                 "--listen", endpoint)  # fmt: skip
    try:
        with Client.connect([endpoint], timeout_s=30) as sim:
            sim.vessel("ego").send(Twist(0.4, -0.2))
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    series = read(RecordedRun(only_run_dir(out))).setpoint["ego"]
    values = [tuple(v) for v in np.round(series.values, 6)]
    assert values[0] == (1.0, 0.05) and (0.4, -0.2) in values, values
    assert np.all(np.diff(series.t) >= 0)
