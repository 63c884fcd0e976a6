"""How every `catabot` command answers a failure: one line naming what is wrong, exit 2.

The tools over run folders (`dataset`, `plot`) and the settings commands (`get`, `set`,
`snapshot`) share it, so a bad folder, a refused value or an unwritable file reads the same
everywhere and never ends in a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NoReturn

from catabot.errors import CataBotError


class OneLineParser(argparse.ArgumentParser):
    """argparse, refusing a bad option in one line as every other refusal reads (its usage
    block, printed first, hid the reason). Subcommands' parsers are of the same class."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: {message} (--help for usage)\n")

    def parse_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: None = None
    ) -> argparse.Namespace:
        parsed, rest = self.parse_known_args(args, namespace)
        self.refuse_extra(parsed, rest)
        return parsed

    def refuse_extra(self, parsed: argparse.Namespace, rest: Sequence[str]) -> None:
        """Arguments nobody took, refused by the subcommand they were given to: argparse
        named the top command (`catabot: unrecognized arguments` for `catabot run s --x`)."""
        if rest:
            self._leaf(parsed).error(f"unrecognized arguments: {' '.join(rest)}")

    def _leaf(self, parsed: argparse.Namespace) -> argparse.ArgumentParser:
        """The deepest subcommand's parser that `parsed` chose (this one without any)."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                chosen = action.choices.get(str(getattr(parsed, action.dest, "")))
                if isinstance(chosen, OneLineParser):
                    return chosen._leaf(parsed)
        return self


class OutputPathError(CataBotError, ValueError):
    """A file to write names a folder, or a folder that does not exist."""


def output_file(path: str, *, flag: str) -> Path:
    """`path` as a file this command may create; OutputPathError names the flag and why
    not, before any work (rerun's writer and `Path.write_text` fail only at the end, deep
    inside, after a replay or a schema has been built)."""
    file = Path(path)
    if file.is_dir():
        raise OutputPathError(f"{flag} {path}: is a folder; give a file name")
    if not file.parent.is_dir():
        raise OutputPathError(f"{flag} {path}: folder {file.parent} does not exist")
    return file


def output_folder(path: str, *, flag: str) -> Path:
    """`path` as a folder this command may write into (made if missing); OutputPathError
    names the flag when it is a file ("File exists" had been all it said)."""
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise OutputPathError(f"{flag} {path}: is a file; give a folder")
    return folder


def answered(prog: str, work: Callable[[], str | None]) -> int:
    """Run `work`; print what it says and return 0, or one line on stderr and return 2."""
    try:
        said = work()
    except CataBotError as exc:
        print(f"catabot {prog}: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"catabot {prog}: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    if said:
        print(said)
    return 0
