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
over the wet cells of the window they are given (the stepping loop narrows it further to
the cells a step can change, :mod:`pdeflow.numerics.resting`).

:func:`advection_kernel` builds this stage for one model, flux, reconstruction and
limiter (nothing of the others is compiled); :func:`rate_kernel` is the same on the
whole grid, the method-of-lines rate.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from . import layout as L
from .compiled import FIELDS, METRIC, STATE, WORK, cached, f8, i8, kernel, specialise
from .model_kernels import ModelKernels
from .state import velocity


@cached
def _is_wet(q: np.ndarray, i: int, dry: float) -> bool:
    for k in range(0, q.shape[0], 2):
        if q[k, i] > dry:
            return True
    return False


@kernel(STATE, f8, i8, i8)
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


@cached
def _limited(a: float, b: float, limiter: int) -> float:
    if a * b <= 0.0:
        return 0.0
    s = 1.0 if a > 0.0 else -1.0
    a = abs(a)
    b = abs(b)
    if limiter == L.LIMITER_MC:
        return s * min(2.0 * a, 2.0 * b, 0.5 * (a + b))
    return s * min(a, b)


@kernel(STATE, WORK, i8, i8, i8, i8, f8, i8)
def reconstruct_muscl(q: np.ndarray, work: np.ndarray, lo: int, hi: int, bc_left: int,
                      bc_right: int, dry: float, limiter: int) -> None:
    """Face values of cells lo..hi into work[0] (left face) and work[1] (right face):
    (h, u) of each layer reconstructed linearly with limited slopes (ghost neighbours
    from the boundary conditions)."""
    n = q.shape[1]
    nf = q.shape[0]
    for i in range(lo, hi + 1):
        for k in range(0, nf, 2):
            h = q[k, i]
            m = q[k + 1, i]
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


ADVECT_SIGNATURE = (STATE, FIELDS, WORK, f8, METRIC, i8, i8, f8, f8, f8, i8, i8)


@functools.cache
def advection_kernel(model: ModelKernels, flux: int, order: int, limiter: int,
                     geometry: int) -> Any:
    r"""The advection stage of one model's scheme on one geometry: ``advect(q, rate,
    work, dx, metric, bc_left, bc_right, g, r, dry, start, stop) -> (smax, r_lo, r_hi)``.

    Writes the rate of the state ``q`` (fields x cells) into ``rate`` in the cells it can
    change, ``r_lo..r_hi``: the wet cells within ``start..stop`` (:func:`wet_cells`; all
    others must be dry) widened by one, clipped to the grid; the rest of ``rate`` is left
    as it was. Returns the largest wave speed over the faces visited [m/s] and
    ``r_lo, r_hi`` (``0.0, 1, 0`` if nothing is wet). ``work`` is scratch space of shape
    (2, fields, cells); ``g``, ``r``, ``dry``: the model's constants
    (:attr:`ModelKernels.constants`). ``model`` gives the face states, fluctuations and
    the MUSCL cell jump; ``flux`` (layout.FLUX_*), ``order`` (1: first order, 2: MUSCL)
    and ``limiter`` (layout.LIMITER_*) choose the scheme.

    ``geometry`` (layout.GEOMETRY_*) and ``metric`` (the rows layout.M_* of
    :class:`~pdeflow.numerics.geometry.Metric`) weight the faces. Planar: every weight is
    1/dx (``metric`` is not read). Axisymmetric, with face areas A and cell volumes V,

    .. math:: \frac{dq_i}{dt} = -\frac{A_{i-1/2} D^+_{i-1/2} + A_{i+1/2} D^-_{i+1/2}
              + \bar A_i \mathcal{A}(q_i^-, q_i^+)}{V_i}
              - \frac{A_{i+1/2} - A_{i-1/2}}{V_i} \overline{F^{adv}}_i,

    \bar A_i the mean of the cell's face areas (on py-pde's uniform radial grid
    \bar A_i / V_i = 2 pi r_i / (2 pi r_i dr) = 1/dr, so the MUSCL cell jump is the
    planar one) and F^adv = (h u, h u^2) of each layer averaged over the cell's two face
    values: the flux difference
    A_{i+1/2} F_{i+1/2} - A_{i-1/2} F_{i-1/2} written with the fluctuations, the
    pressure kept in gradient form g h d(h...)/dr. Mass is conserved exactly (the cell
    term cancels the area change of the mass fluctuations), and a layer at rest feels
    the area-weighted mean of its two one-sided slopes (exactly the slope where it is
    uniform), so that friction holds a cone whose flanks are below the friction angle.
    """
    fluct = model.fluctuations(flux)
    face = model.face
    fields = model.fields
    muscl = order == 2
    axisymmetric = geometry == L.GEOMETRY_AXISYMMETRIC
    # the MUSCL and axisymmetric kernels, only where they are called (see compiled.ready)
    reconstruct = reconstruct_muscl if muscl else None
    cell_jump = model.cell_jump if muscl else None
    area_change = (_area_change_muscl if muscl else _area_change) if axisymmetric else None

    def advect(q, rate, work, dx, metric, bc_left, bc_right, g, r, dry, start, stop):
        lo, hi = wet_cells(q, dry, start, stop)
        n = q.shape[1]
        if lo > hi:
            return 0.0, 1, 0
        r_lo = max(lo - 1, 0)
        r_hi = min(hi + 1, n - 1)
        rate[:, r_lo:r_hi + 1] = 0.0
        if muscl:
            reconstruct(q, work, r_lo, r_hi, bc_left, bc_right, dry, limiter)
            qm = work[0]
            qp = work[1]
        else:
            qm = q  # first order: both face values are the cell average
            qp = q
        inv_dx = 1.0 / dx
        w_l = inv_dx  # weights of a face's fluctuations in the cells left and right
        w_r = inv_dx
        # at the ends of the grid a ghost cell: a wall mirrors the face value next to
        # it, an open end copies it
        s_left = -1.0 if bc_left == L.BC_WALL else 1.0
        s_right = -1.0 if bc_right == L.BC_WALL else 1.0
        smax = 0.0
        for i in range(max(lo, 1), min(hi + 1, n - 1) + 1):
            # face i - 1/2, between cells i - 1 and i
            dm, dp, s = fluct(face(qp, i - 1, 1.0), face(qm, i, 1.0), g, r, dry)
            smax = max(smax, s)
            if axisymmetric:
                w_l = metric[L.M_LEFT, i]
                w_r = metric[L.M_RIGHT, i]
            for k in range(fields):
                rate[k, i - 1] -= dm[k] * w_l
                rate[k, i] -= dp[k] * w_r
        if lo == 0:
            dm, dp, s = fluct(face(qm, 0, s_left), face(qm, 0, 1.0), g, r, dry)
            smax = max(smax, s)
            if axisymmetric:
                w_r = metric[L.M_RIGHT, 0]
            for k in range(fields):
                rate[k, 0] -= dp[k] * w_r
        if hi == n - 1:
            dm, dp, s = fluct(face(qp, n - 1, 1.0), face(qp, n - 1, s_right), g, r, dry)
            smax = max(smax, s)
            if axisymmetric:
                w_l = metric[L.M_LEFT, n]
            for k in range(fields):
                rate[k, n - 1] -= dm[k] * w_l
        if muscl:
            # axisymmetric too: the mean face area over the volume is 1/dr exactly
            cell_jump(qm, qp, rate, r_lo, r_hi, inv_dx, g, r, dry)
        if axisymmetric:
            area_change(qm, qp, rate, r_lo, r_hi, metric, dry)
        return smax, r_lo, r_hi

    return specialise(advect, *ADVECT_SIGNATURE)


@cached
def _area_change(q, unused, rate, lo, hi, metric, dry):
    """Subtract (A_{i+1/2} - A_{i-1/2}) / V_i F^adv(q_i) in the cells lo..hi, F^adv =
    (h u, h u^2) of each layer (first order: the cell averages)."""
    for i in range(lo, hi + 1):
        c = metric[L.M_AREA_CHANGE, i]
        for k in range(0, q.shape[0], 2):
            h = q[k, i]
            u = velocity(h, q[k + 1, i], dry)  # as the fluctuations: 0 in a dry layer
            rate[k, i] -= c * (u * h)
            rate[k + 1, i] -= c * (u * u * h)


@cached
def _area_change_muscl(qm, qp, rate, lo, hi, metric, dry):
    """:func:`_area_change` with F^adv averaged over the cell's face values qm, qp."""
    for i in range(lo, hi + 1):
        c = metric[L.M_AREA_CHANGE, i]
        for k in range(0, qm.shape[0], 2):
            hm = qm[k, i]
            hp = qp[k, i]
            um = velocity(hm, qm[k + 1, i], dry)
            up = velocity(hp, qp[k + 1, i], dry)
            rate[k, i] -= c * 0.5 * (um * hm + up * hp)
            rate[k + 1, i] -= c * 0.5 * (um * um * hm + up * up * hp)


@functools.cache
def rate_kernel(model: ModelKernels, flux: int, order: int, limiter: int,
                geometry: int) -> Any:
    """The advection rate of one scheme on the whole grid (method of lines):
    ``rate(q, out, work, dx, metric, bc_left, bc_right, g, r, dry) -> smax`` writes
    every cell of ``out``; arguments as :func:`advection_kernel`."""
    advect = advection_kernel(model, flux, order, limiter, geometry)

    def advection_rate(q, out, work, dx, metric, bc_left, bc_right, g, r, dry):
        out[:, :] = 0.0
        return advect(q, out, work, dx, metric, bc_left, bc_right, g, r, dry, 0,
                      q.shape[1] - 1)[0]

    return specialise(advection_rate, *ADVECT_SIGNATURE[:-2])
