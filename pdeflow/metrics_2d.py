"""Scalar measures of a state on a 2D grid (issue 36): plain numpy functions.

A 2D state has three rows per layer, (depth [m], discharge along x [m^2/s], discharge
along y [m^2/s]), each of the grid's shape (cells along x, cells along y); x runs down
the slope (axis 0), y across (axis 1). The 1D measures are in :mod:`pdeflow.metrics`;
the 2D ones follow them: a front is the downstream face of the last cell deeper than a
threshold, a mass is a depth weighted by the layers' relative densities.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .metrics import RUNOUT_MASS_FRACTION

ROWS_PER_LAYER = 3
"""depth, discharge along x, discharge along y"""


def layer_depths(data: np.ndarray) -> np.ndarray:
    """The layers' depths [m], shape (layers, nx, ny), of a 2D state array."""
    return data[::ROWS_PER_LAYER]


def total_depth(data: np.ndarray) -> np.ndarray:
    """Total depth [m] per cell (negative round-off counts as 0)."""
    return np.maximum(layer_depths(data), 0.0).sum(axis=0)


def weighted_depth(data: np.ndarray, densities: Sequence[float]) -> np.ndarray:
    """sum_k rho_k/rho_max h_k per cell [m]: the mass per unit bed area over the densest
    layer's density (``densities``: the layers' relative densities)."""
    depths = layer_depths(data)
    return sum(w * depths[k] for k, w in enumerate(densities))


def mass(data: np.ndarray, densities: Sequence[float], cell_area: float) -> float:
    """Mass over the densest layer's density [m^3]: sum of :func:`weighted_depth` times
    the cells' area ``cell_area`` = dx dy [m^2]."""
    return float(np.sum(weighted_depth(data, densities)) * cell_area)


def max_speed(data: np.ndarray, dry: float) -> float:
    """The largest speed |(u, v)| [m/s] of any layer in any cell deeper than ``dry``
    [m] (0 if every cell is dry)."""
    out = 0.0
    for k in range(0, data.shape[0], ROWS_PER_LAYER):
        h = data[k]
        wet = h > dry
        if np.any(wet):
            speed = np.hypot(data[k + 1][wet], data[k + 2][wet]) / h[wet]
            out = max(out, float(speed.max()))
    return out


PEAK_FIELDS = ("depth", "speed", "pressure")
"""the rows of :func:`peak_fields`: depth [m], speed [m/s], pressure [kPa]"""


def peak_fields(data: np.ndarray, dry: float, density: float) -> np.ndarray:
    """Per cell, (total depth [m], largest speed of a layer deeper than ``dry`` [m]
    [m/s], density [kg/m^3] times that speed squared [kPa]), shape (3, nx, ny): the
    fields whose peaks over a run a hazard map shows (AvaFrame's pft, pfv, ppr)."""
    out = np.zeros((3, *data.shape[1:]))
    for k in range(0, data.shape[0], ROWS_PER_LAYER):
        h = data[k]
        out[0] += np.maximum(h, 0.0)
        wet = h > dry
        speed = np.zeros_like(h)
        speed[wet] = np.hypot(data[k + 1][wet], data[k + 2][wet]) / h[wet]
        np.maximum(out[1], speed, out=out[1])
    out[2] = density * out[1] ** 2 / 1000.0
    return out


def front_x(x: np.ndarray, depth: np.ndarray, threshold: float,
            dx: float) -> float | None:
    """The largest x [m] reached: the downstream face of the last column of cells
    (along x, ``x`` their centres [m]) where some cell is deeper than ``threshold``
    [m] (``depth`` of shape (nx, ny)); None if no cell is."""
    wet = np.nonzero(np.any(depth > threshold, axis=1))[0]
    return None if wet.size == 0 else float(x[wet[-1]] + 0.5 * dx)


def lateral_spread(y: np.ndarray, depth: np.ndarray, threshold: float,
                   dy: float) -> float | None:
    """The extent across [m]: from the low face of the first to the high face of the
    last row of cells along y (``y`` their centres [m]) with a cell deeper than
    ``threshold`` [m]; None if no cell is."""
    wet = np.nonzero(np.any(depth > threshold, axis=0))[0]
    return None if wet.size == 0 else float(y[wet[-1]] - y[wet[0]] + dy)


def deposit_area(depth: np.ndarray, threshold: float, cell_area: float) -> float:
    """The area [m^2] covered deeper than ``threshold`` [m]: the number of such cells
    times ``cell_area`` = dx dy [m^2]."""
    return float(np.count_nonzero(depth > threshold) * cell_area)


def mass_radius(r: np.ndarray, cell_mass: np.ndarray,
                fraction: float = RUNOUT_MASS_FRACTION) -> float | None:
    """The radius [m] about a centre inside which ``fraction`` of the mass lies: the
    cell-centre distance ``r`` [m] of the cell at which the mass summed in order of r
    (``cell_mass``, any unit, negative round-off counts as 0) first reaches that
    fraction (with 0.99: the r99 of radial spreads). None if there is no mass. Cell
    centres, not faces: on a Cartesian grid the cells at one radius do not form a
    ring, so this converges at first order with the grid (tests/test_two_d_cylinder.py)."""
    r, cell_mass = np.ravel(r), np.maximum(np.ravel(cell_mass), 0.0)
    order = np.argsort(r, kind="stable")
    cumulative = np.cumsum(cell_mass[order])
    if cumulative.size == 0 or not cumulative[-1] > 0.0:
        return None
    i = int(np.searchsorted(cumulative, fraction * cumulative[-1]))
    return float(r[order][min(i, r.size - 1)])
