"""Run folders: `<name>-<time>`, each run its own even when many start in one second."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from catabot.config.load import parse_scenario
from catabot.run.launcher import make_run_dir


def test_runs_started_together_each_get_their_own_folder(tmp_path: Path) -> None:
    """A check then a make let two runs race for one name: the loser exited 2."""
    scenario = parse_scenario({"name": "race", "vessels": [{"id": "ego"}]})
    out = tmp_path / "new" / "runs"  # made as needed
    with ThreadPoolExecutor(8) as pool:
        made = list(pool.map(lambda _: make_run_dir(out, scenario), range(16)))
    assert len(set(made)) == 16 and all((d / "scenario.json").is_file() for d in made)
    assert all(d.name.startswith("race-") for d in made)
