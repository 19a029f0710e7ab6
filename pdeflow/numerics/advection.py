r"""Finite-volume advection rates (stage (29)) on a uniform 1D grid.

First order: the rate of cell i is -(D^+_{i-1/2} + D^-_{i+1/2}) / dx with the face
fluctuations of :mod:`pdeflow.numerics.pvm` between the cell averages.

Second order (MUSCL): depths and velocities of each layer are reconstructed linearly in
every cell with a limited slope (minmod or monotonised-central), giving face values
q_i^- (left face) and q_i^+ (right face); the rate is

.. math:: -\frac{1}{\Delta x}\bigl(D^+_{i-1/2} + D^-_{i+1/2} + \mathcal{A}(q_i^-, q_i^+)\bigr),

where the fluctuations now act between q_{i-1}^+ and q_i^-, and the cell term
A(q_i^-, q_i^+) = f(q_i^+) - f(q_i^-) + B(q_i^-, q_i^+) is the path-conservative total jump
across the reconstruction inside the cell (Castro & Pares). Limited slopes of h keep the
face depths between neighbouring averages, hence non-negative.

Boundaries use one ghost cell: a wall mirrors the state (h -> h, hu -> -hu), an open
(transmissive) boundary copies it. Only faces next to a wet cell are visited: a face
between two cells that are dry in every layer carries no fluctuation, so the loops run
over the wet region plus the stencil (most of the domain is dry for most of a collapse).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import layout as L
from .pvm import fluct_single, fluct_two_layer
from .state import velocity


@njit(cache=True, inline="always")
def _is_wet(q: np.ndarray, i: int, dry: float) -> bool:
    for k in range(0, q.shape[0], 2):
        if q[k, i] > dry:
            return True
    return False


@njit(cache=True)
def wet_cells(q: np.ndarray, dry: float, start: int, stop: int) -> tuple[int, int]:
    """First and last index in ``start..stop`` of a cell where some layer's depth
    (rows 0, 2, ... of ``q``) exceeds ``dry``; ``(1, 0)`` if there is none."""
    lo = start
    while lo <= stop and not _is_wet(q, lo, dry):
        lo += 1
    if lo > stop:
        return 1, 0
    hi = stop
    while hi > lo and not _is_wet(q, hi, dry):
        hi -= 1
    return lo, hi


@njit(cache=True, inline="always")
def _limited(a: float, b: float, limiter: int) -> float:
    if a * b <= 0.0:
        return 0.0
    s = 1.0 if a > 0.0 else -1.0
    a = abs(a)
    b = abs(b)
    if limiter == L.LIMITER_MC:
        return s * min(2.0 * a, 2.0 * b, 0.5 * (a + b))
    return s * min(a, b)


@njit(cache=True)
def reconstruct(q: np.ndarray, work: np.ndarray, lo: int, hi: int, bc_left: int,
                bc_right: int, dry: float, order: int, limiter: int) -> None:
    """Face values of cells lo..hi into work[0] (left face) and work[1] (right face).

    Order 1 copies the averages; order 2 reconstructs (h, u) of each layer linearly
    with limited slopes (ghost neighbours from the boundary conditions).
    """
    n = q.shape[1]
    nf = q.shape[0]
    for i in range(lo, hi + 1):
        for k in range(0, nf, 2):
            h = q[k, i]
            m = q[k + 1, i]
            if order == 1:
                work[0, k, i] = h
                work[0, k + 1, i] = m
                work[1, k, i] = h
                work[1, k + 1, i] = m
                continue
            u = velocity(h, m, dry)
            if i > 0:
                hl = q[k, i - 1]
                ul = velocity(hl, q[k + 1, i - 1], dry)
            else:
                hl = h
                ul = -u if bc_left == L.BC_WALL else u
            if i < n - 1:
                hr = q[k, i + 1]
                ur = velocity(hr, q[k + 1, i + 1], dry)
            else:
                hr = h
                ur = -u if bc_right == L.BC_WALL else u
            if hl <= dry or hr <= dry:
                # next to a dry cell (a front or a heap's edge): first order, so that the
                # face depth weighting the hydrostatic jump is the cell's own depth
                sh = 0.0
                su = 0.0
            elif m == 0.0 and q[k + 1, max(i - 1, 0)] == 0.0 and \
                    q[k + 1, min(i + 1, n - 1)] == 0.0:
                # at rest with its neighbours: first order as well. A limited slope of h
                # can make the hydrostatic force at a kink of a heap steeper than any
                # slope of the data, so that friction no longer holds a heap the
                # first-order scheme keeps exactly at rest; nothing moves here to gain
                # accuracy on
                sh = 0.0
                su = 0.0
            else:
                sh = _limited(h - hl, hr - h, limiter)
                su = _limited(u - ul, ur - u, limiter)
            hm = h - 0.5 * sh
            hp = h + 0.5 * sh
            work[0, k, i] = hm
            work[1, k, i] = hp
            work[0, k + 1, i] = hm * (u - 0.5 * su) if hm > dry else 0.0
            work[1, k + 1, i] = hp * (u + 0.5 * su) if hp > dry else 0.0


@njit(cache=True, inline="always")
def _ghost(value: float, is_momentum: bool, bc: int) -> float:
    if bc == L.BC_WALL and is_momentum:
        return -value
    return value


@njit(cache=True)
def rate_single(q: np.ndarray, rate: np.ndarray, work: np.ndarray, dx: float,
                bc_left: int, bc_right: int, g: float, dry: float, flux: int,
                order: int, limiter: int) -> float:
    """Advection rate of the single-layer state ``q[(h, hu), cell]`` into ``rate``.

    ``work`` is scratch space of shape (2, 2, n). Returns the largest wave speed [m/s]
    over the faces that were visited.
    """
    rate[:, :] = 0.0
    lo, hi = wet_cells(q, dry, 0, q.shape[1] - 1)
    return advect_single(q, rate, work, dx, bc_left, bc_right, g, dry, flux, order,
                         limiter, lo, hi)[0]


@njit(cache=True)
def advect_single(q: np.ndarray, rate: np.ndarray, work: np.ndarray, dx: float,
                  bc_left: int, bc_right: int, g: float, dry: float, flux: int,
                  order: int, limiter: int, lo: int, hi: int) -> tuple[float, int, int]:
    """:func:`rate_single` for the wet cells ``lo..hi`` (from :func:`wet_cells`).

    Writes ``rate`` only in the cells it can change, ``lo - 1 .. hi + 1`` (clipped to
    the grid), and returns (largest wave speed [m/s], first, last of those cells);
    the rest of ``rate`` is left as it was (the stepper never reads it).
    """
    n = q.shape[1]
    if lo > hi:
        return 0.0, 1, 0
    r_lo = max(lo - 1, 0)
    r_hi = min(hi + 1, n - 1)
    rate[:, r_lo:r_hi + 1] = 0.0
    reconstruct(q, work, r_lo, r_hi, bc_left, bc_right, dry, order, limiter)
    qm = work[0]
    qp = work[1]
    inv_dx = 1.0 / dx
    smax = 0.0
    for i in range(max(lo, 1), min(hi + 1, n - 1) + 1):
        dm0, dm1, dp0, dp1, s = fluct_single(flux, qp[0, i - 1], qp[1, i - 1],
                                             qm[0, i], qm[1, i], g, dry)
        smax = max(smax, s)
        rate[0, i - 1] -= dm0 * inv_dx
        rate[1, i - 1] -= dm1 * inv_dx
        rate[0, i] -= dp0 * inv_dx
        rate[1, i] -= dp1 * inv_dx
    if lo == 0:
        dm0, dm1, dp0, dp1, s = fluct_single(
            flux, qm[0, 0], _ghost(qm[1, 0], True, bc_left), qm[0, 0], qm[1, 0], g, dry)
        smax = max(smax, s)
        rate[0, 0] -= dp0 * inv_dx
        rate[1, 0] -= dp1 * inv_dx
    if hi == n - 1:
        k = n - 1
        dm0, dm1, dp0, dp1, s = fluct_single(
            flux, qp[0, k], qp[1, k], qp[0, k], _ghost(qp[1, k], True, bc_right), g, dry)
        smax = max(smax, s)
        rate[0, k] -= dm0 * inv_dx
        rate[1, k] -= dm1 * inv_dx
    if order > 1:
        for i in range(r_lo, r_hi + 1):
            hl, hr = qm[0, i], qp[0, i]
            ul = velocity(hl, qm[1, i], dry)
            ur = velocity(hr, qp[1, i], dry)
            rate[0, i] -= (ur * hr - ul * hl) * inv_dx
            rate[1, i] -= (ur * ur * hr + 0.5 * g * hr * hr
                           - ul * ul * hl - 0.5 * g * hl * hl) * inv_dx
    return smax, r_lo, r_hi


@njit(cache=True)
def rate_two_layer(q: np.ndarray, rate: np.ndarray, work: np.ndarray, dx: float,
                   bc_left: int, bc_right: int, g: float, r: float, dry: float,
                   flux: int, order: int, limiter: int) -> float:
    """Advection rate of the two-layer state ``q[(h1, h1u1, h2, h2u2), cell]``.

    ``work`` is scratch space of shape (2, 4, n). Returns the largest wave speed [m/s]
    over the faces that were visited.
    """
    rate[:, :] = 0.0
    lo, hi = wet_cells(q, dry, 0, q.shape[1] - 1)
    return advect_two_layer(q, rate, work, dx, bc_left, bc_right, g, r, dry, flux,
                            order, limiter, lo, hi)[0]


@njit(cache=True)
def advect_two_layer(q: np.ndarray, rate: np.ndarray, work: np.ndarray, dx: float,
                     bc_left: int, bc_right: int, g: float, r: float, dry: float,
                     flux: int, order: int, limiter: int, lo: int,
                     hi: int) -> tuple[float, int, int]:
    """:func:`rate_two_layer` for the wet cells ``lo..hi``; as :func:`advect_single`."""
    n = q.shape[1]
    if lo > hi:
        return 0.0, 1, 0
    r_lo = max(lo - 1, 0)
    r_hi = min(hi + 1, n - 1)
    rate[:, r_lo:r_hi + 1] = 0.0
    reconstruct(q, work, r_lo, r_hi, bc_left, bc_right, dry, order, limiter)
    qm = work[0]
    qp = work[1]
    inv_dx = 1.0 / dx
    smax = 0.0
    for i in range(max(lo, 1), min(hi + 1, n - 1) + 1):
        j = i - 1
        dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, s = fluct_two_layer(
            flux, qp[0, j], qp[1, j], qp[2, j], qp[3, j], qm[0, i], qm[1, i], qm[2, i],
            qm[3, i], g, r, dry)
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
        dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, s = fluct_two_layer(
            flux, qm[0, 0], _ghost(qm[1, 0], True, bc_left), qm[2, 0],
            _ghost(qm[3, 0], True, bc_left), qm[0, 0], qm[1, 0], qm[2, 0], qm[3, 0],
            g, r, dry)
        smax = max(smax, s)
        rate[0, 0] -= dp0 * inv_dx
        rate[1, 0] -= dp1 * inv_dx
        rate[2, 0] -= dp2 * inv_dx
        rate[3, 0] -= dp3 * inv_dx
    if hi == n - 1:
        k = n - 1
        dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, s = fluct_two_layer(
            flux, qp[0, k], qp[1, k], qp[2, k], qp[3, k], qp[0, k],
            _ghost(qp[1, k], True, bc_right), qp[2, k], _ghost(qp[3, k], True, bc_right),
            g, r, dry)
        smax = max(smax, s)
        rate[0, k] -= dm0 * inv_dx
        rate[1, k] -= dm1 * inv_dx
        rate[2, k] -= dm2 * inv_dx
        rate[3, k] -= dm3 * inv_dx
    if order > 1:
        # path-conservative jump across the linear reconstruction inside each cell
        for i in range(r_lo, r_hi + 1):
            h1l, h1r = qm[0, i], qp[0, i]
            h2l, h2r = qm[2, i], qp[2, i]
            u1l = velocity(h1l, qm[1, i], dry)
            u1r = velocity(h1r, qp[1, i], dry)
            u2l = velocity(h2l, qm[3, i], dry)
            u2r = velocity(h2r, qp[3, i], dry)
            dh1 = h1r - h1l
            dh2 = h2r - h2l
            rate[0, i] -= (u1r * h1r - u1l * h1l) * inv_dx
            rate[1, i] -= ((u1r * u1r * h1r - u1l * u1l * h1l)
                           + g * 0.5 * (h1l + h1r) * (dh1 + dh2)) * inv_dx
            rate[2, i] -= (u2r * h2r - u2l * h2l) * inv_dx
            rate[3, i] -= ((u2r * u2r * h2r - u2l * u2l * h2l)
                           + g * 0.5 * (h2l + h2r) * (dh2 + r * dh1)) * inv_dx
    return smax, r_lo, r_hi
