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

import math

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import FIELDS, PARAMS, STATE, kernel
from ...numerics.rheology import basal_accel, law_block
from ...numerics.state import velocity
from ...numerics.vectorized import basal_accel_np, velocity_np
from . import layout as T
from .exchange import closure_rate, relaxed_rate


@kernel(STATE, FIELDS, PARAMS)
def source_rate_two_layer(q: np.ndarray, rate: np.ndarray, P: np.ndarray) -> None:
    """Add the regularised source rate of (26)-(27) to ``rate`` (two layers)."""
    r = P[T.R]
    g = P[T.G_Z]
    gx = P[T.G_X]
    dry = P[T.DRY]
    eps = P[T.MOL_EPS]
    du_reg = max(P[T.DU_REG], eps)
    closure = int(P[T.CLOSURE])
    coulomb = int(P[T.LAW + L.LAW_CODE]) == L.FRICTION_COULOMB
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
                m = relaxed_rate(m, h1, h2, du, r, g, P[T.TAN_INT], P[T.K], P[T.C], tau)
            t1 = (P[T.K] * r * g * h1 * P[T.TAN_INT] + P[T.C] * du * du) * du / max(
                abs(du), eps)
            rate[0, i] += m / r
            rate[1, i] += gx * h1 + u1 * m / r - t1 / r
        rate[2, i] -= m
        if wet2:
            if coulomb:
                bf = g * (r * h1 + h2) * P[T.TAN_B] * u2 / max(abs(u2), eps)
            else:  # the law's stress: h2 x deceleration per unit mass
                bf = h2 * basal_accel(law_block(P, T.LAW), h1 + h2,
                                      g * (r * h1 + h2) / h2, h2, abs(u2)) * u2 / max(
                                          abs(u2), eps)
            rate[3, i] += gx * h2 - u1 * m + t1 - bf
        else:
            rate[3, i] -= u1 * m


def source_rate_two_layer_np(q: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Regularised source rate of (26)-(27) of the two layers (the numpy twin of
    :func:`source_rate_two_layer`)."""
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
    if int(P[T.LAW + L.LAW_CODE]) == L.FRICTION_COULOMB:
        bf = g * (r * h1 + h2) * P[T.TAN_B] * u2 / np.maximum(np.abs(u2), eps)
    else:
        gw = g * (r * h1 + h2) / np.maximum(h2, 1e-300)
        bf = h2 * basal_accel_np(P, T.LAW, h1 + h2, gw, h2, np.abs(u2)) * u2 / np.maximum(
            np.abs(u2), eps)
    rate[3] = np.where(wet2, gx * h2 - u1 * m + t1 - bf, -u1 * m)
    return rate
