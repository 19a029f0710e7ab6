r"""Source terms (26)-(27) as a method-of-lines rate (for py-pde's generic solvers).

The splitting scheme treats the sources implicitly and limits the exchange; a generic
ODE integrator needs them as a plain rate instead. Two regularisations make that rate
finite (both documented parameters): sgn(v) is replaced by v / max(|v|, eps) with
eps = ``mol_eps`` (for a rate-dependent basal law, mu(h, |u|) sgn_eps(u), see
:mod:`pdeflow.numerics.rheology`), and the closure's denominator is max(|du|, du_reg, eps). With
``exchange_closure = "relaxed"`` the rate is bounded by the relaxation towards h1_eq
(:func:`.exchange.relaxed_rate`), the rate form of the relaxed stage. A state at
rest is therefore *not* held by static friction in this form: that is the price of
the method of lines, and why the paper splits the sources.

Kinematic form (divided by rho2), with the exchanged mass carrying u1 (as a rate this is
(27) exactly; the split exchange stage carries the velocity of the layer the mass leaves,
which is the same equation rewritten through (25), see :mod:`.exchange`):

.. math::  \dot h_1 = M/r,\quad \dot h_2 = -M,\quad
           \dot m_1 = g_x h_1 + u_1 M / r - t_1/r,\quad
           \dot m_2 = g_x h_2 - u_1 M + t_1 - B\,\mathrm{sgn}_\epsilon(u_2).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import FIELDS, PARAMS, STATE, specialise
from ...numerics.rheology import BasalLaw, basal_accel, law_block, law_block_np
from ...numerics.state import velocity
from ...numerics.vectorized import at_rest, hll_split, layer_fluctuations, velocity_np
from . import layout as T
from .exchange import closure_rate, relaxed_rate


@functools.cache
def source_rate(law: BasalLaw | None) -> Any:
    """The kernel ``(q, rate, P)`` that adds the regularised source rate of (26)-(27)
    with the basal law ``law`` (None: the paper's Coulomb friction) to ``rate``."""
    coulomb = law is None
    # closes over what its law calls only (None for Coulomb), as the scheme's factories
    accel, block = (None, None) if coulomb else (basal_accel(law), law_block)

    def source_rate_two_layer(q, rate, P):
        r = P[T.R]
        g = P[T.G_Z]
        gx = P[T.G_X]
        dry = P[T.DRY]
        eps = P[T.MOL_EPS]
        du_reg = max(P[T.DU_REG], eps)
        closure = int(P[T.CLOSURE])
        for i in range(q.shape[1]):
            h1 = max(q[0, i], 0.0)
            h2 = max(q[2, i], 0.0)
            u1 = velocity(h1, q[1, i], dry)
            u2 = velocity(h2, q[3, i], dry)
            wet1 = h1 > dry
            wet2 = h2 > dry
            m = 0.0
            t1 = 0.0
            if wet1:
                du = u1 - u2
                m = closure_rate(h1, du, r, g, P[T.TAN_INT], P[T.K], P[T.C], du_reg)
                if (m > 0.0 and not wet2) or closure == L.CLOSURE_NONE:
                    m = 0.0
                elif closure == L.CLOSURE_RELAXED:
                    tau = P[T.TAU_STAR] * math.sqrt((h1 + h2) / g)
                    m = relaxed_rate(m, h1, h2, du, r, g, P[T.TAN_INT], P[T.K], P[T.C],
                                     tau)
                t1 = (P[T.K] * r * g * h1 * P[T.TAN_INT] + P[T.C] * du * du) * du / max(
                    abs(du), eps)
                rate[0, i] += m / r
                rate[1, i] += gx * h1 + u1 * m / r - t1 / r
            rate[2, i] -= m
            if wet2:
                if coulomb:
                    bf = g * (r * h1 + h2) * P[T.TAN_B] * u2 / max(abs(u2), eps)
                else:  # the law's stress: h2 x deceleration per unit mass
                    bf = h2 * accel(block(P, T.LAW), h1 + h2, g * (r * h1 + h2) / h2,
                                    h2, abs(u2)) * u2 / max(abs(u2), eps)
                rate[3, i] += gx * h2 - u1 * m + t1 - bf
            else:
                rate[3, i] -= u1 * m

    return specialise(source_rate_two_layer, STATE, FIELDS, PARAMS)


def source_rate_np(q: np.ndarray, P: np.ndarray, law: BasalLaw | None = None) -> np.ndarray:
    """Regularised source rate of (26)-(27) of the two layers with the basal law
    ``law`` (None: Coulomb's): the numpy twin of :func:`source_rate`."""
    rate = np.zeros_like(q)
    r, g, gx, dry, eps = P[T.R], P[T.G_Z], P[T.G_X], P[T.DRY], P[T.MOL_EPS]
    h1 = np.maximum(q[0], 0.0)
    h2 = np.maximum(q[2], 0.0)
    u1 = velocity_np(h1, q[1], dry)
    u2 = velocity_np(h2, q[3], dry)
    wet1 = h1 > dry
    wet2 = h2 > dry
    du = u1 - u2
    num = P[T.C] * du * du - (1.0 - P[T.K]) * r * g * h1 * P[T.TAN_INT]
    m = num / np.maximum(np.abs(du), max(P[T.DU_REG], eps))
    closure = int(P[T.CLOSURE])
    if closure == L.CLOSURE_RELAXED:
        # relaxed closure: bounded by the relaxation towards h1_eq on tau
        tau = P[T.TAU_STAR] * np.sqrt(np.maximum(h1 + h2, 1e-300) / g)
        denom = (1.0 - P[T.K]) * r * g * P[T.TAN_INT]
        h1_eq = P[T.C] * du * du / denom if denom > 0 else np.full_like(h1, np.inf)
        dep = r * (np.minimum(h1_eq, h1) - h1) / tau
        ero = np.maximum(r * (np.minimum(h1_eq, h1 + h2 / r) - h1) / tau, 0.0)
        m = np.where(m < 0, np.maximum(m, dep), np.where(m > 0, np.minimum(m, ero), m))
    m = np.where(wet1 & ((m <= 0) | wet2) & (closure != L.CLOSURE_NONE), m, 0.0)
    sgn_du = du / np.maximum(np.abs(du), eps)
    t1 = np.where(wet1, (P[T.K] * r * g * h1 * P[T.TAN_INT] + P[T.C] * du * du) * sgn_du,
                  0.0)
    rate[0] = m / r
    rate[1] = np.where(wet1, gx * h1 + u1 * m / r - t1 / r, 0.0)
    rate[2] = -m
    if law is None:
        bf = g * (r * h1 + h2) * P[T.TAN_B] * u2 / np.maximum(np.abs(u2), eps)
    else:
        gw = g * (r * h1 + h2) / np.maximum(h2, 1e-300)
        bf = h2 * law.accel_np(law_block_np(P, T.LAW), h1 + h2, gw, h2,
                               np.abs(u2)) * u2 / np.maximum(np.abs(u2), eps)
    rate[3] = np.where(wet2, gx * h2 - u1 * m + t1 - bf, -u1 * m)
    return rate


def _at_uncovered_steps_np(left, right, ul, ur, sL, sR, a0, a1, dH, g, dry, fluct):
    """The upper layer's fluctuations (D-_h1, D+_h1, D-_h1u1, D+_h1u1) with those of
    :func:`.flux.upper_layer_at_uncovered_step` where the lower layer is at rest on both
    sides of a face and steps above the upper layer's surface on one side; ``fluct``
    (the flux's own) elsewhere."""
    h1l, h1r, h2l, h2r = left[0], right[0], left[2], right[2]
    top = np.maximum(h2l, h2r)
    s_l = h1l + h2l - top
    s_r = h1r + h2r - top
    at = ((left[3] == 0.0) & (right[3] == 0.0) & (h2r - h2l != 0.0)
          & ((s_l <= 0.0) | (s_r <= 0.0)))
    s_l = np.maximum(s_l, 0.0)
    s_r = np.maximum(s_r, 0.0)
    f_l, f_r = s_l * ul, s_r * ur
    pressure = g * 0.5 * (h1l + h1r) * dH
    mass = f_l + hll_split(sL, sR, s_r - s_l, f_r - f_l)[0]
    mom = f_l * ul + hll_split(sL, sR, f_r - f_l, f_r * ur - f_l * ul)[0]
    share_l = hll_split(sL, sR, 0.0 * pressure, pressure)[0]  # the flux's share of it
    share_r = pressure - share_l
    # both wet: the thinner side gets at most the share its own depth carries, the
    # thicker side the rest (as .flux.upper_layer_at_uncovered_step)
    both = (h1l > dry) & (h1r > dry)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1bar = 0.5 * (h1l + h1r)
        thin_l = np.where(both & (h1l < h1r), share_l * h1l / h1bar, share_l)
        thin_r = np.where(both & (h1l >= h1r), share_r * h1r / h1bar, share_r)
    share_l, share_r = (np.where(both & (h1l >= h1r), pressure - thin_r, thin_l),
                        np.where(both & (h1l < h1r), pressure - thin_l, thin_r))
    # a side without upper layer gets no share of the hydrostatic jump
    share_l = np.where(h1l > dry, share_l, 0.0)
    share_r = np.where(h1r > dry, share_r, 0.0)
    dm0 = mass - ul * h1l
    dm1 = mom - ul * ul * h1l + share_l
    dp1 = ur * ur * h1r - ul * ul * h1l - (mom - ul * ul * h1l) + share_r
    dm0_, dp0_, dm1_, dp1_ = fluct
    return (np.where(at, dm0, dm0_), np.where(at, a0 - dm0, dp0_),
            np.where(at, dm1, dm1_), np.where(at, dp1, dp1_))


def _speeds_np(hs: list, us: list, dry: float) -> tuple[np.ndarray, np.ndarray]:
    """Slowest and fastest wet layer's velocity [m/s] on one side of every face."""
    u1 = np.where(hs[0] > dry, us[0], us[1])
    u2 = np.where(hs[1] > dry, us[1], us[0])
    return np.minimum(u1, u2), np.maximum(u1, u2)


def fluctuations_np(left: np.ndarray, right: np.ndarray, g: float, dry: float,
                    r: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """HLL fluctuations of the two-layer system (24) over all faces between the states
    ``left`` and ``right`` (the numpy twin of :func:`.flux.fluctuations` for HLL):
    (D^-, D^+, S_L, S_R)."""
    hs_l = [np.maximum(left[2 * k], 0.0) for k in range(2)]
    hs_r = [np.maximum(right[2 * k], 0.0) for k in range(2)]
    us_l = [velocity_np(left[2 * k], left[2 * k + 1], dry) for k in range(2)]
    us_r = [velocity_np(right[2 * k], right[2 * k + 1], dry) for k in range(2)]
    HL = sum(hs_l)
    HR = sum(hs_r)
    cL = np.sqrt(g * HL)
    cR = np.sqrt(g * HR)
    loL, hiL = _speeds_np(hs_l, us_l, dry)
    loR, hiR = _speeds_np(hs_r, us_r, dry)
    sL = np.minimum(loL - cL, loR - cR)
    sR = np.maximum(hiL + cL, hiR + cR)
    dH = HR - HL
    fluct_m = []
    fluct_p = []
    for k in range(2):
        hl, hr = left[2 * k], right[2 * k]
        ml, mr = left[2 * k + 1], right[2 * k + 1]
        ul, ur = us_l[k], us_r[k]
        # the path-conservative coupling: g h1bar Delta(h1 + h2), g h2bar Delta(h2 + r h1)
        dpress = dH if k == 0 else (right[2] - left[2]) + r * (right[0] - left[0])
        a1 = ur * ur * hr - ul * ul * hl + g * 0.5 * (hl + hr) * dpress
        fluct = layer_fluctuations(hl, hr, ml, mr, ul, ur, a1, sL, sR)
        if k == 0:
            fluct = _at_uncovered_steps_np(left, right, ul, ur, sL, sR, ur * hr - ul * hl,
                                           a1, dH, g, dry, fluct)
        dm0, dp0, dm1, dp1 = at_rest(fluct, hl, hr, ml, mr, g, dpress)
        fluct_m += [dm0, dm1]
        fluct_p += [dp0, dp1]
    return np.array(fluct_m), np.array(fluct_p), sL, sR
