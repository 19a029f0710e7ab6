r"""Stage (32) at the bed with a rate-dependent basal law
(:class:`pdeflow.numerics.rheology.BasalLaw`), for the stages of :mod:`.friction` and
:mod:`.sources`.

A run with Coulomb friction (the paper's) compiles the closed-form bed of
:mod:`.friction` and nothing of here. A run with another law (``friction_law``) gets
its stage compiled with :func:`law_bed`'s kernels as constants
(:func:`.sources.stage_kernels`): one stage per law, whose constants (the law's block of
the parameter vector) are read at run time, so a sweep over a law's parameters
compiles once.
"""

from __future__ import annotations

import functools
from typing import Any, NamedTuple

from ...numerics import layout as L
from ...numerics.compiled import cached, specialise
from ...numerics.implicit import drag_root
from ...numerics.rheology import BasalLaw, law_block, law_velocity
from . import layout as T
from .exchange import friction_two_layer
from .friction import FP_MODE, friction_params

FP_LAW = FP_MODE + 1
"""position of the law's block in :attr:`LawBed.friction_params`' tuple"""


class LawBed(NamedTuple):
    """What :func:`.friction.friction_kernels` takes of a basal law."""

    friction_params: Any
    """``P -> fp``: :func:`.friction.friction_params` and the law's block at FP_LAW"""
    bed_under_both: Any
    """as :func:`.friction.bed_under_both`, with the law"""
    bed_under_lower: Any
    """as :func:`.friction.bed_under_lower`, with the law"""


@cached(inline="always")
def friction_params_law(P):
    """:func:`pdeflow.models.two_layer.friction.friction_params` with the basal law's block
    (:func:`pdeflow.numerics.rheology.law_block`) at the position FP_LAW."""
    return friction_params(P) + (law_block(P, T.LAW),)


@functools.cache
def law_bed(law: BasalLaw) -> LawBed:
    """Stage (32) at the bed with the basal law ``law``: the law sees the total depth
    h1 + h2 and the weight of both layers."""
    solve = friction_two_layer_law(law)
    velocity_after = law_velocity(law)

    def bed_under_both_law(b1, b2, m1, h1, h2, kdt, cdt, dt, g, r, fp):
        return solve(b1, b2, m1, h2, kdt, cdt, dt, g, h1 + h2, fp[FP_LAW])

    def bed_under_lower_law(b2, h1, h2, dt, g, r, fp):
        gw = g * (h2 + r * max(h1, 0.0)) / h2
        return velocity_after(b2, h2 + max(h1, 0.0), gw, h2, dt, fp[FP_LAW])

    return LawBed(friction_params_law,
                  specialise(bed_under_both_law, helper=True, inline="always"),
                  specialise(bed_under_lower_law, helper=True, inline="always"))


@cached
def _upper_over(v, b1, m1, kdt, cdt):
    """Upper-layer velocity [m/s] of stage (32) over a lower layer moving at ``v``, and
    its derivative in v [-] (the interface law (22) solved in closed form)."""
    e = b1 - v
    d = drag_root(m1 * abs(e) - kdt, m1, cdt)
    if d <= 0.0:
        return v, 1.0  # locked to the lower layer
    return v + (d if e > 0.0 else -d), 1.0 - m1 / (m1 + 2.0 * cdt * d)


@functools.cache
def friction_two_layer_law(basal: BasalLaw) -> Any:
    """The kernel ``(b1, b2, m1, m2, kdt, cdt, dt, gz, H, law) -> (u1, u2)``: stage (32)
    with the basal law ``basal`` (see its docstring)."""
    static_mu = basal.static_mu
    flowing_mu = basal.flowing_mu
    flowing_mu_slope = basal.flowing_mu_slope

    def friction_two_layer_law(b1, b2, m1, m2, kdt, cdt, dt, gz, H, law):
        r"""Stage (32) of :func:`.exchange.friction_two_layer` with the basal
        law ``law`` (:func:`law_block`): returns (u1, u2) [m/s].

        ``gz`` [m/s^2] times the weight depth m1 + m2 is the normal stress/rho2; ``H`` [m]
        the depth the law sees (h1 + h2). With the static bound B_s = g_z (m1 + m2) mu_static(H)
        the Coulomb solution decides stick or slip exactly as for Coulomb friction (every
        law's friction at s -> 0+ is its static bound). A sliding lower layer's speed v is the
        root of the total momentum balance
        g(v) = m1 (u1(v) - b1) + m2 (v - b2) + dt B(v) = 0 (in the sliding direction),
        B(v) = g_z (m1 + m2) mu(H, v) + D v^2, u1(v) from the interface law: g is strictly
        increasing, g(0+) < 0 (the layer slides) and g >= 0 at the Coulomb solution with B_s
        (B >= B_s), so a safeguarded Newton iteration in that bracket converges to the
        unique root.
        """
        w = m1 + m2
        u1c, u2c = friction_two_layer(b1, b2, m1, m2, kdt, cdt,
                                      dt * gz * w * static_mu(law, H))
        if u2c == 0.0:
            return u1c, 0.0
        sgn = 1.0 if u2c > 0.0 else -1.0
        c1 = sgn * b1  # in the frame where the lower layer slides forwards
        c2 = sgn * b2
        lo = 0.0
        hi = abs(u2c)
        v = hi
        drag = law[L.LAW_DRAG]
        for _ in range(100):
            u1, du1 = _upper_over(v, c1, m1, kdt, cdt)
            gv = (m1 * (u1 - c1) + m2 * (v - c2)
                  + dt * (gz * w * flowing_mu(law, H, v) + drag * v * v))
            if gv > 0.0:
                hi = v
            elif gv < 0.0:
                lo = v
            else:
                break
            slope = (m1 * du1 + m2
                     + dt * (gz * w * flowing_mu_slope(law, H, v) + 2.0 * drag * v))
            v_new = v - gv / slope
            if not (lo < v_new < hi):
                v_new = 0.5 * (lo + hi)  # Newton left the bracket: bisect
            if abs(v_new - v) <= 1e-15 * hi or hi - lo <= 1e-15 * hi:
                v = v_new
                break
            v = v_new
        u1, _ = _upper_over(v, c1, m1, kdt, cdt)
        return sgn * u1, sgn * v

    return specialise(friction_two_layer_law, helper=True)
