r"""The bed's slope in the cell term of a flow over a bed z_b(x, y) (2D grids).

Over a bed the advection stage reconstructs each cell's face values with its free
surface and interfaces flat (the model's ``terrain`` reconstruction,
:attr:`~pdeflow.numerics.model_kernels.ModelKernels.terrain`), takes the faces'
fluctuations between them, and adds the cell term, the total jump across the
reconstruction inside the cell: the model's MUSCL cell jump (flux differences and the
layers' coupling) and, here, each layer's share of the bed's slope

.. math:: \mathcal{A}_k \mathrel{+}= g\, \bar h_k\, (z_b^+ - z_b^-), \qquad
          \bar h_k = (h_k^- + h_k^+)/2,

z_b^- and z_b^+ the bed at the cell's low and high faces along the axis (the metric's
rows layout.M_BED). With the MUSCL jump's g h̄_k (dh_k + ...) the pressure, coupling
and bed terms of a lake at rest cancel (Kurganov & Petrova 2007; docs/terrain.md).
"""

from __future__ import annotations

import numpy as np

from . import layout as L
from .compiled import cached


@cached
def bed_slope(qm: np.ndarray, qp: np.ndarray, rate: np.ndarray, metric: np.ndarray,
              lo: int, hi: int, inv_dx: float, g: float, width: int, normal: int,
              axis: int) -> None:
    """Subtract g h̄_k (z_b^+ - z_b^-) ``inv_dx`` from each layer's momentum normal to
    ``axis`` (row ``normal`` of a layer of ``width`` rows) in cells lo..hi, the face
    values ``qm`` (low) and ``qp`` (high) giving h̄_k [m]; ``inv_dx`` [1/m]."""
    z_lo = L.M_BED + 2 * axis
    for i in range(lo, hi + 1):
        rise = metric[z_lo + 1, i] - metric[z_lo, i]
        for k in range(0, qm.shape[0], width):
            rate[k + normal, i] -= g * 0.5 * (qm[k, i] + qp[k, i]) * rise * inv_dx


# --- what the models' reconstructions over a bed share ------------------------------------

@cached(inline="always")
def surface_half_rise(w: float, w_low: float, w_high: float) -> float:
    """Half the rise [m] of a surface across a cell whose value is ``w`` and its
    neighbours' ``w_low``, ``w_high`` along the axis: half the minmod of the one-sided
    differences (0 at an extremum)."""
    a = w - w_low
    b = w_high - w
    if a * b <= 0.0:
        return 0.0
    return 0.5 * (a if abs(a) < abs(b) else b)


@cached(inline="always")
def clamped(s: float, base: float) -> float:
    """``s`` clamped between 0 (a flat surface) and ``base`` (a surface parallel to the
    layer's base, whose half rise across the cell ``base`` is) [m]."""
    return min(max(s, min(base, 0.0)), max(base, 0.0))


@cached(inline="always")
def tilted(h: float, hm: float, hp: float) -> tuple[float, float]:
    """(low, high) face depths ``hm``, ``hp`` [m] of a layer of depth ``h``, tilted to
    (0, 2h) or (2h, 0) where one would be negative (Kurganov & Petrova's positivity)."""
    if hm < 0.0:
        return 0.0, 2.0 * h
    if hp < 0.0:
        return 2.0 * h, 0.0
    return hm, hp
