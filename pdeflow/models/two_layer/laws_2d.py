r"""Stage (32) at the bed with a rate-dependent basal law
(:class:`pdeflow.numerics.rheology.BasalLaw`) for two wet layers with vector
velocities: the 2D counterpart of :func:`.laws.friction_two_layer_law`.

With the static bound B_s = g_z (m1 + m2) mu_static(H) the 2D Coulomb solution
(:func:`.friction_2d.friction_two_layer_2d`) decides stick or slip exactly as for
Coulomb friction (every law's friction at s -> 0+ is its static bound). A sliding lower
layer's speed v solves v = S(B(v)), S(B) the lower layer's speed in the 2D Coulomb
solution with the bound B and B(v) = g_z (m1 + m2) mu(H, v) + D v^2 (as the 1D law's
balance writes it): S does not increase with B and B does not decrease with v, so
S(B(v)) - v decreases strictly from S(B_s) > 0 at v = 0 to <= 0 at v = S(B_s), and
bisection in that bracket finds the unique root. The direction comes with the Coulomb
solution at B(v).
"""

from __future__ import annotations

import functools
import math
from typing import Any

from ...numerics import layout as L
from ...numerics.compiled import specialise
from ...numerics.rheology import BasalLaw
from .friction_2d import friction_two_layer_2d
from .laws import FP_LAW

BISECTIONS = 200
"""at most this many halvings of the lower layer's speed bracket"""


@functools.cache
def law_bed_2d(basal: BasalLaw) -> Any:
    """``(b1x, b1y, b2x, b2y, m1, h1, h2, kdt, cdt, dt, g, r, fp) -> (u1x, u1y, u2x,
    u2y)``: stage (32) of two wet layers with the basal law ``basal`` (as
    :func:`.friction_2d.coulomb_bed_2d`; ``fp`` holds the law's block at FP_LAW)."""
    static_mu = basal.static_mu
    flowing_mu = basal.flowing_mu

    def bed_under_both_law_2d(b1x, b1y, b2x, b2y, m1, h1, h2, kdt, cdt, dt, g, r, fp):
        law = fp[FP_LAW]
        H = h1 + h2
        w = m1 + h2
        out = friction_two_layer_2d(b1x, b1y, b2x, b2y, m1, h2, kdt, cdt,
                                    dt * g * w * static_mu(law, H))
        hi = math.sqrt(out[2] * out[2] + out[3] * out[3])
        if hi == 0.0:
            return out
        lo = 0.0
        drag = law[L.LAW_DRAG]
        for _ in range(BISECTIONS):
            v = 0.5 * (lo + hi)
            out = friction_two_layer_2d(b1x, b1y, b2x, b2y, m1, h2, kdt, cdt,
                                        dt * (g * w * flowing_mu(law, H, v) + drag * v * v))
            if math.sqrt(out[2] * out[2] + out[3] * out[3]) > v:
                lo = v
            else:
                hi = v
            if hi - lo <= 1e-15 * hi:
                break
        return out

    return specialise(bed_under_both_law_2d, helper=True, inline="always")
