"""Rusanov (local Lax-Friedrichs) interface flux.

One viscosity for every wave: Q = S_max I with S_max = max(|S_L|, |S_R|), the largest
wave-speed bound at the face. Fluctuations D^-+ = (A dq -+ S_max dq) / 2 (polynomial-
viscosity form, :mod:`pdeflow.numerics.pvm`). The most diffusive and most robust of the
three fluxes: it smears the slow internal (interface) waves of the two-layer system as
much as the fast external ones.
"""

from __future__ import annotations

from .compiled import cached


@cached
def rusanov_coefficients(sL: float, sR: float) -> tuple[float, float, float]:
    """Q(x) = S_max: coefficients (a0, a1, a2) of the viscosity polynomial."""
    return max(abs(sL), abs(sR)), 0.0, 0.0
