"""Scalar measures of a state: front position, run-out, mass, volumes.

Two measures of how far the material went: :func:`front_position`, the last cell deeper
than a threshold (what an eye or a laser sheet sees, but it follows the thin tail of the
last per mille of the mass, so it moves with the grid), and
:func:`mass_quantile_position`, the distance from the domain's start (the release's
rear wall, or the axis) within which a fraction (``output.runout_mass_fraction``,
default :data:`RUNOUT_MASS_FRACTION`) of the mass lies, which converges with the grid and
agrees between codes.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def total_depth(data: np.ndarray) -> np.ndarray:
    """Total depth [m] of a state array (sum of the depth rows 0, 2, ...)."""
    return np.maximum(data[::2], 0.0).sum(axis=0)


def front_position(x: np.ndarray, data: np.ndarray, threshold: float = 1e-3,
                   dx: float | None = None, bed: np.ndarray | None = None) -> float | None:
    """Last x [m] whose total depth exceeds ``threshold`` [m] (above the initial
    erodible ``bed`` [m] if given, so that the front is that of the material on the bed,
    as experiments measure it): the downstream face of that cell if ``dx`` is given,
    else its centre. None if no cell is that deep."""
    depth = total_depth(data) if bed is None else total_depth(data) - bed
    wet = np.nonzero(depth > threshold)[0]
    if wet.size == 0:
        return None
    i = wet[-1]
    return float(x[i] + (0.5 * dx if dx else 0.0))


RUNOUT_MASS_FRACTION = 0.99
"""the fraction of the mass within the mass-quantile front by default
(:func:`mass_quantile_position`, ``output.runout_mass_fraction``): 99 % as in the
deposit measures of granular-collapse experiments and codes that report a radius or
length holding nearly all of the mass"""


def weighted_depth(data: np.ndarray, densities: Sequence[float] | None = None) -> np.ndarray:
    """sum_k rho_k/rho_max h_k per cell [m]: the mass per unit bed area over the densest
    layer's density, ``densities`` the layers' relative densities (None: all 1)."""
    weights = densities if densities is not None else [1.0] * (data.shape[0] // 2)
    total = weights[0] * data[0]
    for k in range(1, len(weights)):
        total = total + weights[k] * data[2 * k]
    return total


def mass_quantile_position(faces: np.ndarray, volumes: np.ndarray, depth: np.ndarray,
                           fraction: float = RUNOUT_MASS_FRACTION,
                           radial: bool = False) -> float | None:
    """The position s [m] such that the cells' material between ``faces[0]`` and s holds
    ``fraction`` (0 < fraction < 1) of the total mass: s - faces[0] is the distance
    from the release's rear wall (planar) or the radius (``radial``, faces[0] = 0 the
    axis) that holds that fraction of the deposit.

    ``depth`` [m] per cell is the mass per unit bed area over a density (e.g.
    :func:`weighted_depth`; negative round-off counts as 0), ``faces`` the n + 1 face
    positions [m], ``volumes`` the n cell volumes (dx per unit width, or
    pi (r+^2 - r-^2) [m^2] on a radial grid). The depth is constant within a cell (a
    finite volume), so within the cell where the cumulative mass crosses the fraction
    the position is exact: linear in x on a planar grid, in r^2 on a radial one.
    None if there is no mass."""
    if not 0.0 < fraction < 1.0:
        raise ValueError(f"fraction must lie in (0, 1), got {fraction!r}")
    cell_mass = np.maximum(depth, 0.0) * volumes
    cumulative = np.cumsum(cell_mass)
    total = cumulative[-1] if cumulative.size else 0.0
    if not total > 0.0:
        return None
    target = fraction * total
    # the first cell whose cumulative mass reaches the target (it has mass > 0)
    i = int(np.searchsorted(cumulative, target, side="left"))
    i = min(i, cumulative.size - 1)
    before = cumulative[i - 1] if i > 0 else 0.0
    t = min(max((target - before) / cell_mass[i], 0.0), 1.0)
    lo, hi = float(faces[i]), float(faces[i + 1])
    if radial:
        return float(np.sqrt(lo * lo + t * (hi * hi - lo * lo)))
    return lo + t * (hi - lo)


def mass(data: np.ndarray, cells: float | np.ndarray,
         densities: Sequence[float] | None = None) -> float:
    """Mass divided by the densest layer's density: sum_i sum_k rho_k/rho_max h_k V_i
    over the cells i and layers k, ``densities`` the relative densities of the layers
    (the system's ``densities``; None: all 1), e.g. sum (r h1 + h2) dx for two layers,
    sum h dx for one. ``cells``: dx [m] of uniform planar cells (the mass per unit
    width [m^2]), or the cells' volumes V_i (a Metric's ``volumes``; [m^3])."""
    total = weighted_depth(data, densities)
    if np.ndim(cells) == 0:
        return float(np.sum(total) * cells)
    return float(np.sum(total * cells))
