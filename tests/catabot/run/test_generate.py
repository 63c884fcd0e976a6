"""`catabot scenario generate`: a valid scenario with the asked traffic, or a clear refusal."""

from __future__ import annotations

from pathlib import Path

import pytest

from catabot.config.load import load_scenario
from catabot.run.cli import main
from catabot.world.world import World


def test_generated_scenario_is_valid_and_has_the_traffic(tmp_path: Path) -> None:
    out = tmp_path / "gen.json"
    argv = ["scenario", "generate", "--boats", "30", "--mix", "circle=0.5,waypoints=0.5"]
    assert main([*argv, "--seed", "9", "-o", str(out)]) == 0
    scenario = load_scenario(out)
    assert scenario.seed == 9 and scenario.traffic.count == 30
    kinds = {b.behaviour for b in World.resolve(scenario).traffic.boats}
    assert kinds == {"circle", "waypoints"}


def test_an_unknown_behaviour_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenario", "generate", "--mix", "zigzag=1"]) == 2
    assert "unknown behaviour 'zigzag'" in capsys.readouterr().err
    assert main(["scenario", "generate", "--mix", "circle=0.5,circle=0.5"]) == 2  # kept one
    assert "--mix: 'circle' given twice" in capsys.readouterr().err


def test_the_bundled_bay_comes_with_the_harbours_heights_and_scale(tmp_path: Path) -> None:
    """A PNG has no scale: the defaults (5 m a pixel) made a bay 2.5 times the harbour's."""
    out = tmp_path / "bay.json"
    argv = ["scenario", "generate", "--boats", "2", "--terrain", "bay.png", "-o", str(out)]
    assert main(argv) == 0
    terrain, harbour = load_scenario(out).terrain, load_scenario("harbour").terrain
    assert terrain is not None and harbour is not None
    assert terrain.model_dump() == harbour.model_dump()


def test_set_changes_what_it_made_and_a_field_a_flag_gives_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--set` was taken and dropped: the file had no rain and exit was 0."""
    out = tmp_path / "set.json"
    argv = ["scenario", "generate", "--set", "rain.rate_mm_h=10", "--set", "traffic.count=3"]
    assert main([*argv, "-o", str(out)]) == 0
    assert f"{out}: 3 boat(s), seed 0" in capsys.readouterr().out
    scenario = load_scenario(out)
    assert scenario.rain.rate_mm_h == 10.0 and scenario.traffic.count == 3
    assert main(["scenario", "generate", "--boats", "2", "--set", "traffic.count=3"]) == 2
    assert "traffic.count is given by --boats too" in capsys.readouterr().err
    whole = 'traffic={"behaviour_mix": {"circle": 1}}'  # a whole that holds a flag's field
    assert main(["scenario", "generate", "--boats", "2", "--set", whole]) == 2
    assert "traffic.count is given by --boats too" in capsys.readouterr().err
    assert main(["scenario", "generate", "--set", whole, "-o", str(out)]) == 0  # no KeyError
    assert f"{out}: 0 boat(s)" in capsys.readouterr().out
