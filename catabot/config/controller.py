"""A vessel's controller: the lockstep participant that commands it, and optionally the
program `catabot run` starts as that participant (catabot/run/programs.py)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Literal

from pydantic import Field, field_validator, model_validator

from catabot.config.base import FieldProblem, ParticipantName, Strict


class ControllerConfig(Strict):
    """The vessel is driven by a lockstep participant (an autonomy stack): its commands are a
    clocked stream on `vessel/<id>/cmd/<command>`, so physics waits for each and applies it
    at the same tick on every run (DESIGN.md §4). With `program`, `catabot run` starts the
    stack itself as one more supervised process (catabot/run/programs.py); without, it is
    started by someone else and the run waits for it."""

    participant: ParticipantName = Field(description="the stack's participant name")
    rate_hz: float = Field(10.0, gt=0, description="commands per second, a whole number of ticks")
    command: Literal["thrust", "twist"] = "thrust"
    program: str | None = Field(
        None,
        min_length=1,
        description="a Python file `catabot run` starts as this participant (relative to the "
        "scenario file's folder, else to the current directory)",
    )
    args: list[str] = Field(
        [],
        description="the program's own arguments, after CataBot's flags (a number is taken as "
        "its JSON text: a command line holds only text)",
    )

    @field_validator("args", mode="before")
    @classmethod
    def _numbers_as_text(cls, value: object) -> object:
        """A sweep over a gain wrote `["--gain", 2]` and was refused: a number here can only
        mean its text. A bool is no number a command line would hold."""
        if not isinstance(value, list):
            return value
        return [json.dumps(a) if isinstance(a, int | float) and not isinstance(a, bool) else a
                for a in value]  # fmt: skip

    @model_validator(mode="after")
    def _args_need_program(self) -> ControllerConfig:
        if self.args and self.program is None:
            raise FieldProblem("args", "needs a program (args are the program's arguments)")
        return self


def check_programs(
    controllers: Sequence[ControllerConfig | None], taken: Sequence[str], *, bridge: str
) -> None:
    """A controller is not a CataBot process (one named `physics` passed validation, then
    held the run: physics waited for its own commands), but `bridge`, the ROS gateway, may
    drive a vessel for a ROS stack; a participant started from a program is one process,
    the same program and arguments wherever it is named (it may drive several vessels)."""
    seen: dict[str, tuple[str | None, list[str]]] = {}
    for index, c in enumerate(controllers):
        if c is None:
            continue
        field = f"vessels.{index}.controller"
        base = c.participant.partition(".")[0]  # or a shard's
        if base in taken and (c.program is not None or base != bridge):
            raise FieldProblem(
                field, f"participant {c.participant!r} is a CataBot process's name; pick another"
            )
        first = seen.setdefault(c.participant, (c.program, c.args))
        if first != (c.program, c.args):
            raise FieldProblem(
                field, f"participant {c.participant!r} is named with another program or args "
                "on an earlier vessel: one participant is one process",
            )  # fmt: skip
