"""The ``[terrain]`` table of a 2D case (issue 37): the single-layer flow over a bed.

Keys (docs/terrain.md, "Case files over terrain")::

    [terrain]
    bed = "parabola"     # a topography of pdeflow.terrain.topographies, or a DEM's path
                         # (.asc, .tif, .tiff) relative to the case file, or instead
    # expression = "200 - 0.4 * x"   # the bed z(x, y) [m] (pdeflow.terrain.expression)
    x0 = 0.0             # [m] where the grid's corner (x_start, y_start) lies in the
    y0 = -500.0          # bed's coordinates (default: x_start, y_start)
    release = "rel.shp"  # optional: the release's outline from a shapefile (pyshp), in
                         # the bed's coordinates, for initial.shape = "polygon"
    [terrain.topography] # a topography's parameters (AvaFrame's defaults otherwise)
    fall_height = 1000.0
    [initial]
    measured = "slope_normal"   # or "vertical": how the shape's depth H0 is measured

The bed is taken at the grid's cell corners (:func:`terrain_corners`, (nx + 1, ny + 1)
[m]), the corner (i, j) at (x0 + i dx, y0 + j dy) in the bed's coordinates; the PDE
takes it as ``bed``. The model's depth is measured vertically, so the release's depth
is converted (:func:`release_depth`): a slope-normal thickness is divided by the cosine
of the bed's steepest slope at each cell centre, from the cell's corners. A shapefile's
outline (``terrain.release``) becomes the ``polygon`` shape's vertices
(:func:`release_vertices`, shifted to the grid's corner), so that every use of the shape
(its depth, centre and front) takes it as it takes a case file's polygon.

Every key is checked by :func:`check_terrain` with a one-line error naming it, before
any work; the bed itself is built (and a DEM's coverage of the grid checked) by
:func:`terrain_corners`, which validation calls last (:func:`check_bed`, which also
checks a shapefile release against the DEM).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Any

import numpy as np

from . import systems
from .case_schema import CaseError
from .models.base import check_range
from .numerics.scheme import MAX_CFL_BED
from .terrain import (
    Raster,
    analytic_bed,
    bed_corners,
    bed_expression,
    cell_centres,
    cell_corners,
    cos_slope_corners,
    read_raster,
    release_mask,
    same_crs,
    shapefile_crs,
    shapefile_polygons,
    vertical_depth,
)
from .terrain.release import check_release_on_raster
from .terrain.thickness import MEASURED
from .terrain.topographies import TOPOGRAPHIES

TERRAIN_MODELS = ("single_layer", "two_layer")
"""the models that flow over a bed"""
DEM_SUFFIXES = (".asc", ".tif", ".tiff")
"""what a DEM's file name ends with (:func:`pdeflow.terrain.read_raster`)"""
WHY = "with a [terrain] bed"
"""what the errors say of a key that a bed constrains"""


def _err(case: Any, msg: str) -> CaseError:
    return CaseError(f"{case.source}: {msg}")


def _named(case: Any, name: str, err: Exception) -> CaseError:
    """The one-line error of reading or checking a file (a DEM, a shapefile) that names
    the key ``name`` (``terrain.bed 'dem.asc'``), whether or not the reader did."""
    text = str(err)
    return _err(case, text if text.startswith(name) else f"{name}: {text}")


def is_dem(bed: str) -> bool:
    """Whether ``terrain.bed`` names a DEM file (by its suffix), not a topography."""
    return Path(bed).suffix.lower() in DEM_SUFFIXES


def check_terrain(case: Any) -> None:
    """The keys of ``[terrain]`` and ``initial.measured``: a 2D single-layer case on
    no inclined plane, first-order with cfl <= 0.5, a known bed with its parameters
    in range. Without ``[terrain]``, ``initial.measured`` is refused (it has nothing to
    be measured against)."""
    terrain = case.data.get("terrain")
    if terrain is None:
        if "measured" in case.initial:
            raise _err(case, "initial.measured says how a release over a [terrain] bed "
                             "is measured: add a [terrain] table or remove it")
        return
    if not case.is_2d:
        raise _err(case, "[terrain] belongs to a 2D grid: give grid.width [m] (the "
                         "domain across) too")
    _check_models(case)
    reconstruction = case.data.get("numerics", {}).get("reconstruction", "first-order")
    if reconstruction != "first-order":
        raise _err(case, f"numerics.reconstruction must be 'first-order' {WHY} (the flow "
                         f"over a bed is first order for now), got {reconstruction!r}")
    try:
        check_range(f"numerics.cfl ({WHY})", case.cfl, 0, MAX_CFL_BED, low_open=True)
    except ValueError as err:
        raise _err(case, str(err)) from None
    _check_bed(case, terrain)
    _check_release(case, terrain)
    try:
        check_range("terrain.flow_density", flow_density(case), 0, math.inf,
                    low_open=True, high_open=True, unit="kg/m^3")
    except ValueError as err:
        raise _err(case, str(err)) from None
    measured = case.initial.get("measured", MEASURED[0])
    if measured not in MEASURED:
        raise _err(case, f"initial.measured must be one of {list(MEASURED)}, got "
                         f"{measured!r}")


def _check_models(case: Any) -> None:
    """Only the models in :data:`TERRAIN_MODELS`, with theta_deg = slope_azimuth_deg
    = 0: over a bed, gravity is vertical and the bed's own slopes drive the flow."""
    for model in case.models:
        if model not in TERRAIN_MODELS:
            raise _err(case, f"case.models: {model!r} takes no [terrain] bed yet (issue "
                             f"37); {WHY} use {list(TERRAIN_MODELS)}")
        params = systems.get(model).parameters_class.from_dict(case.data.get(model, {}))
        for key in ("theta_deg", "slope_azimuth_deg"):
            value = getattr(params, key)
            if value != 0.0:
                raise _err(case, f"{model}.{key} must be 0 {WHY} (gravity is vertical, "
                                 f"the bed's slopes drive the flow), got {value:g}")


def _check_bed(case: Any, terrain: dict[str, Any]) -> None:
    """``terrain.bed`` a topography's name or an existing DEM file, or
    ``terrain.expression`` a bed expression (not both); ``terrain.topography`` the
    topography's parameters, numbers in range."""
    names = list(TOPOGRAPHIES)
    if "expression" in terrain:
        for key in ("bed", "topography"):
            if key in terrain:
                raise _err(case, f"terrain.{key} and terrain.expression both give the "
                                 f"bed: keep one")
        try:
            bed_expression(terrain["expression"])
        except ValueError as err:
            raise _err(case, f"terrain.expression: {err}") from None
        return
    if "bed" not in terrain:
        raise _err(case, f"terrain.bed is required: one of {names} or a DEM file "
                         f"({', '.join(DEM_SUFFIXES)}) relative to the case file (or "
                         f"terrain.expression, the bed z(x, y) [m] in x and y)")
    bed = terrain["bed"]
    parameters = terrain.get("topography", {})
    if is_dem(bed):
        if parameters:
            raise _err(case, f"terrain.topography holds a topography's parameters: "
                             f"remove it for the DEM bed {bed!r}")
        if not (case.base_dir / bed).is_file():
            raise _err(case, f"terrain.bed: file {bed} not found next to the case file")
        return
    if bed not in TOPOGRAPHIES:
        raise _err(case, f"terrain.bed must be one of {names} or a DEM file "
                         f"({', '.join(DEM_SUFFIXES)}) relative to the case file, got "
                         f"{bed!r}")
    for key, value in parameters.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not \
                math.isfinite(value):
            raise _err(case, f"terrain.topography.{key} must be a finite number, got "
                             f"{value!r}")
    try:
        analytic_bed(bed, parameters)
    except ValueError as err:  # its messages start with the parameter's name
        raise _err(case, f"terrain.topography.{err}") from None


@functools.lru_cache(maxsize=4)
def _read_dem(path: str, stamp: tuple[int, ...]) -> Raster:
    """The raster at ``path``, read once per version (``stamp``, :func:`_stamped`): a
    case is validated again for each variant it is run with. Not to be modified
    (shared)."""
    return read_raster(path)


@functools.lru_cache(maxsize=4)
def _read_release(path: str, stamp: tuple[int, ...]) -> list[list[np.ndarray]]:
    """The polygons of the shapefile at ``path``, read once per version (as
    :func:`_read_dem`): ``Case.initial`` reads the outline each time it is asked."""
    return shapefile_polygons(path)


def _stamped(path: Path, read: Any) -> Any:
    """``read`` (a cached reader) of the file at ``path`` in its current version: the
    modification times [ns] and sizes of the file and of its sidecar ``.prj`` (an .asc's
    CRS is there, so a new .prj is a new raster)."""
    stamp: tuple[int, ...] = ()
    for file in (path, path.with_suffix(".prj")):
        if file.exists():
            stat = file.stat()
            stamp += (stat.st_mtime_ns, stat.st_size)
    return read(str(path.resolve()), stamp)


FLOW_DENSITY = 200.0
"""the flow's density of the peak pressure [kg/m^3] (``terrain.flow_density``):
AvaFrame's com1DFA default (snow, ``rho``), so that its peak pressures compare; a dry
granular flow is nearer 1500"""


def flow_density(case: Any) -> float:
    """``terrain.flow_density`` [kg/m^3], by default :data:`FLOW_DENSITY`."""
    return case.data["terrain"].get("flow_density", FLOW_DENSITY)


def map_corner(case: Any) -> tuple[float, float, str | None]:
    """(x, y) [m] of the grid's lower-left corner in the bed's (map) coordinates and
    the DEM's CRS (WKT; None for a topography or a DEM without one): where a case's
    peak rasters lie."""
    terrain = case.data["terrain"]
    bed = _bed(case, terrain)
    return (*_origin(case), bed.crs if isinstance(bed, Raster) else None)


def _origin(case: Any) -> tuple[float, float]:
    """Where the grid's corner lies on the bed [m]: terrain.x0, y0, by default the grid's
    x_start, y_start (the grid's coordinates are the bed's)."""
    terrain = case.data["terrain"]
    return float(terrain.get("x0", case.x_start)), float(terrain.get("y0", case.y_start))


def _bed(case: Any, terrain: dict[str, Any]) -> Any:
    """The DEM (a :class:`~pdeflow.terrain.Raster`) or the analytic bed z(x, y) of a
    checked ``[terrain]`` table."""
    if "expression" in terrain:
        return bed_expression(terrain["expression"])
    bed = terrain["bed"]
    if not is_dem(bed):
        return analytic_bed(bed, terrain.get("topography", {}))
    return _stamped(case.base_dir / bed, _read_dem)


def _check_release(case: Any, terrain: dict[str, Any]) -> None:
    """``terrain.release``: an existing shapefile of one outline, for the ``polygon``
    shape without its own vertices, every vertex on the grid, covering a cell centre."""
    if "release" not in terrain:
        return
    release = terrain["release"]
    initial = case.data.get("initial", {})
    if Path(release).suffix.lower() != ".shp":
        raise _err(case, f"terrain.release must be a shapefile (.shp) relative to the "
                         f"case file, got {release!r}")
    if not (case.base_dir / release).is_file():
        raise _err(case, f"terrain.release: file {release} not found next to the case "
                         "file")
    if initial.get("shape") != "polygon":
        raise _err(case, f"initial.shape must be 'polygon' with terrain.release (the "
                         f"shapefile gives its outline), got {initial.get('shape')!r}")
    if "vertices" in initial:
        raise _err(case, "initial.vertices and terrain.release both give the release's "
                         "outline: remove one")
    name = f"terrain.release {release!r}"
    x0, y0 = _origin(case)
    try:
        ring = release_outline(case)
        release_mask([[ring]], cell_centres(x0, case.length, case.dx),
                     cell_centres(y0, case.width, case.dy, axis="y"), name=name)
    except (ValueError, ImportError) as err:
        raise _named(case, name, err) from None


def release_outline(case: Any) -> np.ndarray:
    """The one ring (n, 2) [m, the bed's coordinates] of the shapefile
    ``terrain.release`` (its closing point, a repeat of the first, dropped); one-line
    ValueError for several polygons or rings (the 2D ``polygon`` shape is one outline),
    ImportError without pyshp."""
    polygons = _stamped(case.base_dir / case.data["terrain"]["release"], _read_release)
    rings = sum(len(polygon) for polygon in polygons)
    if len(polygons) != 1 or rings != 1:
        raise ValueError(f"{len(polygons)} polygon(s) of {rings} ring(s): the 2D polygon "
                         "shape takes one outline without holes; keep one record of one "
                         "part")
    ring = polygons[0][0]
    closed = len(ring) > 3 and np.array_equal(ring[0], ring[-1])
    return ring[:-1] if closed else ring


def release_vertices(case: Any) -> list[list[float]] | None:
    """The ``polygon`` shape's vertices [m from the grid's corner] of
    ``terrain.release``'s outline; None without it, or when it cannot be read (then
    :func:`check_terrain` says why, naming the key)."""
    terrain = case.data.get("terrain") or {}
    if "release" not in terrain or not (case.base_dir / terrain["release"]).is_file():
        return None
    try:
        ring = release_outline(case)
    except (ValueError, ImportError):
        return None
    return (ring - np.array(_origin(case))).tolist()


def check_bed(case: Any) -> None:
    """Validation's last check of a case with ``[terrain]``: the bed is built
    (:func:`terrain_corners`), and a shapefile release over a DEM has its CRS and lies
    on cells with data (one-line CaseErrors naming ``terrain.release``)."""
    terrain_corners(case)
    terrain = case.data.get("terrain") or {}
    if "release" not in terrain or not is_dem(terrain.get("bed", "")):
        return
    name = f"terrain.release {terrain['release']!r}"
    try:
        raster = _bed(case, terrain)
        same_crs(raster.crs, shapefile_crs(case.base_dir / terrain["release"]), name=name)
        check_release_on_raster([[release_outline(case)]], raster, name=name)
    except ValueError as err:  # rasterio's CRS parser too (a CRSError)
        raise _named(case, name, err) from None


def terrain_corners(case: Any) -> np.ndarray | None:
    """The bed z_b [m] at the cell corners (nx + 1, ny + 1) of a checked case's grid,
    the corner (i, j) at (x0 + i dx, y0 + j dy) in the bed's coordinates
    (``terrain.x0``, ``terrain.y0``, by default the grid's x_start, y_start); None
    without ``[terrain]``. A DEM that does not cover the corners, or has no data next to
    one, is a one-line CaseError naming ``terrain.bed``, and so is a GeoTIFF without
    rasterio or a bed that is not finite at a corner."""
    terrain = case.data.get("terrain")
    if terrain is None:
        return None
    x0, y0 = _origin(case)
    x = cell_corners(x0, case.length, case.dx)
    y = cell_corners(y0, case.width, case.dy, axis="y")
    name = ("terrain.expression" if "expression" in terrain
            else f"terrain.bed {terrain['bed']!r}")
    try:
        corners = bed_corners(_bed(case, terrain), x, y, name=name)
    except (ValueError, ImportError) as err:
        raise _named(case, name, err) from None
    bad = ~np.isfinite(corners)  # (an expression's log(0); a DEM's are refused above)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise _err(case, f"{name} is not finite at {bad.sum()} of the grid's cell "
                         f"corners, e.g. x = {x[i]:g}, y = {y[j]:g} m")
    return corners


def release_depth(case: Any, h: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """The release's depth [m] measured vertically at the cell centres (nx, ny), from
    the shape's depth ``h`` (nx, ny) [m] measured as ``initial.measured`` says
    ("slope_normal", the default as AvaFrame's release thickness, or "vertical"), over
    the bed ``corners`` (nx + 1, ny + 1) [m]."""
    cos_theta = cos_slope_corners(corners, case.dx, case.dy)
    return vertical_depth(h, cos_theta, case.initial.get("measured", MEASURED[0]))
