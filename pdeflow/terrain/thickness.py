"""The release thickness, measured vertically.

pdeflow's terrain inputs return the release depth measured *vertically* (the depth the
single-layer model over a bed carries). The user gives the thickness either way
(``measured``): "slope_normal" (the default, AvaFrame's convention for its release
thickness: normal to the local slope) is converted by h_vertical = h_normal /
cos(theta), tan(theta) = |grad z_b| the bed's steepest slope; "vertical" is taken as it
is (:func:`vertical_depth`). The slope comes from the bed at the cell centres
(:func:`cos_slope`: central differences, one-sided at the grid's edges) or at the cell
corners (:func:`cos_slope_corners`: the differences of the means of each cell's corners
on opposite faces, what a case over a ``[terrain]`` bed uses); both are exact on a
plane.
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
    return vertical_depth(np.where(mask, float(thickness), 0.0), cos_slope(bed, dx, dy),
                          measured)


def vertical_depth(h: np.ndarray, cos_theta: np.ndarray,
                   measured: str = "slope_normal") -> np.ndarray:
    """The depth [m] measured vertically of the release depth ``h`` [m] (any shape)
    ``measured`` "slope_normal" (divided by ``cos_theta``, the cosine of the bed's
    steepest slope at the same points) or "vertical" (taken as it is)."""
    if measured not in MEASURED:
        raise ValueError(f"measured must be one of {list(MEASURED)}, got {measured!r}")
    h = np.asarray(h, dtype=float)
    return h.copy() if measured == "vertical" else h / cos_theta


def _cos_of(dz_dx: np.ndarray, dz_dy: np.ndarray) -> np.ndarray:
    """cos(theta) = 1 / sqrt(1 + |grad z_b|^2) of the bed's gradient (dz_dx, dz_dy)."""
    return 1.0 / np.sqrt(1.0 + dz_dx**2 + dz_dy**2)


def cos_slope(bed: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """cos(theta) of the bed's steepest slope at each cell, 1 / sqrt(1 + |grad z_b|^2),
    from the gradient of ``bed`` (nx, ny) [m] on cells ``dx`` x ``dy`` [m] (central
    differences inside, one-sided at the edges: exact on a plane)."""
    return _cos_of(*np.gradient(bed, dx, dy))


def cos_slope_corners(corners: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """cos(theta) of the bed's steepest slope at the cell centres (nx, ny), from the
    bed at the cell corners ``corners`` (nx + 1, ny + 1) [m] on cells ``dx`` x ``dy``
    [m]: each cell's gradient is the difference of the means of its two corners on
    opposite faces over the cell's width (the bed a flow over terrain sees: exact on a
    plane, and no corner outside the cell is used, so the edge cells need no one-sided
    rule)."""
    z = np.asarray(corners, dtype=float)
    if z.ndim != 2 or min(z.shape) < 2:
        raise ValueError(f"corners must be an array (nx + 1, ny + 1) of at least 2 x 2 "
                         f"points, got {z.shape}")
    faces_x = 0.5 * (z[:, :-1] + z[:, 1:])  # (nx + 1, ny): the faces across x
    faces_y = 0.5 * (z[:-1, :] + z[1:, :])  # (nx, ny + 1): the faces across y
    return _cos_of(np.diff(faces_x, axis=0) / dx, np.diff(faces_y, axis=1) / dy)
