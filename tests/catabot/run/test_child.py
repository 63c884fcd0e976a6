"""A process's first refusal of each kind reaches the console naming where the counts are."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from catabot.bus.clock import CONDUCTOR
from catabot.run.child import Child

LINE = "2026 x WARNING {who}: refused a sample on catabot/w/config/set: malformed: not JSON"


@pytest.mark.parametrize(("name", "counts"), [
    ("physics", "physics.rejected.json"),
    (CONDUCTOR, "conductor.rejected.json"),  # written from its result line (test_summary)
])  # fmt: skip
def test_the_first_refusal_names_the_file_that_counts_them(
    tmp_path: Path, name: str, counts: str
) -> None:
    said = f"print({LINE.format(who=name)!r})"
    child = Child(name, [sys.executable, "-c", said], tmp_path / f"{name}.log",
                  stdout=True, program=True)  # fmt: skip
    child.proc.wait(timeout=30)
    child._relay.join(timeout=30)
    assert child.notes == [f"{name} refused catabot/w/config/set: malformed: not JSON (messages: "
                           "docs/MESSAGES.md); first of "
                           f"its kind, all counted in {tmp_path / counts}"]  # fmt: skip
