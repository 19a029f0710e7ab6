r"""Hyperbolicity of the two-layer system and the extra momentum exchange (33)-(34).

The characteristic polynomial of the pseudo-Jacobian of (28) (g = g_z, r = rho1/rho2):

.. math::  P(\lambda) = [(\lambda-u_1)^2 - g h_1]\,[(\lambda-u_2)^2 - g h_2] - r g^2 h_1 h_2.

The two external roots are always real; the inner pair (lambda_2, lambda_3) turns
complex inside a band F_c1 < |du| < F_c2 of the relative velocity du = u1 - u2.
Cheap closed-form screens (Castro-Díaz et al. 2023, Adv. Water Resour. 182, 104587):

.. math::  F_L^2 = \frac{g H^3}{2 h_1 h_2}\Bigl[1 - \sqrt{1 - 4(1-r) h_1 h_2 / H^2}\Bigr]
           \le F_{c1}, \qquad F_R^2 = 2 g H (1 + \sqrt r) \ge F_{c2},

so |du| <= F_L or |du| >= F_R is hyperbolic (F_L is the ``bound`` mode's test). The
exact test: in the shifted variable x = lambda - (u1 + u2)/2 the quartic is
depressed, x^4 + p x^2 + q x + s, and since two roots are always real, all four are
real iff its discriminant

.. math::  \Delta = 256 s^3 - 128 p^2 s^2 + 144 p q^2 s - 27 q^4 + 16 p^4 s - 4 p^3 q^2

is non-negative (evaluated in units of g H to avoid overflow; as a quartic in
A = (du/2)^2/(g H), see :func:`_quartic_in_a`). This is the paper's "inner eigenvalues
real" test without computing the roots; :func:`eigenvalues` computes them (numpy, for
the app's spectrum page and tests).

Restoration (33)-(34): F_extra moves momentum between the layers, -dt F/rho1 to the
upper and +dt F/rho2 to the lower one (total momentum unchanged), inside the implicit
friction stage. It is the smallest such exchange after which the state is hyperbolic.
Because the depths are frozen in that stage, hyperbolicity depends on du alone: the
target is the lower band edge F_c1 (:func:`band_lower_edge`, a root of the
discriminant found by safeguarded Halley iteration; F_L itself in ``bound`` mode), and
the implicit friction step, solved in closed form, is inverted for the F_extra that
lands |du| on it (:func:`pdeflow.models.two_layer.friction._restore_hyperbolicity`).
The paper iterates until lambda_3 - lambda_2 <= w (34); near the boundary that gap grows like
the square root of the distance in du, so pdeflow reads w as a tolerance in du: the
restored |du| lies within w below F_c1 (the direct solve lands within round-off of
it; the bisection kept as a fallback stops when its bracket in du is below w).
"""

from __future__ import annotations

import math

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import cached


@cached
def lower_bound_fl(h1: float, h2: float, g: float, r: float) -> float:
    """Closed-form lower edge F_L [m/s] of the non-hyperbolic band (Castro-Diaz 2023)."""
    H = h1 + h2
    disc = 1.0 - 4.0 * (1.0 - r) * h1 * h2 / (H * H)
    return math.sqrt(g * H * H * H / (2.0 * h1 * h2) * (1.0 - math.sqrt(max(disc, 0.0))))


@cached
def upper_bound_fr(h1: float, h2: float, g: float, r: float) -> float:
    """Upper bound F_R [m/s] of the non-hyperbolic band."""
    return math.sqrt(2.0 * g * (h1 + h2) * (1.0 + math.sqrt(r)))


def eigenvalues(h1: float, h2: float, u1: float | np.ndarray, u2: float | np.ndarray,
                g: float, r: float) -> np.ndarray:
    """The four roots of P(lambda) [m/s], sorted by real part (a complex-conjugate pair
    in either order): a complex array of shape (4,), or (..., 4) for arrays of
    velocities u1, u2 (broadcast). numpy, not a kernel: only Python calls it (the app's
    spectrum page, tests), and as a kernel (numba's ``np.roots``) it was the slowest of
    all to compile; for many velocities at once it is one batched eigenvalue solve."""
    u1, u2 = np.broadcast_arrays(np.asarray(u1, dtype=float), np.asarray(u2, dtype=float))
    um = 0.5 * (u1 + u2)  # shift for conditioning; P depends on du only up to a shift
    a = u1 - um
    b = u2 - um
    p = g * h1
    s = g * h2
    a0 = a * a - p
    b0 = b * b - s
    # companion matrix of the monic quartic x^4 + c1 x^3 + c2 x^2 + c3 x + c4 = P(x + um)
    companion = np.zeros((*u1.shape, 4, 4))
    companion[..., 0, 0] = 2.0 * (a + b)
    companion[..., 0, 1] = -(a0 + b0 + 4.0 * a * b)
    companion[..., 0, 2] = 2.0 * (a * b0 + b * a0)
    companion[..., 0, 3] = -(a0 * b0 - r * p * s)
    companion[..., [1, 2, 3], [0, 1, 2]] = 1.0
    roots = np.linalg.eigvals(companion).astype(complex)
    order = np.argsort(roots.real, axis=-1)
    return np.take_along_axis(roots, order, axis=-1) + um[..., None]


@cached
def _quartic_in_a(h1: float, h2: float, r: float) -> tuple[float, float, float, float,
                                                              float]:
    r"""Coefficients (a4, a3, a2, a1, a0) of Delta/16 as a quartic in A = (du/2)^2/(g H).

    With e_i = h_i/H (e1 + e2 = 1), beta = e1 e2, d = 1 - 4 beta = (e2 - e1)^2 and
    c = (1 - r) beta, the depressed quartic has p = -2A - 1, q^2 = 4 A d,
    s = A^2 - A + c, and its discriminant expands to

    .. math::  \Delta/16 = 256\beta A^4 - 16(4c - 3d + 3) A^3
               + (16c^2 - 72cd + 120c - 27d^2 + 42d - 15) A^2
               - (80c^2 + 36cd - 24c - d + 1) A + c(4c - 1)^2 .
    """
    e1 = h1 / (h1 + h2)
    beta = e1 * (1.0 - e1)
    d = 1.0 - 4.0 * beta
    c = (1.0 - r) * beta
    return (256.0 * beta, -16.0 * (4.0 * c - 3.0 * d + 3.0),
            16.0 * c * c - 72.0 * c * d + 120.0 * c - 27.0 * d * d + 42.0 * d - 15.0,
            -(80.0 * c * c + 36.0 * c * d - 24.0 * c - d + 1.0),
            c * (4.0 * c - 1.0) ** 2)


@cached
def discriminant(h1: float, h2: float, u1: float, u2: float, g: float,
                 r: float) -> float:
    """Discriminant of P in units of (g H)^6 (>= 0: all four roots real)."""
    a4, a3, a2, a1, a0 = _quartic_in_a(h1, h2, r)
    du = u1 - u2
    A = 0.25 * du * du / (g * (h1 + h2))
    return 16.0 * ((((a4 * A + a3) * A + a2) * A + a1) * A + a0)


@cached
def is_hyperbolic(h1: float, h2: float, u1: float, u2: float, g: float, r: float,
                  mode: int) -> bool:
    """Hyperbolicity test: ``mode`` layout.HYPERBOLICITY_EXACT: the inner roots (paper);
    HYPERBOLICITY_BOUND: the bound F_L only.

    Two roots of P are always real, so the discriminant alone decides the exact mode:
    it is negative exactly when one conjugate pair is complex (cheaper than the screens)."""
    du = u1 - u2
    if du * du <= (1.0 - r) * g * (h1 + h2):
        return True  # below F_L (1 - sqrt(1 - x) >= x/2 gives F_L^2 >= (1 - r) g H)
    if mode == L.HYPERBOLICITY_BOUND:
        # the bound alone is conservative: it also flags the band's top
        return abs(du) <= lower_bound_fl(h1, h2, g, r)
    return discriminant(h1, h2, u1, u2, g, r) >= 0.0


@cached(inline="always")
def _quartic_at(a: tuple[float, float, float, float, float], x: float) -> float:
    """Delta/16 at A = ``x``: the quartic of :func:`_quartic_in_a` by Horner's rule."""
    a4, a3, a2, a1, a0 = a
    return (((a4 * x + a3) * x + a2) * x + a1) * x + a0


@cached
def restoration_target(h1: float, h2: float, du: float, g: float, r: float,
                       mode: int) -> tuple[bool, float]:
    """:func:`is_hyperbolic` for the restoration: (False, 0) where the state is
    hyperbolic, else (True, the |du| [m/s] to restore): the band edge F_c1 of
    :func:`band_lower_edge` (``mode`` exact), or F_L (``mode`` bound).

    The same tests as :func:`is_hyperbolic` and the same edge as
    :func:`band_lower_edge` with ``du_bad`` = |du|, in one pass: the quartic's
    coefficients and its value at A = (du/2)^2/(g H) found by the test start the
    Halley iteration of the edge."""
    if du * du <= (1.0 - r) * g * (h1 + h2):
        return False, 0.0  # below F_L (see is_hyperbolic)
    if mode == L.HYPERBOLICITY_BOUND:
        fl = lower_bound_fl(h1, h2, g, r)
        return abs(du) > fl, fl
    a = _quartic_in_a(h1, h2, r)
    c2 = g * (h1 + h2)
    A = 0.25 * du * du / c2
    D = _quartic_at(a, A)
    if D >= 0.0:
        return False, 0.0
    return True, _edge_below(a, c2, A, D)


EDGE_SAMPLES = 256
"""samples of A between F_L and |du| that look for the band below a hyperbolic |du|"""


@cached
def restoration_target_all(h1: float, h2: float, du: float, g: float, r: float,
                           mode: int) -> tuple[bool, float]:
    """:func:`restoration_target` for every direction of a 2D state (docs/two_d.md):
    (True, F_c1) whenever |du| > F_c1, above the band as inside it (F_L in ``bound``
    mode), else (False, 0). Above the band the quartic is sampled at
    :data:`EDGE_SAMPLES` points of A between F_L and |du| for a point inside the band,
    from which :func:`_edge_below` refines F_c1 (a band narrower than the spacing is
    missed: the state then counts as hyperbolic)."""
    bad, edge = restoration_target(h1, h2, du, g, r, mode)
    if bad or mode == L.HYPERBOLICITY_BOUND or du * du <= (1.0 - r) * g * (h1 + h2):
        return bad, edge
    fl = lower_bound_fl(h1, h2, g, r)
    if abs(du) <= fl:
        return False, 0.0
    a = _quartic_in_a(h1, h2, r)
    c2 = g * (h1 + h2)
    lo = 0.25 * fl * fl / c2
    hi = 0.25 * du * du / c2
    for j in range(1, EDGE_SAMPLES + 1):
        x = lo + (hi - lo) * j / (EDGE_SAMPLES + 1)
        D = _quartic_at(a, x)
        if D < 0.0:
            return True, _edge_below(a, c2, x, D)
    return False, 0.0


@cached
def band_lower_edge(h1: float, h2: float, g: float, r: float, du_bad: float) -> float:
    """Lower edge F_c1 [m/s] of the non-hyperbolic band, given a non-hyperbolic |du|.

    ``du_bad`` (> F_c1, inside the band) brackets the root together with du = 0
    (hyperbolic: Delta(0) = 16 c (4c - 1)^2 >= 0); the root is refined by
    :func:`_edge_below`. Returns F_c1 to one part in 1e-9, from the hyperbolic side up
    to round-off (callers aiming at the edge stay a hair below it), or -1 if
    ``du_bad`` is not inside the band.
    """
    a = _quartic_in_a(h1, h2, r)
    c2 = g * (h1 + h2)
    hi = 0.25 * du_bad * du_bad / c2
    D = _quartic_at(a, hi)
    if D >= 0.0:
        return -1.0
    return _edge_below(a, c2, hi, D)


@cached(inline="always")
def _edge_below(a: tuple[float, float, float, float, float], c2: float, hi: float,
                D: float) -> float:
    """F_c1 [m/s]: the root of the quartic ``a`` of :func:`_quartic_in_a` below
    A = ``hi`` (where it is ``D`` < 0), returned as 2 sqrt(A c2) (``c2`` = g H
    [m^2/s^2]).

    Halley's method from the non-hyperbolic end (the restoration calls it with |du|
    just above F_c1: two or three iterations), safeguarded by false position on the
    bracket [0, hi] (Delta(0) >= 0); at convergence (a step below 1e-10 A) the root is
    settled on its hyperbolic side.
    """
    a4, a3, a2, a1, a0 = a
    lo = 0.0
    d_lo = a0
    x = hi
    d_hi = D
    for _ in range(100):
        dD = ((4.0 * a4 * x + 3.0 * a3) * x + 2.0 * a2) * x + a1
        d2D = (12.0 * a4 * x + 6.0 * a3) * x + 2.0 * a2
        den = 2.0 * dD * dD - D * d2D
        step = 2.0 * D * dD / den if den != 0.0 else 0.0
        if den != 0.0 and abs(step) <= 1e-10 * x:
            # at the root to within 1e-10: settle on its hyperbolic (smaller A) side
            eps = 1e-10
            while D < 0.0 and eps < 1e-6:
                y = x * (1.0 - eps) - abs(step)
                D = _quartic_at(a, y)
                if D >= 0.0:
                    x = y
                eps *= 4.0
            if D >= 0.0:
                lo = x
            break
        xn = x - step
        if not (lo < xn < hi):
            xn = lo - d_lo * (hi - lo) / (d_hi - d_lo)
            if not (lo < xn < hi):
                xn = 0.5 * (lo + hi)
        x = xn
        D = _quartic_at(a, x)
        if D >= 0.0:
            lo = x
            d_lo = D
        else:
            hi = x
            d_hi = D
        if hi - lo <= 1e-10 * hi:
            break
    return 2.0 * math.sqrt(lo * c2)


BAND_SAMPLES = 2000
"""du samples on [0, 1.05 F_R] that find the band before its edges are refined"""


def band_edges(h1: float, h2: float, g: float, r: float) -> tuple[float, float] | None:
    """(F_c1, F_c2) [m/s]: the band of |du| where two eigenvalues are complex, or None.

    The band is located on a grid of :data:`BAND_SAMPLES` values of du up to 1.05 F_R
    (F_R bounds it from above); F_c1 is then :func:`band_lower_edge` (the target of the
    restoration), F_c2 the discriminant's root above the last complex sample.
    """
    from scipy.optimize import brentq

    du = np.linspace(0.0, 1.05 * upper_bound_fr(h1, h2, g, r), BAND_SAMPLES + 1)
    disc = np.array([discriminant(h1, h2, d, 0.0, g, r) for d in du])
    bad = np.nonzero(disc < 0.0)[0]
    if bad.size == 0:
        return None
    f_c1 = band_lower_edge(h1, h2, g, r, du[bad[0]])
    j = bad[-1]
    f_c2 = brentq(lambda d: discriminant(h1, h2, d, 0.0, g, r), du[j], du[j + 1],
                  xtol=1e-12)
    return float(f_c1), float(f_c2)
