"""How a large cast's chunks of rays are dealt to threads: every chunk once, to whichever
thread comes free, the same hits whatever the threads; a helper's error reaches the caster."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from services.sensors import wave_pass
from services.sensors.wave_kernel import CHUNK
from services.sensors.wave_pass import PARALLEL_RAYS, run_chunks
from tests.services.sensors.wave_helpers import cast, fan, wave_grid


def _spans(
    rays: int, pause_s: float = 0.0, *, helpers_only: bool = False
) -> list[tuple[str, tuple[int, int]]]:
    """Which thread ran which span, each run pausing `pause_s` (on the helpers only)."""
    seen: list[tuple[str, tuple[int, int]]] = []
    caller = threading.current_thread().name

    def run(span: tuple[int, int]) -> None:
        seen.append((threading.current_thread().name, span))
        if not helpers_only or threading.current_thread().name != caller:
            time.sleep(pause_s)

    run_chunks(run, rays)
    return seen


def _covered(seen: list[tuple[str, tuple[int, int]]]) -> list[int]:
    return sorted(c for _, (first, last) in seen for c in range(first, last))


def test_a_small_cast_runs_every_chunk_on_the_calling_thread() -> None:
    seen = _spans(PARALLEL_RAYS - 1)
    assert seen == [(threading.current_thread().name, (0, PARALLEL_RAYS // CHUNK))]


def test_a_large_cast_deals_each_chunk_once_to_every_thread(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    rays = PARALLEL_RAYS + 5  # a last chunk of 5 rays
    with ThreadPoolExecutor(3) as pool:
        monkeypatch.setattr(wave_pass, "_helpers", lambda: (pool, 3))
        seen = _spans(rays, pause_s=0.002)
    assert _covered(seen) == list(range(-(-rays // CHUNK)))
    assert all(last - first <= wave_pass.BATCH for _, (first, last) in seen)
    assert len({name for name, _ in seen}) == 4  # the caller and its three helpers


def test_a_thread_held_back_leaves_its_batches_to_the_others(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A core the machine takes away for a while: its thread does one batch, the caller the
    rest (numba's fixed halves would have waited for it)."""
    caller = threading.current_thread().name
    with ThreadPoolExecutor(1) as pool:
        monkeypatch.setattr(wave_pass, "_helpers", lambda: (pool, 1))
        seen = _spans(PARALLEL_RAYS * 2, 0.5, helpers_only=True)
    helped = [span for name, span in seen if name != caller]
    assert len(helped) == 1 and _covered(seen) == list(range(2 * PARALLEL_RAYS // CHUNK))


def test_a_helpers_error_reaches_the_caster(monkeypatch: pytest.MonkeyPatch) -> None:
    caller = threading.current_thread().name

    def run(span: tuple[int, int]) -> None:
        if threading.current_thread().name != caller:
            raise RuntimeError("helper failed")
        time.sleep(0.001)

    with ThreadPoolExecutor(1) as pool:
        monkeypatch.setattr(wave_pass, "_helpers", lambda: (pool, 1))
        with pytest.raises(RuntimeError, match="helper failed"):
            run_chunks(run, PARALLEL_RAYS)


def test_one_core_has_no_helpers(monkeypatch: pytest.MonkeyPatch) -> None:
    wave_pass._helpers.cache_clear()
    monkeypatch.setattr(wave_pass, "cores", lambda: 1)
    try:
        assert wave_pass._helpers() is None
        assert len({name for name, _ in _spans(PARALLEL_RAYS * 2)}) == 1
    finally:
        wave_pass._helpers.cache_clear()


def test_hits_do_not_depend_on_the_threads(monkeypatch: pytest.MonkeyPatch) -> None:
    """A large cast's chunks are fixed: with one helper or three, or all on the calling
    thread (a small cast's way), the same bytes (each chunk starts its Newton afresh)."""
    grid, d = wave_grid(), fan(PARALLEL_RAYS + 17, 8, (0.3, 40.0))
    casts = []
    for size in (1, 3):
        with ThreadPoolExecutor(size) as pool:
            monkeypatch.setattr(wave_pass, "_helpers", lambda pool=pool, size=size: (pool, size))
            casts.append(cast(grid, d, 60.0))
    monkeypatch.setattr(wave_pass, "PARALLEL_RAYS", 10**9)  # the same rays on one thread
    casts.append(cast(grid, d, 60.0))
    first, far = casts[0]
    assert np.isfinite(first.rng).sum() > 10_000
    for near, far_ in casts[1:]:
        assert far_.tobytes() == far.tobytes()
        for a, b in ((first.rng, near.rng), (first.normal, near.normal), (first.cls, near.cls)):
            assert a.tobytes() == b.tobytes()


def test_threads_casting_at_once_get_the_hits_of_a_cast_alone() -> None:
    """Casts from several threads share the helpers; each gets its own hits."""
    grid, d = wave_grid(), fan(PARALLEL_RAYS + 1, 8, (0.3, 40.0))
    alone = cast(grid, d, 60.0)[0].rng
    with ThreadPoolExecutor(max_workers=3) as pool:
        casts = list(pool.map(lambda _: cast(grid, d, 60.0)[0].rng, range(6)))
    assert all(c.tobytes() == alone.tobytes() for c in casts)
