"""No service imports a heavy library it does not use (issue #17: memory): a process pays
each import in memory and start-up time, and with 100 boats every service is a process.
Each service is imported in a fresh interpreter, as `python -m services.<name>` does."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.paths import REPO

HEAVY = ("open3d", "dartpy", "rerun", "matplotlib", "pandas", "PIL", "tifffile", "rosbags", "numba")
USES = {  # what each service needs of HEAVY
    "physics": {"dartpy", "numba"},  # numba: the compiled force laws (kernels.py)
    "traffic": set(),
    "sensors": set(),
    "recorder": {"PIL", "rosbags"},  # dataset PNGs; the ROS 2 types of run.mcap
    "ros": {"rosbags"},
}


@pytest.mark.parametrize("service", sorted(USES))
def test_a_service_imports_only_the_heavy_libraries_it_uses(service: str) -> None:
    code = (
        f"import importlib, json, sys; importlib.import_module('services.{service}.service'); "
        f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert set(json.loads(out.stdout.splitlines()[-1])) == USES[service]
