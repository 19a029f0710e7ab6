r"""Finite-volume advection rates (stage (29)): one face loop over every axis of the grid.

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

The cells of any grid are flattened (``q[field, cell]``, :mod:`pdeflow.numerics.geometry`)
and each axis is a stride in that index: the stage loops, axis by axis, over the faces
of that axis next to the cells of its window, interior faces first, then the two
boundary sides (a 1D grid is the one axis of stride 1, the arithmetic of the 1D scheme).
The model gives each face's states in the face's normal frame and the rows its
fluctuations go back into (:class:`~pdeflow.numerics.model_kernels.ModelKernels`); MUSCL
reconstructs along each axis in turn. Boundaries use one ghost cell per side: a wall
mirrors the state (h -> h, normal momentum -> -normal momentum), an open (transmissive)
boundary copies it. Only faces next to a wet cell are visited: a face between two cells
that are dry in every layer carries no mass, so the loops run, line by line, over the
wet cells of the window they are given (the stepping loop narrows it further to the
cells a step can change, :mod:`pdeflow.numerics.resting`).

:func:`advection_kernel` builds this stage for one model, flux, reconstruction and
limiter (nothing of the others is compiled); :func:`rate_kernel` is the same on the
whole grid, the method-of-lines rate.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numba import njit, prange

from . import layout as L
from .bed_slope import bed_slope
from .boxes import box_grow, box_of, gather_rows, rows_of, zero_box
from .compiled import FIELDS, METRIC, STATE, WORK, cached, f8, i8, kernel, specialise
from .geometry import area_change, area_change_muscl
from .model_kernels import ModelKernels, check_flux
from .muscl import reconstruction


@cached
def _is_wet(q: np.ndarray, i: int, dry: float, width: int) -> bool:
    for k in range(0, q.shape[0], width):
        if q[k, i] > dry:
            return True
    return False


@kernel(STATE, f8, i8, i8, i8)
def wet_cells(q: np.ndarray, dry: float, start: int, stop: int,
              width: int) -> tuple[int, int]:
    """First and last index in ``start..stop`` of a cell where some layer's depth (rows
    0, ``width``, 2 ``width``, ... of ``q``) exceeds ``dry``; ``(1, 0)`` if none."""
    lo = start
    while lo <= stop and not _is_wet(q, lo, dry, width):
        lo += 1
    if lo > stop:
        return 1, 0
    hi = stop
    while hi > lo and not _is_wet(q, hi, dry, width):
        hi -= 1
    return lo, hi


@cached(inline="always")
def line_wet(q: np.ndarray, dry: float, width: int, base: int, stride: int, k0: int,
             k1: int) -> tuple[int, int]:
    """First and last k in ``k0..k1`` whose cell ``base + k stride`` is wet (some depth,
    rows 0, ``width``, ..., above ``dry``); ``(1, 0)`` if none: :func:`wet_cells` along
    one line of an axis."""
    klo = k0
    while klo <= k1 and not _is_wet(q, base + klo * stride, dry, width):
        klo += 1
    if klo > k1:
        return 1, 0
    khi = k1
    while khi > klo and not _is_wet(q, base + khi * stride, dry, width):
        khi -= 1
    return klo, khi


@cached(inline="always")
def wet_box(q: np.ndarray, dry: float, lo: int, hi: int, width: int, line: int,
            gather: np.ndarray) -> tuple[int, int]:
    """The bounding box of the wet cells (:func:`wet_cells`) of the box (lo, hi) of a
    grid of ``line`` cells a row (:mod:`pdeflow.numerics.boxes`); ``(1, 0)`` if none.
    Each row's wet range goes through ``gather`` (one entry per row,
    :func:`pdeflow.numerics.boxes.gather_rows`; cell indices, exact as floats)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    a0, a1, b0, b1 = x1 + 1, x0 - 1, y1 + 1, y0 - 1  # an empty box
    for k in prange(x1 - x0 + 1):  # the rows on threads in a parallel kernel
        klo, khi = line_wet(q, dry, width, (x0 + k) * line, 1, y0, y1)
        gather[k, 0] = klo
        gather[k, 1] = khi
    for x in range(x0, x1 + 1):  # (min and max: the same box whatever the threads)
        klo, khi = int(gather[x - x0, 0]), int(gather[x - x0, 1])
        if klo <= khi:
            a0 = min(a0, x)
            a1 = x
            b0 = min(b0, klo)
            b1 = max(b1, khi)
    return box_of(a0, a1, b0, b1, line)


@cached(inline="always")
def _resting_speed(q: np.ndarray, i: int, g: float, width: int, s: float) -> float:
    """Over a bed, the wave speed a face takes from its cell ``i``: sqrt(g_z H_i), H_i
    the cell's total depth, if every layer of the cell is at rest (the bound
    :func:`pdeflow.numerics.resting.rest_speed` gives the faces of resting cells that the
    loop skips, so that skipping them changes no step), else the fluctuations' ``s``."""
    depth = 0.0
    for k in range(0, q.shape[0], width):
        for j in range(k + 1, k + width):
            if q[j, i] != 0.0:
                return s
        depth += max(q[k, i], 0.0)
    return math.sqrt(g * depth)


def _faces_function(face: Any, fluct: Any, rows: tuple[int, ...], width: int, axis: int,
                    axisymmetric: bool, lines: bool, terrain: bool = False) -> Any:
    """The faces of one axis as a Python closure (inlined into the advection stage):

    ``faces(q, qm, qp, rate, metric, gather, lo, hi, stride, count, inv_dx, s_lo, s_hi,
    g, r, dry, per_row) -> smax`` subtracts the fluctuations of the axis' faces next to the wet
    cells of ``lo..hi`` (``qp``: the face values on the cells' high sides, ``qm`` on
    their low sides) from ``rate``, weighted ``inv_dx`` [1/m] (axisymmetric: the
    metric's rows), in the rows ``rows`` (``width`` rows per layer); line by line of the
    axis (``lines``: a 2D grid of ``per_row`` cells a row, and ``lo, hi`` a box,
    :mod:`pdeflow.numerics.boxes`, whose cells on each line are all that line's visited,
    each line's largest speed put in ``gather``'s first column; else the one line of a
    1D grid, whose wet cells are ``lo..hi``), in each the faces
    between and beside its wet cells as on a 1D grid: interior faces first, then the
    low and the high boundary sides, whose ghost cells have their normal momenta times
    ``s_lo``, ``s_hi`` (-1: wall, 1: open). Returns the largest wave speed [m/s].

    A line's faces beyond its last wet cell are not visited, as on a 1D grid: a face
    between sub-dry traces of depth is not exactly zero (its hydrostatic jump), so
    visiting them would change the numbers of a line that a 1D run has.

    ``terrain`` (over a bed): a face between two cells at rest takes the larger of the
    cells' sqrt(g_z H) as its wave speed instead of its reconstructed states' (whose
    depths reach h + |d|): the bound the stepping loop takes for the resting faces it
    skips (:mod:`pdeflow.numerics.resting`), so that skipping changes no step. No mass
    crosses such a face (the fluctuations of layers at rest move none), so its speed
    bounds no transport."""
    identity = rows == tuple(range(len(rows)))

    @njit(inline="always")
    def resting(q, i_left, i_right, g, s):
        if not terrain:
            return s
        c_left = _resting_speed(q, i_left, g, width, -1.0)
        c_right = _resting_speed(q, i_right, g, width, -1.0)
        return s if c_left < 0.0 or c_right < 0.0 else max(c_left, c_right)

    @njit(inline="always")
    def line(q, qm, qp, rate, metric, base, stride, count, klo, khi, inv_dx, s_lo, s_hi,
             g, r, dry):
        w_l = inv_dx  # weights of a face's fluctuations in the cells on either side
        w_r = inv_dx
        smax = 0.0
        for k in range(max(klo, 1), min(khi + 1, count - 1) + 1):
            i = base + k * stride  # the face between cells i - stride and i
            dm, dp, s = fluct(face(qp, i - stride, axis, 1.0), face(qm, i, axis, 1.0),
                              g, r, dry)
            smax = max(smax, resting(q, i - stride, i, g, s))
            if axisymmetric:
                w_l = metric[L.M_LEFT, i]
                w_r = metric[L.M_RIGHT, i]
            for j in range(len(rows)):
                row = j if identity else rows[j]
                rate[row, i - stride] -= dm[j] * w_l
                rate[row, i] -= dp[j] * w_r
        if klo == 0:
            i = base
            dm, dp, s = fluct(face(qm, i, axis, s_lo), face(qm, i, axis, 1.0), g, r, dry)
            smax = max(smax, resting(q, i, i, g, s))
            if axisymmetric:
                w_r = metric[L.M_RIGHT, i]
            for j in range(len(rows)):
                rate[j if identity else rows[j], i] -= dp[j] * w_r
        if khi == count - 1:
            i = base + (count - 1) * stride
            dm, dp, s = fluct(face(qp, i, axis, 1.0), face(qp, i, axis, s_hi), g, r, dry)
            smax = max(smax, resting(q, i, i, g, s))
            if axisymmetric:
                w_l = metric[L.M_LEFT, i + 1]
            for j in range(len(rows)):
                rate[j if identity else rows[j], i] -= dm[j] * w_l
        return smax

    def faces(q, qm, qp, rate, metric, gather, lo, hi, stride, count, inv_dx, s_lo, s_hi,
              g, r, dry, per_row):
        if not lines:
            return line(q, qm, qp, rate, metric, 0, 1, count, lo, hi, inv_dx, s_lo, s_hi, g,
                        r, dry)
        # the axis' lines through the box, each over its cells: dry margins not swept
        x0, x1, y0, y1 = rows_of(lo, hi, per_row)
        if axis == 1:  # lines of the last axis: the box's rows
            l0, l1, step, k0, k1 = x0, x1, per_row, y0, y1
        else:  # lines of the first axis: the box's columns
            l0, l1, step, k0, k1 = y0, y1, 1, x0, x1
        for m in prange(l0, l1 + 1):  # lines on threads: each writes its own cells
            base = m * step  # the line of cells base + k stride, k = 0..count - 1
            klo, khi = line_wet(q, dry, width, base, stride, k0, k1)
            gather[m - l0, 0] = 0.0
            if klo <= khi:
                gather[m - l0, 0] = line(q, qm, qp, rate, metric, base, stride, count, klo,
                                         khi, inv_dx, s_lo, s_hi, g, r, dry)
        smax = 0.0
        for m in range(l1 - l0 + 1):  # (a maximum: the same whatever the threads)
            smax = max(smax, gather[m, 0])
        return smax

    return faces


def _axis_function(model: ModelKernels, flux: int, muscl: bool, limiter: int, axis: int,
                   axisymmetric: bool, lines: bool, terrain: bool = False) -> Any:
    """One axis' part of the advection stage as a Python closure (inlined):
    ``along(q, rate, work, gather, metric, lo, hi, r_lo, r_hi, stride, count, inv_dx,
    bc_lo, bc_hi, g, r, dry, per_row) -> smax``: MUSCL's face values along the axis in cells
    ``r_lo..r_hi``, the axis' faces next to ``lo..hi`` (:func:`_faces_function`), the
    MUSCL cell jump along the axis; with ``lines`` (a 2D grid of ``per_row`` cells a
    row) ``lo, hi`` and ``r_lo, r_hi`` are boxes (:mod:`pdeflow.numerics.boxes`).
    ``terrain``: over a bed, the model's face values over it
    (:attr:`ModelKernels.terrain`) in place of MUSCL's, and the cell term with the
    bed's slope (:mod:`.bed_slope`)."""
    check_flux(model, flux)
    rows = model.axis_rows(axis)
    width = model.layer_rows
    faces = njit(inline="always")(_faces_function(model.face, model.fluctuations(flux),
                                                  rows, width, axis, axisymmetric, lines,
                                                  terrain))
    normal = rows[1]  # the row of a layer's momentum normal to the axis' faces
    # the MUSCL kernels, only where they are called (see compiled.ready)
    reconstruct = reconstruction(width, normal) if muscl else None
    cell_jump = model.cell_jump if muscl or terrain else None
    bed_faces = model.terrain if terrain else None

    def along(q, rate, work, gather, metric, lo, hi, r_lo, r_hi, stride, count, inv_dx,
              bc_lo, bc_hi, g, r, dry, per_row):
        x0, x1, y0, y1 = rows_of(r_lo, r_hi, per_row) if lines else (0, 0, r_lo, r_hi)
        if muscl:
            for x in prange(x0, x1 + 1):  # a 2D grid's box row by row, on threads
                reconstruct(q, work, x * per_row + y0, x * per_row + y1, stride, count,
                            bc_lo, bc_hi, dry, limiter)
            qm = work[0]
            qp = work[1]
        elif terrain:
            for x in prange(x0, x1 + 1):
                bed_faces(q, work, metric, x * per_row + y0, x * per_row + y1, axis, dry)
            qm = work[0]
            qp = work[1]
        else:
            qm = q  # first order: both face values are the cell average
            qp = q
        # a ghost cell: a wall mirrors the face value next to it, an open end copies it
        s_lo = -1.0 if bc_lo == L.BC_WALL else 1.0
        s_hi = -1.0 if bc_hi == L.BC_WALL else 1.0
        smax = faces(q, qm, qp, rate, metric, gather, lo, hi, stride, count, inv_dx, s_lo,
                     s_hi, g, r, dry, per_row)
        if muscl:
            # axisymmetric too: the mean face area over the volume is 1/dr exactly
            for x in prange(x0, x1 + 1):
                cell_jump(qm, qp, rate, x * per_row + y0, x * per_row + y1, inv_dx, g, r,
                          dry, axis)
        elif terrain:
            for x in prange(x0, x1 + 1):
                lo_x, hi_x = x * per_row + y0, x * per_row + y1
                cell_jump(qm, qp, rate, lo_x, hi_x, inv_dx, g, r, dry, axis)
                bed_slope(qm, qp, rate, metric, lo_x, hi_x, inv_dx, g, width, normal, axis)
        return smax

    return along


@cached(inline="always")
def _axis(metric: np.ndarray, a: int, dx: float) -> tuple[int, int, float, float]:
    """Axis ``a`` of a 2D grid: its stride, its cells, 1 / its width [1/m] and what its
    faces' speeds are scaled by, (dx / width) 2 (see :func:`advection_kernel`)."""
    width = metric[L.M_AXES, 3 * a + 2]
    return (int(metric[L.M_AXES, 3 * a]), int(metric[L.M_AXES, 3 * a + 1]), 1.0 / width,
            dx / width * 2.0)


ADVECT_SIGNATURE = (STATE, FIELDS, WORK, FIELDS, f8, METRIC, i8, i8, f8, f8, f8, i8, i8)


@functools.cache
def advection_kernel(model: ModelKernels, flux: int, order: int, limiter: int,
                     geometry: int) -> Any:
    r"""The advection stage of one model's scheme on one geometry: ``advect(q, rate,
    work, gather, dx, metric, bc_left, bc_right, g, r, dry, start, stop) -> (smax, r_lo,
    r_hi)``.

    Writes the rate of the state ``q`` (fields x cells, flattened) into ``rate`` in the
    cells it can change, ``r_lo..r_hi``: the wet cells within ``start..stop``
    (:func:`wet_cells`; all others must be dry) widened by one cell, clipped to the
    grid; the rest of ``rate`` is left as it was. On a 2D grid ``start, stop`` and
    ``r_lo, r_hi`` are boxes (:mod:`pdeflow.numerics.boxes`: rows x columns, named by
    their first and last cell): the bounding box of the wet cells of the box ``start,
    stop``, widened by one cell along both axes; cells outside the box are not read
    beyond the stencil of its cells, nor written. Returns the largest wave speed over
    the faces visited [m/s], on a grid of several axes each face's scaled by (dx / dx_a)
    times the number of axes, so that ``cfl dx / smax`` bounds the sum over axes of the
    Courant numbers by ``cfl``; and ``r_lo, r_hi`` (``0.0, 1, 0`` if nothing is wet).
    ``work`` is scratch space of shape (2, fields, cells), ``gather`` that of a 2D
    grid's lines (:func:`pdeflow.numerics.boxes.gather_rows`); ``g``, ``r``, ``dry``: the
    model's constants (:attr:`ModelKernels.constants`). ``model`` gives the face states,
    fluctuations and the MUSCL cell jump; ``flux`` (layout.FLUX_*), ``order`` (1: first
    order, 2: MUSCL) and ``limiter`` (layout.LIMITER_*) choose the scheme. ``bc_left``,
    ``bc_right``: the boundary codes of the low and high sides (several axes:
    :func:`layout.sides`).

    ``geometry`` (layout.GEOMETRY_*) and ``metric`` (the rows layout.M_* of
    :class:`~pdeflow.numerics.geometry.Metric`) weight the faces. Planar: every weight is
    1/dx (``metric`` is not read); 2D: 1/dx_a on the faces of axis a (``metric``'s
    row M_AXES gives the axes); 2D over a bed (rows M_BED): also the model's face values
    over the bed and the bed's slope in the cell term (:mod:`.bed_slope`, first order
    only). Axisymmetric, with face areas A and cell volumes V,

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
    muscl = order == 2
    axisymmetric = geometry == L.GEOMETRY_AXISYMMETRIC
    terrain = geometry == L.GEOMETRY_TERRAIN_2D
    two_d = geometry == L.GEOMETRY_PLANAR_2D or terrain
    if terrain and (muscl or model.terrain is None):
        raise ValueError("over a bed the reconstruction must be 'first-order' and the "
                         "model must have kernels over a bed (the single layer)")
    width = model.layer_rows
    along_x = njit(inline="always")(_axis_function(model, flux, muscl, limiter, 0,
                                                   axisymmetric, two_d, terrain))
    along_y = njit(inline="always")(_axis_function(model, flux, muscl, limiter, 1, False,
                                                   True, terrain)) if two_d else None
    area = (area_change_muscl if muscl else area_change) if axisymmetric else None

    def advect(q, rate, work, gather, dx, metric, bc_left, bc_right, g, r, dry, start,
               stop):
        n = q.shape[1]
        if not two_d:
            lo, hi = wet_cells(q, dry, start, stop, width)
            if lo > hi:
                return 0.0, 1, 0
            r_lo = max(lo - 1, 0)
            r_hi = min(hi + 1, n - 1)
            rate[:, r_lo:r_hi + 1] = 0.0
            smax = along_x(q, rate, work, gather, metric, lo, hi, r_lo, r_hi, 1, n,
                           1.0 / dx, bc_left, bc_right, g, r, dry, n)
            if axisymmetric and muscl:
                area(work[0], work[1], rate, r_lo, r_hi, metric, dry, width)
            elif axisymmetric:
                area(q, q, rate, r_lo, r_hi, metric, dry, width)
            return smax, r_lo, r_hi
        # a 2D grid: start, stop and what is returned are boxes, the wet cells' widened
        # by one cell along both axes: the cells their faces write to
        per_row = int(metric[L.M_AXES, 4])
        lo, hi = wet_box(q, dry, start, stop, width, per_row, gather)
        if lo > hi:
            return 0.0, 1, 0
        r_lo, r_hi = box_grow(lo, hi, 1, per_row, n)
        zero_box(rate, r_lo, r_hi, per_row)
        stride, count, inv_width, scale = _axis(metric, 0, dx)
        smax = scale * along_x(q, rate, work, gather, metric, lo, hi, r_lo, r_hi, stride,
                               count, inv_width, bc_left & 1, bc_right & 1, g, r, dry,
                               per_row)
        stride, count, inv_width, scale = _axis(metric, 1, dx)
        s = scale * along_y(q, rate, work, gather, metric, lo, hi, r_lo, r_hi, stride,
                            count, inv_width, (bc_left >> 1) & 1, (bc_right >> 1) & 1, g,
                            r, dry, per_row)
        return max(smax, s), r_lo, r_hi

    return specialise(advect, *ADVECT_SIGNATURE, parallel=two_d)


@functools.cache
def rate_kernel(model: ModelKernels, flux: int, order: int, limiter: int,
                geometry: int) -> Any:
    """The advection rate of one scheme on the whole grid (method of lines):
    ``rate(q, out, work, dx, metric, bc_left, bc_right, g, r, dry) -> smax`` writes
    every cell of ``out``; arguments as :func:`advection_kernel`."""
    advect = advection_kernel(model, flux, order, limiter, geometry)

    two_d = geometry in (L.GEOMETRY_PLANAR_2D, L.GEOMETRY_TERRAIN_2D)

    def advection_rate(q, out, work, dx, metric, bc_left, bc_right, g, r, dry):
        out[:, :] = 0.0
        n = q.shape[1]
        gather = gather_rows(n, int(metric[L.M_AXES, 4]) if two_d else n, two_d)
        return advect(q, out, work, gather, dx, metric, bc_left, bc_right, g, r, dry, 0,
                      n - 1)[0]

    return specialise(advection_rate, *ADVECT_SIGNATURE[:3], *ADVECT_SIGNATURE[4:-2])
