"""The compressions of MCAP chunks that CataBot writes and reads: zstd, lz4, or none, and
the bits of the MCAP layout both sides spell (the magic, a message index entry).

One place for both sides: the recorder compresses (services/recorder/mcap_chunks.py),
the run-folder reader decompresses (catabot/run/mcap_index.py), with the libraries that
`mcap`'s own reader uses, so Foxglove, `mcap` and rosbags read what is written.
"""

from __future__ import annotations

import lz4.frame
import numpy as np
import zstandard

MAGIC = b"\x89MCAP0\r\n"  # opens and closes every MCAP file
ENTRY = np.dtype([("log_time", "<u8"), ("offset", "<u8")])  # a message index's (time, offset)
COMPRESSIONS = {"none": "", "zstd": "zstd", "lz4": "lz4"}  # scenario name -> MCAP name
ZSTD_LEVEL = 1  # measured on Table II runs: level 3 costs 1.4-1.8x the CPU for < 1% smaller
_ZSTD = zstandard.ZstdCompressor(level=ZSTD_LEVEL)  # one context, not one a chunk (one writer)


def compress(data: bytes, compression: str) -> bytes:
    """`data` compressed the way a chunk's `compression` field names ("" for none)."""
    if compression == "zstd":
        return bytes(_ZSTD.compress(data))
    if compression == "lz4":
        return bytes(lz4.frame.compress(data))
    return data


def decompress(data: bytes | memoryview, compression: str, size: int) -> bytes:
    """A chunk's records from its stored bytes (what `compress` wrote, or another writer);
    `size` is the chunk's uncompressed size. ValueError for a compression not known here."""
    if compression == "zstd":
        return bytes(zstandard.ZstdDecompressor().decompress(data, max_output_size=size))
    if compression == "lz4":
        return bytes(lz4.frame.decompress(data))
    if compression == "":
        return bytes(data)
    raise ValueError(f"chunk compression {compression!r}; known: zstd, lz4, none")
