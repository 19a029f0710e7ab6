r"""Finite-volume advection rates (stage (29)) on a uniform 1D grid.

The rate of cell i is -(D^+_{i-1/2} + D^-_{i+1/2}) / dx with the fluctuations of
:mod:`pdeflow.numerics.hll`. Boundaries use one ghost cell: a wall mirrors the state
(h -> h, hu -> -hu), an open (transmissive) boundary copies it.

Only faces next to a wet cell are visited: a face between two cells that are dry in
every layer carries no fluctuation, so the loops run over the wet region plus one cell
of stencil (most of the domain is dry for most of a collapse). The returned wave speed
is the largest over the visited faces, which is what the CFL condition needs.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .hll import hll_single, hll_two_layer
from .layout import BC_WALL


@njit(cache=True)
def wet_range(h_total: np.ndarray, dry: float) -> tuple[int, int]:
    """First and last index of cells with ``h_total > dry`` (``(1, 0)`` if none)."""
    n = h_total.shape[0]
    lo = 0
    while lo < n and h_total[lo] <= dry:
        lo += 1
    if lo == n:
        return 1, 0
    hi = n - 1
    while h_total[hi] <= dry:
        hi -= 1
    return lo, hi


@njit(cache=True)
def _ghost(value: float, is_momentum: bool, bc: int) -> float:
    if bc == BC_WALL and is_momentum:
        return -value
    return value


@njit(cache=True)
def rate_single(q: np.ndarray, rate: np.ndarray, dx: float, bc_left: int,
                bc_right: int, g: float, dry: float) -> float:
    """Advection rate of the single-layer state ``q[(h, hu), cell]`` into ``rate``.

    Returns the largest wave speed [m/s] over the faces that were visited.
    """
    n = q.shape[1]
    rate[:, :] = 0.0
    lo, hi = wet_range(q[0], dry)
    if lo > hi:
        return 0.0
    f_lo = max(lo, 1)  # faces f = i - 1/2 with i in [f_lo, f_hi] are interior
    f_hi = min(hi + 1, n - 1)
    inv_dx = 1.0 / dx
    smax = 0.0
    for i in range(f_lo, f_hi + 1):
        dm0, dm1, dp0, dp1, s = hll_single(q[0, i - 1], q[1, i - 1], q[0, i], q[1, i],
                                           g, dry)
        smax = max(smax, s)
        rate[0, i - 1] -= dm0 * inv_dx
        rate[1, i - 1] -= dm1 * inv_dx
        rate[0, i] -= dp0 * inv_dx
        rate[1, i] -= dp1 * inv_dx
    if lo == 0:
        dm0, dm1, dp0, dp1, s = hll_single(
            q[0, 0], _ghost(q[1, 0], True, bc_left), q[0, 0], q[1, 0], g, dry)
        smax = max(smax, s)
        rate[0, 0] -= dp0 * inv_dx
        rate[1, 0] -= dp1 * inv_dx
    if hi == n - 1:
        dm0, dm1, dp0, dp1, s = hll_single(
            q[0, n - 1], q[1, n - 1], q[0, n - 1], _ghost(q[1, n - 1], True, bc_right),
            g, dry)
        smax = max(smax, s)
        rate[0, n - 1] -= dm0 * inv_dx
        rate[1, n - 1] -= dm1 * inv_dx
    return smax


@njit(cache=True)
def rate_two_layer(q: np.ndarray, rate: np.ndarray, dx: float, bc_left: int,
                   bc_right: int, g: float, r: float, dry: float) -> float:
    """Advection rate of the two-layer state ``q[(h1, h1u1, h2, h2u2), cell]``.

    Returns the largest wave speed [m/s] over the faces that were visited.
    """
    n = q.shape[1]
    rate[:, :] = 0.0
    lo1, hi1 = wet_range(q[0], dry)
    lo2, hi2 = wet_range(q[2], dry)
    lo = min(lo1, lo2) if lo1 <= hi1 and lo2 <= hi2 else (lo1 if lo1 <= hi1 else lo2)
    hi = max(hi1, hi2) if lo1 <= hi1 and lo2 <= hi2 else (hi1 if lo1 <= hi1 else hi2)
    if lo > hi:
        return 0.0
    f_lo = max(lo, 1)
    f_hi = min(hi + 1, n - 1)
    inv_dx = 1.0 / dx
    smax = 0.0
    for i in range(f_lo, f_hi + 1):
        j = i - 1
        dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, s = hll_two_layer(
            q[0, j], q[1, j], q[2, j], q[3, j], q[0, i], q[1, i], q[2, i], q[3, i],
            g, r, dry)
        smax = max(smax, s)
        rate[0, j] -= dm0 * inv_dx
        rate[1, j] -= dm1 * inv_dx
        rate[2, j] -= dm2 * inv_dx
        rate[3, j] -= dm3 * inv_dx
        rate[0, i] -= dp0 * inv_dx
        rate[1, i] -= dp1 * inv_dx
        rate[2, i] -= dp2 * inv_dx
        rate[3, i] -= dp3 * inv_dx
    if lo == 0:
        dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, s = hll_two_layer(
            q[0, 0], _ghost(q[1, 0], True, bc_left), q[2, 0],
            _ghost(q[3, 0], True, bc_left), q[0, 0], q[1, 0], q[2, 0], q[3, 0],
            g, r, dry)
        smax = max(smax, s)
        rate[0, 0] -= dp0 * inv_dx
        rate[1, 0] -= dp1 * inv_dx
        rate[2, 0] -= dp2 * inv_dx
        rate[3, 0] -= dp3 * inv_dx
    if hi == n - 1:
        k = n - 1
        dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, s = hll_two_layer(
            q[0, k], q[1, k], q[2, k], q[3, k], q[0, k],
            _ghost(q[1, k], True, bc_right), q[2, k], _ghost(q[3, k], True, bc_right),
            g, r, dry)
        smax = max(smax, s)
        rate[0, k] -= dm0 * inv_dx
        rate[1, k] -= dm1 * inv_dx
        rate[2, k] -= dm2 * inv_dx
        rate[3, k] -= dm3 * inv_dx
    return smax
