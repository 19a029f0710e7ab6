r"""HLL interface fluctuations (single layer, and path-conservative for two layers).

Waves and splitting
-------------------
At a face with left state q_L and right state q_R the homogeneous system (29),
:math:`\partial_t q + A(q)\,\partial_x q = 0`, is approximated by two waves with speeds
S_L <= S_R that bound all characteristic speeds on both sides. With the *total jump*

.. math::  \mathcal{A}\Delta q = f(q_R) - f(q_L) + B_{LR},

where f is the advective flux of (24) and B_LR the non-conservative coupling integrated
along the straight segment between q_L and q_R (paper ref. [11]; Castro et al. 2004),

.. math::  B_{LR} = \bigl(0,\; g_z \bar h_1 \Delta h_2,\; 0,\; g_z r \bar h_2 \Delta h_1\bigr),
           \qquad \bar h = (h_L + h_R)/2,

the HLL fluctuations sent to the left and right cells are

.. math::  D^- = \frac{S_L}{S_R - S_L}\bigl(S_R \Delta q - \mathcal{A}\Delta q\bigr), \qquad
           D^+ = \frac{S_R}{S_R - S_L}\bigl(\mathcal{A}\Delta q - S_L \Delta q\bigr),

with D^- + D^+ = A Delta q (path conservation). The cell update is
q_i <- q_i - dt/dx (D^+_{i-1/2} + D^-_{i+1/2}). For a conservative system this is the
classical HLL flux; for S_L >= 0 (S_R <= 0) everything goes right (left).

Layers at rest
--------------
HLL's numerical diffusion S_L S_R Delta h / (S_R - S_L) moves mass across a face even
where the layer is at rest on both sides, so a Coulomb heap below its friction angle
would creep (REFERENCE section 3). Where a layer has zero momentum on both sides of a
face, its mass fluctuation is therefore zero and its hydrostatic jump is split by each
side's *own* depth: for layer 1, D^-_{m1} = g_z h_{1L} Delta H / 2,
D^+_{m1} = g_z h_{1R} Delta H / 2 (sum: Delta(g h1^2/2) + g h1bar Delta h2, unchanged).
Each cell then sees g_z h_i (H_{i+1} - H_{i-1}) / (2 dx): a centred pressure gradient
that the implicit Coulomb stage can balance exactly.

Wave-speed bounds
-----------------
Single layer: S = u -+ sqrt(g_z h) (Davis). Two layers: the external eigenvalues of the
pseudo-Jacobian lie within [min(u1, u2) - sqrt(g_z H), max(u1, u2) + sqrt(g_z H)],
H = h1 + h2, which is used on both sides (only wet layers contribute a velocity).
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def velocity(h: float, m: float, dry: float) -> float:
    """Depth-averaged velocity m/h [m/s]; zero where the layer is thinner than ``dry``."""
    if h > dry:
        return m / h
    return 0.0


@njit(cache=True)
def hll_single(hL, mL, hR, mR, g, dry):
    """HLL fluctuations of the single-layer Savage-Hutter/shallow-water system.

    Returns ``(dm_h, dm_m, dp_h, dp_m, smax)``: the left-going and right-going
    fluctuations of (h, hu) [m^2/s, m^3/s^2] and the largest |wave speed| [m/s].
    """
    uL = velocity(hL, mL, dry)
    uR = velocity(hR, mR, dry)
    cL = math.sqrt(g * max(hL, 0.0))
    cR = math.sqrt(g * max(hR, 0.0))
    sL = min(uL - cL, uR - cR)
    sR = max(uL + cL, uR + cR)
    smax = max(abs(sL), abs(sR))
    # total jump A dq = f(qR) - f(qL)
    a0 = uR * hR - uL * hL
    a1 = uR * uR * hR + 0.5 * g * hR * hR - (uL * uL * hL + 0.5 * g * hL * hL)
    if mL == 0.0 and mR == 0.0:
        # at rest on both sides: no mass diffusion, pressure jump split by own depth
        dH = hR - hL
        return 0.0, 0.5 * g * hL * dH, 0.0, 0.5 * g * hR * dH, smax
    if sR - sL <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, smax
    if sL >= 0.0:
        return 0.0, 0.0, a0, a1, smax
    if sR <= 0.0:
        return a0, a1, 0.0, 0.0, smax
    d0 = hR - hL
    d1 = mR - mL
    inv = 1.0 / (sR - sL)
    dm0 = sL * inv * (sR * d0 - a0)
    dm1 = sL * inv * (sR * d1 - a1)
    return dm0, dm1, a0 - dm0, a1 - dm1, smax


@njit(cache=True)
def hll_two_layer(h1L, m1L, h2L, m2L, h1R, m1R, h2R, m2R, g, r, dry):
    """Path-conservative HLL fluctuations of the two-layer system (24), stage (29).

    Layer 1 is the upper (friction-collisional) layer, layer 2 the lower (frictional)
    one; ``g`` is g_z [m/s^2] and ``r`` = rho1/rho2. Returns
    ``(dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, smax)`` for q = (h1, h1u1, h2, h2u2).
    """
    u1L = velocity(h1L, m1L, dry)
    u2L = velocity(h2L, m2L, dry)
    u1R = velocity(h1R, m1R, dry)
    u2R = velocity(h2R, m2R, dry)
    HL = max(h1L, 0.0) + max(h2L, 0.0)
    HR = max(h1R, 0.0) + max(h2R, 0.0)
    cL = math.sqrt(g * HL)
    cR = math.sqrt(g * HR)
    # extreme velocities of the wet layers on each side
    loL = min(u1L if h1L > dry else u2L, u2L if h2L > dry else u1L)
    hiL = max(u1L if h1L > dry else u2L, u2L if h2L > dry else u1L)
    loR = min(u1R if h1R > dry else u2R, u2R if h2R > dry else u1R)
    hiR = max(u1R if h1R > dry else u2R, u2R if h2R > dry else u1R)
    sL = min(loL - cL, loR - cR)
    sR = max(hiL + cL, hiR + cR)
    smax = max(abs(sL), abs(sR))

    dh1 = h1R - h1L
    dh2 = h2R - h2L
    # total jump: flux difference plus the non-conservative products on a linear path
    a0 = u1R * h1R - u1L * h1L
    a1 = (u1R * u1R * h1R - u1L * u1L * h1L) + g * 0.5 * (h1L + h1R) * (dh1 + dh2)
    a2 = u2R * h2R - u2L * h2L
    a3 = (u2R * u2R * h2R - u2L * u2L * h2L) + g * 0.5 * (h2L + h2R) * (dh2 + r * dh1)

    rest1 = m1L == 0.0 and m1R == 0.0
    rest2 = m2L == 0.0 and m2R == 0.0

    if sR - sL <= 0.0:
        dm0 = dm1 = dm2 = dm3 = 0.0
        dp0 = dp1 = dp2 = dp3 = 0.0
    elif sL >= 0.0:
        dm0 = dm1 = dm2 = dm3 = 0.0
        dp0, dp1, dp2, dp3 = a0, a1, a2, a3
    elif sR <= 0.0:
        dm0, dm1, dm2, dm3 = a0, a1, a2, a3
        dp0 = dp1 = dp2 = dp3 = 0.0
    else:
        inv = 1.0 / (sR - sL)
        dm0 = sL * inv * (sR * dh1 - a0)
        dm1 = sL * inv * (sR * (m1R - m1L) - a1)
        dm2 = sL * inv * (sR * dh2 - a2)
        dm3 = sL * inv * (sR * (m2R - m2L) - a3)
        dp0 = a0 - dm0
        dp1 = a1 - dm1
        dp2 = a2 - dm2
        dp3 = a3 - dm3
    if rest1:
        dH = dh1 + dh2
        dm0 = 0.0
        dp0 = 0.0
        dm1 = 0.5 * g * h1L * dH
        dp1 = 0.5 * g * h1R * dH
    if rest2:
        dE = dh2 + r * dh1
        dm2 = 0.0
        dp2 = 0.0
        dm3 = 0.5 * g * h2L * dE
        dp3 = 0.5 * g * h2R * dE
    return dm0, dm1, dm2, dm3, dp0, dp1, dp2, dp3, smax
