"""The bed at the cell corners of a 2D grid: what the flow over terrain takes (issue 37).

The single-layer model over a bed takes z_b at the corners of its cells, an array
(nx + 1, ny + 1) [m] (axis 0 along x): the corners are shared by the faces, so the
bed's slopes across a face and inside a cell are differences of the same numbers.
A bed is either

* an analytic topography (:mod:`.topographies`, by name, with its parameters),
  evaluated at the corners; or
* a raster (a DEM), resampled at the corners bilinearly by
  :func:`~.resample.bed_on_grid` (the corners are one more tensor grid: its coverage
  and no-data errors apply, naming the corners).

The corners are given in the bed's own coordinates [m] (the map's, or AvaFrame's for
a topography): :func:`~.resample.cell_corners` makes them from a grid's origin in those
coordinates, its length and its cell size.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping

import numpy as np

from .raster import Raster
from .resample import bed_on_grid
from .topographies import TOPOGRAPHIES

Bed = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""an analytic bed: z_b [m] at the points x, y [m] (arrays alike)"""


def topography_parameters(name: str) -> tuple[str, ...]:
    """The parameters of the topography ``name`` (those of its function after x, y), in
    their order; ValueError (one line) for a name that is not one of
    :data:`~.topographies.TOPOGRAPHIES`."""
    if name not in TOPOGRAPHIES:
        raise ValueError(f"unknown topography {name!r}; allowed: {list(TOPOGRAPHIES)}")
    return tuple(inspect.signature(TOPOGRAPHIES[name]).parameters)[2:]


def analytic_bed(name: str, parameters: Mapping[str, float] | None = None) -> Bed:
    """The topography ``name`` with ``parameters`` (a subset of
    :func:`topography_parameters`; the others take AvaFrame's defaults) as a bed z(x, y).

    Checked at once, before any grid is made: an unknown parameter is a one-line
    ValueError starting with its name, and so is a value out of range (the function's
    own checks, run on one point)."""
    parameters = dict(parameters or {})
    allowed = topography_parameters(name)
    for key in parameters:
        if key not in allowed:
            raise ValueError(f"{key} is no parameter of the topography {name!r}; "
                             f"allowed: {list(allowed)}")
    function = TOPOGRAPHIES[name]
    function(np.zeros(1), np.zeros(1), **parameters)  # its range checks, now

    def bed(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return function(x, y, **parameters)

    return bed


def bed_corners(bed: Raster | Bed, x: np.ndarray, y: np.ndarray,
                name: str = "bed") -> np.ndarray:
    """The bed z_b [m] at the cell corners ``x`` (nx + 1,) x ``y`` (ny + 1,) [m, the
    bed's coordinates], shape (nx + 1, ny + 1): the raster ``bed`` resampled bilinearly
    (its coverage and no-data errors name ``name``), or the analytic ``bed``
    evaluated."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if isinstance(bed, Raster):
        return bed_on_grid(bed, x, y, name=name, points="cell corners")
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806  (nx + 1, ny + 1)
    return np.asarray(bed(X, Y), dtype=float)

