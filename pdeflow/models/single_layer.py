r"""The single-layer baseline: Savage-Hutter-type layer with Coulomb basal friction.

With q = (h, hu), isotropic hydrostatic pressure (earth-pressure coefficient 1, as in
the paper's comparison model of Mangeney et al.), g_z = g cos(theta),
g_x = g sin(theta):

.. math::
   \partial_t h + \partial_x(hu) &= 0 \\
   \partial_t(hu) + \partial_x(h u^2 + g_z h^2/2) &= g_x h - \mathrm{sgn}(u)\, g_z h \tan\varphi_B

The friction is applied implicitly and set-valued (a layer stops in finite time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..numerics import layout as L
from .base import GranularPDE, SharedParameters, check_range


@dataclass
class SingleLayerParameters(SharedParameters):
    """Parameters of :class:`SingleLayerGranular` (and those of
    :class:`~pdeflow.models.base.SharedParameters`)."""

    kind = "single-layer"

    phi_b_deg: float = 30.0
    """basal friction angle [deg] (paper: 30 in its comparisons)"""

    def validate_model(self) -> None:
        check_range("phi_b_deg", self.phi_b_deg, 0, 90, low_open=True, high_open=True,
                    unit="deg")

    def to_array(self) -> np.ndarray:
        th = math.radians(self.theta_deg)
        P = np.zeros(L.N_SINGLE_LAYER)
        P[L.S_G_Z] = self.g * math.cos(th)
        P[L.S_G_X] = self.g * math.sin(th)
        P[L.S_TAN_B] = math.tan(math.radians(self.phi_b_deg))
        P[L.S_DRY] = self.dry_tolerance
        P[L.S_SLOW_U] = self.rest_speed
        P[L.S_SLOW_H] = self.rest_depth
        P[L.S_MOL_EPS] = self.mol_eps
        return P


class SingleLayerGranular(GranularPDE):
    """Single-layer Coulomb granular flow (the paper's baseline) as a py-pde PDE.

    State: ``FieldCollection`` of h [m] and hu [m^2/s] on a 1D ``CartesianGrid``.
    """

    field_names = ("h", "hu")
    two_layer = False
    parameters_class = SingleLayerParameters
