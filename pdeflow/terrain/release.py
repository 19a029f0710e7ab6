"""Release areas as polygons.

A release is a list of polygons [m, the grid's coordinates]; a polygon is a list of
rings (n, 2), the outline and any holes, combined by the even-odd rule; polygons add
up. A case file's 2D ``polygon`` shape (its ``vertices``) is one polygon of one ring
(:func:`case_polygon`); a shapefile (:mod:`.shapefiles`) gives one polygon per record,
its parts the rings. A cell is released where its centre is inside, by the same test
as the 2D ``polygon`` shape (:func:`pdeflow.initial_shapes_2d.inside_polygon`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..initial_shapes_2d import inside_polygon
from .raster import Raster

Polygon = Sequence[np.ndarray]
"""the rings (n, 2) [m] of one polygon: its outline and its holes"""


def _rings(polygon: Polygon, name: str) -> list[np.ndarray]:
    """The rings of ``polygon`` as float arrays; one-line ValueError unless each has at
    least 3 finite points [x, y]."""
    rings = []
    for ring in polygon:
        r = np.asarray(ring, dtype=float)
        if r.ndim != 2 or r.shape[0] < 3 or r.shape[1] != 2 or not np.all(np.isfinite(r)):
            raise ValueError(f"{name}: a ring must be at least 3 points [x, y] of finite "
                             f"numbers [m], got shape {r.shape}")
        rings.append(r)
    if not rings:
        raise ValueError(f"{name}: a polygon needs at least one ring")
    return rings


def inside_release(polygons: Sequence[Polygon], x: np.ndarray, y: np.ndarray,
                   name: str = "release") -> np.ndarray:
    """Whether the points ``x``, ``y`` [m] (any shape, alike) lie inside the release
    ``polygons``: even-odd over each polygon's rings, union over the polygons."""
    if len(polygons) == 0:
        raise ValueError(f"{name}: the release has no polygon (at least 1 is needed)")
    inside = np.zeros(np.shape(x), dtype=bool)
    for polygon in polygons:
        mine = np.zeros(np.shape(x), dtype=bool)
        for ring in _rings(polygon, name):
            mine ^= inside_polygon(ring, x, y)
        inside |= mine
    return inside


def release_mask(polygons: Sequence[Polygon], x: np.ndarray, y: np.ndarray,
                 raster: Raster | None = None, name: str = "release") -> np.ndarray:
    """The released cells (nx, ny) of the grid with the cell centres ``x`` (nx,),
    ``y`` (ny,) [m]. With the DEM ``raster``, first refused (one line) when a vertex
    lies outside the raster or a raster cell under the release has no data
    (:func:`check_release_on_raster`); always refused when no cell centre is inside."""
    if raster is not None:
        check_release_on_raster(polygons, raster, name)
    x, y = np.asarray(x, float), np.asarray(y, float)
    _check_on_grid(polygons, x, y, name)
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806
    mask = inside_release(polygons, X, Y, name)
    if not mask.any():
        raise ValueError(f"{name}: the release covers no cell centre of the grid (x in "
                         f"[{X.min():g}, {X.max():g}] m, y in [{Y.min():g}, {Y.max():g}] "
                         "m): move it onto the grid, enlarge it or refine the grid")
    return mask


def _edges(centres: np.ndarray) -> tuple[float, float]:
    """The outer faces [m] of an axis with the uniform cell ``centres``."""
    half = 0.5 * (centres[-1] - centres[0]) / (centres.size - 1) if centres.size > 1 else 0.0
    return float(centres[0] - half), float(centres[-1] + half)


def _check_on_grid(polygons: Sequence[Polygon], x: np.ndarray, y: np.ndarray,
                   name: str) -> None:
    """One-line ValueError when a vertex lies outside the grid's domain: the part of a
    release beyond it would be lost unseen (as a 2D case's polygon, every vertex must
    lie in the domain)."""
    (x_lo, x_hi), (y_lo, y_hi) = _edges(x), _edges(y)
    _vertices_within(polygons, (x_lo, x_hi, y_lo, y_hi), name, "the grid's domain")


def _vertices_within(polygons: Sequence[Polygon], box: tuple[float, float, float, float],
                     name: str, what: str) -> None:
    """One-line ValueError naming the first vertex outside ``box`` (x_min, x_max,
    y_min, y_max) [m], ``what`` the box is (the grid's domain, the DEM)."""
    x_lo, x_hi, y_lo, y_hi = box
    for polygon in polygons:
        for ring in _rings(polygon, name):
            out = ((ring[:, 0] < x_lo) | (ring[:, 0] > x_hi) | (ring[:, 1] < y_lo)
                   | (ring[:, 1] > y_hi))
            if out.any():
                vx, vy = ring[np.argmax(out)]
                raise ValueError(f"{name}: the vertex ({vx:g}, {vy:g}) m lies outside "
                                 f"{what}: each must lie in x [{x_lo:g}, {x_hi:g}] m x y "
                                 f"[{y_lo:g}, {y_hi:g}] m")


def case_polygon(vertices: Sequence[Sequence[float]], x_start: float = 0.0,
                 y_start: float = 0.0) -> list[np.ndarray]:
    """A case file's 2D ``polygon`` ``vertices`` [[x, y], ...] [m from the domain's
    corner] as one polygon of one ring in the grid's coordinates (plus ``x_start``,
    ``y_start`` [m])."""
    return [np.asarray(vertices, dtype=float) + np.array([x_start, y_start])]


def same_crs(dem_crs: str | None, release_crs: str | None, name: str = "release") -> None:
    """One-line ValueError when the DEM's and the release's coordinate reference
    systems (WKT) are both known and differ: pdeflow does not reproject. Compared as
    CRSs by rasterio where it is installed, else as texts (whitespace aside)."""
    if dem_crs is None or release_crs is None:
        return
    try:
        from rasterio.crs import CRS
        same = CRS.from_wkt(dem_crs) == CRS.from_wkt(release_crs)
    except ImportError:
        same = " ".join(dem_crs.split()) == " ".join(release_crs.split())
    if not same:
        raise ValueError(f"{name}: its coordinate reference system differs from the DEM's "
                         f"({_crs_name(release_crs)} against {_crs_name(dem_crs)}): "
                         "reproject one of them (pdeflow does not)")


def _crs_name(wkt: str) -> str:
    """The name a WKT text gives its CRS (its first quoted string), for messages."""
    parts = wkt.split('"')
    return repr(parts[1]) if len(parts) > 2 else "unnamed"


def check_release_on_raster(polygons: Sequence[Polygon], raster: Raster,
                            name: str = "release") -> None:
    """One-line ValueError when a vertex of the release lies outside the raster's
    extent or a raster cell whose centre is inside the release has no data."""
    _vertices_within(polygons, raster.bounds, name, "the DEM")
    X, Y = np.meshgrid(raster.x_centres, raster.y_centres, indexing="xy")  # noqa: N806
    on_nodata = inside_release(polygons, X, Y, name) & raster.nodata
    if on_nodata.any():
        first = np.argwhere(on_nodata)[0]
        raise ValueError(f"{name}: {int(on_nodata.sum())} DEM cells under the release have "
                         f"no data, e.g. the one centred at ({X[tuple(first)]:g}, "
                         f"{Y[tuple(first)]:g}) m: release on cells with data only")
