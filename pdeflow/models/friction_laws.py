"""The basal friction law as model parameters: a choice and each law's constants.

Both shipped models mix :class:`FrictionLawParameters` into their parameter dataclass
(``single_layer.friction_law``, ``two_layer.friction_law`` for the lower layer's bed).
A law is a :class:`FrictionLaw` in :data:`LAWS`, by name: its kernels
(:class:`pdeflow.numerics.rheology.BasalLaw`, which the models' stages are compiled
with: the one channel by which a law reaches the kernels) and its constants, which
:meth:`FrictionLawParameters.fill_law` writes into the law's block of the model's
kernel parameter vector (so that a sweep over a law's constants compiles once).
Coulomb, the default, has no kernels here: each model's closed-form Coulomb step, with
the model's own ``phi_b_deg``; the other laws ignore that angle. Defaults: glass beads
of d = 0.5 mm for ``pouliquen`` and ``mu_i`` (Forterre & Pouliquen 2003, Jop, Forterre
& Pouliquen 2006), snow for ``voellmy``; docs/rheology.md says which of these numbers
could be checked, and where (none from the papers themselves).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..numerics import layout as L
from ..numerics.rheology import MU_I, POULIQUEN, VOELLMY, BasalLaw
from .base import check_range


@dataclass(frozen=True)
class FrictionLaw:
    """A basal friction law: its kernels and how its constants come from the
    parameters."""

    kernels: BasalLaw | None
    """the law's kernels; None: Coulomb's closed-form step, the models' own kernels"""
    constants: Callable[[FrictionLawParameters, float, float, float], tuple[float, ...]]
    """``(parameters, g_z [m/s^2], g [m/s^2], tan(phi_b)) -> constants``: the law's
    block of the parameter vector (at most ``layout.N_LAW`` floats, offsets
    ``layout.LAW_*``; the rest are 0)"""


def _coulomb(p: FrictionLawParameters, g_z: float, g: float,
             tan_b: float) -> tuple[float, ...]:
    return (tan_b,)


def _rational(p: FrictionLawParameters, s0: float, inv_l: float = 0.0,
              beta_g: float = 0.0) -> tuple[float, ...]:
    """mu1 = tan d1, dmu = tan d2 - tan d1 and the rest of a rational law's block."""
    mu1 = math.tan(math.radians(p.delta1_deg))
    return (mu1, math.tan(math.radians(p.delta2_deg)) - mu1, s0, inv_l, beta_g)


def _pouliquen(p: FrictionLawParameters, g_z: float, g: float,
               tan_b: float) -> tuple[float, ...]:
    return _rational(p, p.pouliquen_beta * math.sqrt(g_z) / p.pouliquen_L,
                     1.0 / p.pouliquen_L, p.pouliquen_beta * math.sqrt(g_z))


def _mu_i(p: FrictionLawParameters, g_z: float, g: float,
          tan_b: float) -> tuple[float, ...]:
    return _rational(p, 2.0 * p.mu_i_I0 * math.sqrt(p.packing_fraction * g_z)
                     / (5.0 * p.grain_diameter))


def _voellmy(p: FrictionLawParameters, g_z: float, g: float,
             tan_b: float) -> tuple[float, ...]:
    drag = [0.0] * L.N_LAW
    drag[L.LAW_MU1], drag[L.LAW_DRAG] = p.voellmy_mu, g / p.voellmy_xi
    return tuple(drag)


LAWS: dict[str, FrictionLaw] = {
    "coulomb": FrictionLaw(None, _coulomb), "pouliquen": FrictionLaw(POULIQUEN, _pouliquen),
    "mu_i": FrictionLaw(MU_I, _mu_i), "voellmy": FrictionLaw(VOELLMY, _voellmy)}
"""The basal laws by name (``friction_law``), Coulomb's first: the default"""


def register(name: str, law: FrictionLaw) -> None:
    """Add the law ``law`` as ``name`` (a law of its own, e.g. in a test); a name taken
    by another law is an error."""
    if LAWS.get(name, law) != law:
        raise ValueError(f"a friction law named {name!r} is registered already")
    LAWS[name] = law


def unregister(name: str) -> None:
    """Remove the law ``name`` (a test that registered one)."""
    LAWS.pop(name, None)


@dataclass
class FrictionLawParameters:
    """The basal friction law and its constants (a mixin of the models' parameters)."""

    friction_law: str = "coulomb"
    """basal law: 'coulomb' (the paper's, tan phi_b), 'pouliquen' (mu(h, Fr)), 'mu_i'
    (depth-averaged mu(I)) or 'voellmy' (mu + g u^2/(xi h))"""
    delta1_deg: float = 20.9
    """pouliquen / mu_i: angle of the friction at vanishing rate, tan d1 = mu_s [deg]
    (glass beads)"""
    delta2_deg: float = 32.76
    """pouliquen / mu_i: limiting angle at large rate, tan d2 = mu_2 [deg] (glass beads)"""
    pouliquen_L: float = 0.65e-3
    """pouliquen: the length L of h_stop(theta) = L (tan d2 - tan theta)/(tan theta -
    tan d1) [m] (glass beads of 0.5 mm)"""
    pouliquen_beta: float = 0.136
    """pouliquen: beta of the flow rule Fr = beta h / h_stop(theta) [-]"""
    mu_i_I0: float = 0.279
    """mu_i: inertial number I0 of mu(I) = mu_s + (mu_2 - mu_s)/(I0/I + 1) [-]"""
    grain_diameter: float = 0.5e-3
    """mu_i: grain diameter d in I [m]"""
    packing_fraction: float = 0.6
    """mu_i: solid volume fraction phi in I [-]"""
    voellmy_mu: float = 0.155
    """voellmy: dry friction coefficient mu [-] (snow)"""
    voellmy_xi: float = 4000.0
    """voellmy: turbulent friction coefficient xi [m/s^2] (snow)"""

    @property
    def basal_law(self) -> BasalLaw | None:
        """The chosen law's kernels, None for Coulomb's closed form: the model's runs
        then use its kernels compiled with them
        (:meth:`pdeflow.systems.EquationSystem.kernels_for`)."""
        return LAWS[self.friction_law].kernels

    @property
    def rate_dependent_law(self) -> bool:
        """True for a law other than Coulomb's."""
        return self.basal_law is not None

    def validate_law(self) -> None:
        """Raise ValueError naming the first law parameter outside its range."""
        if self.friction_law not in LAWS:
            raise ValueError(f"friction_law must be one of {list(LAWS)}, got "
                             f"{self.friction_law!r}")
        check_range("delta1_deg", self.delta1_deg, 0, 90, low_open=True, high_open=True,
                    unit="deg")
        check_range("delta2_deg", self.delta2_deg, self.delta1_deg, 90, high_open=True,
                    unit="deg")
        check_range("pouliquen_L", self.pouliquen_L, 0, math.inf, low_open=True,
                    high_open=True, unit="m")
        check_range("pouliquen_beta", self.pouliquen_beta, 0, math.inf, low_open=True,
                    high_open=True)
        check_range("mu_i_I0", self.mu_i_I0, 0, math.inf, low_open=True, high_open=True)
        check_range("grain_diameter", self.grain_diameter, 0, math.inf, low_open=True,
                    high_open=True, unit="m")
        check_range("packing_fraction", self.packing_fraction, 0, 1, low_open=True)
        check_range("voellmy_mu", self.voellmy_mu, 0, math.inf, high_open=True)
        check_range("voellmy_xi", self.voellmy_xi, 0, math.inf, low_open=True,
                    high_open=True, unit="m/s^2")

    def fill_law(self, P: np.ndarray, base: int, tan_b: float) -> None:
        """Write the law's block at ``base`` of the kernel vector ``P`` (its header
        already set); ``tan_b`` is the model's Coulomb coefficient tan(phi_b)."""
        g_z = float(P[L.G_Z])
        # g sin(theta) from the header; read as G_X alone where G_Y is 0 (1D, azimuth 0),
        # where the constants stay those computed before the azimuth existed, to the bit
        along = math.hypot(P[L.G_X], P[L.G_Y]) if P[L.G_Y] != 0.0 else float(P[L.G_X])
        g = math.hypot(g_z, along)
        block = np.zeros(L.N_LAW)
        constants = LAWS[self.friction_law].constants(self, g_z, g, tan_b)
        block[:len(constants)] = constants
        P[base:base + L.N_LAW] = block


def h_stop(theta_deg: float, p: FrictionLawParameters) -> float:
    """Pouliquen's h_stop(theta) [m] of the parameters ``p`` (inf outside (d1, d2))."""
    t = math.tan(math.radians(theta_deg))
    t1 = math.tan(math.radians(p.delta1_deg))
    t2 = math.tan(math.radians(p.delta2_deg))
    if t <= t1:
        return math.inf
    return max(p.pouliquen_L * (t2 - t) / (t - t1), 0.0)
