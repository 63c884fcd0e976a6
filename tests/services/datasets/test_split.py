"""The train/val split: seeded by the scenario, by blocks of simulated time, never one-sided."""

from __future__ import annotations

from services.datasets.split import block_ns, empty_set, split

S = 1_000_000_000


def test_the_same_seed_splits_the_same_way_and_another_may_not() -> None:
    stamps = [k * S // 5 for k in range(600)]  # 120 s of frames at 5 Hz
    first = split(stamps, seed=3, val_fraction=0.2)
    assert first == split(stamps, seed=3, val_fraction=0.2)
    assert any(split(stamps, seed=s, val_fraction=0.2) != first for s in (4, 5, 6))
    assert first.count("val") / len(first) == 2 / 12  # 12 blocks of 10 s: round(2.4)


def test_frames_of_one_block_share_a_set() -> None:
    stamps = [k * S // 10 for k in range(300)]  # 30 s: blocks of 10 s
    subsets = split(stamps, seed=1, val_fraction=0.3, block_s=10.0)
    for block in range(3):
        assert len(set(subsets[block * 100 : (block + 1) * 100])) == 1


def test_neither_set_is_empty_with_two_blocks_or_more() -> None:
    stamps = [0, 11 * S]
    for seed in range(20):
        assert sorted(split(stamps, seed=seed, val_fraction=0.01, block_s=10.0)) == ["train", "val"]
        assert sorted(split(stamps, seed=seed, val_fraction=0.99, block_s=10.0)) == ["train", "val"]
    assert split(stamps, seed=0, val_fraction=0.0, block_s=10.0) == ["train", "train"]


def test_short_runs_get_ten_blocks_from_their_first_frame() -> None:
    assert block_ns([0, 2 * S - 1], None) == S // 5
    perception = [k * S // 5 for k in range(1, 150)]  # its frames: 0.2-29.8 s at 5 Hz
    length = block_ns(perception, None)
    assert {(s - S // 5) // length for s in perception} == set(range(10))  # not eleven
    for late in (
        [95 * S + k * S // 5 for k in range(26)],
        [100 * S + k * S // 5 for k in range(51)],
    ):
        sets = split(late, seed=1, val_fraction=0.2)  # a camera on late: 25 of 26 went to val
        assert 0.1 <= sets.count("val") / len(sets) <= 0.3, sets.count("val")
    assert block_ns([0, 600 * S], None) == 10 * S
    assert block_ns([0, 600 * S], 2.5) == 5 * S // 2


def test_the_val_share_is_the_one_asked_for_to_within_a_block() -> None:
    """Blocks went to val each on its own draw: 20 of 50 frames for 0.2, 41 of 50 for 0.5."""
    stamps = [k * S // 5 for k in range(50)]  # 10 s at 5 Hz: ten blocks of 1 s
    for fraction in (0.1, 0.2, 0.5, 0.8):
        for seed in range(5):
            subsets = split(stamps, seed=seed, val_fraction=fraction, block_s=1.0)
            assert subsets.count("val") / len(stamps) == fraction, (fraction, seed)
            blocks = split(stamps, seed=seed, val_fraction=fraction)  # 10 blocks of 0.98 s
            assert abs(blocks.count("val") / len(stamps) - fraction) <= 0.1, (fraction, seed)


def test_a_split_that_leaves_a_set_empty_is_said() -> None:
    """30 s of frames in one 100 s block: 150 train, 0 val, and the export line said nothing."""
    stamps = [k * 200_000_000 for k in range(150)]
    subsets = split(stamps, seed=1, val_fraction=0.2, block_s=100.0)
    assert set(subsets) == {"train"}
    assert empty_set(subsets, 0.2) == (
        "; the val set is empty: the frames fall in one block of the split (--split-block-s; "
        "give a shorter one)"
    )
    assert empty_set(split(stamps, seed=1, val_fraction=0.2), 0.2) == ""  # ten blocks
    assert empty_set(subsets, 0.0) == ""  # asked for: the CLI says so itself
