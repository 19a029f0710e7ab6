"""Release areas and the release thickness.

A release is a list of polygons [m, the grid's coordinates]; a polygon is a list of
rings (n, 2), the outline and any holes, combined by the even-odd rule; polygons add
up. A case file's 2D ``polygon`` shape (its ``vertices``) is one polygon of one ring;
a shapefile (through pyshp, the extra ``terrain``) gives one polygon per record, its
parts the rings. A cell is released where its centre is inside, by the same test as
the 2D ``polygon`` shape (:func:`pdeflow.initial_shapes_2d.inside_polygon`).

**Thickness.** pdeflow's terrain inputs return the release depth measured
*vertically*. The user gives the thickness either way (``measured``): "slope_normal"
(the default, AvaFrame's convention for its release thickness: normal to the local
slope) is converted by h_vertical = h_normal / cos(theta), with tan(theta) = |grad z_b|
the bed's steepest slope from the resampled bed's gradient (central differences, one-
sided at the grid's edges); "vertical" is taken as it is.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..initial_shapes_2d import inside_polygon
from ..models.base import check_range
from .raster import Raster

Polygon = Sequence[np.ndarray]
"""the rings (n, 2) [m] of one polygon: its outline and its holes"""
MEASURED = ("slope_normal", "vertical")
"""how a release thickness may be measured"""
POLYGON_TYPES = {5: "POLYGON", 15: "POLYGONZ", 25: "POLYGONM"}
"""the shapefile shape types that hold polygons (pyshp's codes)"""


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
    X, Y = np.meshgrid(np.asarray(x, float), np.asarray(y, float), indexing="ij")  # noqa: N806
    mask = inside_release(polygons, X, Y, name)
    if not mask.any():
        raise ValueError(f"{name}: the release covers no cell centre of the grid (x in "
                         f"[{X.min():g}, {X.max():g}] m, y in [{Y.min():g}, {Y.max():g}] "
                         "m): move it onto the grid, enlarge it or refine the grid")
    return mask


def check_release_on_raster(polygons: Sequence[Polygon], raster: Raster,
                            name: str = "release") -> None:
    """One-line ValueError when a vertex of the release lies outside the raster's
    extent or a raster cell whose centre is inside the release has no data."""
    x_min, x_max, y_min, y_max = raster.bounds
    for polygon in polygons:
        for ring in _rings(polygon, name):
            out = ((ring[:, 0] < x_min) | (ring[:, 0] > x_max) | (ring[:, 1] < y_min)
                   | (ring[:, 1] > y_max))
            if out.any():
                vx, vy = ring[np.argmax(out)]
                raise ValueError(f"{name}: the vertex ({vx:g}, {vy:g}) m lies outside the "
                                 f"DEM: each must lie in x [{x_min:g}, {x_max:g}] m x y "
                                 f"[{y_min:g}, {y_max:g}] m")
    X, Y = np.meshgrid(raster.x_centres, raster.y_centres, indexing="xy")  # noqa: N806
    on_nodata = inside_release(polygons, X, Y, name) & raster.nodata
    if on_nodata.any():
        first = np.argwhere(on_nodata)[0]
        raise ValueError(f"{name}: {int(on_nodata.sum())} DEM cells under the release have "
                         f"no data, e.g. the one centred at ({X[tuple(first)]:g}, "
                         f"{Y[tuple(first)]:g}) m: release on cells with data only")


def vertical_thickness(mask: np.ndarray, thickness: float, bed: np.ndarray, dx: float,
                       dy: float, measured: str = "slope_normal") -> np.ndarray:
    """The release depth [m] measured vertically on the released cells ``mask`` (nx,
    ny), 0 elsewhere, from the release ``thickness`` [m] ``measured`` "slope_normal"
    (default, as AvaFrame's release thickness: divided by cos(theta), tan(theta) = |grad
    z_b| of the ``bed`` (nx, ny) [m] on cells ``dx`` x ``dy`` [m]) or "vertical"."""
    if measured not in MEASURED:
        raise ValueError(f"measured must be one of {list(MEASURED)}, got {measured!r}")
    check_range("thickness", thickness, 0, math.inf, low_open=True, high_open=True, unit="m")
    check_range("dx", dx, 0, math.inf, low_open=True, high_open=True, unit="m")
    check_range("dy", dy, 0, math.inf, low_open=True, high_open=True, unit="m")
    bed = np.asarray(bed, dtype=float)
    if bed.shape != np.shape(mask) or bed.ndim != 2 or min(bed.shape) < 2:
        raise ValueError(f"bed must be an array (nx, ny) of at least 2 x 2 cells shaped "
                         f"as mask {np.shape(mask)}, got {bed.shape}")
    h = np.where(mask, float(thickness), 0.0)
    if measured == "vertical":
        return h
    return h / cos_slope(bed, dx, dy)


def cos_slope(bed: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """cos(theta) of the bed's steepest slope at each cell, 1 / sqrt(1 + |grad z_b|^2),
    from the gradient of ``bed`` (nx, ny) [m] on cells ``dx`` x ``dy`` [m] (central
    differences inside, one-sided at the edges: exact on a plane)."""
    dz_dx, dz_dy = np.gradient(bed, dx, dy)
    return 1.0 / np.sqrt(1.0 + dz_dx**2 + dz_dy**2)


def _pyshp() -> Any:
    """pyshp's module, or a one-line ImportError naming the extra that installs it."""
    try:
        import shapefile
    except ImportError:
        raise ImportError("reading a shapefile needs pyshp: pip install "
                          "'pdeflow[terrain]' (or give the release as polygons)") from None
    return shapefile


def shapefile_polygons(path: str | Path) -> list[list[np.ndarray]]:
    """The polygons of the shapefile at ``path`` [m, its map coordinates], one per
    record, each a list of its parts (rings). One-line ValueError when it holds no
    polygons or shapes of another type."""
    shapefile = _pyshp()
    with shapefile.Reader(str(path)) as reader:
        if reader.shapeType not in POLYGON_TYPES:
            raise ValueError(f"{path}: a release shapefile must hold polygons (types "
                             f"{list(POLYGON_TYPES.values())}), got shape type "
                             f"{reader.shapeType}")
        polygons = []
        for shape in reader.iterShapes():
            points = np.asarray(shape.points, dtype=float).reshape(-1, 2)
            bounds = [*shape.parts, len(points)]
            polygons.append([points[a:b] for a, b in zip(bounds[:-1], bounds[1:],
                                                          strict=True)])
    if not polygons:
        raise ValueError(f"{path}: the shapefile holds no polygon (at least 1 is needed)")
    return polygons
