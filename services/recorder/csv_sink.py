"""Time-synchronous CSV files, one per stream (DESIGN.md §7).

Rows are held in memory and reach the file only in `flush()`, which the recorder calls once
per tick: a run killed at any moment therefore leaves whole rows of whole ticks on disk,
never a half-written line. A write that fails (a full disk) is undone: the file is cut back
to its last complete flush, and `DiskError` names the file. The header is taken from the
first sample of each stream, so a sample of another shape (a different number of thrusters,
another message type) is refused with `RecorderError` instead of silently shifting columns
under the header.
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

from catabot.bus.messages import Message
from catabot.errors import CataBotError
from services.recorder import tabular


class RecorderError(CataBotError, ValueError):
    """A sample the recorder cannot write without corrupting a file; the service logs it."""


def stream_filename(stream: str, suffix: str) -> str:
    """`vessel/ego/state` -> `vessel.ego.state<suffix>`: flat, and never escapes the folder."""
    name = stream.strip("/").replace("/", ".")
    if not name or name.startswith(".") or "\\" in name or "\x00" in name:
        raise RecorderError(f"stream {stream!r} cannot name a file")
    return name + suffix


class DiskError(CataBotError):
    """A file could not be written (disk full, I/O error): the recording cannot go on (not a
    `RecorderError`, which refuses one sample and goes on)."""


@dataclass
class _CsvFile:
    """One open CSV file, its header shape, the rows not yet written and the bytes written
    by complete flushes."""

    stream: str
    handle: BinaryIO
    cls: type[Message]
    width: int
    pending: list[str] = field(default_factory=list)
    size: int = 0

    def flush(self) -> None:
        data = "".join(self.pending).encode("utf-8")
        self.pending.clear()
        write_whole(self.handle, data, self.size)
        self.size += len(data)


def write_whole(handle: BinaryIO, data: bytes, size: int) -> None:
    """All of `data` at offset `size` of an unbuffered file, or nothing: a partial write is
    cut back off, so the file never ends in a torn row or record."""
    view = memoryview(data)
    try:
        while view:
            view = view[handle.write(view) or 0 :]
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.ftruncate(handle.fileno(), size)
            handle.seek(size)
        raise DiskError(f"cannot write {handle.name}: {exc.strerror or exc}") from None


def _line(cells: list[str]) -> str:
    """One CSV line, quoted where a cell needs it (the csv module's rules)."""
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(cells)
    return buffer.getvalue()


class CsvSink:
    """Writes every sample of every stream as one CSV row; `flush()` once per tick."""

    def __init__(self, directory: Path) -> None:
        self._dir = Path(directory)
        self._dir.mkdir(parents=True, exist_ok=True)
        self._files: dict[str, _CsvFile] = {}
        self._groups: dict[tuple[tuple[str, ...], type[Message]], list[_CsvFile]] = {}
        self._closed = False

    def path(self, stream: str) -> Path:
        """Where the rows of `stream` go."""
        return self._dir / stream_filename(stream, ".csv")

    def write(self, stream: str, msg: Message) -> None:
        """Queue one row; the first sample of a stream creates its file and header."""
        if self._closed:
            raise RecorderError(f"{stream}: the CSV sink is closed")
        out = self._files.get(stream) or self._open(stream, msg)
        if type(msg) is not out.cls:
            raise RecorderError(
                f"{stream}: a {type(msg).__name__} sample on a stream of {out.cls.__name__}; "
                "not written"
            )
        try:
            cells = tabular.row(msg)
        except TypeError as exc:
            raise RecorderError(f"{stream}: {exc}; not written") from exc
        if len(cells) != out.width:
            raise RecorderError(
                f"{stream}: sample has {len(cells)} columns but the header has {out.width} "
                "(set by the first sample); not written"
            )
        out.pending.append(_line(cells))

    def write_lines(self, streams: Sequence[str], cls: type[Message], lines: Sequence[str]) -> None:
        """Queue `lines[i]` (a formatted row of `tabular.columns(cls)`) on `streams[i]`: the
        batch path, which formats every row of a tick at once (`services/recorder/batches`)."""
        if self._closed:
            raise RecorderError(f"{streams[0] if streams else '?'}: the CSV sink is closed")
        group = (tuple(streams), cls)
        files = self._groups.get(group)
        if files is None:  # the same streams every tick: open and check them once
            files = self._groups[group] = [self._file_for(stream, cls) for stream in streams]
        if len(files) != len(lines):
            raise RecorderError(f"{len(lines)} lines for {len(files)} streams; not written")
        for out, line in zip(files, lines, strict=True):
            out.pending.append(line)

    def _file_for(self, stream: str, cls: type[Message]) -> _CsvFile:
        out = self._files.get(stream) or self._open_for(stream, cls, tabular.columns(cls))
        if out.cls is not cls:
            raise RecorderError(
                f"{stream}: a {cls.__name__} sample on a stream of {out.cls.__name__}; not written"
            )
        return out

    def _open(self, stream: str, msg: Message) -> _CsvFile:
        return self._open_for(stream, type(msg), tabular.sample_columns(msg))

    def _open_for(self, stream: str, cls: type[Message], header: list[str]) -> _CsvFile:
        path = self.path(stream)
        if any(o.handle.name == str(path) for o in self._files.values()):
            raise RecorderError(f"{stream}: file {path.name} is already used by another stream")
        handle = open(path, "wb", buffering=0)  # noqa: SIM115 - closed by close()
        out = _CsvFile(stream, handle, cls, len(header), [_line(header)])
        self._files[stream] = out
        return out

    def flush(self) -> None:
        """Write the rows queued since the last call and flush every file (once per tick)."""
        for out in self._files.values():
            if out.pending:
                out.flush()

    def close(self) -> None:
        """Flush and close every file; further writes are refused."""
        if self._closed:
            return
        self.flush()
        for out in self._files.values():
            out.handle.close()
        self._closed = True

    def __enter__(self) -> CsvSink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
