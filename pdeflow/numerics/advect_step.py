"""One step's advection stage of the ``fv-split`` stepping loop, and the state update.

:func:`advect_step_function` is the stage the loop of :mod:`pdeflow.numerics.splitting`
inlines once per step: the CFL time step from the advection stage's wave speeds (and,
with Strang splitting, the first half source step), the update of the cells the step
may change and, with MUSCL, the SSP-RK2 (Heun) corrector. :func:`update_function` is
the state update for a model's rows per layer (the blow-up diagnosis replays a step
with an instrumented one).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numba import njit

from . import layout as L
from .boxes import box_join, box_meet, row_calls, update_in_box_function
from .compiled import cached
from .threads import box_passes, update_on_rows


def update_function(width: int) -> Any:
    """The state update of a model with ``width`` rows per layer (depth first) as a
    Python closure: ``update(q, base, rate, dt, weight, lo, hi)``, see :func:`update`."""

    def update(q, base, rate, dt, weight, lo, hi):
        """q <- weight * base + (1 - weight) * (q + dt * rate) in cells ``lo..hi``;
        returns (max |mass rate|, ok).

        ``ok`` is False if the result is not finite or a depth is negative beyond
        round-off (round-off below zero is clipped by the source stage).
        """
        mass_rate = 0.0
        ok = True
        for k in range(q.shape[0]):
            for i in range(lo, hi + 1):
                v = weight * base[k, i] + (1.0 - weight) * (q[k, i] + dt * rate[k, i])
                if k % width == 0:
                    mass_rate = max(mass_rate, abs(rate[k, i]))
                    if v < -1e-12 * (1.0 + abs(q[k, i])):
                        ok = False
                if not math.isfinite(v):
                    ok = False
                q[k, i] = v
        return mass_rate, ok

    return update


update = cached(inline="always")(update_function(2))
"""the state update of the one-axis models (two rows per layer)"""


@functools.cache
def update_kernel(width: int) -> Any:
    """The compiled state update for ``width`` rows per layer (:data:`update` for 2)."""
    return update if width == 2 else njit(inline="always")(update_function(width))


@cached(inline="always")
def _copy_range(dst, src, lo, hi):
    """dst[lo:hi + 1] = src[lo:hi + 1] for 1D arrays (a loop: numba compiles an
    array-to-array slice assignment with its shape-mismatch error message, seconds)."""
    for i in range(lo, hi + 1):
        dst[i] = src[i]


@cached(inline="always")
def speed_scale(metric: np.ndarray, dx: float) -> float:
    """On a 2D grid, max over axes of (dx / dx_a) times 2: what the advection stage
    scales a face's wave speed by (:func:`pdeflow.numerics.advection.advection_kernel`),
    for the speeds and accelerations the stepping loop adds to it."""
    return max(dx / metric[L.M_AXES, 2], dx / metric[L.M_AXES, 5]) * 2.0


def advect_step_function(order: int, strang: bool, update: Any = None, width: int = 2,
                         two_d: bool = False) -> Any:
    """The advection stage of one step of the stepping loop, with Strang the first half
    source step before it, as a Python closure (compiled inside :func:`stepping_kernel`;
    the blow-up diagnosis runs it in Python with an instrumented ``update``):

    ``advect_step(advect, sources, predictor, q, t, t_end, dx, metric, bc_left, bc_right,
    P, g, r, dry, cfl, diag, rate, backup, rec, gather, q0, diag_keep, fex_keep, first,
    e_lo, e_hi, b_lo, b_hi, s_rest, line)`` advances the cells of the box ``b_lo, b_hi``
    (:mod:`pdeflow.numerics.boxes`, ``line`` cells a row; on a 1D grid the range
    ``b_lo..b_hi``) with the model's kernels (see
    :func:`stepping_kernel`): the cells the step may change, saved in ``backup`` (and,
    for Strang, the bookkeeping in ``diag_keep``, ``fex_keep``). The advection stages
    evaluate the wet cells of the box ``e_lo, e_hi`` (``b`` widened by one, so that every face
    of a cell of ``b`` is evaluated) and update only those of ``b``; ``s_rest`` [m/s]
    is the largest wave speed of the faces at rest they skip
    (:mod:`pdeflow.numerics.resting`), so that dt is that of a full sweep.

    Returns ``(dt, mass_rate, ok, a_lo, a_hi, changed)``: the step [s], the largest mass
    rate, whether the state is finite and non-negative, the cells the update touched and
    whether the half source step changed anything. ``width``: the model's rows per
    layer; ``two_d``: a 2D grid (the wave speeds are scaled, :func:`speed_scale`).
    """
    muscl = order == 2
    compiled = update is None
    update = update or update_kernel(width)
    if compiled and two_d:  # its rows on numba's threads (pdeflow.numerics.threads)
        update_box = update_on_rows(update)
    else:
        update_box = update_in_box_function(update)
        if compiled:
            update_box = njit(inline="always")(update_box)
    sources_box, predictor_box = row_calls(compiled, two_d)
    copy_box, copy_box1, clear_outside, _, _ = box_passes(compiled and two_d)

    def advect_step(advect, sources, predictor, q, t, t_end, dx, metric, bc_left, bc_right,
                    P, g, r, dry, cfl, diag, rate, backup, rec, gather, q0, diag_keep,
                    fex_keep, first, e_lo, e_hi, b_lo, b_hi, s_rest, line):
        fex = diag[L.N_DIAG:]
        smax, a_lo, a_hi = advect(q, rate, rec, gather, dx, metric, bc_left, bc_right, g,
                                  r, dry, e_lo, e_hi)
        smax = max(smax, s_rest)
        a_lo, a_hi = box_meet(a_lo, a_hi, b_lo, b_hi, line)
        dt = t_end - t
        if strang:
            # the first half source step may accelerate a layer by up to dt/2 |g_x|
            # (friction only brakes): choose dt with dt (smax + dt |g_x| / 2) = cfl dx
            # (2D: |g_x| + |g_y|, the plane's gravity along both axes, scaled as speeds)
            gx = (abs(P[L.G_X]) + abs(P[L.G_Y])) * speed_scale(metric, dx) if two_d \
                else abs(P[L.G_X])
            den = smax + math.sqrt(smax * smax + 2.0 * gx * cfl * dx)
            if den > 0.0:
                dt = min(dt, 2.0 * cfl * dx / den)
        elif smax > 0.0:
            dt = min(dt, cfl * dx / smax)
        changed = 0.0
        if strang:
            h_lo = b_lo if first else a_lo
            h_hi = b_hi if first else a_hi
            for attempt in range(40):
                diag[L.D_DT] = 0.5 * dt
                sources_box(sources, q, 0.5 * dt, t, P, diag, gather, h_lo, h_hi, line)
                changed = diag[L.D_CHANGED]
                # (a deposit can lift a cell of sub-dry layers above dry: search wider)
                smax2, a_lo, a_hi = advect(q, rate, rec, gather, dx, metric, bc_left,
                                           bc_right, g, r, dry, e_lo, e_hi)
                smax2 = max(smax2, s_rest)
                a_lo, a_hi = box_meet(a_lo, a_hi, b_lo, b_hi, line)
                if smax2 * dt <= cfl * dx * (1.0 + 1e-9) or attempt == 39:
                    break
                # the half source step made the waves faster than dt allows (erosion
                # can deepen the upper layer 1/r-fold): undo it and retry shorter
                copy_box(q, backup, b_lo, b_hi, line)
                _copy_range(diag, diag_keep, 0, L.N_DIAG - 1)
                copy_box1(fex, fex_keep, b_lo, b_hi, line)
                dt = min(0.5 * dt, cfl * dx / smax2)
        if not muscl:
            mass_rate, ok = update_box(q, q, rate, dt, 0.0, gather, a_lo, a_hi, line)
            return dt, mass_rate, ok, a_lo, a_hi, changed
        copy_box(q0, q, b_lo, b_hi, line)
        mass_rate, ok = update_box(q, q0, rate, dt, 0.0, gather, a_lo, a_hi, line)
        if ok:
            predictor_box(predictor, q, dt, P, a_lo, a_hi, line)
            _, c_lo, c_hi = advect(q, rate, rec, gather, dx, metric, bc_left, bc_right, g,
                                   r, dry, e_lo, e_hi)
            c_lo, c_hi = box_meet(c_lo, c_hi, b_lo, b_hi, line)
            # cells of the first stage that the second does not reach get rate 0 (on a
            # 2D grid also those of the joined box in neither: their rate is stale)
            u_lo, u_hi = box_join(a_lo, a_hi, c_lo, c_hi, line)
            clear_outside(rate, u_lo, u_hi, c_lo, c_hi, line)
            mass2, ok = update_box(q, q0, rate, dt, 0.5, gather, u_lo, u_hi, line)
            mass_rate = max(mass_rate, mass2)
            a_lo = u_lo
            a_hi = u_hi
        return dt, mass_rate, ok, a_lo, a_hi, changed

    return advect_step
