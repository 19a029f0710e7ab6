r"""Basal friction laws, and their set-valued backward-Euler friction step.

A law gives the basal friction of a layer of depth h [m] sliding at speed s = |u| [m/s]
as an acceleration per unit mass ``gw mu(h, s) + D s^2 / h_m`` (``gw`` = g_z times the
layer's weight over its mass: g_z for one layer; D = g/xi only for Voellmy) and, at rest,
the set [-gw mu_static(h), gw mu_static(h)]. Codes and the parameter block are in
:mod:`pdeflow.numerics.layout` (``FRICTION_*``, ``LAW_*``); the model's dataclass fills
them (:mod:`pdeflow.models.friction_laws`).

The laws, written for s > 0 as mu(h, s) = mu1 + dmu s / (s0(h) + s), s0 = S0 h^(3/2):

* ``pouliquen`` (Pouliquen & Forterre 2002, J. Fluid Mech. 453; the paper's equation
  numbers could not be checked here, see docs/model.md): for Fr = s/sqrt(g_z h) >= beta,
  mu = tan d1 + (tan d2 - tan d1) / (1 + beta h / (L Fr)), i.e. S0 = beta sqrt(g_z) / L;
  for 0 < Fr < beta the value at Fr = beta, mu_stop(h) = tan d1 + (tan d2 - tan d1) /
  (1 + h/L), which is also the static bound. Steady uniform flow on a slope theta has
  Fr = beta h / h_stop(theta), h_stop = L (tan d2 - tan theta)/(tan theta - tan d1).
  (The paper's start branch mu_start with d3 > d1, and its (Fr/beta)^gamma
  interpolation, make friction *decrease* from rest to motion; a weakening law has two
  backward-Euler solutions in a step, so it is not offered: see docs/model.md.)
* ``mu_i`` (Jop, Forterre & Pouliquen 2006, Nature 441): mu(I) = mu_s +
  (mu2 - mu_s) / (I0/I + 1) with the depth-averaged I = 5 s d / (2 h sqrt(phi g_z h))
  of a Bagnold profile, i.e. S0 = 2 I0 sqrt(phi g_z) / (5 d); static bound mu_s.
* ``voellmy`` (Voellmy 1955, Salm 1993): mu + g s^2 / (xi h) (dmu = 0); static bound mu.

Backward Euler over a step dt with the velocity ``b`` before friction reads
s + dt [gw mu(h, s) + D s^2/h_m] = |b| for s = |u| > 0, and u = 0 if |b| <= dt gw
mu_static(h). The left side is continuous and strictly increasing in s, and tends to
dt gw mu_static as s -> 0+ for every law (mu_static = mu(h, 0+)): so the friction graph is
maximal monotone, the step has exactly one solution, and a cell whose drive is below the
static friction stops in that step (exact rest, no creep). It is solved in closed form:
Voellmy's equation is a quadratic in s; the rational laws become one after multiplying
by s0 + s > 0: s^2 + (s0 + c - y) s - s0 y = 0 with y = |b| - dt gw mu1 > 0, c = dt gw dmu,
whose one positive root is taken in a cancellation-free form. Thin films: s0 -> 0 as
h -> 0 (I and Fr blow up), the root stays finite and tends to y - c (friction mu2); no
division by h appears except Voellmy's D/h_m, with h_m above the dry tolerance.
"""

from __future__ import annotations

import math

from . import layout as L
from .compiled import cached
from .implicit import drag_root


@cached(inline="always")
def law_block(P, base):
    """The law's block of ``P`` at ``base`` as a tuple of floats (code, mu1, dmu, S0,
    1/L, beta sqrt(g_z), D): what the helpers below take. A tuple, not the array: an
    array passed on to a helper costs a reference-count update per call, which was
    6-30 times the friction law's own arithmetic (measured)."""
    return (P[base + L.LAW_CODE], P[base + L.LAW_MU1], P[base + L.LAW_DMU],
            P[base + L.LAW_S0], P[base + L.LAW_INV_L], P[base + L.LAW_BETA_G],
            P[base + L.LAW_DRAG])


@cached(inline="always")
def static_mu(law, h):
    """Upper end of the friction coefficient's set at rest [-] for depth ``h`` [m]."""
    mu = law[1]
    if int(law[0]) == L.FRICTION_POULIQUEN:
        mu += law[2] / (1.0 + h * law[4])
    return mu


@cached(inline="always")
def flowing_mu(law, h, s):
    """Friction coefficient mu(h, s) [-] of a layer of depth ``h`` [m] at speed ``s`` > 0
    [m/s] (without Voellmy's drag, see :func:`basal_accel`)."""
    code = int(law[0])
    mu1 = law[1]
    if code == L.FRICTION_VOELLMY or code == L.FRICTION_COULOMB:
        return mu1
    if code == L.FRICTION_POULIQUEN and s < law[5] * math.sqrt(h):
        return static_mu(law, h)  # the plateau Fr < beta: mu_stop(h)
    s0 = law[3] * h * math.sqrt(h)
    return mu1 + law[2] * s / (s0 + s)


@cached(inline="always")
def flowing_mu_slope(law, h, s):
    """d mu(h, s) / d s [s/m] for s > 0 (0 on Pouliquen's plateau and for Voellmy)."""
    code = int(law[0])
    if code == L.FRICTION_VOELLMY or code == L.FRICTION_COULOMB:
        return 0.0
    if code == L.FRICTION_POULIQUEN and s < law[5] * math.sqrt(h):
        return 0.0
    s0 = law[3] * h * math.sqrt(h)
    return law[2] * s0 / ((s0 + s) * (s0 + s))


@cached(inline="always")
def basal_accel(law, h, gw, hm, s):
    """Friction deceleration [m/s^2] at speed ``s`` >= 0 [m/s] (s = 0: the static
    bound): gw mu(h, s) + D s^2 / hm, ``hm`` the layer's mass depth [m]."""
    if s <= 0.0:
        return gw * static_mu(law, h)
    return gw * flowing_mu(law, h, s) + law[6] * s * s / hm


@cached(inline="always")
def _rational_root(y, c, s0):
    """Positive root s of s + c s / (s0 + s) = y (y > 0, c >= 0, s0 >= 0) [m/s]."""
    bb = s0 + c - y
    disc = math.sqrt(bb * bb + 4.0 * s0 * y)
    if bb >= 0.0:
        den = bb + disc
        return 2.0 * s0 * y / den if den > 0.0 else 0.0
    return 0.5 * (disc - bb)


@cached(inline="always")
def law_speed(a, h, gw, hm, dt, law):
    """Speed |u| [m/s] after the set-valued backward-Euler friction step of a layer
    whose velocity before friction has magnitude ``a`` [m/s]: depth ``h`` [m] seen by the
    law, ``gw`` = g_z weight/mass [m/s^2], mass depth ``hm`` [m] (see module docstring)."""
    ydt = dt * gw
    code = int(law[0])
    y = a - ydt * law[1]
    if code == L.FRICTION_POULIQUEN:
        # mu_stop(h) = mu1 + dmu / (1 + h/L) is the static bound and the plateau
        # Fr < beta; both tests multiplied by 1 + h/L > 0 (no division on the way)
        w = 1.0 + h * law[4]
        drive = y * w - ydt * law[2]  # (a - dt gw mu_stop) (1 + h/L)
        if drive <= 0.0:
            return 0.0  # held at rest by static friction
        root_h = math.sqrt(h)
        if drive <= law[5] * root_h * w:
            return drive / w
        return _rational_root(y, ydt * law[2], law[3] * h * root_h)
    if y <= 0.0:
        return 0.0  # held at rest: the static bound of the other laws is mu1
    if code == L.FRICTION_VOELLMY:
        return drag_root(y, 1.0, dt * law[6] / hm)
    if code == L.FRICTION_COULOMB:
        return y
    return _rational_root(y, ydt * law[2], law[3] * h * math.sqrt(h))


@cached(inline="always")
def law_velocity(b, h, gw, hm, dt, law):
    """:func:`law_speed` with the sign of ``b``: the velocity after friction [m/s]."""
    s = law_speed(abs(b), h, gw, hm, dt, law)
    return s if b > 0.0 else -s
