"""Reading elevation rasters (PNG via Pillow, TIFF/GeoTIFF via tifffile) into one 2-D band.

The file type is decided by its first bytes, not its name, so a misnamed file still loads and a
JPEG renamed `.png` is refused instead of being decoded lossily. What comes back is the raw band
(image row 0 = the top, north edge) and its full-scale value:

- PNG, 8 or 16 bit, grayscale (with or without alpha) or RGB/RGBA whose colour channels are all
  equal (the red channel is used; an image whose channels differ is refused, because there is no
  single right way to turn colour into height). Full scale is the bit depth's maximum, 255 or
  65535. 16-bit colour PNGs are refused: Pillow would silently cut them to 8 bits.
- TIFF/GeoTIFF, first image, one band. Unsigned integer bands map like PNGs (full scale = the
  dtype's maximum); float and signed integer bands are taken as elevations in metres as they are
  (full scale None). Georeferencing tags and no-data values are not interpreted: the scale comes
  from the terrain configuration, and a non-finite sample is refused.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
TIFF_MAGICS = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")
_PNG_COLOUR_TYPES = {0: "grayscale", 2: "RGB", 3: "palette", 4: "grayscale+alpha", 6: "RGBA"}


class ElevationImageError(CataBotError, ValueError):
    """An elevation image that cannot be used; the message names the file and the reason."""


def read_elevation_band(path: Path) -> tuple[NDArray[np.generic], int | None]:
    """The image's single elevation band (rows top to bottom) and its full-scale value.

    Full scale is None when the band already holds metres (float or signed TIFF bands).
    """
    try:
        with path.open("rb") as f:
            head = f.read(32)
    except OSError as exc:
        raise ElevationImageError(f"elevation image {path}: cannot read: {exc.strerror}") from None
    full_scale: int | None
    if head.startswith(PNG_MAGIC):
        band, full_scale = _read_png(path, head)
    elif head[:4] in TIFF_MAGICS:
        band, full_scale = _read_tiff(path)
    else:
        raise ElevationImageError(
            f"elevation image {path}: not a PNG or TIFF file (unrecognised first bytes)"
        )
    if band.ndim != 2 or band.shape[0] < 2 or band.shape[1] < 2:
        raise ElevationImageError(
            f"elevation image {path}: must be at least 2 x 2 pixels (got shape {band.shape})"
        )
    return band, full_scale


def _read_png(path: Path, head: bytes) -> tuple[NDArray[np.generic], int]:
    """Decode a PNG with Pillow after checking bit depth and colour type from its header."""
    from PIL import Image, UnidentifiedImageError

    bit_depth, colour_type = head[24], head[25]
    kind = _PNG_COLOUR_TYPES.get(colour_type, f"colour type {colour_type}")
    if colour_type == 3 or bit_depth not in (8, 16) or (bit_depth == 16 and colour_type in (2, 6)):
        raise ElevationImageError(
            f"elevation image {path}: unsupported PNG ({bit_depth}-bit {kind}); use 8- or 16-bit "
            "grayscale, or 8-bit RGB/RGBA with equal channels"
        )
    try:
        with Image.open(path) as image:
            image.load()
            pixels = np.asarray(image)
    except (OSError, UnidentifiedImageError, ValueError) as exc:
        raise ElevationImageError(f"elevation image {path}: cannot decode PNG: {exc}") from None
    if pixels.ndim == 3:
        pixels = _single_channel(path, pixels, colour=colour_type in (2, 6))
    return pixels, 65535 if bit_depth == 16 else 255


def _single_channel(
    path: Path, pixels: NDArray[np.generic], *, colour: bool
) -> NDArray[np.generic]:
    """First channel of an (H, W, C) image; colour channels must be identical, alpha is dropped."""
    if colour:
        red, green, blue = pixels[..., 0], pixels[..., 1], pixels[..., 2]
        differ = (red != green) | (red != blue)
        if differ.any():
            row, col = (int(v) for v in np.argwhere(differ)[0])
            raise ElevationImageError(
                f"elevation image {path}: colour image with unequal channels (first at row {row}, "
                f"column {col}: RGB {tuple(int(v) for v in pixels[row, col, :3])}); "
                "an elevation image must be grayscale or have R = G = B"
            )
    return np.ascontiguousarray(pixels[..., 0])


def _read_tiff(path: Path) -> tuple[NDArray[np.generic], int | None]:
    """First image of a TIFF; one band; unsigned ints are scaled later, others are metres."""
    import tifffile

    try:
        band = np.asarray(tifffile.imread(path, key=0))
    except Exception as exc:  # tifffile raises many types for corrupt files
        raise ElevationImageError(f"elevation image {path}: cannot decode TIFF: {exc}") from None
    band = np.squeeze(band)
    if band.ndim != 2:
        raise ElevationImageError(
            f"elevation image {path}: TIFF must hold a single band (got shape {band.shape})"
        )
    if np.issubdtype(band.dtype, np.unsignedinteger):
        return band, int(np.iinfo(band.dtype).max)
    if np.issubdtype(band.dtype, np.signedinteger):
        return band, None
    if not np.issubdtype(band.dtype, np.floating):
        raise ElevationImageError(f"elevation image {path}: unsupported sample type {band.dtype}")
    if not np.isfinite(band).all():
        raise ElevationImageError(
            f"elevation image {path}: contains non-finite samples "
            "(no-data values are not supported)"
        )
    return band, None
