r"""HLL: the paper's interface flux (single layer; path-conservative for two layers).

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

the HLL fluctuations sent to the left and right cells (:mod:`pdeflow.numerics.pvm`
evaluates them for every flux in the polynomial-viscosity form) are

.. math::  D^- = \frac{S_L}{S_R - S_L}\bigl(S_R \Delta q - \mathcal{A}\Delta q\bigr), \qquad
           D^+ = \frac{S_R}{S_R - S_L}\bigl(\mathcal{A}\Delta q - S_L \Delta q\bigr),

with D^- + D^+ = A Delta q (path conservation). The cell update is
q_i <- q_i - dt/dx (D^+_{i-1/2} + D^-_{i+1/2}). For a conservative system this is the
classical HLL flux; for S_L >= 0 (S_R <= 0) everything goes right (left).

Layers at rest
--------------
HLL's numerical diffusion S_L S_R Delta h / (S_R - S_L) moves mass across a face even
where the layer is at rest on both sides, so a Coulomb heap below its friction angle would
creep (tests/test_scheme_invariants.py). Where a layer has zero momentum on both sides of a
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

from .compiled import cached


@cached
def hll_coefficients(sL: float, sR: float) -> tuple[float, float, float]:
    """Viscosity polynomial Q(x) = a0 + a1 x of HLL: the line through (S_L, |S_L|) and
    (S_R, |S_R|). With D^-+ = (A dq -+ Q(A) dq)/2 this gives the HLL fluctuations above
    (S_L >= 0: everything to the right; S_R <= 0: everything to the left)."""
    if sR - sL <= 0.0:
        return 0.0, 0.0, 0.0
    a0 = (sR * abs(sL) - sL * abs(sR)) / (sR - sL)
    a1 = (abs(sR) - abs(sL)) / (sR - sL)
    return a0, a1, 0.0
