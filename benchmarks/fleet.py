"""What the sensor benchmarks share: a fleet of the bundled models seen as their shapes or
as their hull boxes, and timings of the two taken side by side.

The two variants are the same bodies at the same poses; "boxes" drops each model's shape,
so every body is its hull box (what sensors saw before shapes, and what a model without a
`shape` still is), "shapes" is what a run casts. Their calls are interleaved (box, shape,
box, shape...), so load from other work on the shared cores falls on both alike, and the
ratio of their medians is the figure compared with the target (shapes <= 1.2 x boxes).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

from catabot.bus.messages import CLASS_BUOY, CLASS_VESSEL
from catabot.config.vessel import load_vessel_model
from catabot.world.shapes import vessel_mesh
from services.sensors.scene import Body

MIX = ("monohull", "monohull", "monohull", "catabot", "wamv")  # boat i is MIX[i % 5]
TARGET = 1.2  # shapes / boxes at most (issue #17, "Vessel shapes")


def body(bid: str, model: str, instance: int, *, shapes: bool) -> Body:
    """A bundled model as the scene sees it: its shape in its box, or its hull box alone."""
    cls = CLASS_BUOY if model == "buoy" else CLASS_VESSEL
    loaded = load_vessel_model(model)
    mesh = vessel_mesh(loaded, source=model) if shapes else None
    lo, hi = (mesh.lo, mesh.hi) if mesh is not None else loaded.hull_box()
    return Body(bid, cls, instance, tuple(lo.tolist()), tuple(hi.tolist()), mesh)


def fleet(boats: int, *, shapes: bool) -> list[Body]:
    """The ego (a catamaran), `boats` boats `v0`... of the MIX, and one buoy `b1`; bodies of
    one model share one mesh, as in a run."""
    models = {m: body("", m, 0, shapes=shapes) for m in {*MIX, "catabot", "buoy"}}

    def of(bid: str, model: str, instance: int) -> Body:
        b = models[model]
        return Body(bid, b.cls, instance, b.lo, b.hi, b.shape)

    bodies = [of("ego", "catabot", 1)]
    bodies += [of(f"v{i}", MIX[i % len(MIX)], 2 + i) for i in range(boats)]
    return [*bodies, of("b1", "buoy", 2 + boats)]


def side_by_side(
    boxes: Callable[[], object], shapes: Callable[[], object], repeats: int
) -> tuple[list[float], list[float]]:
    """Wall milliseconds of `repeats` calls of each, interleaved, after one warm-up each."""
    boxes()
    shapes()
    a, b = [], []
    for _ in range(repeats):
        for fn, out in ((boxes, a), (shapes, b)):
            start = time.perf_counter()
            fn()
            out.append(1e3 * (time.perf_counter() - start))
    return a, b


def comparison_line(what: str, boxes: list[float], shapes: list[float]) -> str:
    """One row of the boxes-vs-shapes table: medians, minima and their ratios."""
    mb, ms = statistics.median(boxes), statistics.median(shapes)
    ratio = ms / mb
    verdict = "met" if ratio <= TARGET else "NOT met"
    return (
        f"{what:44} {mb:9.2f} {ms:9.2f} {min(boxes):8.2f} {min(shapes):8.2f} "
        f"{ratio:7.2f} {min(shapes) / min(boxes):7.2f}  <= {TARGET}: {verdict}"
    )


def comparison_head() -> str:
    head = ("what", "boxes ms", "shapes ms", "box min", "shp min", "ratio", "min r.")
    return "{:44} {:>9} {:>9} {:>8} {:>8} {:>7} {:>7}  target".format(*head)
