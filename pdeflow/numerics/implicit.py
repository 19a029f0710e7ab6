"""Closed-form backward-Euler friction steps that friction laws and models share.

Coulomb's set-valued step (a layer whose drive is below the friction stops) and the
positive root of a linear-plus-quadratic drag balance, written cancellation-free. Kept
apart from the rate-dependent laws (:mod:`.rheology`) so that a Coulomb run compiles
none of the laws' code.
"""

from __future__ import annotations

import math

from .compiled import cached


@cached
def coulomb_single(b: float, mu_dt: float) -> float:
    """Backward-Euler Coulomb step u = b - mu_dt Sgn(u) (set-valued): shrink towards 0.

    ``b`` is the velocity before friction [m/s], ``mu_dt`` = dt g_z tan(phi) [m/s].
    """
    if b > mu_dt:
        return b - mu_dt
    if b < -mu_dt:
        return b + mu_dt
    return 0.0


@cached
def drag_root(y: float, mass: float, cdt: float) -> float:
    """Positive x with mass x + cdt x^2 = y (y >= 0), in a cancellation-free form."""
    if y <= 0.0:
        return 0.0
    if cdt <= 0.0:
        return y / mass
    return 2.0 * y / (mass + math.sqrt(mass * mass + 4.0 * cdt * y))
