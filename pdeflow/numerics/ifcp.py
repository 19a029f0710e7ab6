r"""IFCP: intermediate-field-capturing polynomial viscosity (Fernandez-Nieto, Castro &
Pares 2011), the sharper flux for the two-layer system.

HLL's viscosity Q(x) is the straight line through (S_L, |S_L|) and (S_R, |S_R|): it
overestimates |lambda| badly for the slow internal waves, which it smears. IFCP adds a
third node at the intermediate (internal) speed S_int and uses the parabola

.. math:: Q(x) = \alpha_0 + \alpha_1 x + \alpha_2 x^2,\qquad Q(S) = |S| \text{ at }
          S \in \{S_L, S_{int}, S_R\},

evaluated on the total jump as Q(A) dq = alpha0 dq + alpha1 A dq + alpha2 A (A dq), with A
the pseudo-Jacobian of (28) at the Roe-averaged state. The model supplies S_int; the
two-layer model's (:func:`pdeflow.models.two_layer.flux.internal_speed`) approximates
the internal eigenvalues by U_c -+ c_int with U_c = (h1 u2 + h2 u1)/H and
c_int^2 = (1 - r) g h1 h2 / H (1 - du^2 / ((1 - r) g H)) (clipped at 0); S_int is the one
of larger magnitude. Where the three nodes are too close (S_int at an end of [S_L, S_R]),
the parabola degenerates and the HLL line is used; so it is near a layer's front (any
layer thinner than 5 % of the total depth on either side), where the parabola does not
keep depths non-negative.

For a single layer the two nodes are the Roe eigenvalues u -+ c, which gives Roe's
scheme Q = |A| (with Harten's entropy fix, and HLL at dry fronts).
"""

from __future__ import annotations

from .compiled import cached
from .hll import hll_coefficients


@cached
def ifcp_coefficients(sL: float, sR: float, sint: float) -> tuple[float, float, float]:
    """Coefficients (a0, a1, a2) of the parabola through |x| at S_L, S_int, S_R."""
    width = sR - sL
    if width <= 0.0 or sint - sL < 1e-3 * width or sR - sint < 1e-3 * width:
        return hll_coefficients(sL, sR)
    d1 = (abs(sR) - abs(sL)) / width
    d2 = (abs(sint) - abs(sL) - d1 * (sint - sL)) / ((sint - sL) * (sint - sR))
    return abs(sL) - d1 * sL + d2 * sL * sR, d1 - d2 * (sL + sR), d2


@cached
def roe_coefficients(lam1: float, lam2: float, delta: float) -> tuple[float, float, float]:
    """Line through the entropy-fixed |lambda| at the two Roe eigenvalues (one layer)."""
    a1 = abs(lam1) if abs(lam1) >= delta else (lam1 * lam1 + delta * delta) / (2 * delta)
    a2 = abs(lam2) if abs(lam2) >= delta else (lam2 * lam2 + delta * delta) / (2 * delta)
    if lam2 - lam1 <= 0.0:
        return max(a1, a2), 0.0, 0.0
    s1 = (a2 - a1) / (lam2 - lam1)
    return a1 - s1 * lam1, s1, 0.0
