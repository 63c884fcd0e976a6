"""Why a stack leaves, as the conductor is told (catabot/client/client.py, Client.__exit__):
an audit's stack interrupted by Ctrl-C inside `with Client.connect(...)` was named as having
left "without a word", as a crash or a lost link is. The live close: tests/e2e/test_client.py."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from catabot.client.client import Client
from catabot.client.errors import RunEnded


def _leaving(exc: BaseException | None) -> str:
    said: list[str] = []
    fake: Any = SimpleNamespace(close=lambda *, fault="": said.append(fault))
    Client.__exit__(fake, type(exc) if exc else None, exc, None)
    return said[0]


@pytest.mark.parametrize(
    ("exc", "fault"),
    [
        (KeyboardInterrupt(), "interrupted (KeyboardInterrupt in the stack)"),
        (SystemExit(3), "interrupted (SystemExit in the stack)"),
        (ZeroDivisionError("division by zero"), "ZeroDivisionError: division by zero"),
        (RunEnded("the run ended"), ""),
        (None, ""),
    ],
)
def test_the_conductor_hears_why_the_stack_left(exc: BaseException | None, fault: str) -> None:
    assert _leaving(exc) == fault
