"""Test problems of the stability study (:mod:`pdeflow.analysis.stability`).

* :func:`dam_break`: test 5.1 (column L0 = 1 m, H0 = 2 m, walls), dx = 0.1 m, default
  parameters, 1 s.
* :func:`shear`: two uniform layers, h1 = 0.3 m over h2 = 0.7 m, sliding over each other,
  u1 = du/2, u2 = -du/2, open ends, 10 m on 400 cells, a 1 mm random perturbation of the
  interface, 4 s; frictionless and without mass exchange (phi = 1e-3 deg, k = c = 0,
  exchange_closure 'none'), so that nothing but the numerics and the hyperbolicity
  correction acts. Where (r, du) lies in the non-hyperbolic band (:func:`shear_band`),
  the model itself is ill-posed (Kelvin-Helmholtz): without correction the perturbation
  grows.

A problem builds its PDE for any :class:`~pdeflow.variant.Variant` (the scheme and the
hyperbolicity mode; the integrator is the study's business) and knows its reference wave
speed s_ref (:func:`reference_speed`), which sets the generic solvers' fixed time step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from pde import CartesianGrid
from pde.trackers.base import FinishedSimulation

from ..models import TwoLayerGranular
from ..models.two_layer import hyperbolicity as hyp
from ..solvers.fv_split import FVSplitSolver
from ..variant import Variant

G = 9.81  #: gravity of all problems [m/s^2]
H1, H2 = 0.3, 0.7  #: layer depths of the shear problem [m] (H = 1 m)
FRICTIONLESS = {"phi_int_deg": 1e-3, "phi_b_deg": 1e-3, "k": 0.0, "c": 0.0,
                "exchange_closure": "none"}
"""two-layer parameters under which only the numerics and the correction act"""
REFERENCE = Variant()  #: the variant of the reference solution: the paper's scheme


@dataclass
class Problem:
    """A test problem: grid [m], end time [s], state builder, model parameters."""

    name: str
    length: float
    cells: int
    t_end: float
    bc: tuple[str, str]
    params: dict[str, Any]
    profiles: Callable[[np.ndarray], dict[str, np.ndarray]]
    perturbation: bool = False
    """True: judge growth of the interface perturbation max|h1 - h1_mean|"""
    s_ref: float | None = None
    """largest wave speed of the reference solution [m/s] (set by :func:`reference_speed`)"""

    @property
    def dx(self) -> float:
        return self.length / self.cells

    def make(self, variant: Variant):
        """Two-layer PDE (the variant's scheme and hyperbolicity mode) and the initial
        state."""
        grid = CartesianGrid([[0.0, self.length]], self.cells)
        eq = TwoLayerGranular(bc=self.bc, scheme=variant.scheme,
                              **{**self.params, "hyperbolicity": variant.hyperbolicity})
        return eq, eq.make_state(grid, **self.profiles(grid.axes_coords[0]))


def dam_break(cells: int = 70) -> Problem:
    """Test 5.1 (default parameters) on ``cells`` cells over 7 m, 1 s."""

    def profiles(x: np.ndarray) -> dict[str, np.ndarray]:
        h2 = np.where(x < 1, np.minimum(2.0, (1 - x) * math.tan(math.radians(60))), 0.0)
        return {"h1": np.where(x < 1, 2.0 - h2, 0.0), "h2": h2}

    return Problem("dam-break", 7.0, cells, 1.0, ("wall", "wall"), {}, profiles)


def shear(r: float, du_scaled: float, cells: int = 400, t_end: float = 4.0,
          seed: int = 0) -> Problem:
    """Layers of 0.3 m over 0.7 m sliding with du = du_scaled sqrt(g H) [m/s], density
    ratio r; the reference wave speed is that of the initial state (a uniform flow)."""
    du = du_scaled * math.sqrt(G * (H1 + H2))
    length = 10.0

    def profiles(x: np.ndarray) -> dict[str, np.ndarray]:
        rng = np.random.default_rng(seed)
        eta = 1e-3 * rng.standard_normal(x.size) * np.exp(-((x - length / 2) / 2.0) ** 2)
        return {"h1": H1 + eta, "h2": H2 - eta, "u1": np.full(x.size, 0.5 * du),
                "u2": np.full(x.size, -0.5 * du)}

    return Problem(f"shear r={r:g} du={du_scaled:g}sqrt(gH)", length, cells, t_end,
                   ("open", "open"), {**FRICTIONLESS, "density_ratio": r}, profiles,
                   perturbation=True, s_ref=0.5 * du + math.sqrt(G * (H1 + H2)))


def shear_band(r: float) -> tuple[float, float]:
    """Edges (F_c1, F_c2) [m/s] of the non-hyperbolic band of the shear problem's layers
    (:func:`pdeflow.models.two_layer.hyperbolicity.band_edges`); NaN if there is none."""
    return hyp.band_edges(H1, H2, G, r) or (math.nan, math.nan)


def cfl_problems(quick: bool = False) -> list[Problem]:
    """The problems of the CFL search: 5.1, and the shear flow at r = 0.67 below the
    band (du = 0.3 sqrt(gH), hyperbolic) and inside it (du = 1.0 sqrt(gH))."""
    cells = 100 if quick else 400
    t_end = 1.0 if quick else 4.0
    return [dam_break(), shear(0.67, 0.3, cells, t_end), shear(0.67, 1.0, cells, t_end)]


def reference_speed(problem: Problem) -> float:
    """Largest HLL wave-speed bound [m/s] over every step of the reference solution
    (fv-split, hyperbolicity 'exact', CFL 0.3); stored in ``problem.s_ref``."""
    eq, state = problem.make(REFERENCE)
    P = eq.parameter_array()
    stepper = FVSplitSolver(eq, cfl=0.3, max_steps=1).make_stepper(state)
    t, smax = 0.0, 0.0
    while t < problem.t_end:
        smax = max(smax, eq.kernels.numpy_advection(state.data, problem.dx, eq.bc_codes,
                                                    P)[1])
        try:
            t = stepper(state, t, problem.t_end)
        except FinishedSimulation:
            break
    problem.s_ref = smax
    return smax
