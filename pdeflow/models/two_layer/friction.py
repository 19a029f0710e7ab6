r"""Implicit friction (32) of one cell, with the extra exchange F_extra of (33)-(34).

:func:`implicit_friction` solves stage (32) of a cell for both layers together, in closed
form (:func:`.exchange.friction_two_layer`), with an extra momentum
exchange F_extra between the layers; :func:`restore_hyperbolicity` finds the smallest
F_extra after which the cell's state is hyperbolic (33)-(34), by inverting that closed
form, with :func:`bisect_fextra` as the fallback. The predictors zero the momentum that
friction would hold at rest in the intermediate stage of SSP-RK2 (MUSCL).

These are built per basal law by :func:`friction_kernels`, from the law's stage (32)
at the bed (:func:`bed_under_both`, :func:`bed_under_lower`: Coulomb's closed form;
:mod:`.laws`: a rate-dependent law's), which they take as constants; the module's
:data:`COULOMB` are the paper's.

Kinematic units (divided by rho2) as in :mod:`.exchange`:
f = F_extra/rho2 [m^2/s^2], velocities [m/s], depths [m].

The helpers take the parameters they read as the tuple ``fp`` of :func:`friction_params`
(built once per stage), not the parameter array: an array passed on to a helper that
calls others costs two atomic reference-count updates per call.
"""

from __future__ import annotations

import functools
from typing import Any, NamedTuple

from ...numerics import layout as L
from ...numerics.compiled import PARAMS, STATE, cached, f8, i8, specialise
from ...numerics.implicit import coulomb_single, drag_root
from ...numerics.state import velocity
from . import layout as T
from .exchange import friction_two_layer
from .hyperbolicity import band_lower_edge, is_hyperbolic, lower_bound_fl

FP_R, FP_G, FP_DRY, FP_TAN_INT, FP_TAN_B, FP_W, FP_MODE = range(7)
"""positions in :func:`friction_params`' tuple"""


@cached(inline="always")
def friction_params(P):
    """What stages (32)-(34) read of the parameter vector ``P``, as a tuple of floats:
    (r [-], g_z [m/s^2], dry tolerance [m], tan(phi_int), tan(phi_B), w [m/s], the
    hyperbolicity mode's code) at the positions FP_*."""
    return (P[T.R], P[T.G_Z], P[T.DRY], P[T.TAN_INT], P[T.TAN_B], P[T.W],
            P[T.HYPERBOLICITY])


@cached(inline="always")
def bed_under_both(b1, b2, m1, h1, h2, kdt, cdt, dt, g, r, fp):
    """Stage (32) of two wet layers with Coulomb friction at the bed: (u1, u2) [m/s]
    (``m1`` = r h1, ``kdt``, ``cdt``: the interface law's terms times dt)."""
    bdt = dt * g * (r * h1 + h2) * fp[FP_TAN_B]
    return friction_two_layer(b1, b2, m1, h2, kdt, cdt, bdt)


@cached(inline="always")
def bed_under_lower(b2, h1, h2, dt, g, r, fp):
    """Stage (32) of the lower layer alone (a dry upper layer's weight still counted):
    Coulomb friction at the bed, u2 [m/s]."""
    mu_dt = dt * g * fp[FP_TAN_B] * (h2 + r * max(h1, 0.0)) / h2
    return coulomb_single(b2, mu_dt)


class FrictionKernels(NamedTuple):
    """Stages (32)-(34) of one cell and MUSCL's predictor, with one basal law."""

    friction_params: Any
    """``P -> fp``: what the helpers read of the parameter vector (a tuple)"""
    implicit_friction: Any
    """:func:`implicit_friction`"""
    bisect_fextra: Any
    """:func:`bisect_fextra`"""
    restore_hyperbolicity: Any
    """:func:`restore_hyperbolicity`"""
    restore_to_edge: Any
    """:func:`restore_to_edge`"""
    predictor: Any
    """``(q, dt, P, lo, hi)``: :func:`predictor_two_layer`"""


@functools.cache
def friction_kernels(params: Any, both: Any, lower: Any,
                     coulomb: bool = False) -> FrictionKernels:
    """The kernels of stages (32)-(34) with the basal law whose parameters tuple is
    ``params(P)`` and whose stage (32) at the bed is ``both`` (two wet layers, as
    :func:`bed_under_both`) and ``lower`` (the lower layer alone, as
    :func:`bed_under_lower`), each compiled with them as constants (``coulomb``: the
    paper's, :data:`COULOMB`, whose predictor a new interpreter imports by name)."""
    implicit = _implicit_friction(both, lower)
    bisect = _bisect_fextra(implicit)
    to_edge = _restore_to_edge(both, implicit, bisect)
    return FrictionKernels(params, implicit, bisect, _restore_hyperbolicity(to_edge),
                           to_edge, _predictor(params, implicit, coulomb))


@functools.cache
def _implicit_friction(bed_under_both: Any, bed_under_lower: Any) -> Any:
    def implicit_friction(b1, b2, h1, h2, dt, fp, f, k, c):
        """Implicit stage (32) for one cell with extra exchange ``f`` = F_extra/rho2 and the
        interface law (22) with friction reduction ``k`` and collisional coefficient ``c``
        (the parameters', or those of t1 - M du in a cell that eroded this step); ``fp``:
        :func:`friction_params`."""
        r = fp[FP_R]
        g = fp[FP_G]
        dry = fp[FP_DRY]
        wet1 = h1 > dry
        wet2 = h2 > dry
        if wet1 and wet2:
            m1 = r * h1
            if f != 0.0:
                b1 = b1 - dt * f / m1
                b2 = b2 + dt * f / h2
            kdt = dt * k * r * g * h1 * fp[FP_TAN_INT]
            return bed_under_both(b1, b2, m1, h1, h2, kdt, dt * c, dt, g, r, fp)
        if wet1:
            # no lower layer: the upper layer rubs on the bed with the interface law (22)
            m1 = r * h1
            kdt = dt * k * r * g * h1 * fp[FP_TAN_INT]
            u1 = drag_root(m1 * abs(b1) - kdt, m1, dt * c)
            return (u1 if b1 > 0.0 else -u1), 0.0
        if wet2:
            return 0.0, bed_under_lower(b2, h1, h2, dt, g, r, fp)
        return 0.0, 0.0

    return specialise(implicit_friction, helper=True)


@functools.cache
def _bisect_fextra(implicit_friction: Any) -> Any:
    def bisect_fextra(b1, b2, h1, h2, du0, dt, fp, k, c):
        """F_extra/rho2 [m^2/s^2] by bracketing and bisection on the hyperbolicity test:
        the fallback of :func:`restore_hyperbolicity`, stopping when the bracket in du is
        below w."""
        g = fp[FP_G]
        r = fp[FP_R]
        mode = int(fp[FP_MODE])
        w = fp[FP_W]
        # Bracket: f_lo leaves du of the original sign and non-hyperbolic; f_hi makes the
        # state hyperbolic or flips the sign of du (du(f) decreases monotonically in f, so
        # the smallest hyperbolic f lies before the sign change).
        f_hi = du0 / (dt * (1.0 / (r * h1) + 1.0 / h2))
        f_lo = 0.0
        du_lo = abs(du0)
        sgn = 1.0 if du0 > 0.0 else -1.0
        for _ in range(60):
            v1, v2 = implicit_friction(b1, b2, h1, h2, dt, fp, f_hi, k, c)
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
            v1, v2 = implicit_friction(b1, b2, h1, h2, dt, fp, f_mid, k, c)
            du_mid = sgn * (v1 - v2)
            if du_mid <= 0.0 or is_hyperbolic(h1, h2, v1, v2, g, r, mode):
                f_hi = f_mid
                du_hi = du_mid
            else:
                f_lo = f_mid
                du_lo = du_mid
        return f_hi

    return specialise(bisect_fextra, helper=True)


@functools.cache
def _restore_to_edge(bed_under_both: Any, implicit_friction: Any,
                     bisect_fextra: Any) -> Any:
    def restore_to_edge(b1, b2, h1, h2, u1, u2, dt, fp, k, c, edge):
        r"""Smallest F_extra/rho2 [m^2/s^2] making the post-friction state hyperbolic, the
        velocities (u1, u2) [m/s] it leads to, and whether the bisection fallback was used.

        The depths are frozen, so the target is a relative velocity: ``edge`` [m/s], the
        lower band edge F_c1 (F_L in ``bound`` mode; <= 0: none found, bisect). Stage (32)
        with the extra exchange f = F_extra/rho2
        shifts b1 by -dt f/m1 and b2 by +dt f/m2 and keeps m1 b1 + m2 b2, so on each branch
        of its closed-form solution (:func:`.exchange.friction_two_layer`)
        du is an explicit function of f, inverted here for du = sgn(du0) d with

        * lower layer sliding in direction s2 (mu = m1 m2/(m1 + m2), p = m1 b1 + m2 b2
          - dt B s2): :math:`m_1 b_1 - m_1 p/(m_1+m_2) - \Delta t f
          = \mathrm{sgn}(du_0)\,(\Delta t K + \mu d + \Delta t C d^2)`;
        * lower layer stuck: :math:`m_1 (b_1 - \Delta t f/m_1)
          = \mathrm{sgn}(du_0)\,(\Delta t K + m_1 d + \Delta t C d^2)`.

        The branch is not known beforehand: each candidate is checked by solving (32)
        with it (|du| must land within w below the edge, where the state is hyperbolic);
        if none passes (round-off at a branch boundary), bisection decides
        (:func:`bisect_fextra`).
        """
        g = fp[FP_G]
        r = fp[FP_R]
        du0 = u1 - u2
        found = False
        f = v1 = v2 = 0.0
        if edge > 0.0:
            d = edge * (1.0 - 1e-8)  # a hair inside: round-off must not leave the band edge
            sgn = 1.0 if du0 > 0.0 else -1.0
            m1 = r * h1
            m2 = h2
            mt = m1 + m2
            kdt = dt * k * r * g * h1 * fp[FP_TAN_INT]
            cdt = dt * c
            bdt = dt * g * (r * h1 + h2) * fp[FP_TAN_B]
            low = edge - fp[FP_W]
            s_first = 1.0 if u2 >= 0.0 else -1.0
            for branch in range(3):
                if found:
                    break
                if branch == 2:
                    f = (m1 * b1 - sgn * (kdt + m1 * d + cdt * d * d)) / dt
                else:
                    s2 = s_first if branch == 0 else -s_first
                    p = m1 * b1 + m2 * b2 - bdt * s2
                    f = (m1 * b1 - m1 * p / mt
                         - sgn * (kdt + m1 * m2 / mt * d + cdt * d * d)) / dt
                if f * sgn > 0.0:
                    # implicit_friction(b1, b2, h1, h2, dt, fp, f, k, c) of two wet layers
                    v1, v2 = bed_under_both(b1 - dt * f / m1, b2 + dt * f / h2, m1, h1, h2,
                                            kdt, cdt, dt, g, r, fp)
                    # below the edge is hyperbolic down to F_L (the band is one interval)
                    found = low <= sgn * (v1 - v2) <= edge
        if not found:
            f = bisect_fextra(b1, b2, h1, h2, du0, dt, fp, k, c)
            v1, v2 = implicit_friction(b1, b2, h1, h2, dt, fp, f, k, c)
        return f, v1, v2, not found

    return specialise(restore_to_edge, helper=True)


@functools.cache
def _restore_hyperbolicity(restore_to_edge: Any) -> Any:
    def restore_hyperbolicity(b1, b2, h1, h2, u1, u2, dt, fp, k, c):
        """Smallest F_extra/rho2 [m^2/s^2] making the post-friction state (u1, u2) [m/s]
        of a non-hyperbolic cell hyperbolic, the velocities it leads to, and whether the
        bisection fallback was used: :func:`restore_to_edge` with the edge of
        :func:`pdeflow.models.two_layer.hyperbolicity.band_lower_edge` (F_L in ``bound`` mode).
        The source stage finds the edge with its hyperbolicity test
        (:func:`pdeflow.models.two_layer.hyperbolicity.restoration_target`)."""
        g = fp[FP_G]
        r = fp[FP_R]
        if int(fp[FP_MODE]) == L.HYPERBOLICITY_BOUND:
            edge = lower_bound_fl(h1, h2, g, r)
        else:
            edge = band_lower_edge(h1, h2, g, r, abs(u1 - u2))
        return restore_to_edge(b1, b2, h1, h2, u1, u2, dt, fp, k, c, edge)

    return specialise(restore_hyperbolicity, helper=True)


@functools.cache
def _predictor(friction_params: Any, implicit_friction: Any, coulomb: bool) -> Any:
    def predictor_two_layer(q, dt, P, lo, hi):
        """Zero the momentum of layers that the implicit friction (32) would hold at rest,
        in place, in the cells ``lo..hi``. Applied to the intermediate stage of SSP-RK2:
        otherwise the predictor's pressure momentum, which friction balances, moves mass and
        heaps creep. Moving layers are left untouched (friction proper is applied once, in
        the source stage)."""
        dry = P[T.DRY]
        fp = friction_params(P)
        for i in range(lo, hi + 1):
            h1 = max(q[0, i], 0.0)
            h2 = max(q[2, i], 0.0)
            if h1 <= dry and h2 <= dry:
                continue
            b1 = velocity(h1, q[1, i], dry) + dt * P[T.G_X] if h1 > dry else 0.0
            b2 = velocity(h2, q[3, i], dry) + dt * P[T.G_X] if h2 > dry else 0.0
            u1, u2 = implicit_friction(b1, b2, h1, h2, dt, fp, 0.0, P[T.K], P[T.C])
            if u1 == 0.0:
                q[1, i] = 0.0
            if u2 == 0.0:
                q[3, i] = 0.0

    return specialise(predictor_two_layer, STATE, f8, PARAMS, i8, i8,
                      name="predictor_two_layer" if coulomb else None)


COULOMB = friction_kernels(friction_params, bed_under_both, bed_under_lower, coulomb=True)
"""the kernels of the paper's Coulomb friction at the bed"""
implicit_friction = COULOMB.implicit_friction
bisect_fextra = COULOMB.bisect_fextra
restore_hyperbolicity = COULOMB.restore_hyperbolicity
restore_to_edge = COULOMB.restore_to_edge
predictor_two_layer = COULOMB.predictor
