r"""Source terms (26)-(27) on a 2D state as a method-of-lines rate (py-pde's generic
solvers): the 1D rate of :mod:`.rates` with vectors. Each sgn(v) becomes
v / max(|v|, eps) (eps = ``mol_eps``): the interface stress along the shear vector
du = u1 - u2, the basal Coulomb stress along u2; the closure (25) on |du|; gravity
along the plane, (g_x, g_y) = g sin(theta) (cos a, sin a) at the slope's azimuth a; a
rate-dependent basal law's stress along u2.
"""

from __future__ import annotations

import functools
import math
from typing import Any

from ...numerics import layout as L
from ...numerics.compiled import FIELDS, PARAMS, STATE, specialise
from ...numerics.rheology import BasalLaw, basal_accel, law_block
from ...numerics.state import velocity
from . import layout as T
from .exchange import closure_rate, relaxed_rate


@functools.cache
def source_rate_2d(law: BasalLaw | None) -> Any:
    """The kernel ``(q, rate, P)`` that adds the regularised source rate of (26)-(27)
    with the basal law ``law`` (None: Coulomb's) to ``rate`` (rows h1, h1u1, h1v1, h2,
    h2u2, h2v2; [m/s], [m^2/s^2]); as :func:`.rates.source_rate`."""
    coulomb = law is None
    accel, block = (None, None) if coulomb else (basal_accel(law), law_block)

    def source_rate_two_layer_2d(q, rate, P):
        r = P[T.R]
        g = P[T.G_Z]
        gx = P[T.G_X]
        gy = P[T.G_Y]
        dry = P[T.DRY]
        eps = P[T.MOL_EPS]
        du_reg = max(P[T.DU_REG], eps)
        closure = int(P[T.CLOSURE])
        for i in range(q.shape[1]):
            h1 = max(q[0, i], 0.0)
            h2 = max(q[3, i], 0.0)
            u1 = velocity(h1, q[1, i], dry)
            v1 = velocity(h1, q[2, i], dry)
            u2 = velocity(h2, q[4, i], dry)
            v2 = velocity(h2, q[5, i], dry)
            m = 0.0
            t1x = 0.0
            t1y = 0.0
            if h1 > dry:
                dux = u1 - u2
                duy = v1 - v2
                du = math.sqrt(dux * dux + duy * duy)
                m = closure_rate(h1, du, r, g, P[T.TAN_INT], P[T.K], P[T.C], du_reg)
                if (m > 0.0 and not h2 > dry) or closure == L.CLOSURE_NONE:
                    m = 0.0
                elif closure == L.CLOSURE_RELAXED:
                    tau = P[T.TAU_STAR] * math.sqrt((h1 + h2) / g)
                    m = relaxed_rate(m, h1, h2, du, r, g, P[T.TAN_INT], P[T.K], P[T.C], tau)
                stress = (P[T.K] * r * g * h1 * P[T.TAN_INT] + P[T.C] * du * du) / max(du, eps)
                t1x = stress * dux
                t1y = stress * duy
                rate[0, i] += m / r
                rate[1, i] += gx * h1 + u1 * m / r - t1x / r
                rate[2, i] += gy * h1 + v1 * m / r - t1y / r
            rate[3, i] -= m
            if h2 > dry:
                speed = math.sqrt(u2 * u2 + v2 * v2)
                if coulomb:
                    bf = g * (r * h1 + h2) * P[T.TAN_B] / max(speed, eps)
                else:  # the law's stress: h2 x deceleration per unit mass
                    bf = h2 * accel(block(P, T.LAW), h1 + h2, g * (r * h1 + h2) / h2,
                                    h2, speed) / max(speed, eps)
                rate[4, i] += gx * h2 - u1 * m + t1x - bf * u2
                rate[5, i] += gy * h2 - v1 * m + t1y - bf * v2
            else:
                rate[4, i] -= u1 * m
                rate[5, i] -= v1 * m

    return specialise(source_rate_two_layer_2d, STATE, FIELDS, PARAMS)
