r"""The two-layer granular model of the paper: system (24) with closure (25).

Layer 1 (upper, density rho1) is friction-collisional, layer 2 (lower, rho2 > rho1) is
frictional; both are depth-averaged with isotropic hydrostatic pressure. With
q = (h1, h1 u1, h2, h2 u2), g_z = g cos(theta), g_x = g sin(theta), r = rho1/rho2:

.. math::
   \partial_t h_1 + \partial_x(h_1 u_1) &= M/\rho_1 \\
   \partial_t(h_1 u_1) + \partial_x(h_1 u_1^2 + g_z h_1^2/2) &=
        g_x h_1 - g_z h_1 \partial_x h_2 + u_1 M/\rho_1 - t_1/\rho_1 \\
   \partial_t h_2 + \partial_x(h_2 u_2) &= -M/\rho_2 \\
   \partial_t(h_2 u_2) + \partial_x(h_2 u_2^2 + g_z h_2^2/2) &=
        g_x h_2 - g_z r h_2 \partial_x h_1 - u_2 M/\rho_2 + t_2/\rho_2 - t_B/\rho_2

(paper eq. 24), interface stresses (22)-(23), basal Coulomb stress
t_B = sgn(u2) g_z (rho1 h1 + rho2 h2) tan(phi_B) (15), and M = (t1 - t2)/(u1 - u2) (25).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..numerics import layout as L
from .base import GranularPDE, SharedParameters, check_range

HYPERBOLICITY_MODES = {"none": 0, "exact": 1, "bound": 2}


@dataclass
class TwoLayerParameters(SharedParameters):
    """Physical and numerical parameters of :class:`TwoLayerGranular` (and those of
    :class:`~pdeflow.models.base.SharedParameters`).

    The paper's Table 1 is lost; defaults marked *calibrated* were chosen to reproduce
    the paper's reported results of test 5.1 (see ``docs/parameters.md``).
    """

    kind = "two-layer"

    density_ratio: float = 0.67
    """rho1/rho2 in (0, 1): the paper's value for dense-collisional flows [-]"""
    phi_int_deg: float = 30.0
    """internal friction angle at the interface [deg] (paper: 30)"""
    phi_b_deg: float = 41.0
    """basal friction angle of the lower layer [deg] (calibrated)"""
    k: float = 0.65
    """friction reduction on the upper side of the interface, eq. (17), in [0, 1) (calibrated)"""
    c: float = 0.03
    """collisional (Voellmy) coefficient of eq. (17) [-] (calibrated)"""
    w: float = 1e-3
    """tolerance of the restoration (33)-(34) in du: restored |du| within w below F_c1 [m/s]"""
    film_depth: float = 1e-3
    """upper-layer films thinner than this after an exchange are deposited whole [m]"""
    du_reg: float = 0.0
    """lower bound of |u1 - u2| in the closure's denominator [m/s]; 0 = the paper's"""
    exchange_closure: str = "paper"
    """'paper': closure (25) as published (singular at du = 0); 'relaxed': its rate
    bounded by a relaxation towards the equilibrium depth on the time scale
    tau_star sqrt(H/g) (see pdeflow.numerics.sources); 'none': no mass exchange (two
    immiscible layers, for verification and teaching)"""
    tau_star: float = 1.0
    """relaxation time of the 'relaxed' closure in units of sqrt(H/g) [-]"""
    hyperbolicity: str = "exact"
    """restoration of hyperbolicity: 'exact' (paper), 'bound' (F_L), 'none'"""

    def validate_model(self) -> None:
        check_range("density_ratio", self.density_ratio, 0, 1, low_open=True,
                    high_open=True)
        check_range("phi_int_deg", self.phi_int_deg, 0, 90, low_open=True,
                    high_open=True, unit="deg")
        check_range("phi_b_deg", self.phi_b_deg, 0, 90, low_open=True, high_open=True,
                    unit="deg")
        check_range("k", self.k, 0, 1, high_open=True)
        check_range("c", self.c, 0, math.inf)
        check_range("w", self.w, 0, math.inf, low_open=True, unit="m/s")
        check_range("film_depth", self.film_depth, 0, 1, unit="m")
        check_range("du_reg", self.du_reg, 0, math.inf, unit="m/s")
        check_range("tau_star", self.tau_star, 0, math.inf, low_open=True)
        if self.exchange_closure not in ("paper", "relaxed", "none"):
            raise ValueError("exchange_closure must be 'paper', 'relaxed' or 'none', got "
                             f"{self.exchange_closure!r}")
        if self.hyperbolicity not in HYPERBOLICITY_MODES:
            raise ValueError(f"hyperbolicity must be one of {list(HYPERBOLICITY_MODES)}, "
                             f"got {self.hyperbolicity!r}")

    def to_array(self) -> np.ndarray:
        """Kernel parameter vector (layout in :mod:`pdeflow.numerics.layout`)."""
        th = math.radians(self.theta_deg)
        P = np.zeros(L.N_TWO_LAYER)
        P[L.G_Z] = self.g * math.cos(th)
        P[L.G_X] = self.g * math.sin(th)
        P[L.R] = self.density_ratio
        P[L.TAN_INT] = math.tan(math.radians(self.phi_int_deg))
        P[L.TAN_B] = math.tan(math.radians(self.phi_b_deg))
        P[L.K] = self.k
        P[L.C] = self.c
        P[L.W] = self.w
        P[L.DRY] = self.dry_tolerance
        P[L.FILM] = self.film_depth
        P[L.DU_REG] = self.du_reg
        P[L.HYPERBOLICITY] = HYPERBOLICITY_MODES[self.hyperbolicity]
        P[L.SLOW_U] = self.rest_speed
        P[L.SLOW_H] = self.rest_depth
        P[L.MOL_EPS] = self.mol_eps
        P[L.TAU_STAR] = {"paper": 0.0, "relaxed": self.tau_star,
                         "none": -1.0}[self.exchange_closure]
        return P


class TwoLayerGranular(GranularPDE):
    """Two-layer depth-averaged granular flow (paper eqs. 24-27) as a py-pde PDE.

    State: ``FieldCollection`` of h1 [m], h1u1 [m^2/s], h2 [m], h2u2 [m^2/s] on a 1D
    ``CartesianGrid`` whose cells are the finite volumes. Integrate with
    ``solver="fv-split"`` (the paper's scheme) or any py-pde solver (method of lines).
    """

    field_names = ("h1", "h1u1", "h2", "h2u2")
    two_layer = True
    parameters_class = TwoLayerParameters
