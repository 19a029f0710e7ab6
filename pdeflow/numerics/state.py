"""Pointwise helpers on the conserved state (depth h [m], momentum hu [m^2/s])."""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def velocity(h: float, m: float, dry: float) -> float:
    """Depth-averaged velocity m/h [m/s]; zero where the layer is thinner than ``dry``."""
    if h > dry:
        return m / h
    return 0.0
