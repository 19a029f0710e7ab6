"""The bed z_b at the computational grid's cell centres, from a raster.

**Bilinear between the raster's cell centres.** A raster's value is the elevation at its
cell's centre; the bed at a computational cell centre is the bilinear interpolant of
the four raster centres around it. Why bilinear:

* it reproduces any plane exactly (to round-off), so an inclined plane given as a DEM
  is the same bed as the analytic plane;
* it is continuous, so the resampled bed has no steps at the raster's cell edges (a
  nearest-cell bed would turn a smooth slope into stairs the flow would feel);
* it is local and bounded by its four values, so it makes no new peaks or pits (a
  cubic spline overshoots at breaks of slope and near no-data edges);
* it needs no data beyond the four neighbours, so a no-data cell spoils only the
  computational cells next to it, which are refused.

It samples, it does not average: on a computational grid much coarser than the raster
(dx several times the cellsize) the bed follows the raster's values at the centres and
aliases its small-scale relief; averaging the raster over each cell first is the remedy
and is not built.

Coordinates: the grid's cell centres are given in the raster's map coordinates [m];
which map direction is the flow's x is left to the flow over terrain (issue 37).
"""

from __future__ import annotations

import math

import numpy as np

from .raster import Raster

EDGE_TOLERANCE = 1e-9
"""how far [in raster cells] a grid centre may lie beyond the outermost raster centres
and still count as on them: a grid aligned with the raster has its first centre on the
raster's first centre, up to the round-off of computing both"""


def cell_centres(start: float, length: float, spacing: float, axis: str = "x") -> np.ndarray:
    """The cell centres [m] of one axis of a case's grid: ``start`` + spacing (i + 1/2),
    i < round(length / spacing), as a case file's ``x_start``, ``length``, ``dx`` (axis
    "x") or ``y_start``, ``width``, ``dy`` (axis "y") give them."""
    keys = ("x_start", "length", "dx") if axis == "x" else ("y_start", "width", "dy")
    for key, value in zip(keys, (start, length, spacing), strict=True):
        if not math.isfinite(value):
            raise ValueError(f"{key} must be a finite number [m], got {value!r}")
    if not 0 < length:
        raise ValueError(f"{keys[1]} must lie in (0, inf) m, got {length!r}")
    if not 0 < spacing <= length:
        raise ValueError(f"{keys[2]} must lie in (0, {length:g}] m ({keys[1]}), "
                         f"got {spacing!r}")
    n = max(1, round(length / spacing))
    return start + spacing * (np.arange(n) + 0.5)


def cell_corners(start: float, length: float, spacing: float, axis: str = "x") -> np.ndarray:
    """The cell corners [m] of one axis of a case's grid, ``start`` + spacing k for
    k <= n, the n cells of :func:`cell_centres` (same keys, same checks): where the flow
    over terrain takes the bed's elevation."""
    n = cell_centres(start, length, spacing, axis).size
    return start + spacing * np.arange(n + 1)


def _fractional(coords: np.ndarray, first_centre: float, cellsize: float,
                cells: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For ``coords`` [m] along a raster axis whose centres are ``first_centre`` +
    cellsize k (k < cells): the lower neighbour k0 (so k0 + 1 < cells), the weight t of
    the upper one in [0, 1], and whether the point lies on the centres' span."""
    f = (coords - first_centre) / cellsize
    inside = (f >= -EDGE_TOLERANCE) & (f <= cells - 1 + EDGE_TOLERANCE)
    f = np.clip(f, 0.0, cells - 1.0)
    k0 = np.minimum(np.floor(f).astype(int), cells - 2)
    return k0, f - k0, inside


def bed_on_grid(raster: Raster, x: np.ndarray, y: np.ndarray,
                name: str = "dem", points: str = "cell centres") -> np.ndarray:
    """The bed z_b [m] at the cell centres ``x`` (nx,) x ``y`` (ny,) [m, the raster's
    map coordinates], shape (nx, ny) as pdeflow's 2D fields: bilinear between the
    raster's cell centres (module docstring). Any other points of a tensor grid are
    sampled alike, e.g. the cell corners (nx + 1,) x (ny + 1,) (``points`` names them
    in the error).

    ValueError (one line, naming ``name`` and the uncovered extent) before any
    interpolation when a point lies outside the span of the raster's cell centres or
    next to a no-data cell it would use.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    for axis, c in (("x", x), ("y", y)):
        if c.ndim != 1 or c.size == 0 or not np.all(np.isfinite(c)):
            raise ValueError(f"{axis}: the cell centres must be a non-empty 1D array of "
                             f"finite numbers [m], got shape {c.shape}")
    if raster.nrows < 2 or raster.ncols < 2:
        raise ValueError(f"{name}: a raster of {raster.nrows} x {raster.ncols} cells has "
                         "no cell between its centres: bilinear resampling needs at "
                         "least 2 x 2 cells")
    south_up = raster.values[::-1]  # row 0 the southernmost: y ascending
    nodata = raster.nodata[::-1]
    j0, tx, in_x = _fractional(x, raster.x_centres[0], raster.cellsize, raster.ncols)
    i0, ty, in_y = _fractional(y, raster.y_centres[-1], raster.cellsize, raster.nrows)
    J, I = np.meshgrid(j0, i0, indexing="ij")  # noqa: N806  (nx, ny) index arrays
    TX, TY = np.meshgrid(tx, ty, indexing="ij")  # noqa: N806
    corners = ((I, J, (1 - TX) * (1 - TY)), (I, J + 1, TX * (1 - TY)),
               (I + 1, J, (1 - TX) * TY), (I + 1, J + 1, TX * TY))
    covered = np.logical_and.outer(in_x, in_y)
    for i, j, w in corners:
        covered &= ~(nodata[i, j] & (w > 0))
    if not covered.all():
        _refuse(raster, x, y, covered, name, points)
    z = np.zeros(covered.shape)
    for i, j, w in corners:
        z += w * np.where(nodata[i, j], 0.0, south_up[i, j])
    return z


def _refuse(raster: Raster, x: np.ndarray, y: np.ndarray, covered: np.ndarray,
            name: str, points: str) -> None:
    """Raise the one-line error of :func:`bed_on_grid` with the uncovered extent."""
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806
    bad = ~covered
    xc, yc = raster.x_centres, raster.y_centres
    raise ValueError(
        f"{name}: the raster does not cover the grid: {int(bad.sum())} of {bad.size} "
        f"{points}, in x [{X[bad].min():g}, {X[bad].max():g}] m x y [{Y[bad].min():g}, "
        f"{Y[bad].max():g}] m, lie outside its cell centres' span (x [{xc[0]:g}, "
        f"{xc[-1]:g}] m x y [{yc[-1]:g}, {yc[0]:g}] m) or next to its no-data cells: "
        "move or shrink the grid (x_start, y_start, length, width) or fill the raster")


def filled_nearest(raster: Raster) -> tuple[Raster, np.ndarray]:
    """``raster`` with each no-data cell given the value of the nearest cell with data
    (Euclidean, ties by scipy's order), and the mask of the cells so filled: a DEM
    clipped to the outline of a path becomes a rectangle a grid can cover. The fill is
    a flat-ish continuation of the edge, not terrain: a flow that reaches it has left
    the DEM (the caller reports the mass there)."""
    from scipy.ndimage import distance_transform_edt

    if raster.nodata.all():
        raise ValueError("the raster has no cell with data to fill from")
    index = distance_transform_edt(raster.nodata, return_distances=False,
                                   return_indices=True)
    values = raster.values[tuple(index)]
    return (Raster(values, raster.x_corner, raster.y_corner, raster.cellsize,
                   np.zeros(values.shape, bool), raster.crs, raster.nodata_value),
            raster.nodata.copy())
