r"""The paper's operator-split scheme: source stages (30)-(34) and the CFL stepping loop.

One step of length dt (Lie splitting, as in the paper):

1. advection (29): q <- q + dt L_HLL(q), dt = CFL dx / max|S| over the faces;
2. exchange (31): limited closure (25), see :func:`pdeflow.numerics.sources.exchange_depth`;
   the exchanged mass carries the velocity of the layer it leaves;
3. implicit momentum sources (32): gravity along the bed, Voellmy interface stress
   (t1 - M du where the step eroded, see :mod:`pdeflow.numerics.sources`), Coulomb basal
   friction, solved for both layers together;
4. hyperbolicity (33)-(34): where the inner eigenvalues are complex, stage 3 is
   repeated with the smallest extra exchange F_extra that restores hyperbolicity.

Stages 2-4 form :func:`source_stage_two_layer`, which is also what the PDE's post-step
hook runs; with dt = 0 it only cleans up (non-negative depths, zero velocity in dry
cells), which is what a method-of-lines solver needs. :func:`advance_two_layer` is
the stepping loop of the ``fv-split`` solver: compiled once and cached on disk, with
all parameters passed as arrays, so that sweeps never recompile.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import layout as L
from .advection import advect_single, advect_two_layer, wet_cells
from .hyperbolicity import band_lower_edge, is_hyperbolic, lower_bound_fl
from .sources import _drag_root, coulomb_single, exchange_step, friction_two_layer
from .state import velocity

STATUS_END = 0  #: reached t_end
STATUS_REST = 1  #: everything at rest: nothing will change any more
STATUS_FAIL = 2  #: non-finite or negative state: the step was undone


@njit(cache=True)
def _friction(b1, b2, h1, h2, dt, P, f, k, c):
    """Implicit stage (32) for one cell with extra exchange ``f`` = F_extra/rho2 and the
    interface law (22) with friction reduction ``k`` and collisional coefficient ``c``
    (the parameters', or those of t1 - M du in a cell that eroded this step)."""
    r = P[L.R]
    g = P[L.G_Z]
    dry = P[L.DRY]
    wet1 = h1 > dry
    wet2 = h2 > dry
    if wet1 and wet2:
        m1 = r * h1
        if f != 0.0:
            b1 = b1 - dt * f / m1
            b2 = b2 + dt * f / h2
        kdt = dt * k * r * g * h1 * P[L.TAN_INT]
        bdt = dt * g * (r * h1 + h2) * P[L.TAN_B]
        return friction_two_layer(b1, b2, m1, h2, kdt, dt * c, bdt)
    if wet1:
        # no lower layer: the upper layer rubs on the bed with the interface law (22)
        m1 = r * h1
        kdt = dt * k * r * g * h1 * P[L.TAN_INT]
        u1 = _drag_root(m1 * abs(b1) - kdt, m1, dt * c)
        return (u1 if b1 > 0.0 else -u1), 0.0
    if wet2:
        mu_dt = dt * g * P[L.TAN_B] * (h2 + r * max(h1, 0.0)) / h2
        return 0.0, coulomb_single(b2, mu_dt)
    return 0.0, 0.0


@njit(cache=True)
def _bisect_fextra(b1, b2, h1, h2, du0, dt, P, k, c):
    """F_extra/rho2 [m^2/s^2] by bracketing and bisection on the hyperbolicity test:
    the fallback of :func:`_restore_hyperbolicity`, stopping when the bracket in du is
    below w."""
    g = P[L.G_Z]
    r = P[L.R]
    mode = int(P[L.HYPERBOLICITY])
    w = P[L.W]
    # Bracket: f_lo leaves du of the original sign and non-hyperbolic; f_hi makes the
    # state hyperbolic or flips the sign of du (du(f) decreases monotonically in f, so
    # the smallest hyperbolic f lies before the sign change).
    f_hi = du0 / (dt * (1.0 / (r * h1) + 1.0 / h2))
    f_lo = 0.0
    du_lo = abs(du0)
    sgn = 1.0 if du0 > 0.0 else -1.0
    for _ in range(60):
        v1, v2 = _friction(b1, b2, h1, h2, dt, P, f_hi, k, c)
        du_hi = sgn * (v1 - v2)
        if du_hi <= 0.0 or is_hyperbolic(h1, h2, v1, v2, g, r, mode):
            break
        f_lo = f_hi
        du_lo = du_hi
        f_hi *= 2.0
    for _ in range(200):
        if du_lo - du_hi <= w or abs(f_hi - f_lo) <= 1e-12 * abs(f_hi):
            break
        f_mid = 0.5 * (f_lo + f_hi)
        v1, v2 = _friction(b1, b2, h1, h2, dt, P, f_mid, k, c)
        du_mid = sgn * (v1 - v2)
        if du_mid <= 0.0 or is_hyperbolic(h1, h2, v1, v2, g, r, mode):
            f_hi = f_mid
            du_hi = du_mid
        else:
            f_lo = f_mid
            du_lo = du_mid
    return f_hi


@njit(cache=True)
def _restore_hyperbolicity(b1, b2, h1, h2, u1, u2, dt, P, k, c):
    r"""Smallest F_extra/rho2 [m^2/s^2] making the post-friction state hyperbolic, the
    velocities (u1, u2) [m/s] it leads to, and whether the bisection fallback was used.

    The depths are frozen, so the target is a relative velocity: the lower band edge
    F_c1 (F_L in ``bound`` mode). Stage (32) with the extra exchange f = F_extra/rho2
    shifts b1 by -dt f/m1 and b2 by +dt f/m2 and keeps m1 b1 + m2 b2, so on each branch
    of its closed-form solution (:func:`pdeflow.numerics.sources.friction_two_layer`)
    du is an explicit function of f, inverted here for du = sgn(du0) d with

    * lower layer sliding in direction s2 (mu = m1 m2/(m1 + m2), p = m1 b1 + m2 b2
      - dt B s2): :math:`m_1 b_1 - m_1 p/(m_1+m_2) - \Delta t f
      = \mathrm{sgn}(du_0)\,(\Delta t K + \mu d + \Delta t C d^2)`;
    * lower layer stuck: :math:`m_1 (b_1 - \Delta t f/m_1)
      = \mathrm{sgn}(du_0)\,(\Delta t K + m_1 d + \Delta t C d^2)`.

    The branch is not known beforehand: each candidate is checked by solving (32)
    with it (|du| must land within w below the edge, where the state is hyperbolic);
    if none passes (round-off at a branch boundary), bisection decides
    (:func:`_bisect_fextra`).
    """
    g = P[L.G_Z]
    r = P[L.R]
    mode = int(P[L.HYPERBOLICITY])
    du0 = u1 - u2
    if mode == 2:
        edge = lower_bound_fl(h1, h2, g, r)
    else:
        edge = band_lower_edge(h1, h2, g, r, abs(du0))
    if edge > 0.0:
        d = edge * (1.0 - 1e-8)  # a hair inside: round-off must not leave the band edge
        sgn = 1.0 if du0 > 0.0 else -1.0
        m1 = r * h1
        m2 = h2
        mt = m1 + m2
        kdt = dt * k * r * g * h1 * P[L.TAN_INT]
        cdt = dt * c
        bdt = dt * g * (r * h1 + h2) * P[L.TAN_B]
        s_first = 1.0 if u2 >= 0.0 else -1.0
        for branch in range(3):
            if branch == 2:
                f = (m1 * b1 - sgn * (kdt + m1 * d + cdt * d * d)) / dt
            else:
                s2 = s_first if branch == 0 else -s_first
                p = m1 * b1 + m2 * b2 - bdt * s2
                f = (m1 * b1 - m1 * p / mt
                     - sgn * (kdt + m1 * m2 / mt * d + cdt * d * d)) / dt
            if f * sgn <= 0.0:
                continue
            v1, v2 = _friction(b1, b2, h1, h2, dt, P, f, k, c)
            # below the edge is hyperbolic down to F_L (the band is one interval)
            if edge - P[L.W] <= sgn * (v1 - v2) <= edge:
                return f, v1, v2, False
    f = _bisect_fextra(b1, b2, h1, h2, du0, dt, P, k, c)
    v1, v2 = _friction(b1, b2, h1, h2, dt, P, f, k, c)
    return f, v1, v2, True


@njit(cache=True)
def source_stage_two_layer(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                           diag: np.ndarray) -> None:
    """Stages (31)-(34) on the two-layer state ``q`` in place, for a step ``dt`` [s].

    ``t`` is the time at the end of the step [s]; ``diag`` receives the bookkeeping
    listed in :mod:`pdeflow.numerics.layout` and, from index N_DIAG on, F_extra/rho1
    per cell [m^2/s^2].
    """
    sources_two_layer(q, dt, t, P, diag, 0, q.shape[1] - 1)


@njit(cache=True)
def sources_two_layer(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                      diag: np.ndarray, lo: int, hi: int) -> None:
    """:func:`source_stage_two_layer` on the cells ``lo..hi`` only (the others must be
    dry and at rest, where the stage changes nothing)."""
    r = P[L.R]
    g = P[L.G_Z]
    gx = P[L.G_X]
    dry = P[L.DRY]
    slow_u = P[L.SLOW_U]
    slow_h = P[L.SLOW_H]
    mode = int(P[L.HYPERBOLICITY])
    moving1 = False
    moving2 = False
    fast1 = False
    fast2 = False
    changed = False
    fex = diag[L.N_DIAG:]
    for i in range(lo, hi + 1):
        h1 = q[0, i]
        m1 = q[1, i]
        h2 = q[2, i]
        m2 = q[3, i]
        if fex[i] != 0.0:
            fex[i] = 0.0
        if h1 == 0.0 and h2 == 0.0 and m1 == 0.0 and m2 == 0.0:
            continue
        h1 = max(h1, 0.0)
        h2 = max(h2, 0.0)
        u1 = velocity(h1, m1, dry)
        u2 = velocity(h2, m2, dry)
        if dt > 0.0:
            # interface stress of (32): the paper's t1 (22) unless erosion rewrites it
            k_eff = P[L.K]
            c_eff = P[L.C]
            # --- (31) mass exchange; the exchanged mass carries the velocity of the layer
            # it leaves (upwind): u1 when depositing, u2 when eroding ------------------
            if h1 > 0.0 and P[L.TAU_STAR] >= 0.0:
                tau = P[L.TAU_STAR] * math.sqrt((h1 + h2) / g) if P[L.TAU_STAR] > 0.0 \
                    else 0.0
                du = u1 - u2
                dh1, full = exchange_step(h1, h2, du, dt, r, g, P[L.TAN_INT], P[L.K],
                                          P[L.C], P[L.DU_REG], P[L.FILM], tau)
                if dh1 != 0.0:
                    mom = h2 * u2 + r * h1 * u1  # rho-weighted momentum / rho2
                    phi = 0.0
                    if dh1 > 0.0:
                        u1 = (h1 * u1 + dh1 * u2) / (h1 + dh1)
                        phi = min(dh1 / full, 1.0) if full > 0.0 else 1.0
                    h1 = h1 + dh1
                    h2 = max(h2 - r * dh1, 0.0)
                    if h1 <= dry:
                        h1 = h1 if h1 > 0.0 else 0.0
                        u1 = 0.0
                    # lower layer takes the rest of the (rho-weighted) momentum
                    if h2 > dry:
                        u2 = (mom - r * h1 * u1) / h2
                        if phi > 0.0:
                            # t1 - M du = phi t2 + (1 - phi) t1 (see the module docstring)
                            k_eff = P[L.K] + phi * (1.0 - P[L.K])
                            c_eff = (1.0 - phi) * P[L.C]
                    else:
                        u2 = 0.0
                        if h1 > dry:
                            u1 = mom / (r * h1)
                    changed = True
                    if dh1 < 0.0:
                        diag[L.D_DEPOSITED] -= dh1
                    else:
                        diag[L.D_ERODED] += dh1
            # --- (32) implicit momentum sources ------------------------------------------
            b1 = u1 + dt * gx if h1 > dry else 0.0
            b2 = u2 + dt * gx if h2 > dry else 0.0
            v1, v2 = _friction(b1, b2, h1, h2, dt, P, 0.0, k_eff, c_eff)
            # --- (33)-(34) hyperbolicity --------------------------------------------------
            if mode > 0 and h1 > dry and h2 > dry:
                if not is_hyperbolic(h1, h2, v1, v2, g, r, mode):
                    f, v1, v2, bisected = _restore_hyperbolicity(b1, b2, h1, h2, v1, v2,
                                                                 dt, P, k_eff, c_eff)
                    if bisected:
                        diag[L.D_HYP_BISECTIONS] += 1.0
                    fex[i] = abs(f) / r
                    diag[L.D_HYP_EVENTS] += 1.0
                    if fex[i] > diag[L.D_FEXTRA_MAX]:
                        diag[L.D_FEXTRA_MAX] = fex[i]
                        diag[L.D_FEXTRA_CELL] = i
                        diag[L.D_FEXTRA_TIME] = t
            u1 = v1
            u2 = v2
        m1 = h1 * u1 if h1 > dry else 0.0
        m2 = h2 * u2 if h2 > dry else 0.0
        if m1 != 0.0:
            moving1 = True
            if h1 > slow_h and abs(u1) >= slow_u:
                fast1 = True
        if m2 != 0.0:
            moving2 = True
            if h2 > slow_h and abs(u2) >= slow_u:
                fast2 = True
        q[0, i] = h1
        q[1, i] = m1
        q[2, i] = h2
        q[3, i] = m2
    if moving1:
        diag[L.D_MOVE_UPPER] = t
    if moving2:
        diag[L.D_MOVE_LOWER] = t
    if fast1:
        diag[L.D_FAST_UPPER] = t
    if fast2:
        diag[L.D_FAST_LOWER] = t
    diag[L.D_CHANGED] = 1.0 if (changed or moving1 or moving2) else 0.0
    diag[L.D_T] = t
    diag[L.D_STEPS] += 1.0


@njit(cache=True)
def source_stage_single(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                        diag: np.ndarray) -> None:
    """Implicit Coulomb friction (and gravity along the bed) for the single layer."""
    sources_single(q, dt, t, P, diag, 0, q.shape[1] - 1)


@njit(cache=True)
def sources_single(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                   diag: np.ndarray, lo: int, hi: int) -> None:
    """:func:`source_stage_single` on the cells ``lo..hi`` only."""
    g = P[L.S_G_Z]
    gx = P[L.S_G_X]
    dry = P[L.S_DRY]
    mu_dt = dt * g * P[L.S_TAN_B]
    moving = False
    fast = False
    for i in range(lo, hi + 1):
        h = q[0, i]
        m = q[1, i]
        if h == 0.0 and m == 0.0:
            continue
        h = max(h, 0.0)
        u = velocity(h, m, dry)
        if dt > 0.0 and h > dry:
            u = coulomb_single(u + dt * gx, mu_dt)
        m = h * u if h > dry else 0.0
        if m != 0.0:
            moving = True
            if h > P[L.S_SLOW_H] and abs(u) >= P[L.S_SLOW_U]:
                fast = True
        q[0, i] = h
        q[1, i] = m
    if moving:
        diag[L.D_MOVE_UPPER] = t
    if fast:
        diag[L.D_FAST_UPPER] = t
    diag[L.D_CHANGED] = 1.0 if moving else 0.0
    diag[L.D_T] = t
    diag[L.D_STEPS] += 1.0


@njit(cache=True)
def _update(q, base, rate, dt, weight, lo, hi):
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


@njit(cache=True)
def _rate(q, rate, work, dx, bc_left, bc_right, P, two_layer, flux, order, limiter,
          start, stop):
    """Advection rate of the wet cells within ``start..stop`` (all others dry):
    returns (largest wave speed, first, last cell whose rate was written)."""
    dry = P[L.DRY] if two_layer else P[L.S_DRY]
    lo, hi = wet_cells(q, dry, start, stop)
    if two_layer:
        return advect_two_layer(q, rate, work, dx, bc_left, bc_right, P[L.G_Z], P[L.R],
                                dry, flux, order, limiter, lo, hi)
    return advect_single(q, rate, work, dx, bc_left, bc_right, P[L.S_G_Z], dry, flux,
                         order, limiter, lo, hi)


@njit(cache=True)
def _sources(q, dt, t, P, diag, two_layer, lo, hi):
    if two_layer:
        sources_two_layer(q, dt, t, P, diag, lo, hi)
    else:
        sources_single(q, dt, t, P, diag, lo, hi)


@njit(cache=True)
def friction_predictor(q: np.ndarray, dt: float, P: np.ndarray, two_layer: bool,
                       lo: int, hi: int) -> None:
    """Zero the momentum of layers that the implicit friction (32) would hold at rest,
    in place. Applied to the intermediate stage of SSP-RK2: otherwise the predictor's
    pressure momentum, which friction balances, moves mass and heaps creep. Moving
    layers are left untouched (friction proper is applied once, in the source stage).
    Only the cells ``lo..hi`` are visited."""
    for i in range(lo, hi + 1):
        if two_layer:
            dry = P[L.DRY]
            h1 = max(q[0, i], 0.0)
            h2 = max(q[2, i], 0.0)
            if h1 <= dry and h2 <= dry:
                continue
            b1 = velocity(h1, q[1, i], dry) + dt * P[L.G_X] if h1 > dry else 0.0
            b2 = velocity(h2, q[3, i], dry) + dt * P[L.G_X] if h2 > dry else 0.0
            u1, u2 = _friction(b1, b2, h1, h2, dt, P, 0.0, P[L.K], P[L.C])
            if u1 == 0.0:
                q[1, i] = 0.0
            if u2 == 0.0:
                q[3, i] = 0.0
        else:
            dry = P[L.S_DRY]
            h = max(q[0, i], 0.0)
            if h > dry:
                u = coulomb_single(q[1, i] / h + dt * P[L.S_G_X],
                                   dt * P[L.S_G_Z] * P[L.S_TAN_B])
                if u == 0.0:
                    q[1, i] = 0.0


@njit(cache=True)
def _advect_step(q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, rec, q0,
                 diag_keep, fex_keep, two_layer, flux, order, limiter, strang, first, lo,
                 hi, b_lo, b_hi):
    """The advection stage of one step of :func:`advance_split` (with Strang, the first
    half source step before it), from the wet cells ``lo..hi``; ``b_lo..b_hi`` are the
    cells the step may change, saved in ``backup`` (and, for Strang, the bookkeeping in
    ``diag_keep``, ``fex_keep``).

    Returns ``(dt, mass_rate, ok, a_lo, a_hi, changed)``: the step [s], the largest mass
    rate, whether the state is finite and non-negative, the cells the update touched and
    whether the half source step changed anything.
    """
    fex = diag[L.N_DIAG:]
    smax, a_lo, a_hi = _rate(q, rate, rec, dx, bc_left, bc_right, P, two_layer,
                             flux, order, limiter, lo, hi)
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
            _sources(q, 0.5 * dt, t, P, diag, two_layer, h_lo, h_hi)
            changed = diag[L.D_CHANGED]
            # (a deposit can lift a cell of sub-dry layers above dry: search wider)
            smax2, a_lo, a_hi = _rate(q, rate, rec, dx, bc_left, bc_right, P,
                                      two_layer, flux, order, limiter, b_lo, b_hi)
            if smax2 * dt <= cfl * dx * (1.0 + 1e-9) or attempt == 39:
                break
            # the half source step made the waves faster than dt allows (erosion
            # can deepen the upper layer 1/r-fold): undo it and retry shorter
            q[:, b_lo:b_hi + 1] = backup[:, b_lo:b_hi + 1]
            diag[:L.N_DIAG] = diag_keep
            fex[b_lo:b_hi + 1] = fex_keep[b_lo:b_hi + 1]
            dt = min(0.5 * dt, cfl * dx / smax2)
    if order == 1:
        mass_rate, ok = _update(q, q, rate, dt, 0.0, a_lo, a_hi)
    else:
        q0[:, b_lo:b_hi + 1] = q[:, b_lo:b_hi + 1]
        mass_rate, ok = _update(q, q0, rate, dt, 0.0, a_lo, a_hi)
        if ok:
            friction_predictor(q, dt, P, two_layer, a_lo, a_hi)
            _, c_lo, c_hi = _rate(q, rate, rec, dx, bc_left, bc_right, P,
                                  two_layer, flux, order, limiter, b_lo, b_hi)
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
            mass2, ok = _update(q, q0, rate, dt, 0.5, a_lo, a_hi)
            mass_rate = max(mass_rate, mass2)
    return dt, mass_rate, ok, a_lo, a_hi, changed


@njit(cache=True)
def advance_split(q: np.ndarray, t: float, t_end: float, dx: float, bc_left: int,
                  bc_right: int, P: np.ndarray, cfl: float, diag: np.ndarray,
                  rate: np.ndarray, backup: np.ndarray, work: np.ndarray, max_steps: int,
                  two_layer: bool, stop_at_rest: bool, flux: int, order: int,
                  limiter: int, strang: bool):
    """Advance ``q`` from ``t`` to ``t_end`` with the CFL-limited splitting scheme.

    ``rate`` and ``backup`` have the shape of ``q``; ``work`` has shape (3, *q.shape).
    ``flux`` (layout.FLUX_*), ``order`` (1: first order with forward Euler; 2: MUSCL
    with the SSP-RK2/Heun integrator, see :func:`friction_predictor`) and ``limiter``
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
    n = q.shape[1]
    steps = 0
    rec = work[:2]
    q0 = work[2]
    fex = diag[L.N_DIAG:]
    # to undo a Strang half source step that broke the CFL, or an IFCP step
    diag_keep = np.empty(L.N_DIAG)
    fex_keep = np.empty(n)
    # Cells outside the wet region plus the stencil are dry and at rest, which every
    # stage leaves unchanged: only the active cells are visited. The first step visits
    # all cells (the source stage cleans the initial state); the wet region then grows
    # by at most one cell per advection stage, so the next search window is the last
    # region widened by two.
    w_lo = 0
    w_hi = n - 1
    s_lo = 0
    s_hi = n - 1
    first = True
    while t < t_end and steps < max_steps:
        # cells a step can change: two advection stages around the wet region
        lo, hi = wet_cells(q, P[L.DRY] if two_layer else P[L.S_DRY], w_lo, w_hi)
        if first:
            b_lo = 0
            b_hi = n - 1
        elif lo > hi:
            b_lo = 1
            b_hi = 0
        else:
            b_lo = max(lo - 2, 0)
            b_hi = min(hi + 2, n - 1)
        backup[:, b_lo:b_hi + 1] = q[:, b_lo:b_hi + 1]
        if strang or flux == L.FLUX_IFCP:
            diag_keep[:] = diag[:L.N_DIAG]
            fex_keep[b_lo:b_hi + 1] = fex[b_lo:b_hi + 1]
        fl = flux
        for _ in range(2):
            dt, mass_rate, ok, a_lo, a_hi, changed = _advect_step(
                q, t, t_end, dx, bc_left, bc_right, P, cfl, diag, rate, backup, rec, q0,
                diag_keep, fex_keep, two_layer, fl, order, limiter, strang, first, lo, hi,
                b_lo, b_hi)
            if ok or fl != L.FLUX_IFCP:
                break
            # IFCP is Roe's linearisation for one layer: not positive where cells move
            # apart fast. Redo the step with HLL, which is, and count it.
            q[:, b_lo:b_hi + 1] = backup[:, b_lo:b_hi + 1]
            diag[:L.N_DIAG] = diag_keep
            fex[b_lo:b_hi + 1] = fex_keep[b_lo:b_hi + 1]
            diag[L.D_FLUX_FALLBACKS] += 1.0
            fl = L.FLUX_HLL
        t_new = t + dt if dt < t_end - t else t_end
        if not ok:
            q[:, b_lo:b_hi + 1] = backup[:, b_lo:b_hi + 1]
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
        _sources(q, 0.5 * dt if strang else dt, t_new, P, diag, two_layer, a_lo, a_hi)
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
