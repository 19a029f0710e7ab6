"""Pointwise helpers on the conserved state (depth h [m], momentum hu [m^2/s]).

:func:`velocity` is the kernels' (numba, one cell); :func:`velocity_profile` is the same
rule on whole arrays, for everything outside the kernels (stored runs, trackers, plots,
final states). Both call a layer dry where it is not thicker than the model's dry
tolerance (the parameter ``dry_tolerance``, default :data:`DRY_TOLERANCE`). The source
stage of every step sets the momentum of such cells to zero, so on any state the solver
wrote, a threshold at or below the model's dry tolerance gives the same velocities.
"""

from __future__ import annotations

import numpy as np

from .compiled import cached

DRY_TOLERANCE = 1e-6
"""Default dry tolerance of the models [m]: a layer not thicker than this has zero
velocity (the parameter ``dry_tolerance`` of both models)."""


@cached
def velocity(h: float, m: float, dry: float) -> float:
    """Depth-averaged velocity m/h [m/s]; zero where the layer is thinner than ``dry``."""
    if h > dry:
        return m / h
    return 0.0


def velocity_profile(h: np.ndarray, m: np.ndarray, dry: float = DRY_TOLERANCE,
                     fill: float = 0.0) -> np.ndarray:
    """Depth-averaged velocity hu/h [m/s] of a layer, cell by cell (numpy).

    Args:
        h: depths [m] (any shape, or a number).
        m: momenta hu [m^2/s], the shape of ``h``.
        dry: the model's dry tolerance [m]: where h <= dry the layer is dry.
        fill: the value in dry cells: 0 (as the kernels), or NaN for a gap in a plot.
    """
    h = np.asarray(h, dtype=float)
    wet = h > dry
    return np.where(wet, np.asarray(m, dtype=float) / np.where(wet, h, 1.0), fill)
