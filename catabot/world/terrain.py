"""Terrain from an elevation image: heights, water depth, a shared mesh, start-pose checks.

World frame (DESIGN.md §2): `map` is ENU with its origin at the image's bottom-left corner and
the water surface at rest at z = 0. Image row 0 is the TOP (north) edge, so world y grows
towards row 0; pixel (row, col) is the square [col, col+1] x [H-1-row, H-row] times
`metres_per_pixel`, and its value is the elevation at the square's centre.

Pixel values map linearly: 0 -> `min_elevation_m`, the bit depth's maximum (255 or 65535, not
the image's own brightest pixel) -> `max_elevation_m`. That is the original's "maximum pixel
value": with its defaults (-35 m .. 60 m) the water line of `new-york-river.png` is at pixel
35 / 95 * 255 = 94.0, as its README says, whereas the image's own maximum (253) would put it
at 93.2. Heights between pixel centres are bilinear; outside the image the nearest edge value
is used (the terrain extends flat, it does not turn into deep water), so a vessel that leaves
the map meets the same shore or sea it left.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from catabot.config.load import TERRAINS
from catabot.config.terrain import TerrainConfig, TerrainError
from catabot.world.elevation import ElevationImageError, read_elevation_band
from catabot.world.terrain_grid import (
    any_in_window,
    auto_resolution,
    disk_samples,
    grid_axis,
    grid_triangles,
)

if TYPE_CHECKING:
    import open3d

Array = NDArray[np.float64]
MAX_MESH_TRIANGLES = 500_000  # open3d builds ~0.5 M triangles in ~0.27 s (anchors.md)


def load_terrain(config: TerrainConfig, *, base_dir: str | Path | None = None) -> Terrain:
    """Read the configured image (relative paths are taken from `base_dir`) into a Terrain."""
    path = Path(config.elevation_image).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    if not path.is_file():
        raise TerrainError(f"terrain.elevation_image: file not found: {path}{_where_looked()}")
    try:
        band, full_scale = read_elevation_band(path)
    except ElevationImageError as exc:
        raise TerrainError(f"terrain.elevation_image: {exc}") from None
    heights = band.astype(np.float64)
    if full_scale is not None:
        span = config.max_elevation_m - config.min_elevation_m
        heights = config.min_elevation_m + heights * (span / full_scale)
    return Terrain(
        heights[::-1],
        config.metres_per_pixel,
        resolution_m=config.resolution_m,
        name=str(path),
    )


def _where_looked() -> str:
    """Where a name is looked for: a bare name that is not beside the scenario may be a
    bundled image (config/load.py)."""
    names = ", ".join(sorted(p.name for p in TERRAINS.glob("*.png")))
    return (f" (a relative path is taken from the scenario file's folder, a `--set`'s and "
            f"`scenario generate`'s from the current one; a bare name not there from the "
            f"bundled images: {names})")  # fmt: skip


class Terrain:
    """A height field on a regular grid of pixel centres; every query is vectorised.

    `elevation_m` is indexed [iy, ix] with iy = 0 at the SOUTH edge (world order, the image
    flipped), so Terrain(f(X, Y), ...) builds a synthetic terrain straight from world formulas.
    """

    def __init__(
        self,
        elevation_m: ArrayLike,
        metres_per_pixel: float,
        *,
        resolution_m: float | None = None,
        name: str = "<array>",
    ) -> None:
        grid = np.array(elevation_m, dtype=np.float64)
        if grid.ndim != 2 or min(grid.shape) < 2 or not np.isfinite(grid).all():
            raise TerrainError(f"terrain {name}: needs a finite 2-D grid of at least 2 x 2")
        if not (math.isfinite(metres_per_pixel) and metres_per_pixel > 0):
            raise TerrainError(f"terrain {name}: metres_per_pixel must be > 0")
        grid.setflags(write=False)
        self._z, self._mpp, self.name = grid, float(metres_per_pixel), name
        self._resolution = resolution_m

    @property
    def elevation_m(self) -> Array:
        """Read-only (ny, nx) elevations at pixel centres, row 0 = south."""
        return self._z

    @property
    def metres_per_pixel(self) -> float:
        return self._mpp

    @property
    def size_m(self) -> tuple[float, float]:
        """Extent (east, north) in metres: the image's width and height times the pixel size."""
        ny, nx = self._z.shape
        return nx * self._mpp, ny * self._mpp

    @property
    def resolution_m(self) -> float:
        """Default mesh spacing: the configured one, or the finest within the triangle budget."""
        if self._resolution is not None:
            return self._resolution
        return auto_resolution(self._z.shape, self._mpp, MAX_MESH_TRIANGLES)

    def height(self, x: ArrayLike, y: ArrayLike) -> Array:
        """Ground elevation (m, up) at world points, bilinear; clamped to the edge outside."""
        ny, nx = self._z.shape
        u = np.clip(np.asarray(x, dtype=np.float64) / self._mpp - 0.5, 0.0, nx - 1.0)
        v = np.clip(np.asarray(y, dtype=np.float64) / self._mpp - 0.5, 0.0, ny - 1.0)
        i = np.minimum(np.fmax(u, 0.0).astype(np.intp), nx - 2)  # fmax: NaN -> 0; NaN out
        j = np.minimum(np.fmax(v, 0.0).astype(np.intp), ny - 2)
        fu, fv, z = u - i, v - j, self._z
        south = z[j, i] + fu * (z[j, i + 1] - z[j, i])
        north = z[j + 1, i] + fu * (z[j + 1, i + 1] - z[j + 1, i])
        return np.asarray(south + fv * (north - south))

    def depth(self, x: ArrayLike, y: ArrayLike) -> Array:
        """Water depth below the rest surface z = 0 (m, >= 0; 0 on land)."""
        return np.maximum(-self.height(x, y), 0.0)

    def slope(self, x: ArrayLike, y: ArrayLike) -> tuple[Array, Array]:
        """(dh/dx, dh/dy) by central differences over one pixel: continuous, unlike the
        bilinear cell's own derivative, so contact normals do not jump at pixel borders."""
        x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        e = 0.5 * self._mpp
        h = self.height(np.stack([x + e, x - e, x, x]), np.stack([y, y, y + e, y - e]))
        return (h[0] - h[1]) / (2 * e), (h[2] - h[3]) / (2 * e)

    def mesh(self, resolution_m: float | None = None) -> tuple[Array, NDArray[np.int32]]:
        """Regular-grid triangulation shared by physics and sensors: (vertices (N, 3) float64,
        triangles (M, 3) int32, counter-clockwise seen from above so normals point up).

        Grid lines pass through pixel centres at spacing <= resolution_m (so at one pixel the
        vertices are exactly the pixel values) plus one line on each image edge, so the mesh
        covers the whole [0, width] x [0, height] extent.
        """
        r = self.resolution_m if resolution_m is None else resolution_m
        if not (math.isfinite(r) and r > 0):
            raise TerrainError(f"mesh resolution must be > 0 m (got {r})")
        ny, nx = self._z.shape
        xs, ys = grid_axis(nx, self._mpp, r), grid_axis(ny, self._mpp, r)
        gx, gy = np.meshgrid(xs, ys)
        vertices = np.stack([gx.ravel(), gy.ravel(), self.height(gx, gy).ravel()], axis=1)
        return vertices, grid_triangles(len(xs), len(ys))

    def raycasting_scene(
        self, resolution_m: float | None = None
    ) -> open3d.t.geometry.RaycastingScene:
        """An open3d RaycastingScene holding the terrain mesh (geometry id 0); build once per run.

        open3d works in float32: at 16 km from the origin that is a few mm, below LiDAR noise.
        """
        import open3d as o3d

        vertices, triangles = self.mesh(resolution_m)
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(
            o3d.core.Tensor.from_numpy(vertices.astype(np.float32)),
            o3d.core.Tensor.from_numpy(triangles.astype(np.uint32)),
        )
        return scene

    def find_open_water(
        self,
        draft_m: float,
        *,
        near: tuple[float, float] | None = None,
        clearance_m: float = 0.5,
        footprint_m: float = 3.0,
    ) -> tuple[float, float]:
        """The pixel centre nearest to `near` (default: the terrain centre) where every bilinear
        height within `footprint_m` is deeper than draft + clearance, so check_start accepts it.

        Vectorised: a pixel qualifies when no pixel is shallow in the square window that holds
        every pixel a bilinear sample within the footprint circle can touch.
        """
        need = _non_negative(draft_m=draft_m, clearance_m=clearance_m) + clearance_m
        _non_negative(footprint_m=footprint_m)
        k = math.ceil(footprint_m / self._mpp) + 1
        ok = ~any_in_window(self._z >= -need, k)
        if not ok.any():
            raise TerrainError(self._no_open_water(draft_m, clearance_m, footprint_m))
        iy, ix = np.nonzero(ok)
        w, h = self.size_m
        tx, ty = (w / 2, h / 2) if near is None else near
        cx, cy = (ix + 0.5) * self._mpp, (iy + 0.5) * self._mpp
        best = int(np.argmin((cx - tx) ** 2 + (cy - ty) ** 2))  # ties: first, deterministic
        return float(cx[best]), float(cy[best])

    def _no_open_water(self, draft_m: float, clearance_m: float, footprint_m: float) -> str:
        """Why no start was found; a map smaller than the hull (metres_per_pixel in km, or
        a pixel's size mistyped) said only "deepest point 35 m", which read as nonsense."""
        (w, h), depth = self.size_m, -float(self._z.min())
        text = (
            f"terrain {self.name} ({w:g} x {h:g} m, {self._mpp:g} m a pixel): no open water "
            f"deeper than draft {draft_m:g} m + clearance {clearance_m:g} m over a whole hull "
            f"footprint of radius {footprint_m:g} m (deepest point {depth:.2f} m)"
        )
        if min(w, h) < 4 * footprint_m:
            text += "; the map is hardly larger than one hull: is metres_per_pixel right?"
        return text

    def check_water(self, x: float, y: float, *, what: str, depth_m: float = 0.0) -> None:
        """Refuse a point (`what`, as the error names it) outside the map, on land, or in
        water no deeper than `depth_m`."""
        w, h = self.size_m
        where = f"{what} ({x:.1f}, {y:.1f})"
        if not (0.0 <= x <= w and 0.0 <= y <= h):
            raise TerrainError(f"{where} is outside the terrain (x 0..{w:g} m, y 0..{h:g} m)")
        ground = float(self.height(x, y))
        if ground >= 0.0:
            raise TerrainError(f"{where} is on land: ground elevation {ground:.1f} m")
        if -ground <= depth_m:
            raise TerrainError(
                f"{where}: water {-ground:.2f} m deep, needs more than {depth_m:g} m"
            )

    def check_start(
        self, x: float, y: float, *, draft_m: float, footprint_m: float, clearance_m: float = 0.5,
        z_m: float = 0.0, what: str = "start pose",
    ) -> None:  # fmt: skip
        """Refuse a start pose outside the map, on land, or in water too shallow for the hull
        anywhere within `footprint_m` of (x, y) (sampled at <= half a pixel); `z_m`, the
        body origin's start height: a hull started deep must clear the seabed too (one
        started inside it was fired out at 117 m/s)."""
        _non_negative(draft_m=draft_m, clearance_m=clearance_m)
        _non_negative(footprint_m=footprint_m)
        hull = (draft_m, clearance_m, footprint_m)
        try:
            self.check_water(x, y, what=what)
        except TerrainError as exc:
            raise TerrainError(f"{exc}{self._nearest_start(x, y, *hull)}") from None
        where = f"{what} ({x:.1f}, {y:.1f})"
        px, py = disk_samples(x, y, footprint_m, 0.5 * self._mpp)
        depth = float(self.depth(px, py).min())
        keel = z_m - draft_m
        if depth + keel > clearance_m:
            return
        if z_m != 0.0:
            raise TerrainError(
                f"{where}: its keel at z {keel:.2f} m is not {clearance_m:g} m above the seabed "
                f"(at z {-depth:.2f} m, the shallowest within {footprint_m:g} m)"
            )
        raise TerrainError(
            f"{where}: water depth {depth:.2f} m (shallowest within {footprint_m:g} m) is too "
            f"shallow for draft {draft_m:g} m + clearance {clearance_m:g} m"
            f"{self._nearest_start(x, y, *hull)}"
        )

    def _nearest_start(
        self, x: float, y: float, draft_m: float, clearance_m: float, footprint_m: float
    ) -> str:
        """Where a refused start could go instead, the nearest that check_start accepts ("":
        none): a trial user read the image's pixels to find water."""
        try:
            fx, fy = self.find_open_water(
                draft_m, near=(x, y), clearance_m=clearance_m, footprint_m=footprint_m
            )
        except TerrainError:
            return ""
        away = math.hypot(fx - x, fy - y)
        return f"; the nearest start deep enough is ({fx:.1f}, {fy:.1f}), {away:.0f} m away"


def _non_negative(**values: float) -> float:
    """Validate keyword numbers as finite and >= 0; returns the first one."""
    for name, value in values.items():
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be a finite number >= 0 (got {value})")
    return next(iter(values.values()))
