"""The root of every error CataBot raises on purpose.

Each precise error (a bad scenario field, a malformed payload, a missing terrain file...)
derives from `CataBotError` and from the built-in error it stands for (ValueError,
RuntimeError), so an entry point catches this one type and prints the message instead of
a traceback, and library code may still catch `ValueError` where that reads better.
"""

from __future__ import annotations


class CataBotError(Exception):
    """Something CataBot refuses or cannot do; the message says what and where."""
