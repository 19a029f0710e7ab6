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
from typing import Any

import numpy as np

from ..numerics import layout as L
from ..numerics.state import DRY_TOLERANCE
from .base import GranularPDE, ParametersBase, check_range


@dataclass
class SingleLayerParameters(ParametersBase):
    """Parameters of :class:`SingleLayerGranular`."""

    kind = "single-layer"

    g: float = 9.81
    """gravitational acceleration [m/s^2]"""
    theta_deg: float = 0.0
    """bed slope [deg], x pointing down-slope"""
    phi_b_deg: float = 30.0
    """basal friction angle [deg] (paper: 30 in its comparisons)"""
    dry_tolerance: float = DRY_TOLERANCE
    """layers thinner than this have zero velocity [m]"""
    rest_speed: float = 0.01
    """speed below which the layer counts as practically at rest [m/s]"""
    rest_depth: float = 1e-3
    """depth above which the practical-rest test looks at a cell [m]"""
    mol_eps: float = 1e-3
    """velocity scale regularising sgn() in the method-of-lines rate [m/s]"""

    def validate(self) -> None:
        """Raise ValueError naming the first parameter outside its allowed range."""
        check_range("g", self.g, 0, math.inf, low_open=True, unit="m/s^2")
        check_range("theta_deg", self.theta_deg, -90, 90, low_open=True,
                    high_open=True, unit="deg")
        check_range("phi_b_deg", self.phi_b_deg, 0, 90, low_open=True, high_open=True,
                    unit="deg")
        check_range("dry_tolerance", self.dry_tolerance, 0, 1, low_open=True, unit="m")
        check_range("rest_speed", self.rest_speed, 0, math.inf, low_open=True,
                    unit="m/s")
        check_range("rest_depth", self.rest_depth, 0, math.inf, unit="m")
        check_range("mol_eps", self.mol_eps, 0, math.inf, low_open=True, unit="m/s")

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

    def __init__(self, parameters: SingleLayerParameters | dict | None = None, *,
                 bc: tuple[str, str] = ("wall", "open"), flux: str = "hll",
                 reconstruction: str = "first-order", limiter: str = "minmod",
                 **kwargs: Any):
        super().__init__(bc, flux=flux, reconstruction=reconstruction, limiter=limiter)
        if parameters is None:
            parameters = {}
        if isinstance(parameters, SingleLayerParameters):
            parameters = parameters.to_dict()
        self.parameters = SingleLayerParameters.from_dict({**parameters, **kwargs})

    def parameter_array(self) -> np.ndarray:
        return self.parameters.to_array()

    def __repr__(self) -> str:
        return f"SingleLayerGranular({self.parameters}, bc={self.bc}, {self.variant})"
