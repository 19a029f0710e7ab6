r"""The paper's operator-split scheme: the CFL stepping loop of the ``fv-split`` solver.

One step of length dt (Lie splitting, as in the paper):

1. advection (29): q <- q + dt L_HLL(q), dt = CFL dx / max|S| over the faces
   (:mod:`pdeflow.numerics.advection`);
2. exchange (31), 3. implicit momentum sources (32), 4. hyperbolicity (33)-(34): the
   source stage of :mod:`pdeflow.numerics.source_stage`.

With MUSCL the advection is integrated with SSP-RK2 (Heun); with Strang splitting half
a source step is applied before and after it. :func:`stepping_kernel` compiles the loop
for one scheme (model, flux, reconstruction, limiter, splitting) and caches it on disk;
all parameters are arrays and the grid an argument, so that sweeps never recompile.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numba import njit

from . import layout as L
from .advection import advection_kernel, wet_cells
from .compiled import FIELDS, PARAMS, STATE, VECTOR, WORK, f8, flag, i8, ready, specialise
from .friction import predictor_single, predictor_two_layer
from .source_stage import (
    source_stage_single,
    source_stage_two_layer,
    sources_single,
    sources_two_layer,
)

# the full-grid source stages are imported from here by analysis.stability's mol_run
__all__ = ["source_stage_single", "source_stage_two_layer", "stepping_kernel",
           "advance_split", "STATUS_END", "STATUS_REST", "STATUS_FAIL"]

STATUS_END = 0  #: reached t_end
STATUS_REST = 1  #: everything at rest: nothing will change any more
STATUS_FAIL = 2  #: non-finite or negative state: the step was undone


@njit(cache=True, inline="always")
def update(q, base, rate, dt, weight, lo, hi):
    """q <- weight * base + (1 - weight) * (q + dt * rate) in cells ``lo..hi``; returns
    (max |mass rate|, ok).

    ``ok`` is False if the result is not finite or a depth is negative beyond round-off
    (round-off below zero is clipped by the source stage).
    """
    mass_rate = 0.0
    ok = True
    for k in range(q.shape[0]):
        for i in range(lo, hi + 1):
            v = weight * base[k, i] + (1.0 - weight) * (q[k, i] + dt * rate[k, i])
            if k % 2 == 0:
                mass_rate = max(mass_rate, abs(rate[k, i]))
                if v < -1e-12 * (1.0 + abs(q[k, i])):
                    ok = False
            if not math.isfinite(v):
                ok = False
            q[k, i] = v
    return mass_rate, ok


@njit(cache=True, inline="always")
def _copy_cells(dst, src, lo, hi):
    """dst[..., lo:hi + 1] = src[..., lo:hi + 1] for 2D arrays (a loop: numba compiles
    an array-to-array slice assignment with its shape-mismatch error message, seconds)."""
    for k in range(dst.shape[0]):
        for i in range(lo, hi + 1):
            dst[k, i] = src[k, i]


@njit(cache=True, inline="always")
def _copy_range(dst, src, lo, hi):
    """dst[lo:hi + 1] = src[lo:hi + 1] for 1D arrays (see :func:`_copy_cells`)."""
    for i in range(lo, hi + 1):
        dst[i] = src[i]


def advect_step_function(two_layer: bool, order: int, strang: bool, advect: Any,
                         update: Any = update) -> Any:
    """The advection stage of one step of the stepping loop, with Strang the first half
    source step before it, as a Python closure (compiled by :func:`stepping_kernel`;
    the blow-up diagnosis runs it in Python with an instrumented ``update``):

    ``advect_step(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, rec,
    q0, diag_keep, fex_keep, first, lo, hi, b_lo, b_hi)`` advances from the wet cells
    ``lo..hi``; ``b_lo..b_hi`` are the cells the step may change, saved in ``backup``
    (and, for Strang, the bookkeeping in ``diag_keep``, ``fex_keep``).

    Returns ``(dt, mass_rate, ok, a_lo, a_hi, changed)``: the step [s], the largest mass
    rate, whether the state is finite and non-negative, the cells the update touched and
    whether the half source step changed anything. ``advect`` is the scheme's
    :func:`~pdeflow.numerics.advection.advection_kernel`.
    """
    sources = sources_two_layer if two_layer else sources_single
    predictor = predictor_two_layer if two_layer else predictor_single
    muscl = order == 2

    def advect_step(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, rec,
                    q0, diag_keep, fex_keep, first, lo, hi, b_lo, b_hi):
        if two_layer:
            g, r, dry = P[L.G_Z], P[L.R], P[L.DRY]
        else:
            g, r, dry = P[L.S_G_Z], 0.0, P[L.S_DRY]
        fex = diag[L.N_DIAG:]
        smax, a_lo, a_hi = advect(q, rate, rec, dx, bc_left, bc_right, g, r, dry, lo, hi)
        dt = t_end - t
        if strang:
            # the first half source step may accelerate a layer by up to dt/2 |g_x|
            # (friction only brakes): choose dt with dt (smax + dt |g_x| / 2) = cfl dx
            gx = abs(P[L.G_X])
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
                sources(q, 0.5 * dt, t, P, diag, h_lo, h_hi)
                changed = diag[L.D_CHANGED]
                # (a deposit can lift a cell of sub-dry layers above dry: search wider)
                smax2, a_lo, a_hi = advect(q, rate, rec, dx, bc_left, bc_right, g, r, dry,
                                           b_lo, b_hi)
                if smax2 * dt <= cfl * dx * (1.0 + 1e-9) or attempt == 39:
                    break
                # the half source step made the waves faster than dt allows (erosion
                # can deepen the upper layer 1/r-fold): undo it and retry shorter
                _copy_cells(q, backup, b_lo, b_hi)
                _copy_range(diag, diag_keep, 0, L.N_DIAG - 1)
                _copy_range(fex, fex_keep, b_lo, b_hi)
                dt = min(0.5 * dt, cfl * dx / smax2)
        if not muscl:
            mass_rate, ok = update(q, q, rate, dt, 0.0, a_lo, a_hi)
            return dt, mass_rate, ok, a_lo, a_hi, changed
        _copy_cells(q0, q, b_lo, b_hi)
        mass_rate, ok = update(q, q0, rate, dt, 0.0, a_lo, a_hi)
        if ok:
            predictor(q, dt, P, a_lo, a_hi)
            _, c_lo, c_hi = advect(q, rate, rec, dx, bc_left, bc_right, g, r, dry, b_lo,
                                   b_hi)
            # cells of the first stage that the second does not reach get rate 0
            for i in range(a_lo, a_hi + 1):
                if i < c_lo or i > c_hi:
                    rate[:, i] = 0.0
            if a_lo > a_hi:
                a_lo = c_lo
                a_hi = c_hi
            elif c_lo <= c_hi:
                a_lo = min(a_lo, c_lo)
                a_hi = max(a_hi, c_hi)
            mass2, ok = update(q, q0, rate, dt, 0.5, a_lo, a_hi)
            mass_rate = max(mass_rate, mass2)
        return dt, mass_rate, ok, a_lo, a_hi, changed

    return advect_step


def stepping_function(two_layer: bool, ifcp: bool, strang: bool, advect_step: Any,
                      hll_step: Any) -> Any:
    """The stepping loop as a Python closure (compiled by :func:`stepping_kernel`):
    ``advance(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, work,
    max_steps, stop_at_rest) -> (t, steps, status)``, see :func:`stepping_kernel`.
    ``advect_step`` is the scheme's :func:`advect_step_function`; with the IFCP flux,
    ``hll_step`` is the same with HLL, which redoes a step that IFCP left negative."""
    sources = sources_two_layer if two_layer else sources_single

    def advance(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, work,
                max_steps, stop_at_rest):
        n = q.shape[1]
        dry = P[L.DRY] if two_layer else P[L.S_DRY]
        steps = 0
        rec = work[:2]
        q0 = work[2]
        fex = diag[L.N_DIAG:]
        # to undo a Strang half source step that broke the CFL, or an IFCP step
        diag_keep = np.empty(L.N_DIAG)
        fex_keep = np.empty(n)
        # Cells outside the wet region plus the stencil are dry and at rest, which every
        # stage leaves unchanged: only the active cells are visited. The first step
        # visits all cells (the source stage cleans the initial state); the wet region
        # then grows by at most one cell per advection stage, so the next search window
        # is the last region widened by two.
        w_lo = 0
        w_hi = n - 1
        s_lo = 0
        s_hi = n - 1
        first = True
        while t < t_end and steps < max_steps:
            # cells a step can change: two advection stages around the wet region
            lo, hi = wet_cells(q, dry, w_lo, w_hi)
            if first:
                b_lo = 0
                b_hi = n - 1
            elif lo > hi:
                b_lo = 1
                b_hi = 0
            else:
                b_lo = max(lo - 2, 0)
                b_hi = min(hi + 2, n - 1)
            _copy_cells(backup, q, b_lo, b_hi)
            if strang or ifcp:
                _copy_range(diag_keep, diag, 0, L.N_DIAG - 1)
                _copy_range(fex_keep, fex, b_lo, b_hi)
            dt, mass_rate, ok, a_lo, a_hi, changed = advect_step(
                q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, rec, q0,
                diag_keep, fex_keep, first, lo, hi, b_lo, b_hi)
            if ifcp and not ok:
                # IFCP is Roe's linearisation for one layer: not positive where cells
                # move apart fast. Redo the step with HLL, which is, and count it.
                _copy_cells(q, backup, b_lo, b_hi)
                _copy_range(diag, diag_keep, 0, L.N_DIAG - 1)
                _copy_range(fex, fex_keep, b_lo, b_hi)
                diag[L.D_FLUX_FALLBACKS] += 1.0
                dt, mass_rate, ok, a_lo, a_hi, changed = hll_step(
                    q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, rec,
                    q0, diag_keep, fex_keep, first, lo, hi, b_lo, b_hi)
            t_new = t + dt if dt < t_end - t else t_end
            if not ok:
                _copy_cells(q, backup, b_lo, b_hi)
                return t, steps, STATUS_FAIL
            diag[L.D_DT] = 0.5 * dt if strang else dt
            if first:
                a_lo = 0
                a_hi = n - 1
            elif a_lo > a_hi:
                a_lo = s_lo  # nothing wet: the stage only needs to clear the last F_extra
                a_hi = s_lo - 1
            # F_extra of cells that left the active region
            for i in range(s_lo, min(s_hi, a_lo - 1) + 1):
                fex[i] = 0.0
            for i in range(max(s_lo, a_hi + 1), s_hi + 1):
                fex[i] = 0.0
            sources(q, 0.5 * dt if strang else dt, t_new, P, diag, a_lo, a_hi)
            changed = max(changed, diag[L.D_CHANGED])
            s_lo = a_lo
            s_hi = a_hi
            if lo <= hi:
                w_lo = max(lo - 2, 0)
                w_hi = min(hi + 2, n - 1)
            first = False
            t = t_new
            steps += 1
            if stop_at_rest and mass_rate == 0.0 and changed == 0.0:
                return t, steps, STATUS_REST
        return t, steps, STATUS_END

    return advance


STEPPING_SIGNATURE = (STATE, f8, f8, f8, i8, i8, PARAMS, f8, VECTOR, FIELDS, FIELDS, WORK,
                      i8, flag)
ADVECT_STEP_SIGNATURE = (STATE, f8, f8, f8, i8, i8, PARAMS, f8, VECTOR, FIELDS, FIELDS,
                         WORK, FIELDS, VECTOR, VECTOR, flag, i8, i8, i8, i8)


@functools.cache
def advect_step_kernel(two_layer: bool, flux: int, order: int, limiter: int,
                       strang: bool) -> Any:
    """:func:`advect_step_function` of one scheme, compiled."""
    advect = advection_kernel(two_layer, flux, order, limiter)
    return specialise(advect_step_function(two_layer, order, strang, advect),
                      *ADVECT_STEP_SIGNATURE)


@functools.cache
def stepping_kernel(two_layer: bool, flux: int, order: int, limiter: int,
                    strang: bool) -> Any:
    """The ``fv-split`` stepping loop of one scheme (compiled on first use, see
    :func:`pdeflow.numerics.compiled.ready`): advance ``q`` from ``t`` to ``t_end``
    with the CFL-limited splitting scheme,

    ``advance(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, work,
    max_steps, stop_at_rest) -> (t, steps, status)``.

    ``rate`` and ``backup`` have the shape of ``q``; ``work`` has shape (3, *q.shape).
    ``flux`` (layout.FLUX_*), ``order`` (1: first order with forward Euler; 2: MUSCL
    with the SSP-RK2/Heun integrator, see
    :func:`~pdeflow.numerics.friction.predictor_two_layer`) and ``limiter``
    (layout.LIMITER_*) choose the advection stage; ``strang`` applies half a source
    step before and after it (else Lie, as in the paper). With Strang, dt is chosen
    before the first half source step; if that half step makes the waves faster than
    dt allows (erosion deepens the upper layer), it is undone and the step retried
    with a shorter dt.

    Returns ``(t, steps, status)``: status :data:`STATUS_END`; :data:`STATUS_REST`
    (everything at rest and unchanged: stationary from ``t`` on); or
    :data:`STATUS_FAIL` (the last step produced a non-finite or negative state and was
    undone; ``q`` holds the last good state).
    """
    ifcp = flux == L.FLUX_IFCP
    step = advect_step_kernel(two_layer, flux, order, limiter, strang)
    hll_step = advect_step_kernel(two_layer, L.FLUX_HLL, order, limiter, strang) \
        if ifcp else step
    return specialise(stepping_function(two_layer, ifcp, strang, step, hll_step),
                      *STEPPING_SIGNATURE, entry=True)


def python_stepping(two_layer: bool, flux: int, order: int, limiter: int, strang: bool,
                    update: Any) -> Any:
    """:func:`stepping_kernel` as plain Python around the compiled advection and source
    kernels, with ``update`` for :func:`update` (the blow-up diagnosis replays a step
    with an update that records what it wrote)."""

    # compiled (and closed to other signatures) before Python calls its kernels
    ready(stepping_kernel(two_layer, flux, order, limiter, strang))

    def step(fl: int) -> Any:
        advect = advection_kernel(two_layer, fl, order, limiter)
        return advect_step_function(two_layer, order, strang, advect, update)

    ifcp = flux == L.FLUX_IFCP
    return stepping_function(two_layer, ifcp, strang, step(flux),
                             step(L.FLUX_HLL) if ifcp else None)


def advance_split(q: np.ndarray, t: float, t_end: float, dx: float, bc_left: int,
                  bc_right: int, P: np.ndarray, cfl: float, diag: np.ndarray,
                  rate: np.ndarray, backup: np.ndarray, work: np.ndarray, max_steps: int,
                  two_layer: bool, stop_at_rest: bool, flux: int, order: int,
                  limiter: int, strang: bool) -> tuple[float, int, int]:
    """:func:`stepping_kernel` of the scheme given by the last five codes, called on the
    other arguments: ``(t, steps, status)``."""
    kernel = ready(stepping_kernel(bool(two_layer), int(flux), int(order), int(limiter),
                                   bool(strang)))
    return kernel(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, work,
                  max_steps, stop_at_rest)
