r"""The single-layer baseline: Savage-Hutter-type layer with Coulomb basal friction.

With q = (h, hu), isotropic hydrostatic pressure (earth-pressure coefficient 1, as in
the paper's comparison model of Mangeney et al.), g_z = g cos(theta),
g_x = g sin(theta):

.. math::
   \partial_t h + \partial_x(hu) &= 0 \\
   \partial_t(hu) + \partial_x(h u^2 + g_z h^2/2) &= g_x h - \mathrm{sgn}(u)\, g_z h \tan\varphi_B

The friction is applied implicitly and set-valued (a layer stops in finite time); the
basal law is Coulomb's (above) or one of :mod:`pdeflow.models.friction_laws`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ... import systems
from ..base import GranularPDE, SharedParameters, check_range, stop_time
from ..friction_laws import FrictionLawParameters
from ..parameters import parameter_vector
from . import layout as S
from .kernels import KERNELS, kernels, kernels_2d


@dataclass
class SingleLayerParameters(FrictionLawParameters, SharedParameters):
    """Parameters of :class:`SingleLayerGranular` (and those of
    :class:`~pdeflow.models.base.SharedParameters`)."""

    kind = "single-layer"

    phi_b_deg: float = 30.0
    """basal friction angle [deg] (paper: 30 in its comparisons)"""

    def validate_model(self) -> None:
        check_range("phi_b_deg", self.phi_b_deg, 0, 90, low_open=True, high_open=True,
                    unit="deg")
        self.validate_law()

    def to_array(self) -> np.ndarray:
        """Kernel parameter vector (layout in :mod:`.layout`)."""
        P = parameter_vector(self, S.SIZE)
        P[S.TAN_B] = math.tan(math.radians(self.phi_b_deg))
        P[S.DRY] = self.dry_tolerance
        P[S.SLOW_U] = self.rest_speed
        P[S.SLOW_H] = self.rest_depth
        P[S.MOL_EPS] = self.mol_eps
        self.fill_law(P, S.LAW, P[S.TAN_B])
        return P


class SingleLayerGranular(GranularPDE):
    """Single-layer Coulomb granular flow (the paper's baseline) as a py-pde PDE.

    State: ``FieldCollection`` of h [m] and hu [m^2/s] on a 1D ``CartesianGrid`` (or a
    ``PolarSymGrid``), or of h, hu and hv [m^2/s] on a 2D ``CartesianGrid`` (x down the
    slope, y across).
    """

    parameters_class = SingleLayerParameters


def summarize(diag, tf: float, at_rest: bool, x: np.ndarray, d: np.ndarray,
              metric: Any) -> dict:
    """The single-layer numbers of a run's summary."""
    return {"stop_time": stop_time(diag.last_move, tf, at_rest),
            "slow_time": stop_time(diag.last_fast, tf, False),
            "max_fextra_over_rho1": 0.0}


SYSTEM = systems.register(systems.EquationSystem(
    name="single_layer", label="single layer", adjective="single-layer",
    layers=(systems.Layer("h", "hu", "u", "single layer", "single", "hv", "v"),),
    parameters_class=SingleLayerParameters, pde_class=SingleLayerGranular,
    kernels=KERNELS, law_kernels=kernels, kernels_2d=lambda law, _p: kernels_2d(law),
    diagnostics=S.DIAGNOSTICS,
    densities=lambda p: (1.0,),
    layer_depths=lambda h, x, ini, p: (h,),
    summarize=summarize, bytes_per_cell=180, paper_runout_law=(2.25, 1.06),
    quantities=(systems.Quantity("slow_time", "slow", "s"),)))
"""The single-layer Coulomb baseline as an equation system."""
SingleLayerGranular.system = SYSTEM
