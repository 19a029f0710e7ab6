"""The single layer at a face of a 2D grid: its states, fluctuations and MUSCL cell jump.

State ``q[field, cell]`` = (h, hu, hv) [m, m^2/s, m^2/s] on the flattened cells of a 2D
``CartesianGrid`` (x down the slope: axis 0, y across: axis 1). A face normal to an axis
sees the state in its normal frame (:func:`face`: depth, normal momentum, tangential
momentum) and :data:`ROWS` says where each entry of a fluctuation goes back. The
fluctuations are the 1D Saint-Venant ones of :mod:`.flux` for (h, normal momentum), and
the tangential momentum carried by the mass flux through the face, from upwind (the
contact wave of HLLC's star states reduced to its transport). A state without
tangential momentum gives the 1D fluctuations to the bit and zero tangential ones, so a
2D run uniform across a direction gives the 1D run's numbers.
"""

from __future__ import annotations

import functools
from typing import Any

from ...numerics.compiled import cached, f8, specialise, types
from ...numerics.state import velocity
from . import flux as saint_venant

ROWS = ((0, 1, 2), (0, 2, 1))
"""per axis: the rows of q that (depth, normal momentum, tangential momentum) go into"""


@cached(inline="always")
def face(q, i, axis, sign):
    """State ``(h, normal momentum times sign, tangential momentum)`` of cell (or face
    value) ``i`` at a face normal to ``axis`` (0: x, 1: y) [m, m^2/s, m^2/s]; ``sign``
    -1: the mirror image of a wall's ghost cell."""
    if axis == 0:
        return q[0, i], sign * q[1, i], q[2, i]
    return q[0, i], sign * q[2, i], q[1, i]


@functools.cache
def fluctuations(flux: int) -> Any:
    """``fluct(left, right, g, r, dry) -> (D^-, D^+, smax)`` in a face's normal frame,
    (h, normal, tangential) tuples, for one flux (layout.FLUX_*); ``g`` = g_z
    [m/s^2], ``r`` unused, ``smax`` the largest wave speed [m/s]."""
    normal = saint_venant.fluctuations(flux)

    def fluct_single_2d(left, right, g, r, dry):
        hL, mL, tL = left
        hR, mR, tR = right
        dm, dp, smax = normal((hL, mL), (hR, mR), g, r, dry)
        # the tangential velocity rides on the mass flux through the face, from upwind
        fL = velocity(hL, mL, dry) * hL
        fR = velocity(hR, mR, dry) * hR
        vL = velocity(hL, tL, dry)
        vR = velocity(hR, tR, dry)
        mass = fL + dm[0]
        t_minus = mass * (vL if mass > 0.0 else vR) - fL * vL
        t_total = fR * vR - fL * vL
        return (dm[0], dm[1], t_minus), (dp[0], dp[1], t_total - t_minus), smax

    tuple3 = types.UniTuple(types.float64, 3)
    return specialise(fluct_single_2d, tuple3, tuple3, f8, f8, f8, helper=True)


@cached
def cell_jump(qm, qp, rate, lo, hi, inv_dx, g, r, dry, axis):
    """MUSCL: subtract the flux difference along ``axis`` across the reconstruction
    inside cells lo..hi (``inv_dx`` [1/m]: 1 / the cell width along it; ``r`` unused):
    the 1D single layer's for h and the normal momentum, and the tangential momentum
    carried by the mass flux."""
    n = 1 + axis
    t = 2 - axis
    for i in range(lo, hi + 1):
        hl, hr = qm[0, i], qp[0, i]
        ul = velocity(hl, qm[n, i], dry)
        ur = velocity(hr, qp[n, i], dry)
        rate[0, i] -= (ur * hr - ul * hl) * inv_dx
        rate[n, i] -= (ur * ur * hr + 0.5 * g * hr * hr
                       - ul * ul * hl - 0.5 * g * hl * hl) * inv_dx
        vl = velocity(hl, qm[t, i], dry)
        vr = velocity(hr, qp[t, i], dry)
        rate[t, i] -= (ur * hr * vr - ul * hl * vl) * inv_dx
