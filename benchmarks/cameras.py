"""Camera frame and radar sample cost on the shared ray-casting scene.

The scene: the bundled harbour terrain (catabot/data/terrain/bay.png, 600 m square) with the
island in view, 100 boats of the bundled models (benchmarks/fleet.py), 20 of them spread
25-200 m ahead inside the camera's 80 deg view and 80 scattered over the bay, and a buoy;
calm water and the harbour's waves (Hs 0.3 m). Measured per sample, median of REPEATS:
- camera 640 x 480, all four outputs (colour, depth, normals, segmentation + boxes);
- the same camera with segmentation (and boxes) only, and at 320 x 240 for comparison;
- its parts: the Scene cast alone (with the camera's projected-box cull, as `sample` casts,
  and with the scene's own rays x bodies cull) and the post-processing alone (cached hits);
- the radar, one sample per 10 ms tick (2.4 beams x 33 rays);
- the four-output camera with every body as its hull box and as its shape, side by side
  (interleaved calls, benchmarks/fleet.py), and Embree alone on the terrain with the frame's
  rays, for reference;
- the four-output camera and the radar on calm water, the medium swell and the harbour chop
  side by side (interleaved), with what the water's ray cast chose (grid or exact march).
Targets: >= 15 camera frames/s with all four outputs on this machine (issue "Sensor farm");
shapes at most 1.2 x boxes (issue #17, "Vessel shapes"); the four-output frame in the medium
swell at most 1.25 x calm water (issue #17, "Sensors in waves").
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable

import numpy as np

from benchmarks.fleet import comparison_head, comparison_line, fleet, side_by_side
from benchmarks.sensors import TERRAIN, interleaved, sea_head, sea_lines
from catabot.bus.blas import single_thread_blas
from catabot.bus.heap import keep_heap
from catabot.bus.messages import VesselState
from catabot.config.sensors import CameraParams, RadarParams
from catabot.config.waves import WaveConfig
from catabot.world.terrain import load_terrain
from catabot.world.waves import WaveField
from services.sensors.camera import CameraModel
from services.sensors.camera_boxes import candidate_rays
from services.sensors.mount import Mount
from services.sensors.radar import RadarModel
from services.sensors.scene import Scene

BOATS = 100
IN_VIEW = 20
REPEATS = 15
PAIRS = 30  # boxes-vs-shapes frames of each, interleaved
EGO = (290.0, 300.0)
HEADING = math.radians(15.0)
AT = {"tick": 0, "stamp_ns": 0}
SEA_ROUNDS = 15  # frames of each sea, interleaved (radar: 20 ticks a round)
SEAS = {
    "calm": WaveConfig(),
    "medium": WaveConfig(preset="medium"),
    "harbour": WaveConfig(significant_height_m=0.3, peak_period_s=4.0, direction_rad=1.2),
}


def quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def ego_state() -> VesselState:
    zero = (0.0, 0.0, 0.0)
    return VesselState(0, 0, (*EGO, 0.0), quat(HEADING), zero, zero, zero, zero)


def scene(waves: WaveConfig, *, shapes: bool = True) -> Scene:
    """The bay, the ego vessel, IN_VIEW boats in front of it and the rest of the BOATS over
    the bay (seeded positions), and a buoy; every body as its shape or its hull box."""
    rng = np.random.default_rng(7)
    poses = {"ego": ((*EGO, 0.0), quat(HEADING)), "b1": ((320.0, 360.0, 0.0), quat(0.0))}
    for i in range(BOATS):
        dist, off = rng.uniform(25.0, 200.0), rng.uniform(-0.55, 0.55)
        x, y = EGO[0] + dist * math.cos(HEADING + off), EGO[1] + dist * math.sin(HEADING + off)
        if i >= IN_VIEW:
            x, y = rng.uniform(50.0, 550.0, 2)
        poses[f"v{i}"] = ((x, y, 0.0), quat(rng.uniform(0, 2 * math.pi)))
    bodies = fleet(BOATS, shapes=shapes)
    world = Scene(terrain=load_terrain(TERRAIN), waves=WaveField(waves, 1), bodies=bodies)
    world.update(poses, 0.0)
    return world


def median_ms(fn: Callable[[], object], repeats: int = REPEATS) -> tuple[float, float, float]:
    """Median and least wall milliseconds and median CPU milliseconds (CPU counts every
    thread: Embree casts on two; on a busy machine wall time grows while CPU time stays near
    what the work needs, and the least wall time is the best guide)."""
    fn()  # warm: first-cast Embree build, caches
    wall, cpu = [], []
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return 1e3 * statistics.median(wall), 1e3 * min(wall), 1e3 * statistics.median(cpu)


def camera_rows(world: Scene, sea: str) -> list[tuple[str, tuple[float, float, float]]]:
    state = ego_state()
    full = CameraModel(CameraParams(), Mount(scene=world, seed=1, name="ego/cam"))
    seg = CameraModel(
        CameraParams(outputs={"color": False, "depth": False, "normals": False}),
        Mount(scene=world, seed=1, name="ego/seg"),
    )
    small = CameraModel(
        CameraParams(width=320, height=240), Mount(scene=world, seed=1, name="ego/s")
    )
    origin, rot = full.pose(state)
    dirs = np.dot(full.rays, rot.T.astype(np.float32))
    pairs = candidate_rays((world.corners() - origin) @ rot, full.cam)
    hits = world.cast(origin, dirs, full.params.max_range_m, pairs, silhouettes=True)
    return [
        (f"camera 640x480, all outputs ({sea})", median_ms(lambda: full.sample(state, **AT))),
        (f"camera 640x480, segmentation only ({sea})", median_ms(lambda: seg.sample(state, **AT))),
        (f"camera 320x240, all outputs ({sea})", median_ms(lambda: small.sample(state, **AT))),
        (
            f"  cast, boxes culled by projection ({sea})",
            median_ms(lambda: world.cast(origin, dirs, 1e3, pairs)),
        ),
        (
            f"  cast, scene's own body cull ({sea})",
            median_ms(lambda: world.cast(origin, dirs, 1e3)),
        ),
        (
            f"  outputs from hits ({sea})",
            median_ms(lambda: full.frame(hits, dirs, origin, rot, **AT)),
        ),
    ]


def radar_row(world: Scene, sea: str) -> tuple[str, tuple[float, float, float]]:
    state = ego_state()
    radar = RadarModel(
        RadarParams(), Mount(scene=world, period_ns=10_000_000, seed=1, name="ego/radar")
    )
    ticks = iter(range(10**9))

    def one() -> None:
        k = next(ticks)
        radar.sample(state, tick=k, stamp_ns=k * 10_000_000)

    return f"radar, one 10 ms tick ({sea})", median_ms(one, repeats=200)


def compared(sea: str) -> str:
    """The four-output camera on the same scene with bodies as hull boxes and as shapes."""
    frames = []
    for shapes in (False, True):
        world = scene(SEAS[sea], shapes=shapes)
        camera = CameraModel(CameraParams(), Mount(scene=world, seed=1, name="ego/cam"))
        frames.append(lambda camera=camera: camera.sample(ego_state(), **AT))
    boxes, shapes_ms = side_by_side(frames[0], frames[1], PAIRS)
    return comparison_line(f"camera 640 x 480, all four outputs, {sea}", boxes, shapes_ms)


def seas_compared() -> list[str]:
    """The four-output camera and the radar on every sea, interleaved."""
    frames: dict[str, Callable[[], object]] = {}
    ticks: dict[str, Callable[[], object]] = {}
    worlds = {sea: scene(waves) for sea, waves in SEAS.items()}
    for sea, world in worlds.items():
        camera = CameraModel(CameraParams(), Mount(scene=world, seed=1, name="ego/cam"))
        frames[sea] = lambda camera=camera: camera.sample(ego_state(), **AT)
        ticks[sea] = _radar_ticks(world)
    plans = {}
    times = interleaved(frames, SEA_ROUNDS)
    for sea, world in worlds.items():
        frames[sea]()
        plans[sea] = world.water_plan
    lines = sea_lines("camera 640 x 480, all four outputs", times, plans)
    radar = interleaved(ticks, SEA_ROUNDS)
    return lines + sea_lines("radar, 20 ticks of 10 ms", radar, {}, target=False)


def _radar_ticks(world: Scene) -> Callable[[], object]:
    """20 consecutive radar samples (a tick's sweep is too short to time alone)."""
    radar = RadarModel(
        RadarParams(), Mount(scene=world, period_ns=10_000_000, seed=1, name="ego/radar")
    )
    state, counter = ego_state(), iter(range(10**9))

    def twenty() -> None:
        for _ in range(20):
            k = next(counter)
            radar.sample(state, tick=k, stamp_ns=k * 10_000_000)

    return twenty


def embree_alone() -> str:
    """Embree's own rate on the terrain scene with the frame's rays (float32, as cast)."""
    import open3d as o3d

    camera = CameraModel(CameraParams(), Mount(scene=scene(SEAS["calm"]), seed=1))
    origin, rot = camera.pose(ego_state())
    rays = np.empty((camera.rays.shape[0], 6), dtype=np.float32)
    rays[:, :3], rays[:, 3:] = origin, np.dot(camera.rays, rot.T.astype(np.float32))
    terrain = load_terrain(TERRAIN).raycasting_scene()
    tensor = o3d.core.Tensor.from_numpy(rays)
    ms = median_ms(lambda: terrain.cast_rays(tensor))[0]
    n = rays.shape[0]
    rate = f"{n / ms / 1e3:.1f} M rays/s"
    return f"Embree alone, the frame's {n} rays on the terrain: {ms:.2f} ms, {rate}"


def main() -> None:
    single_thread_blas()  # as every service does (catabot/run/service.py)
    keep_heap()
    print(
        f"camera and radar cost: bay terrain, {BOATS} boats ({IN_VIEW} in view) and a buoy, "
        f"median of {REPEATS}"
    )
    print(f"{'what':52} {'wall ms':>8} {'per s':>8} {'min ms':>8} {'CPU ms':>8}")
    for sea, waves in SEAS.items():
        start = time.perf_counter()
        world = scene(waves)
        world.cast(np.zeros(3), np.array([[1.0, 0.0, 0.0]]), 1.0)
        if sea == "calm":
            build_ms = 1e3 * (time.perf_counter() - start)
            print(f"{'scene build (terrain into Embree), once per run':52} {build_ms:8.1f}")
        for name, (ms, least, cpu) in [*camera_rows(world, sea), radar_row(world, sea)]:
            print(f"{name:52} {ms:8.2f} {1e3 / ms:8.1f} {least:8.2f} {cpu:8.2f}")
    print("target: camera all outputs >= 15 frames/s")
    print(f"\nboxes vs shapes, {BOATS} boats (interleaved, median of {PAIRS}; ratio of medians)")
    print(comparison_head())
    for sea in ("calm", "harbour"):
        print(compared(sea))
    print(embree_alone())
    print(f"\ncalm water vs the medium swell vs harbour chop (interleaved, {SEA_ROUNDS} each)")
    print(sea_head())
    print("\n".join(seas_compared()))
    print(f"load average during the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
