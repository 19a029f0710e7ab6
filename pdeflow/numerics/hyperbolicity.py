r"""Hyperbolicity of the two-layer system and the extra momentum exchange (33)-(34).

The characteristic polynomial of the pseudo-Jacobian of (28) (g = g_z, r = rho1/rho2):

.. math::  P(\lambda) = [(\lambda-u_1)^2 - g h_1]\,[(\lambda-u_2)^2 - g h_2] - r g^2 h_1 h_2.

The two external roots are always real; the inner pair (lambda_2, lambda_3) turns
complex inside a band F_c1 < |du| < F_c2 of the relative velocity du = u1 - u2.
Cheap closed-form screens (Castro-Diaz et al. 2023, REFERENCE section 2):

.. math::  F_L^2 = \frac{g H^3}{2 h_1 h_2}\Bigl[1 - \sqrt{1 - 4(1-r) h_1 h_2 / H^2}\Bigr]
           \le F_{c1}, \qquad F_R^2 = 2 g H (1 + \sqrt r) \ge F_{c2},

so |du| <= F_L or |du| >= F_R is hyperbolic without further work. Inside the screen
the exact test decides: in the shifted variable x = lambda - (u1 + u2)/2 the quartic
is depressed, x^4 + p x^2 + q x + s, and since two roots are always real, all four
are real iff its discriminant

.. math::  \Delta = 256 s^3 - 128 p^2 s^2 + 144 p q^2 s - 27 q^4 + 16 p^4 s - 4 p^3 q^2

is non-negative (evaluated in units of g H to avoid overflow). This is the paper's
"inner eigenvalues real" test without computing the roots; :func:`eigenvalues`
computes them (for diagnostics and tests).

Restoration (33)-(34): F_extra moves momentum between the layers, -dt F/rho1 to the
upper and +dt F/rho2 to the lower one (total momentum unchanged), inside the implicit
friction stage. It is the smallest such exchange after which the state is hyperbolic,
found by bracketing and bisection. The paper stops its iteration when
lambda_3 - lambda_2 <= w (34); near the boundary that gap grows like the square root
of the distance in du, so pdeflow applies the threshold w to the bracket in du
instead: the iteration stops when the hyperbolic state's |du| is within w of the
last non-hyperbolic one (a resolution of w in du rather than ~w^2).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def lower_bound_fl(h1: float, h2: float, g: float, r: float) -> float:
    """Closed-form lower edge F_L [m/s] of the non-hyperbolic band (Castro-Diaz 2023)."""
    H = h1 + h2
    disc = 1.0 - 4.0 * (1.0 - r) * h1 * h2 / (H * H)
    return math.sqrt(g * H**3 / (2.0 * h1 * h2) * (1.0 - math.sqrt(max(disc, 0.0))))


@njit(cache=True)
def upper_bound_fr(h1: float, h2: float, g: float, r: float) -> float:
    """Upper bound F_R [m/s] of the non-hyperbolic band."""
    return math.sqrt(2.0 * g * (h1 + h2) * (1.0 + math.sqrt(r)))


@njit(cache=True)
def eigenvalues(h1: float, h2: float, u1: float, u2: float, g: float,
                r: float) -> np.ndarray:
    """The four roots of P(lambda), sorted by real part (complex array) [m/s]."""
    um = 0.5 * (u1 + u2)  # shift for conditioning; P depends on du only up to a shift
    a = u1 - um
    b = u2 - um
    p = g * h1
    s = g * h2
    a0 = a * a - p
    b0 = b * b - s
    coeffs = np.empty(5)
    coeffs[0] = 1.0
    coeffs[1] = -2.0 * (a + b)
    coeffs[2] = a0 + b0 + 4.0 * a * b
    coeffs[3] = -2.0 * (a * b0 + b * a0)
    coeffs[4] = a0 * b0 - r * p * s
    roots = np.roots(coeffs.astype(np.complex128))
    order = np.argsort(roots.real)
    return roots[order] + um


@njit(cache=True)
def inner_gap(h1: float, h2: float, u1: float, u2: float, g: float, r: float) -> float:
    """lambda_3 - lambda_2 [m/s] if the inner roots are real, else -1."""
    lam = eigenvalues(h1, h2, u1, u2, g, r)
    scale = math.sqrt(g * (h1 + h2)) + abs(u1 - u2)
    if abs(lam[1].imag) > 1e-7 * scale or abs(lam[2].imag) > 1e-7 * scale:
        return -1.0
    return lam[2].real - lam[1].real


@njit(cache=True)
def discriminant(h1: float, h2: float, u1: float, u2: float, g: float,
                 r: float) -> float:
    """Discriminant of P in units of (g H)^6 (>= 0: all four roots real)."""
    c2 = g * (h1 + h2)
    a = 0.5 * (u1 - u2)
    a2 = a * a / c2
    e1 = g * h1 / c2
    e2 = g * h2 / c2
    # [(x - a)^2 - e1][(x + a)^2 - e2] - r e1 e2 = x^4 + p x^2 + q x + s, x in sqrt(g H)
    p = -2.0 * a2 - e1 - e2
    q = 2.0 * a * (e2 - e1) / math.sqrt(c2)
    s = (a2 - e1) * (a2 - e2) - r * e1 * e2
    return (256.0 * s**3 - 128.0 * p * p * s * s + 144.0 * p * q * q * s
            - 27.0 * q**4 + 16.0 * p**4 * s - 4.0 * p**3 * q * q)


@njit(cache=True)
def is_hyperbolic(h1: float, h2: float, u1: float, u2: float, g: float, r: float,
                  mode: int) -> bool:
    """Hyperbolicity test: mode 1 exact inner roots (paper), mode 2 the bound F_L only."""
    du = abs(u1 - u2)
    if du <= lower_bound_fl(h1, h2, g, r):
        return True
    if mode == 2:
        return False  # the bound alone is conservative: it also flags the band's top
    if du >= upper_bound_fr(h1, h2, g, r):
        return True
    return discriminant(h1, h2, u1, u2, g, r) >= 0.0
