"""The release thickness, measured vertically.

pdeflow's terrain inputs return the release depth measured *vertically*. The user gives
the thickness either way (``measured``): "slope_normal" (the default, AvaFrame's
convention for its release thickness: normal to the local slope) is converted by
h_vertical = h_normal / cos(theta), with tan(theta) = |grad z_b| the bed's steepest
slope from the resampled bed's gradient (central differences, one-sided at the grid's
edges); "vertical" is taken as it is.
"""

from __future__ import annotations

import math

import numpy as np

from ..models.base import check_range

MEASURED = ("slope_normal", "vertical")
"""how a release thickness may be measured"""


def vertical_thickness(mask: np.ndarray, thickness: float, bed: np.ndarray, dx: float,
                       dy: float, measured: str = "slope_normal") -> np.ndarray:
    """The release depth [m] measured vertically on the released cells ``mask`` (nx,
    ny), 0 elsewhere, from the release ``thickness`` [m] ``measured`` "slope_normal"
    (default, as AvaFrame's release thickness: divided by cos(theta), tan(theta) = |grad
    z_b| of the ``bed`` (nx, ny) [m] on cells ``dx`` x ``dy`` [m]) or "vertical"."""
    if measured not in MEASURED:
        raise ValueError(f"measured must be one of {list(MEASURED)}, got {measured!r}")
    check_range("thickness", thickness, 0, math.inf, low_open=True, high_open=True, unit="m")
    check_range("dx", dx, 0, math.inf, low_open=True, high_open=True, unit="m")
    check_range("dy", dy, 0, math.inf, low_open=True, high_open=True, unit="m")
    bed = np.asarray(bed, dtype=float)
    if bed.shape != np.shape(mask) or bed.ndim != 2 or min(bed.shape) < 2:
        raise ValueError(f"bed must be an array (nx, ny) of at least 2 x 2 cells shaped "
                         f"as mask {np.shape(mask)}, got {bed.shape}")
    h = np.where(mask, float(thickness), 0.0)
    if measured == "vertical":
        return h
    return h / cos_slope(bed, dx, dy)


def cos_slope(bed: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """cos(theta) of the bed's steepest slope at each cell, 1 / sqrt(1 + |grad z_b|^2),
    from the gradient of ``bed`` (nx, ny) [m] on cells ``dx`` x ``dy`` [m] (central
    differences inside, one-sided at the edges: exact on a plane)."""
    dz_dx, dz_dy = np.gradient(bed, dx, dy)
    return 1.0 / np.sqrt(1.0 + dz_dx**2 + dz_dy**2)
