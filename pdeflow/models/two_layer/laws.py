r"""The two-layer source stage with a rate-dependent basal law
(:mod:`pdeflow.numerics.rheology`), as kernels of their own.

A run with Coulomb friction (the paper's) compiles the kernels of :mod:`.sources` and
:mod:`.friction` exactly as before: the laws add nothing to their code, their call
trees or their compile time. A run with another law (``friction_law``) gets the
kernels here, through the model's second bundle (:data:`.kernels.LAW_KERNELS`); which
of the rate-dependent laws is a code in the parameter vector, read at run time, so a
sweep over laws and their parameters compiles once.

The stage (31)-(34) is long and only its friction (32) changes: its kernels here are
the same Python code as :func:`.sources.sources_two_layer` and its callees with
:func:`implicit_friction_law` in place of :func:`.friction.implicit_friction`
(:func:`pdeflow.numerics.callees.with_callees`); the disk cache keys them by that code
and their callees', so they never mix with the Coulomb ones.
"""

from __future__ import annotations

from ...numerics.callees import with_callees
from ...numerics.compiled import PARAMS, STATE, VECTOR, cached, f8, i8, kernel
from ...numerics.rheology import (
    drag_root,
    flowing_mu,
    flowing_mu_slope,
    law_block,
    law_velocity,
    static_mu,
)
from . import friction, sources
from . import layout as T
from .exchange import friction_two_layer
from .friction import FP_MODE, friction_params


@cached
def _upper_over(v, b1, m1, kdt, cdt):
    """Upper-layer velocity [m/s] of stage (32) over a lower layer moving at ``v``, and
    its derivative in v [-] (the interface law (22) solved in closed form)."""
    e = b1 - v
    d = drag_root(m1 * abs(e) - kdt, m1, cdt)
    if d <= 0.0:
        return v, 1.0  # locked to the lower layer
    return v + (d if e > 0.0 else -d), 1.0 - m1 / (m1 + 2.0 * cdt * d)


@cached
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
    drag = law[6]
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


@cached(inline="always")
def friction_params_law(P):
    """:func:`pdeflow.models.two_layer.friction.friction_params` with the basal law's block
    (:func:`pdeflow.numerics.rheology.law_block`) at the position FP_LAW."""
    return friction_params(P) + (law_block(P, T.LAW),)


FP_LAW = FP_MODE + 1
"""position of the law's block in :func:`friction_params_law`' tuple"""


@cached(inline="always")
def bed_under_both_law(b1, b2, m1, h1, h2, kdt, cdt, dt, g, r, fp):
    """:func:`pdeflow.models.two_layer.friction.bed_under_both` with the basal law of
    ``fp[FP_LAW]`` (:func:`friction_two_layer_law`; the law
    sees the total depth h1 + h2 and the weight of both layers)."""
    return friction_two_layer_law(b1, b2, m1, h2, kdt, cdt, dt, g, h1 + h2, fp[FP_LAW])


@cached(inline="always")
def bed_under_lower_law(b2, h1, h2, dt, g, r, fp):
    """:func:`pdeflow.models.two_layer.friction.bed_under_lower` with the basal law."""
    gw = g * (h2 + r * max(h1, 0.0)) / h2
    return law_velocity(b2, h2 + max(h1, 0.0), gw, h2, dt, fp[FP_LAW])


implicit_friction_law = cached(with_callees(__name__,
    friction.implicit_friction, "implicit_friction_law",
    bed_under_both=bed_under_both_law, bed_under_lower=bed_under_lower_law))
bisect_fextra_law = cached(with_callees(__name__,
    friction.bisect_fextra, "bisect_fextra_law", implicit_friction=implicit_friction_law))
restore_to_edge_law = cached(with_callees(__name__,
    friction.restore_to_edge, "restore_to_edge_law", bed_under_both=bed_under_both_law,
    implicit_friction=implicit_friction_law, bisect_fextra=bisect_fextra_law))
predictor_two_layer_law = kernel(STATE, f8, PARAMS, i8, i8)(with_callees(__name__,
    friction.predictor_two_layer, "predictor_two_layer_law",
    implicit_friction=implicit_friction_law, friction_params=friction_params_law))
sources_two_layer_law = kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)(with_callees(__name__,
    sources.sources_two_layer, "sources_two_layer_law",
    implicit_friction=implicit_friction_law, friction_params=friction_params_law,
    restore_to_edge=restore_to_edge_law))
source_stage_two_layer_law = kernel(STATE, f8, f8, PARAMS, VECTOR)(with_callees(__name__,
    sources.source_stage_two_layer, "source_stage_two_layer_law",
    sources_two_layer=sources_two_layer_law))


__all__ = ["implicit_friction_law", "sources_two_layer_law", "source_stage_two_layer_law",
           "predictor_two_layer_law"]
