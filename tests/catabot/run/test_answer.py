"""An argument nobody takes is refused by the subcommand it was given to, in one line:
argparse named the top command (`catabot: unrecognized arguments` for `catabot run s --x`)."""

from __future__ import annotations

import pytest

from catabot.run.cli import main


@pytest.mark.parametrize(
    ("argv", "prog"),
    [
        (["run", "s.json", "--bogus"], "catabot run"),
        (["scenario", "validate", "s.json", "--bogus"], "catabot scenario"),
        (["dataset", "export", "r", "-f", "yolo", "-o", "o", "--bogus"], "catabot dataset export"),
        (["deploy", "compose", "s.json", "--bogus"], "catabot deploy compose"),
    ],
)
def test_an_extra_argument_is_named_with_its_subcommand(
    argv: list[str], prog: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err == f"{prog}: unrecognized arguments: --bogus (--help for usage)\n"


def test_a_router_takes_no_mode(capsys: pytest.CaptureFixture[str]) -> None:
    """It is a router: `--mode peer` was taken and ignored, and its help said peer."""
    with pytest.raises(SystemExit):
        main(["router", "--mode", "peer"])
    err = capsys.readouterr().err
    assert err == "catabot router: unrecognized arguments: --mode peer (--help for usage)\n"
