"""The basal friction law as model parameters: a choice and each law's constants.

Both shipped models mix :class:`FrictionLawParameters` into their parameter dataclass
(``single_layer.friction_law``, ``two_layer.friction_law`` for the lower layer's bed);
:meth:`FrictionLawParameters.fill_law` writes the law's block of the model's kernel
parameter vector (offsets ``layout.LAW_*``), which
:mod:`pdeflow.numerics.rheology` reads. Coulomb, the default, uses the model's own
``phi_b_deg``; the other laws ignore it. Defaults: glass beads of d = 0.5 mm for
``pouliquen`` and ``mu_i`` (Forterre & Pouliquen 2003, Jop, Forterre & Pouliquen 2006),
snow for ``voellmy``; docs/rheology.md says which of these numbers could be checked,
and where (none from the papers themselves).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..numerics import layout as L
from .base import check_range

FRICTION_LAWS = L.FRICTION_LAWS


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
    def rate_dependent_law(self) -> bool:
        """True for a law other than Coulomb's: the model's runs then use its law
        kernels (:meth:`pdeflow.systems.EquationSystem.kernels_for`)."""
        return FRICTION_LAWS[self.friction_law] != L.FRICTION_COULOMB

    def validate_law(self) -> None:
        """Raise ValueError naming the first law parameter outside its range."""
        if self.friction_law not in FRICTION_LAWS:
            raise ValueError(f"friction_law must be one of {list(FRICTION_LAWS)}, got "
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
        """Write the law's block at ``base`` of the kernel vector ``P`` (its G_Z already
        set); ``tan_b`` is the model's Coulomb coefficient tan(phi_b)."""
        code = FRICTION_LAWS[self.friction_law]
        g_z = float(P[L.G_Z])
        mu1 = math.tan(math.radians(self.delta1_deg))
        dmu = math.tan(math.radians(self.delta2_deg)) - mu1
        block = np.zeros(L.N_LAW)
        block[L.LAW_CODE] = code
        if code == L.FRICTION_COULOMB:
            block[L.LAW_MU1] = tan_b
        elif code == L.FRICTION_POULIQUEN:
            block[L.LAW_MU1], block[L.LAW_DMU] = mu1, dmu
            block[L.LAW_S0] = self.pouliquen_beta * math.sqrt(g_z) / self.pouliquen_L
            block[L.LAW_INV_L] = 1.0 / self.pouliquen_L
            block[L.LAW_BETA_G] = self.pouliquen_beta * math.sqrt(g_z)
        elif code == L.FRICTION_MU_I:
            block[L.LAW_MU1], block[L.LAW_DMU] = mu1, dmu
            block[L.LAW_S0] = (2.0 * self.mu_i_I0 * math.sqrt(self.packing_fraction * g_z)
                               / (5.0 * self.grain_diameter))
        else:
            block[L.LAW_MU1] = self.voellmy_mu
            g = math.hypot(float(P[L.G_Z]), float(P[L.G_X]))
            block[L.LAW_DRAG] = g / self.voellmy_xi
        P[base:base + L.N_LAW] = block


def h_stop(theta_deg: float, p: FrictionLawParameters) -> float:
    """Pouliquen's h_stop(theta) [m] of the parameters ``p`` (inf outside (d1, d2))."""
    t = math.tan(math.radians(theta_deg))
    t1 = math.tan(math.radians(p.delta1_deg))
    t2 = math.tan(math.radians(p.delta2_deg))
    if t <= t1:
        return math.inf
    return max(p.pouliquen_L * (t2 - t) / (t - t1), 0.0)
