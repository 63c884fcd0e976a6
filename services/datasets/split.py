"""The train/val split of an exported dataset: seeded, so one run always splits the same way.

Neighbouring frames of one camera are near-duplicates, so frames are split in blocks of
simulated time, not one by one: a frame-by-frame split would put almost the same picture in
both sets and make the validation score meaningless. A block is `block_s` long (default: 10 s,
or a tenth of the frames' span if that is shorter, so a short run still gives both sets),
counted from the first frame. Each block draws u from its own generator,
`seeding.rng(seed, "dataset/split/<block>")` (DESIGN.md §2), and the round(`val_fraction` x
blocks) blocks of least u go to val, so the share is the one asked for to within a block
(each block going to val on its own draw, a run of ten blocks gave 40 % and 82 % for 0.2 and
0.5); with two blocks or more neither set stays empty.
"""

from __future__ import annotations

from collections.abc import Sequence

from catabot.world import seeding

DEFAULT_BLOCK_S = 10.0
MAX_BLOCK_S = 9.2e9  # the clock's int64 of nanoseconds


def block_ns(stamps_ns: Sequence[int], block_s: float | None) -> int:
    """The block length: as given, else 10 s or a tenth of the frames' span, whichever is
    shorter: ten blocks from the first frame, the last frame in the tenth (a tenth rounded
    down, 0.2-29.8 s: 2.96 s, made an eleventh block of the last two frames alone)."""
    if block_s is not None:
        return max(1, round(block_s * 1e9))
    span = max(stamps_ns, default=0) - min(stamps_ns, default=0) + 1
    return max(1, min(round(DEFAULT_BLOCK_S * 1e9), -(-span // 10)))  # ceil


def split(
    stamps_ns: Sequence[int], *, seed: int, val_fraction: float, block_s: float | None = None
) -> list[str]:
    """ "train" or "val" for each frame stamp."""
    length = block_ns(stamps_ns, block_s)
    first = min(stamps_ns, default=0)  # a camera switched on late: blocks from its start
    blocks = [int((s - first) // length) for s in stamps_ns]
    draws = {b: float(seeding.rng(seed, f"dataset/split/{b}").random()) for b in set(blocks)}
    ordered = sorted(draws, key=lambda b: (draws[b], b))
    val = set(ordered[: _val_blocks(len(ordered), val_fraction)])
    return ["val" if b in val else "train" for b in blocks]


def empty_set(subsets: Sequence[str], val_fraction: float) -> str:
    """A note when a split asked for both sets left one empty (a 30 s run in one 100 s
    block gave 150 train, 0 val, unsaid); --val-fraction 0 or 1 is the CLI's to say."""
    if not 0.0 < val_fraction < 1.0 or not subsets:
        return ""
    for empty in ("train", "val"):
        if empty not in subsets:
            return (f"; the {empty} set is empty: the frames fall in one block of the split "
                    "(--split-block-s; give a shorter one)")  # fmt: skip
    return ""


def _val_blocks(n: int, fraction: float) -> int:
    """How many of n blocks go to val: the share asked for, neither set empty when n >= 2."""
    k = round(fraction * n)
    if n >= 2 and 0.0 < fraction < 1.0:
        k = min(max(k, 1), n - 1)
    return k
