r"""Implicit friction (32) of one cell with vector velocities, and the restoration of
hyperbolicity along the shear (33)-(34) in 2D.

Backward Euler for the momentum sources with the depths frozen, as in 1D
(:mod:`.exchange`), now for vectors: with m1 = r h1, m2 = h2 and b = u + dt (g_x, g_y),

.. math::  m_1 (u_1 - b_1) + \Delta t\, F_{12} = 0,\qquad
           m_2 (u_2 - b_2) - \Delta t\, F_{12} + \Delta t\, F_B = 0,

.. math::  F_{12} \in K\,\mathrm{Sgn}(u_1 - u_2) + C\,(u_1 - u_2)|u_1 - u_2|,\qquad
           F_B \in B\,\mathrm{Sgn}(u_2),

Sgn(v) = v/|v| for v != 0 and the unit disc at 0: each friction opposes its relative
velocity and is set-valued. These are the optimality conditions of a strictly convex
function of (u1, u2), so the solution is unique. It is found as in 1D: the upper layer
over a stuck lower layer slides along b1 with the 1D closed-form speed; the lower layer
sticks if the force it must resist, push = m2 b2 + m1 (b1 - u1), is within B dt; else it
slides along a direction e for which the 1D sliding solution (total momentum
p = m1 b1 + m2 b2 - B dt e, relative velocity along rel = m1 (b1 - p/mt)) gives a lower
layer moving along e. The 1D solution along the push ("it slides the way it is
pushed") is taken if its lower layer moves along the push; otherwise damped Newton
minimises the convex function of the lower layer's velocity left when the upper
layer's is eliminated (:func:`_gradient`), from that solution.

A cell whose velocities all lie along one axis (all other components exactly zero: a
run uniform across y, or rotated) is solved by the 1D kernels of :mod:`.friction`
(its implicit friction, and the closed-form restoration to the band edge), so such a
2D run does the 1D arithmetic to the bit; a Coulomb layer whose drive is within the
friction bound stays exactly at rest either way.
"""

from __future__ import annotations

import functools
import math
from typing import Any

from ...numerics.compiled import cached, specialise
from ...numerics.implicit import drag_root
from .friction import FP_DRY, FP_G, FP_R, FP_TAN_B, FP_TAN_INT, FP_W, FrictionKernels

DIRECTION_TOL = 1e-14
"""the 1D solution along the push is taken when its lower layer slides along the push
to within this [-]"""
NEWTON_ITERATIONS = 60
"""at most this many Newton steps for a lower layer sliding off the push's direction"""
NEWTON_TOL = 1e-14
"""Newton stops at a step below this times the lower layer's speed [-]"""
ROUNDOFF = 4.0 * 2.0 ** -52
"""Newton's backtracking stops at a step below this times the lower layer's speed [-]
(four units in the last place: the residual's round-off, not its decrease, decides)"""


@cached(inline="always")
def _along(x, y, speed):
    """``speed`` [m/s] along the direction of the vector (x, y) (0 if it is zero): the
    unit vector first, so that (x, 0) gives (sgn(x) speed, 0) exactly."""
    n = math.sqrt(x * x + y * y)
    if n == 0.0:
        return 0.0, 0.0
    return x / n * speed, y / n * speed


@cached(inline="always")
def _slide(ex, ey, p0x, p0y, b1x, b1y, m1, mt, mu, Kdt, Cdt, Bdt):
    """(d, u2) of the lower layer sliding along (ex, ey): the 1D sliding solution
    (:func:`.exchange._sliding`) with vectors."""
    px = p0x - Bdt * ex
    py = p0y - Bdt * ey
    relx = m1 * (b1x - px / mt)
    rely = m1 * (b1y - py / mt)
    dx, dy = _along(relx, rely, drag_root(math.sqrt(relx * relx + rely * rely) - Kdt,
                                          mu, Cdt))
    return dx, dy, (px - m1 * dx) / mt, (py - m1 * dy) / mt


@cached(inline="always")
def _upper_over(u2x, u2y, b1x, b1y, m1, Kdt, Cdt):
    """The upper layer over a lower layer moving at u2: (s, nx, ny, rho, ds/drho): its
    speed s [m/s] relative to u2 along n = (b1 - u2)/rho, rho = |b1 - u2| [m/s]."""
    vx = b1x - u2x
    vy = b1y - u2y
    rho = math.sqrt(vx * vx + vy * vy)
    if rho == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    s = drag_root(m1 * rho - Kdt, m1, Cdt)
    slope = m1 / (m1 + 2.0 * Cdt * s) if s > 0.0 else 0.0
    return s, vx / rho, vy / rho, rho, slope


@cached(inline="always")
def _gradient(u2x, u2y, b1x, b1y, b2x, b2y, m1, m2, Kdt, Cdt, Bdt):
    """Gradient (gx, gy) [m^2/s] and Hessian (hxx, hyy, hxy) [m] of the convex function
    of the lower layer's velocity u2 (u2 != 0) whose minimum is stage (32) (the upper
    layer's velocity eliminated: its Moreau envelope): the gradient is the residual
    m2 (u2 - b2) + m1 (u1 - b1) + B dt u2/|u2| of the lower layer's balance."""
    s, nx, ny, rho, slope = _upper_over(u2x, u2y, b1x, b1y, m1, Kdt, Cdt)
    n2 = math.sqrt(u2x * u2x + u2y * u2y)
    ex = u2x / n2
    ey = u2y / n2
    gx = m2 * (u2x - b2x) + m1 * (s - rho) * nx + Bdt * ex
    gy = m2 * (u2y - b2y) + m1 * (s - rho) * ny + Bdt * ey
    along = m1 * (1.0 - slope)
    across = m1 * (1.0 - s / rho) if rho > 0.0 else m1
    bend = Bdt / n2
    hxx = m2 + bend * (1.0 - ex * ex) + along * nx * nx + across * (1.0 - nx * nx)
    hyy = m2 + bend * (1.0 - ey * ey) + along * ny * ny + across * (1.0 - ny * ny)
    hxy = -bend * ex * ey + (along - across) * nx * ny
    return gx, gy, hxx, hyy, hxy


@cached
def _newton(u2x, u2y, b1x, b1y, b2x, b2y, m1, m2, Kdt, Cdt, Bdt):
    """The sliding lower layer's velocity (u2x, u2y) [m/s]: damped Newton on the
    residual of :func:`_gradient` from (u2x, u2y), backtracking on its squared norm
    (a descent direction for it, as the Hessian is positive definite; unlike the
    function's values it resolves the root to round-off)."""
    gx, gy, hxx, hyy, hxy = _gradient(u2x, u2y, b1x, b1y, b2x, b2y, m1, m2, Kdt, Cdt,
                                      Bdt)
    for _ in range(NEWTON_ITERATIONS):
        det = hxx * hyy - hxy * hxy
        if not det > 0.0:
            # Near u2 = 0 the kink's term B dt / |u2| (the 'bend') dominates the
            # Hessian, which is then rank one to round-off (det rounds to 0 or below:
            # measured |u2| ~ 1e-19 m/s, Hessian ~ 1e10 m). The iterate is at the
            # minimum to round-off, as when the line search finds no decrease; dividing
            # would raise ZeroDivisionError in the compiled kernel, which numba cannot
            # propagate out of it and swallows, leaving the source stage half done.
            return u2x, u2y
        dx = -(hyy * gx - hxy * gy) / det
        dy = -(hxx * gy - hxy * gx) / det
        norm = gx * gx + gy * gy
        # a step shorter than this moves u2 by less than its round-off: halving it
        # further cannot lower the residual (without this bound a third of the solves
        # ended after 40 halvings, 14 of the 17 gradients a solve took)
        step = math.sqrt(dx * dx + dy * dy)
        if step == 0.0:
            break  # the residual is zero
        least = ROUNDOFF * math.sqrt(u2x * u2x + u2y * u2y) / step
        t = 1.0
        while True:
            vx = u2x + t * dx
            vy = u2y + t * dy
            if vx != 0.0 or vy != 0.0:
                g = _gradient(vx, vy, b1x, b1y, b2x, b2y, m1, m2, Kdt, Cdt, Bdt)
                if g[0] * g[0] + g[1] * g[1] <= (1.0 - 1e-4 * t) * norm:
                    break
            t *= 0.5
            if t < 1e-12 or t <= least:
                return u2x, u2y  # no decrease left: at the root to round-off
        u2x = vx
        u2y = vy
        gx, gy, hxx, hyy, hxy = g
        if t == 1.0 and math.sqrt(dx * dx + dy * dy) <= NEWTON_TOL * math.sqrt(
                u2x * u2x + u2y * u2y):
            break
    return u2x, u2y


@cached
def friction_two_layer_2d(b1x, b1y, b2x, b2y, m1, m2, Kdt, Cdt, Bdt):
    """The coupled implicit friction step of two wet layers with vector velocities:
    (u1x, u1y, u2x, u2y) [m/s]; arguments as
    :func:`.exchange.friction_two_layer`, velocities by component."""
    s1 = drag_root(m1 * math.sqrt(b1x * b1x + b1y * b1y) - Kdt, m1, Cdt)
    u1x, u1y = _along(b1x, b1y, s1)
    pushx = m2 * b2x + m1 * (b1x - u1x)
    pushy = m2 * b2y + m1 * (b1y - u1y)
    push = math.sqrt(pushx * pushx + pushy * pushy)
    if push <= Bdt:
        return u1x, u1y, 0.0, 0.0
    mt = m1 + m2
    mu = m1 * m2 / mt
    ex = pushx / push
    ey = pushy / push
    dx, dy, u2x, u2y = _slide(ex, ey, m1 * b1x + m2 * b2x, m1 * b1y + m2 * b2y, b1x, b1y,
                              m1, mt, mu, Kdt, Cdt, Bdt)
    if u2x * ex + u2y * ey <= 0.0:
        return dx, dy, 0.0, 0.0  # round-off at the stick/slip boundary, as in 1D
    n2 = math.sqrt(u2x * u2x + u2y * u2y)
    if abs(u2x / n2 - ex) + abs(u2y / n2 - ey) <= DIRECTION_TOL:
        return u2x + dx, u2y + dy, u2x, u2y  # slides the way it is pushed, as in 1D
    u2x, u2y = _newton(u2x, u2y, b1x, b1y, b2x, b2y, m1, m2, Kdt, Cdt, Bdt)
    s, nx, ny, _, _ = _upper_over(u2x, u2y, b1x, b1y, m1, Kdt, Cdt)
    return u2x + s * nx, u2y + s * ny, u2x, u2y


@cached(inline="always")
def coulomb_bed_2d(b1x, b1y, b2x, b2y, m1, h1, h2, kdt, cdt, dt, g, r, fp):
    """Stage (32) of two wet layers with Coulomb friction at the bed, vectors:
    (u1x, u1y, u2x, u2y) [m/s] (as :func:`.friction.bed_under_both`)."""
    bdt = dt * g * (r * h1 + h2) * fp[FP_TAN_B]
    return friction_two_layer_2d(b1x, b1y, b2x, b2y, m1, h2, kdt, cdt, bdt)


@functools.cache
def implicit_friction_2d(fk: FrictionKernels, bed: Any = coulomb_bed_2d) -> Any:
    """``(b1x, b1y, b2x, b2y, h1, h2, dt, fp, fx, fy, k, c) -> (u1x, u1y, u2x, u2y)``:
    stage (32) of one cell with vector velocities [m/s] and the extra exchange
    (fx, fy) = F_extra/rho2 [m^2/s^2]; the 1D kernel of ``fk`` where every vector lies
    along one axis, else ``bed`` (stage (32) of two wet layers with the basal law, as
    :func:`coulomb_bed_2d`); arguments as :func:`.friction.implicit_friction`'s."""
    one_d = fk.implicit_friction

    def implicit_friction_two_d(b1x, b1y, b2x, b2y, h1, h2, dt, fp, fx, fy, k, c):
        if b1y == 0.0 and b2y == 0.0 and fy == 0.0:
            u1, u2 = one_d(b1x, b2x, h1, h2, dt, fp, fx, k, c)
            return u1, 0.0, u2, 0.0
        if b1x == 0.0 and b2x == 0.0 and fx == 0.0:
            u1, u2 = one_d(b1y, b2y, h1, h2, dt, fp, fy, k, c)
            return 0.0, u1, 0.0, u2
        r = fp[FP_R]
        g = fp[FP_G]
        dry = fp[FP_DRY]
        wet1 = h1 > dry
        wet2 = h2 > dry
        m1 = r * h1
        kdt = dt * k * r * g * h1 * fp[FP_TAN_INT]
        if wet1 and wet2:
            b1x -= dt * fx / m1
            b1y -= dt * fy / m1
            b2x += dt * fx / h2
            b2y += dt * fy / h2
            return bed(b1x, b1y, b2x, b2y, m1, h1, h2, kdt, dt * c, dt, g, r, fp)
        if wet1:
            u1x, u1y = _along(b1x, b1y, drag_root(
                m1 * math.sqrt(b1x * b1x + b1y * b1y) - kdt, m1, dt * c))
            return u1x, u1y, 0.0, 0.0
        if wet2:
            # the 1D layer alone along b2: its speed is the 1D speed of |b2|
            s2 = one_d(0.0, math.sqrt(b2x * b2x + b2y * b2y), h1, h2, dt, fp, 0.0, k,
                       c)[1]
            u2x, u2y = _along(b2x, b2y, s2)
            return 0.0, 0.0, u2x, u2y
        return 0.0, 0.0, 0.0, 0.0

    return specialise(implicit_friction_two_d, helper=True)


RESTORE_PASSES = 8
"""at most this many searches along the shear of the moment (each one after the last
if the shear turned normal to its direction before |du| reached F_c1)"""


@cached(inline="always")
def _settled(v, ex, ey, aim):
    """Whether the velocities ``v`` = (u1x, u1y, u2x, u2y) [m/s] have |du| <= ``aim``
    [m/s] or du no longer along (ex, ey)."""
    dux = v[0] - v[2]
    duy = v[1] - v[3]
    return dux * ex + duy * ey <= 0.0 or math.sqrt(dux * dux + duy * duy) <= aim


@cached(inline="always")
def _regula_falsi(f_lo, d_lo, f_hi, d_hi, goal):
    """The next F_extra/rho2 [m^2/s^2] to try between ``f_lo`` (|du| = ``d_lo`` above
    the window) and ``f_hi`` (|du| = ``d_hi``): where the line through both reaches
    ``goal`` [m/s], kept a tenth of the bracket away from its ends so that the bracket
    shrinks each time (|du| falls about linearly in f, dt (1/m1 + 1/m2) per unit, until
    a friction bound is crossed: the first try usually lands in the window, where
    bisection took about ten)."""
    span = f_hi - f_lo
    if d_lo <= d_hi:
        return f_lo + 0.5 * span  # not falling: bisect
    f = f_lo + span * (d_lo - goal) / (d_lo - d_hi)
    return min(max(f, f_lo + 0.1 * span), f_hi - 0.1 * span)


@functools.cache
def restore_2d(fk: FrictionKernels, bed: Any = coulomb_bed_2d) -> Any:
    """``(b1x, b1y, b2x, b2y, h1, h2, v1x, v1y, v2x, v2y, dt, fp, k, c, edge) ->
    (f, v1x, v1y, v2x, v2y, bisected)``: the smallest F_extra/rho2 = f [m^2/s^2] along
    the post-friction shear du = v1 - v2 after which stage (32) gives |du| within w
    below ``edge`` [m/s] (F_c1: hyperbolic in every direction, docs/two_d.md), and the
    velocities it leads to (``bed`` as :func:`implicit_friction_2d`'s). Where every
    vector lies along one axis, the 1D closed form of ``fk``
    (:func:`.friction.restore_to_edge`); elsewhere a bracketed search on f along the
    shear (:func:`_regula_falsi`; repeated along the new shear if it turned normal to
    the old one first)."""
    one_d = fk.restore_to_edge
    friction = implicit_friction_2d(fk, bed)

    def restore_two_d(b1x, b1y, b2x, b2y, h1, h2, v1x, v1y, v2x, v2y, dt, fp, k, c,
                      edge):
        if b1y == 0.0 and b2y == 0.0 and v1y == 0.0 and v2y == 0.0:
            f, u1, u2, bisected = one_d(b1x, b2x, h1, h2, v1x, v2x, dt, fp, k, c, edge)
            return abs(f), u1, 0.0, u2, 0.0, bisected
        if b1x == 0.0 and b2x == 0.0 and v1x == 0.0 and v2x == 0.0:
            f, u1, u2, bisected = one_d(b1y, b2y, h1, h2, v1y, v2y, dt, fp, k, c, edge)
            return abs(f), 0.0, u1, 0.0, u2, bisected
        aim = edge * (1.0 - 1e-8)  # a hair inside, as the 1D restoration aims
        low = edge - fp[FP_W]
        unit = dt * (1.0 / (fp[FP_R] * h1) + 1.0 / h2)  # du removed per unit f, no friction
        fx = fy = 0.0
        out = (v1x, v1y, v2x, v2y)
        for _ in range(RESTORE_PASSES):
            dux = out[0] - out[2]
            duy = out[1] - out[3]
            du0 = math.sqrt(dux * dux + duy * duy)
            if du0 <= aim:
                break
            ex = dux / du0
            ey = duy / du0
            # f along e between f_lo (|du| = d_lo > aim, du . e > 0) and f_hi (|du| <=
            # aim, or du turned past normal to e: another pass takes that on)
            f_lo = 0.0
            d_lo = du0
            f_hi = du0 / unit
            hi = out
            for _ in range(60):
                hi = friction(b1x, b1y, b2x, b2y, h1, h2, dt, fp, fx + f_hi * ex,
                              fy + f_hi * ey, k, c)
                if _settled(hi, ex, ey, aim):
                    break
                f_lo = f_hi
                d_lo = math.hypot(hi[0] - hi[2], hi[1] - hi[3])
                f_hi *= 2.0
            for _ in range(200):
                d = math.hypot(hi[0] - hi[2], hi[1] - hi[3])
                if (low <= d <= aim) or f_hi - f_lo <= 1e-13 * f_hi:
                    break
                f_mid = _regula_falsi(f_lo, d_lo, f_hi, d, 0.5 * (low + aim))
                mid = friction(b1x, b1y, b2x, b2y, h1, h2, dt, fp, fx + f_mid * ex,
                               fy + f_mid * ey, k, c)
                if _settled(mid, ex, ey, aim):
                    f_hi = f_mid
                    hi = mid
                else:
                    f_lo = f_mid
                    d_lo = math.hypot(mid[0] - mid[2], mid[1] - mid[3])
            fx += f_hi * ex
            fy += f_hi * ey
            out = hi
        return math.hypot(fx, fy), out[0], out[1], out[2], out[3], True

    return specialise(restore_two_d, helper=True)
