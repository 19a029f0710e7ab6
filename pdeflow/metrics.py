"""Scalar measures of a state: front position, run-out, mass, volumes."""

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


def mass(data: np.ndarray, cells: float | np.ndarray,
         densities: Sequence[float] | None = None) -> float:
    """Mass divided by the densest layer's density: sum_i sum_k rho_k/rho_max h_k V_i
    over the cells i and layers k, ``densities`` the relative densities of the layers
    (the system's ``densities``; None: all 1), e.g. sum (r h1 + h2) dx for two layers,
    sum h dx for one. ``cells``: dx [m] of uniform planar cells (the mass per unit
    width [m^2]), or the cells' volumes V_i (a Metric's ``volumes``; [m^3])."""
    weights = densities if densities is not None else [1.0] * (data.shape[0] // 2)
    total = weights[0] * data[0]
    for k in range(1, len(weights)):
        total = total + weights[k] * data[2 * k]
    if np.ndim(cells) == 0:
        return float(np.sum(total) * cells)
    return float(np.sum(total * cells))
