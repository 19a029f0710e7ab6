"""Scalar measures of a state: front position, run-out, mass, volumes."""

from __future__ import annotations

import numpy as np


def total_depth(data: np.ndarray) -> np.ndarray:
    """Total depth [m] of a state array (sum of the depth rows 0, 2, ...)."""
    return np.maximum(data[::2], 0.0).sum(axis=0)


def front_position(x: np.ndarray, data: np.ndarray, threshold: float = 1e-3,
                   dx: float | None = None) -> float | None:
    """Last x [m] whose total depth exceeds ``threshold`` [m]: the downstream face of
    that cell if ``dx`` is given, else its centre. None if no cell is that deep."""
    wet = np.nonzero(total_depth(data) > threshold)[0]
    if wet.size == 0:
        return None
    i = wet[-1]
    return float(x[i] + (0.5 * dx if dx else 0.0))


def mass(data: np.ndarray, dx: float, density_ratio: float | None = None) -> float:
    """Mass per unit width divided by the lower density rho2 [m^2]:
    sum (r h1 + h2) dx for two layers, sum h dx for one."""
    if density_ratio is None:
        return float(np.sum(data[0]) * dx)
    return float(np.sum(density_ratio * data[0] + data[2]) * dx)
