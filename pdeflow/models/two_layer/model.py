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

from ... import systems
from ...initial_shapes import is_column
from ...numerics import layout as L
from ...numerics.geometry import Metric
from ..base import GranularPDE, SharedParameters, check_range, stop_time
from ..friction_laws import FrictionLawParameters
from ..parameters import parameter_vector
from . import layout as T
from .kernels import KERNELS, kernels, kernels_2d
from .sources_2d import DIRECTIONS

HYPERBOLICITY_MODES = L.HYPERBOLICITY_MODES


@dataclass
class TwoLayerParameters(FrictionLawParameters, SharedParameters):
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
    tau_star sqrt(H/g) (see pdeflow.models.two_layer.exchange); 'none': no mass exchange (two
    immiscible layers, for verification and teaching)"""
    tau_star: float = 1.0
    """relaxation time of the 'relaxed' closure in units of sqrt(H/g) [-]"""
    hyperbolicity: str = "exact"
    """restoration of hyperbolicity: 'exact' (paper), 'bound' (F_L), 'none'"""
    hyperbolicity_directions: str = "all"
    """on a 2D grid, the directions the restoration makes hyperbolic: 'all' (default:
    |du| brought to F_c1, so that every direction is, docs/two_d.md) or 'flow' (the
    paper's 1D rule along du only, which leaves |du| >= F_c2 alone: the 1D numbers for a
    flow uniform across); no effect on a 1D grid"""

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
        if self.exchange_closure not in L.CLOSURES:
            raise ValueError(f"exchange_closure must be one of {list(L.CLOSURES)}, got "
                             f"{self.exchange_closure!r}")
        if self.hyperbolicity not in HYPERBOLICITY_MODES:
            raise ValueError(f"hyperbolicity must be one of {list(HYPERBOLICITY_MODES)}, "
                             f"got {self.hyperbolicity!r}")
        if self.hyperbolicity_directions not in DIRECTIONS:
            raise ValueError("hyperbolicity_directions must be one of "
                             f"{list(DIRECTIONS)}, got {self.hyperbolicity_directions!r}")
        self.validate_law()

    def to_array(self) -> np.ndarray:
        """Kernel parameter vector (layout in :mod:`.layout`)."""
        P = parameter_vector(self, T.SIZE)
        P[T.R] = self.density_ratio
        P[T.TAN_INT] = math.tan(math.radians(self.phi_int_deg))
        P[T.TAN_B] = math.tan(math.radians(self.phi_b_deg))
        P[T.K] = self.k
        P[T.C] = self.c
        P[T.W] = self.w
        P[T.DRY] = self.dry_tolerance
        P[T.FILM] = self.film_depth
        P[T.DU_REG] = self.du_reg
        P[T.HYPERBOLICITY] = L.HYPERBOLICITY_MODES[self.hyperbolicity]
        P[T.SLOW_U] = self.rest_speed
        P[T.SLOW_H] = self.rest_depth
        P[T.MOL_EPS] = self.mol_eps
        P[T.CLOSURE] = L.CLOSURES[self.exchange_closure]
        P[T.TAU_STAR] = self.tau_star
        self.fill_law(P, T.LAW, P[T.TAN_B])
        return P


class TwoLayerGranular(GranularPDE):
    """Two-layer depth-averaged granular flow (paper eqs. 24-27) as a py-pde PDE.

    State: ``FieldCollection`` of h1 [m], h1u1 [m^2/s], h2 [m], h2u2 [m^2/s] on a 1D
    ``CartesianGrid`` (or a ``PolarSymGrid``), or of h1, h1u1, h1v1, h2, h2u2, h2v2 on a
    2D ``CartesianGrid`` (x down the slope, y across); its cells are the finite volumes.
    Integrate with ``solver="fv-split"`` (the paper's scheme) or any py-pde solver
    (method of lines).
    """

    parameters_class = TwoLayerParameters


def layer_depths(h: np.ndarray, x: np.ndarray, initial: dict,
                 p: TwoLayerParameters) -> tuple[np.ndarray, np.ndarray]:
    """(h1, h2) [m] of an initial total depth ``h``: a column's lower layer is the
    Rankine wedge of angle ``initial.wedge_angle_deg`` (default 45 + phi_int/2 deg, the
    active failure plane) at its front ``x = L0``; other shapes split ``h`` by
    ``initial.upper_fraction`` (default 0.5)."""
    if is_column(initial):
        L0, H0 = float(initial["L0"]), float(initial["H0"])
        alpha = float(initial.get("wedge_angle_deg", 45.0 + p.phi_int_deg / 2))
        h2 = np.where(x < L0, np.minimum(H0, (L0 - x) * math.tan(math.radians(alpha))),
                      0.0)
        return h - h2, h2
    f = float(initial.get("upper_fraction", 0.5))
    return f * h, (1 - f) * h


def summarize(diag, tf: float, at_rest: bool, x: np.ndarray, d: np.ndarray,
              metric: Metric) -> dict:
    """The two-layer numbers of a run's summary (see :data:`SYSTEM`). The exchanged
    volumes are booked per cell depth by the source stage: on a planar grid times dx;
    on other grids they are not known (None)."""
    planar = metric.geometry == "planar"
    dx = metric.dx
    lo = stop_time(diag.last_move_lower, tf, at_rest)
    up = stop_time(diag.last_move_upper, tf, at_rest)
    return {
        "lower_stop_time": lo,
        "upper_stop_time": up,
        "stop_time": None if (lo is None or up is None) else max(lo, up),
        "lower_slow_time": stop_time(diag.last_fast_lower, tf, False),
        "upper_slow_time": stop_time(diag.last_fast_upper, tf, False),
        "max_fextra_over_rho1": diag.fextra_max,
        # the cell index is flat over a 2D grid's cells: its x is that of row
        # cell // (stride of axis 0), the stride 1 in 1D
        "max_fextra_x": float(x[int(diag.fextra_cell) // metric.axes[0][0]]),
        "max_fextra_time": diag.fextra_time,
        "hyperbolicity_events": int(diag.hyperbolicity_events),
        "hyperbolicity_bisections": int(diag.hyperbolicity_bisections),
        "deposited_volume": float(diag.deposited * dx) if planar else None,
        "eroded_volume": float(diag.eroded * dx) if planar else None,
        # h1 is row 0, h2 the first row of the second half (2 in 1D, 3 in 2D)
        "upper_volume_final": metric.integral(np.ravel(d[0])),
        "lower_volume_final": metric.integral(np.ravel(d[len(d) // 2])),
    }


Q = systems.Quantity
SYSTEM = systems.register(systems.EquationSystem(
    name="two_layer", label="two layers", adjective="two-layer",
    layers=(systems.Layer("h1", "h1u1", "u1", "upper layer", "upper", "h1v1", "v1"),
            systems.Layer("h2", "h2u2", "u2", "lower layer", "lower", "h2v2", "v2")),
    parameters_class=TwoLayerParameters, pde_class=TwoLayerGranular, kernels=KERNELS,
    law_kernels=kernels, diagnostics=T.DIAGNOSTICS,
    kernels_2d=lambda law, p: kernels_2d(law, p.hyperbolicity_directions),
    densities=lambda p: (p.density_ratio, 1.0), layer_depths=layer_depths,
    summarize=summarize, has_fextra=True, cell_diagnostic="fextra_over_rho1",
    bytes_per_cell=320,
    paper_runout_law=(1.61, 0.84), bed_layer=1,
    quantities=(
        Q("lower_stop_time", "lower stop", "s"), Q("upper_stop_time", "upper stop", "s"),
        Q("lower_slow_time", "lower slow", "s"), Q("upper_slow_time", "upper slow", "s"),
        Q("max_fextra_x", "x of max F_extra", "m"),
        Q("max_fextra_time", "t of max F_extra", "s"),
        Q("hyperbolicity_events", "restorations", ""),
        Q("hyperbolicity_bisections", "bisections", ""),
        Q("deposited_volume", "deposited", "m2"), Q("eroded_volume", "eroded", "m2"),
        Q("upper_volume_final", "upper volume", "m2"),
        Q("lower_volume_final", "lower volume", "m2"))))
"""The two-layer model of the paper as an equation system."""
TwoLayerGranular.system = SYSTEM
