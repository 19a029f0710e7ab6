r"""Basal friction laws, and their set-valued backward-Euler friction step.

A law gives the basal friction of a layer of depth h [m] sliding at speed s = |u| [m/s]
as an acceleration per unit mass ``gw mu(h, s) + D s^2 / h_m`` (``gw`` = g_z times the
layer's weight over its mass: g_z for one layer; D = g/xi only for Voellmy) and, at rest,
the set [-gw mu_static(h), gw mu_static(h)]. A law is a :class:`BasalLaw`: its kernels
over its constants ``law`` (the tuple :func:`law_block` reads from the law's block of
the parameter vector, offsets ``layout.LAW_*``, which the model's dataclass fills,
:mod:`pdeflow.models.friction_laws`). A model's source stage is compiled per law, with
the law's kernels as constants (e.g. :func:`pdeflow.models.single_layer.sources.stage_kernels`),
so that a run compiles its own law's code only; Coulomb's friction is not a law here
but each model's closed-form step (:mod:`.implicit`).

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

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import layout as L
from .compiled import cached, specialise
from .implicit import drag_root

MU1, DMU, S0, INV_L, BETA_G, DRAG = (L.LAW_MU1, L.LAW_DMU, L.LAW_S0, L.LAW_INV_L,
                                     L.LAW_BETA_G, L.LAW_DRAG)


@dataclass(frozen=True, eq=False)
class BasalLaw:
    """A rate-dependent basal law as kernels of its constants ``law`` (a tuple of
    ``layout.N_LAW`` floats, :func:`law_block`), compared and hashed by identity (the
    stage factories build one stage per law). Its deceleration is ``gw mu(h, s) +
    law[LAW_DRAG] s^2 / hm`` (:func:`basal_accel`)."""

    name: str
    """the name case files use (``friction_law``)"""
    static_mu: Any
    """``(law, h) -> mu_static(h)``: the upper end of the set at rest [-]"""
    flowing_mu: Any
    """``(law, h, s) -> mu(h, s)`` [-] for s > 0 (mu(h, 0+) = mu_static(h))"""
    flowing_mu_slope: Any
    """``(law, h, s) -> d mu / d s`` [s/m] for s > 0 (>= 0: friction graph monotone)"""
    speed: Any
    """``(a, h, gw, hm, dt, law) -> s``: the speed after the set-valued backward-Euler
    step from speed ``a`` [m/s] (0: held at rest), see the module docstring"""
    accel_np: Callable[..., np.ndarray]
    """numpy twin of :func:`basal_accel` over arrays: ``(law, h, gw, hm, s)``"""


@cached(inline="always")
def law_block(P, base):
    """The law's block of ``P`` at ``base`` as a tuple of its ``layout.N_LAW`` (six)
    floats: what the law's kernels take. A tuple, not the array: an array passed on to
    a helper costs a reference-count update per call, which was 6-30 times the friction
    law's own arithmetic (measured)."""
    return (P[base], P[base + 1], P[base + 2], P[base + 3], P[base + 4], P[base + 5])


def law_block_np(P: np.ndarray, base: int) -> tuple[float, ...]:
    """:func:`law_block` in Python (for the numpy twins)."""
    return tuple(float(v) for v in P[base:base + L.N_LAW])


@functools.cache
def basal_accel(law: BasalLaw) -> Any:
    """The kernel ``(law, h, gw, hm, s)``: friction deceleration [m/s^2] of ``law`` at
    speed ``s`` >= 0 [m/s] (s = 0: the static bound), gw mu(h, s) + D s^2 / hm, ``hm``
    the layer's mass depth [m]."""
    static_mu, flowing_mu = law.static_mu, law.flowing_mu

    def basal_accel_law(c, h, gw, hm, s):
        if s <= 0.0:
            return gw * static_mu(c, h)
        return gw * flowing_mu(c, h, s) + c[DRAG] * s * s / hm

    return specialise(basal_accel_law, helper=True, inline="always")


@functools.cache
def law_velocity(law: BasalLaw) -> Any:
    """The kernel ``(b, h, gw, hm, dt, law)``: :attr:`BasalLaw.speed` with the sign of
    ``b``, the velocity after the friction step [m/s]."""
    speed = law.speed

    def law_velocity_law(b, h, gw, hm, dt, c):
        s = speed(abs(b), h, gw, hm, dt, c)
        return s if b > 0.0 else -s

    return specialise(law_velocity_law, helper=True, inline="always")


@cached(inline="always")
def _rational_mu(law, h, s):
    """mu1 + dmu s / (s0(h) + s), s0 = S0 h^(3/2) [-]."""
    s0 = law[S0] * h * math.sqrt(h)
    return law[MU1] + law[DMU] * s / (s0 + s)


@cached(inline="always")
def _rational_slope(law, h, s):
    """d/ds of :func:`_rational_mu` [s/m]."""
    s0 = law[S0] * h * math.sqrt(h)
    return law[DMU] * s0 / ((s0 + s) * (s0 + s))


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
def _mu1(law, h):
    """mu1 [-]: the static bound of mu_i and Voellmy, and Voellmy's mu."""
    return law[MU1]


@cached(inline="always")
def _mu1_flowing(law, h, s):
    """Voellmy's mu [-] (its rate part is the drag)."""
    return law[MU1]


@cached(inline="always")
def _no_slope(law, h, s):
    """0: a coefficient that does not depend on the speed."""
    return 0.0


@cached(inline="always")
def _pouliquen_static(law, h):
    """mu_stop(h) = mu1 + dmu / (1 + h/L) [-]."""
    return law[MU1] + law[DMU] / (1.0 + h * law[INV_L])


@cached(inline="always")
def _pouliquen_mu(law, h, s):
    """Pouliquen's mu(h, s) [-]: mu_stop(h) on the plateau Fr < beta."""
    if s < law[BETA_G] * math.sqrt(h):
        return _pouliquen_static(law, h)
    return _rational_mu(law, h, s)


@cached(inline="always")
def _pouliquen_slope(law, h, s):
    """d mu / d s of :func:`_pouliquen_mu` [s/m] (0 on the plateau)."""
    if s < law[BETA_G] * math.sqrt(h):
        return 0.0
    return _rational_slope(law, h, s)


@cached(inline="always")
def _pouliquen_speed(a, h, gw, hm, dt, law):
    """Pouliquen's friction step (see :attr:`BasalLaw.speed`)."""
    ydt = dt * gw
    y = a - ydt * law[MU1]
    # mu_stop(h) = mu1 + dmu / (1 + h/L) is the static bound and the plateau Fr < beta;
    # both tests multiplied by 1 + h/L > 0 (no division on the way)
    w = 1.0 + h * law[INV_L]
    drive = y * w - ydt * law[DMU]  # (a - dt gw mu_stop) (1 + h/L)
    if drive <= 0.0:
        return 0.0  # held at rest by static friction
    root_h = math.sqrt(h)
    if drive <= law[BETA_G] * root_h * w:
        return drive / w
    return _rational_root(y, ydt * law[DMU], law[S0] * h * root_h)


@cached(inline="always")
def _mu_i_speed(a, h, gw, hm, dt, law):
    """mu(I)'s friction step (see :attr:`BasalLaw.speed`)."""
    ydt = dt * gw
    y = a - ydt * law[MU1]
    if y <= 0.0:
        return 0.0  # held at rest: the static bound is mu1
    return _rational_root(y, ydt * law[DMU], law[S0] * h * math.sqrt(h))


@cached(inline="always")
def _voellmy_speed(a, h, gw, hm, dt, law):
    """Voellmy's friction step (see :attr:`BasalLaw.speed`): a quadratic in s."""
    y = a - dt * gw * law[MU1]
    if y <= 0.0:
        return 0.0  # held at rest: the static bound is mu
    return drag_root(y, 1.0, dt * law[DRAG] / hm)


def _accel_np(law: tuple, mu_static: Any, mu: Any, gw: Any, hm: Any,
              s: np.ndarray) -> np.ndarray:
    """gw mu + D s^2 / hm over arrays, mu_static where s = 0 [m/s^2]."""
    mu = np.where(s > 0.0, mu, mu_static)
    return gw * mu + law[DRAG] * s * s / np.maximum(hm, 1e-300)


def _rational_np(law: tuple, hp: np.ndarray, s: np.ndarray) -> np.ndarray:
    s0 = law[S0] * hp * np.sqrt(hp)
    return law[MU1] + law[DMU] * s / np.maximum(s0 + s, 1e-300)


def _pouliquen_np(law, h, gw, hm, s):
    hp = np.maximum(h, 1e-300)
    mu_static = law[MU1] + law[DMU] / (1.0 + hp * law[INV_L])
    mu = np.where(s < law[BETA_G] * np.sqrt(hp), mu_static, _rational_np(law, hp, s))
    return _accel_np(law, mu_static, mu, gw, hm, s)


def _mu_i_np(law, h, gw, hm, s):
    hp = np.maximum(h, 1e-300)
    return _accel_np(law, law[MU1] + 0.0, _rational_np(law, hp, s), gw, hm, s)


def _voellmy_np(law, h, gw, hm, s):
    hp = np.maximum(h, 1e-300)
    return _accel_np(law, law[MU1] + 0.0, np.full_like(hp, law[MU1]), gw, hm, s)


POULIQUEN = BasalLaw("pouliquen", _pouliquen_static, _pouliquen_mu, _pouliquen_slope,
                     _pouliquen_speed, _pouliquen_np)
"""Pouliquen & Forterre (2002): mu(h, Fr) with the plateau Fr < beta"""
MU_I = BasalLaw("mu_i", _mu1, _rational_mu, _rational_slope, _mu_i_speed, _mu_i_np)
"""the depth-averaged mu(I) of Jop, Forterre & Pouliquen (2006), Bagnold profile"""
VOELLMY = BasalLaw("voellmy", _mu1, _mu1_flowing, _no_slope, _voellmy_speed, _voellmy_np)
"""Voellmy (1955): mu + g u^2 / (xi h)"""
