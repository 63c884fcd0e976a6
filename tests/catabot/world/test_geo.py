"""Geodesy against PROJ (pyproj): exact ENU <-> WGS84, round trips, and the paper's tables.

PROJ's `topocentric` operation is an independent implementation of the same ENU frame, so
agreement to well under a centimetre is a check of both the rotation and the ECEF ->
geodetic step. The paper-table method is measured against the exact mapping at 1, 5 and
20 km in every direction; the bounds asserted below sit just above those measurements
(worst origin 70 deg N): horizontal 0.215 / 5.37 / 85.9 m, vertical 0.079 / 1.97 / 31.6 m.
"""

from __future__ import annotations

import numpy as np
import pyproj
import pytest

from catabot.world import geo

ORIGINS = [
    (0.0, 0.0, 0.0),  # equator, prime meridian
    (45.0, 7.0, 100.0),
    (70.0, 20.0, -5.0),
    (-33.9, 151.2, 10.0),  # southern hemisphere
    (-10.0, 179.99, 0.0),  # 20 km reach crosses the antimeridian
    (0.5, -179.995, 0.0),
]
HEADINGS = np.radians(np.arange(0.0, 360.0, 7.5))
TO_ECEF = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
TO_GEODETIC = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)


def proj_enu_to_geodetic(origin: tuple[float, float, float], e, n, u):
    lat0, lon0, h0 = origin
    pipeline = (
        f"+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 +lat_0={lat0} +lon_0={lon0}"
        f" +h_0={h0} +step +inv +proj=cart +ellps=WGS84"
        " +step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    lon, lat, alt = pyproj.Transformer.from_pipeline(pipeline).transform(e, n, u)
    return np.asarray(lat), np.asarray(lon), np.asarray(alt)


def ecef_distance(a, b) -> np.ndarray:
    """3-D distance (m) between two sets of (lat, lon, alt), via PROJ's own ECEF."""
    xa = np.array(TO_ECEF.transform(a[1], a[0], a[2]))
    xb = np.array(TO_ECEF.transform(b[1], b[0], b[2]))
    return np.linalg.norm(xa - xb, axis=0)


def ring(distance_m: float, up_m: float = 0.0):
    return (
        distance_m * np.cos(HEADINGS),
        distance_m * np.sin(HEADINGS),
        np.full(HEADINGS.shape, up_m),
    )


@pytest.mark.parametrize("origin", ORIGINS)
def test_enu_to_geodetic_matches_proj_within_1cm_out_to_20km(origin) -> None:
    for distance in (0.0, 10.0, 1000.0, 5000.0, 20000.0):
        for up in (-30.0, 0.0, 50.0):
            e, n, u = ring(distance, up)
            ours = geo.enu_to_geodetic(e, n, u, origin=origin)
            theirs = proj_enu_to_geodetic(origin, e, n, u)
            assert ecef_distance(ours, theirs).max() < 0.01
            assert np.all((ours[1] >= -180.0) & (ours[1] < 180.0))


def test_ecef_to_geodetic_matches_proj_everywhere_to_a_millimetre() -> None:
    rng = np.random.default_rng(7)
    lat = np.concatenate([rng.uniform(-90, 90, 2000), [90.0, -90.0, 0.0, 89.9999]])
    lon = rng.uniform(-180, 180, lat.size)
    alt = rng.uniform(-11000, 100000, lat.size)
    x, y, z = TO_ECEF.transform(lon, lat, alt)
    ours = geo.ecef_to_geodetic(np.stack([x, y, z], -1))
    theirs = (lat, lon, alt)
    assert ecef_distance(ours, theirs).max() < 1e-3
    np.testing.assert_allclose(
        geo.geodetic_to_ecef(lat, lon, alt), np.stack([x, y, z], -1), atol=1e-6
    )


@pytest.mark.parametrize("origin", ORIGINS)
def test_round_trips(origin) -> None:
    e, n, u = ring(15000.0, 12.0)
    frame = geo.EnuFrame(*origin)
    back = frame.to_enu(*frame.to_geodetic(e, n, u))
    np.testing.assert_allclose(np.stack(back), np.stack([e, n, u]), atol=1e-6)
    lat, lon, alt = frame.to_geodetic(e, n, u)
    again = geo.enu_to_geodetic(*geo.geodetic_to_enu(lat, lon, alt, origin=origin), origin=origin)
    assert ecef_distance(again, (lat, lon, alt)).max() < 1e-6


def test_origin_maps_to_itself_and_arrays_broadcast() -> None:
    lat, lon, alt = geo.enu_to_geodetic(0.0, 0.0, 0.0, origin=(43.7, -72.3, 150.0))
    assert (float(lat), float(lon), float(alt)) == pytest.approx((43.7, -72.3, 150.0), abs=1e-9)
    lat, _, _ = geo.enu_to_geodetic(np.zeros((4, 5)), 0.0, np.arange(5.0), origin=(0, 0, 0))
    assert lat.shape == (4, 5)


def paper_errors(origin, distance_m: float) -> tuple[float, float]:
    """Worst horizontal and vertical error (m) of the paper method over all headings."""
    e, n, u = ring(distance_m)
    frame = geo.EnuFrame(*origin)
    pe, pn, pu = frame.to_enu(*geo.paper_table_enu_to_geodetic(e, n, u, origin=origin))
    return float(np.hypot(pe - e, pn - n).max()), float(np.abs(pu - u).max())


# distance (m): (horizontal bound, vertical bound), measured maxima in the module docstring
PAPER_BOUNDS = {1000.0: (0.25, 0.09), 5000.0: (5.6, 2.05), 20000.0: (88.0, 32.0)}


@pytest.mark.parametrize("distance", sorted(PAPER_BOUNDS))
def test_paper_table_error_against_wgs84(distance) -> None:
    h_bound, v_bound = PAPER_BOUNDS[distance]
    errors = [paper_errors(origin, distance) for origin in ORIGINS]
    assert max(h for h, _ in errors) < h_bound
    assert max(v for _, v in errors) < v_bound
    # at the equator the parallel is the tangent's east axis: only the tables' own error
    assert paper_errors(ORIGINS[0], distance)[0] < 0.25 * distance / 20000.0 + 0.005


def test_paper_tables_match_the_ellipsoid() -> None:
    """Eq. (8)'s meridian distance and eq. (9)'s degree width against exact WGS84 values."""
    lats = np.linspace(-89.5, 89.5, 719)
    lat_m, lon_m = geo.paper_table_geodetic_to_metres(lats, np.ones_like(lats))
    _, _, arc = pyproj.Geod(ellps="WGS84").inv(0 * lats, 0 * lats, 0 * lats, lats)
    assert np.abs(np.abs(lat_m) - arc).max() < 3.0  # over up to 10 000 km
    phi = np.radians(lats)
    width = geo.WGS84_A * np.cos(phi) / np.sqrt(1 - geo.WGS84_E2 * np.sin(phi) ** 2)
    assert np.abs(lon_m / (width * np.pi / 180) - 1).max() < 6e-5  # the lerp of eq. (9)
    assert np.allclose(geo.paper_table_metres_to_latitude(lat_m), lats, atol=1e-12)


def test_paper_table_origin_and_antimeridian() -> None:
    lat, lon, alt = geo.paper_table_enu_to_geodetic(0.0, 0.0, 2.0, origin=(-33.9, 151.2, 10.0))
    assert (float(lat), float(lon), float(alt)) == pytest.approx((-33.9, 151.2, 12.0), abs=1e-12)
    _, lon, _ = geo.paper_table_enu_to_geodetic(2000.0, 0.0, 0.0, origin=(0.0, 179.99, 0.0))
    assert -180.0 < float(lon) < -179.97


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: geo.EnuFrame(90.5, 0.0), r"latitude \(deg\) must be within \[-90, 90\]"),
        (lambda: geo.EnuFrame(0.0, 181.0), r"longitude \(deg\) must be within \[-180, 180\]"),
        (lambda: geo.geodetic_to_ecef(np.nan, 0.0, 0.0), "latitude"),
        (lambda: geo.EnuFrame(0.0, 0.0).to_geodetic(np.inf, 0.0, 0.0), "ENU offset"),
        (lambda: geo.ecef_to_geodetic(np.zeros((2, 2))), "last axis of length 3"),
        (
            lambda: geo.paper_table_enu_to_geodetic(0.0, 2e5, 0.0, origin=(89.5, 0.0, 0.0)),
            "runs past a pole",
        ),
    ],
)
def test_geo_errors_are_precise(call, message) -> None:
    with pytest.raises(geo.GeoError, match=message):
        call()
