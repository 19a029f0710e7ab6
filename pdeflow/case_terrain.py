"""The ``[terrain]`` table of a 2D case (issue 37): the single-layer flow over a bed.

Keys (docs/terrain.md, "Case files over terrain")::

    [terrain]
    bed = "parabola"     # a topography of pdeflow.terrain.topographies, or a DEM's path
                         # (.asc, .tif, .tiff) relative to the case file
    x0 = 0.0             # [m] where the grid's corner (x_start, y_start) lies in the
    y0 = -500.0          # bed's coordinates (default: x_start, y_start)
    [terrain.topography] # a topography's parameters (AvaFrame's defaults otherwise)
    fall_height = 1000.0
    [initial]
    measured = "slope_normal"   # or "vertical": how the shape's depth H0 is measured

The bed is taken at the grid's cell corners (:func:`terrain_corners`, (nx + 1, ny + 1)
[m]), the corner (i, j) at (x0 + i dx, y0 + j dy) in the bed's coordinates; the PDE
takes it as ``bed``. The model's depth is measured vertically, so the release's depth
is converted (:func:`release_depth`): a slope-normal thickness is divided by the cosine
of the bed's steepest slope at each cell centre, from the cell's corners.

Every key is checked by :func:`check_terrain` with a one-line error naming it, before
any work; the bed itself is built (and a DEM's coverage of the grid checked) by
:func:`terrain_corners`, which validation calls last.
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
from .terrain import (
    Raster,
    analytic_bed,
    bed_corners,
    cell_corners,
    cos_slope_corners,
    read_raster,
    vertical_depth,
)
from .terrain.thickness import MEASURED
from .terrain.topographies import TOPOGRAPHIES

TERRAIN_MODELS = ("single_layer",)
"""the models that flow over a bed (the two-layer model refuses one for now)"""
DEM_SUFFIXES = (".asc", ".tif", ".tiff")
"""what a DEM's file name ends with (:func:`pdeflow.terrain.read_raster`)"""
MAX_CFL_TERRAIN = 0.5
"""the largest CFL number of the flow over a bed"""
WHY = "with a [terrain] bed"


def _err(case: Any, msg: str) -> CaseError:
    return CaseError(f"{case.source}: {msg}")


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
        check_range(f"numerics.cfl ({WHY})", case.cfl, 0, MAX_CFL_TERRAIN, low_open=True)
    except ValueError as err:
        raise _err(case, str(err)) from None
    _check_bed(case, terrain)
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
    """``terrain.bed`` a topography's name or an existing DEM file;
    ``terrain.topography`` the topography's parameters, numbers in range."""
    names = list(TOPOGRAPHIES)
    if "bed" not in terrain:
        raise _err(case, f"terrain.bed is required: one of {names} or a DEM file "
                         f"({', '.join(DEM_SUFFIXES)}) relative to the case file")
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
def _read_dem(path: str, stamp: tuple[int, int]) -> Raster:
    """The raster at ``path``, read once per version (``stamp``: its modification time
    [ns] and size): a case is validated again for each variant it is run with. Not to
    be modified (shared)."""
    return read_raster(path)


def _bed(case: Any, terrain: dict[str, Any]) -> Any:
    """The DEM (a :class:`~pdeflow.terrain.Raster`) or the analytic bed z(x, y) of a
    checked ``[terrain]`` table."""
    bed = terrain["bed"]
    if not is_dem(bed):
        return analytic_bed(bed, terrain.get("topography", {}))
    path = (case.base_dir / bed).resolve()
    stat = path.stat()
    return _read_dem(str(path), (stat.st_mtime_ns, stat.st_size))


def terrain_corners(case: Any) -> np.ndarray | None:
    """The bed z_b [m] at the cell corners (nx + 1, ny + 1) of a checked case's grid,
    the corner (i, j) at (x0 + i dx, y0 + j dy) in the bed's coordinates
    (``terrain.x0``, ``terrain.y0``, by default the grid's x_start, y_start); None
    without ``[terrain]``. A DEM that does not cover the corners, or has no data next to
    one, is a one-line CaseError naming ``terrain.bed``, and so is a GeoTIFF without
    rasterio."""
    terrain = case.data.get("terrain")
    if terrain is None:
        return None
    x = cell_corners(float(terrain.get("x0", case.x_start)), case.length, case.dx)
    y = cell_corners(float(terrain.get("y0", case.y_start)), case.width, case.dy, axis="y")
    name = f"terrain.bed {terrain['bed']!r}"
    try:
        return bed_corners(_bed(case, terrain), x, y, name=name)
    except (ValueError, ImportError) as err:
        text = str(err)
        raise _err(case, text if text.startswith(name) else f"{name}: {text}") from None


def release_depth(case: Any, h: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """The release's depth [m] measured vertically at the cell centres (nx, ny), from
    the shape's depth ``h`` (nx, ny) [m] measured as ``initial.measured`` says
    ("slope_normal", the default as AvaFrame's release thickness, or "vertical"), over
    the bed ``corners`` (nx + 1, ny + 1) [m]."""
    cos_theta = cos_slope_corners(corners, case.dx, case.dy)
    return vertical_depth(h, cos_theta, case.initial.get("measured", MEASURED[0]))
