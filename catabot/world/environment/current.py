"""Water current: a uniform vector plus an optional gridded map, looked up for many points.

The current is horizontal and steady (no time dependence yet). Lookups take arrays of any
shape and cost one vectorised bilinear interpolation, so the physics can query every vessel
at once each step.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from catabot.config.environment import (
    MAX_CURRENT_MPS,
    CurrentConfig,
    CurrentMapConfig,
    CurrentMapError,
)

Array = NDArray[np.float64]
IMAGE_SUFFIXES = (".png", ".bmp", ".tif", ".tiff")


class CurrentField:
    """Current velocity (u east, v north; m/s) anywhere in `map`: uniform + bilinear grid.

    grid[j, i] is the map's velocity at (origin.x + i * spacing, origin.y + j * spacing).
    Outside the grid: "edge" extends the border values, "zero" adds nothing.
    """

    def __init__(
        self,
        uniform_mps: tuple[float, float] = (0.0, 0.0),
        *,
        grid: Array | None = None,
        origin_m: tuple[float, float] = (0.0, 0.0),
        spacing_m: float = 1.0,
        outside: str = "edge",
    ) -> None:
        self.uniform = np.array(uniform_mps, dtype=np.float64)
        if not np.all(np.isfinite(self.uniform)):
            raise CurrentMapError(f"uniform current must be finite (got {uniform_mps})")
        self.grid = None if grid is None else _checked_grid(grid, "grid")
        if not (np.isfinite(spacing_m) and spacing_m > 0):
            raise CurrentMapError(f"current map spacing_m must be > 0 (got {spacing_m})")
        if outside not in ("edge", "zero"):
            raise CurrentMapError(f"current map outside must be 'edge' or 'zero' ({outside!r})")
        self.origin = np.array(origin_m, dtype=np.float64)
        self.spacing = float(spacing_m)
        self.outside = outside
        self._flat = None if self.grid is None else self.grid.reshape(-1, 2)

    @classmethod
    def from_config(cls, config: CurrentConfig, *, base_dir: Path | None = None) -> CurrentField:
        """Build from scenario settings; a relative map path is taken from `base_dir` if given."""
        m = config.map
        if m is None:
            return cls(config.velocity_mps)
        grid = load_current_map(m, base_dir=base_dir)
        return cls(
            config.velocity_mps,
            grid=grid,
            origin_m=m.origin_m,
            spacing_m=m.spacing_m,
            outside=m.outside,
        )

    @property
    def is_zero(self) -> bool:
        """True when the current is nil everywhere (lets the physics skip the lookup)."""
        return self.grid is None and not np.any(self.uniform)

    def velocity_at(self, x: Array, y: Array) -> Array:
        """Current at points (x, y) of any (equal) shape: array of shape x.shape + (2,)."""
        xs, ys = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        out = np.empty((*xs.shape, 2))
        out[...] = self.uniform
        if self.grid is not None:
            out += self._bilinear(xs, ys)
        return out

    def _bilinear(self, x: Array, y: Array) -> Array:
        """Bilinear interpolation of the grid; exact at the nodes (weights 0 and 1).

        Gathers from the flattened grid with `take` (much cheaper than 2-D fancy indexing
        for a hundred points, which is the physics' use).
        """
        assert self.grid is not None and self._flat is not None
        rows, cols = self.grid.shape[:2]
        fx = (x - self.origin[0]) / self.spacing
        fy = (y - self.origin[1]) / self.spacing
        cx, cy = np.clip(fx, 0.0, cols - 1.0), np.clip(fy, 0.0, rows - 1.0)
        i0 = np.minimum(cx.astype(np.intp), cols - 2)  # cx >= 0, so truncation is floor
        j0 = np.minimum(cy.astype(np.intp), rows - 2)
        tx, ty = (cx - i0)[..., None], (cy - j0)[..., None]
        flat, k = self._flat, j0 * cols + i0
        south = (1.0 - tx) * flat.take(k, axis=0) + tx * flat.take(k + 1, axis=0)
        k += cols
        north = (1.0 - tx) * flat.take(k, axis=0) + tx * flat.take(k + 1, axis=0)
        value = (1.0 - ty) * south + ty * north
        if self.outside == "zero":
            inside = (fx >= 0) & (fx <= cols - 1) & (fy >= 0) & (fy <= rows - 1)
            value *= inside[..., None]
        return np.asarray(value)


def load_current_map(config: CurrentMapConfig, *, base_dir: Path | None = None) -> Array:
    """Read a current map file into a (rows, cols, 2) float64 grid, row 0 at the south edge;
    a refusal names the field, as the rest of a scenario's do."""
    try:
        return _load_map(config, base_dir)
    except CurrentMapError as exc:
        raise CurrentMapError(f"water.current.map: {exc}") from None


def _load_map(config: CurrentMapConfig, base_dir: Path | None) -> Array:
    path = Path(config.path)
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    suffix = path.suffix.lower()
    if suffix == ".npy":  # read first: a file that is no .npy hears that first
        grid = _read_npy(path)
        if config.scale_mps is not None:
            raise CurrentMapError(
                f"current map {path}: scale_mps is only for images (.npy holds m/s already)"
            )
        return _checked_grid(grid, str(path))
    if suffix in IMAGE_SUFFIXES:  # read first: a file that is no image hears that first
        pixels = _read_pixels(path)
        if config.scale_mps is None:
            raise CurrentMapError(
                f"current map {path}: an image needs scale_mps (m/s for channel value 255)"
            )
        uv = (pixels[::-1, :, :2] - 128.0) / 127.0 * config.scale_mps  # row 0: south edge
        return _checked_grid(np.ascontiguousarray(uv), str(path))
    raise CurrentMapError(
        f"current map {path}: unknown file type {suffix or '(none)'!r} "
        f"(allowed: .npy, {', '.join(IMAGE_SUFFIXES)})"
    )


def _read_npy(path: Path) -> Array:
    """Refused before NumPy reads it when it is no .npy file (NumPy's own words advised
    `allow_pickle=True`, unsafe for a file of unknown origin)."""
    try:
        with path.open("rb") as file:
            magic = file.read(6)
    except OSError as exc:
        raise CurrentMapError(f"current map {path}: cannot read: {exc.strerror or exc}") from None
    if magic != b"\x93NUMPY":
        raise CurrentMapError(f"current map {path}: not a .npy file (NumPy's np.save format)")
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise CurrentMapError(f"current map {path}: cannot read: {exc}") from None
    if not isinstance(data, np.ndarray) or not np.issubdtype(data.dtype, np.number):
        raise CurrentMapError(f"current map {path}: must hold a numeric array")
    return np.asarray(data, dtype=np.float64)


def _read_pixels(path: Path) -> Array:
    """The image's RGB pixels as floats, row 0 at the top (the caller scales and flips)."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            mode = image.mode
            if mode not in ("RGB", "RGBA"):
                raise CurrentMapError(
                    f"current map {path}: image mode {mode!r}; need 8-bit RGB or RGBA "
                    "(R: u east, G: v north)"
                )
            return np.asarray(image.convert("RGB"), dtype=np.float64)
    except (OSError, UnidentifiedImageError) as exc:
        raise CurrentMapError(f"current map {path}: cannot read image: {exc}") from None


def _checked_grid(grid: Array, what: str) -> Array:
    g = np.asarray(grid, dtype=np.float64)
    if g.ndim != 3 or g.shape[2] != 2:
        raise CurrentMapError(f"current map {what}: shape must be (rows, cols, 2), got {g.shape}")
    if g.shape[0] < 2 or g.shape[1] < 2:
        raise CurrentMapError(f"current map {what}: needs at least 2 x 2 nodes, got {g.shape}")
    bad = np.argwhere(~np.isfinite(g))
    if bad.size:
        j, i, c = (int(v) for v in bad[0])
        raise CurrentMapError(f"current map {what}: value at row {j}, col {i}, comp {c} not finite")
    fastest = float(np.hypot(g[..., 0], g[..., 1]).max())
    if fastest > MAX_CURRENT_MPS:
        raise CurrentMapError(
            f"current map {what}: {fastest:g} m/s somewhere; at most {MAX_CURRENT_MPS:g} m/s"
        )
    return np.ascontiguousarray(g)
