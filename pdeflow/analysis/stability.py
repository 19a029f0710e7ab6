"""Stability map of the solver variants: largest stable CFL number and the region of
(rho1/rho2, relative velocity) where each variant stays stable.

``python -m pdeflow.analysis.stability --out docs/`` runs everything (a few minutes on two
cores) and rewrites the generated sections of ``docs/stability.md`` (between the
``<!-- BEGIN stability:... -->`` / ``<!-- END ... -->`` markers; the rest of the file is
left alone) and the figures ``stability_map.png`` and ``stability_cfl.png``.
``--extremes`` adds the heavy extreme runs (10^5 cells for 0.1 s, aspect ratio 100 on a fine
grid, a deposit left for 100 s, a column just below / above its friction angle).

Variants
--------
Every variant is one entry of :data:`VARIANTS` (name -> :class:`Variant`): a py-pde solver
name, the model's scheme options and parameters, the solver's options. To add one, add a
line there; everything else (runs, figures, tables) follows.

* ``fv-split`` variants run the solver itself (CFL-limited steps). Its CFL number is
  validated to (0, 1] ((0, 0.5] with MUSCL); to find where the scheme really fails,
  larger CFL numbers are run with that validation bypassed (the attribute is set after
  construction).
* py-pde's generic solvers (``euler``, ``runge-kutta``) integrate the method-of-lines rate
  (HLL flux divergence plus regularised sources) with a fixed time step
  dt = CFL dx / s_ref, s_ref = the largest wave speed of the problem's reference solution
  (fv-split, hyperbolicity 'exact', CFL 0.3). They run in :func:`mol_run`, a compiled,
  disk-cached copy of py-pde's fixed-step Euler and Runge-Kutta loops on pdeflow's compiled
  rate and post-step hook (py-pde's own numba stepper compiles anew for every parameter
  set, a few seconds each; the copy is checked against py-pde in the tests).

Problems
--------
* ``dam-break``: test 5.1 (column L0 = 1 m, H0 = 2 m, walls), dx = 0.1 m, default
  parameters, 1 s.
* ``shear``: two uniform layers, h1 = 0.3 m over h2 = 0.7 m, sliding over each other,
  u1 = du/2, u2 = -du/2, open ends, 10 m on 400 cells, a 1 mm random perturbation of the
  interface, 4 s; frictionless and without mass exchange (phi = 1e-3 deg, k = c = 0,
  exchange_closure 'none'), so that nothing but the numerics and the hyperbolicity
  correction acts. Where (r, du) lies in the non-hyperbolic band, the model itself is
  ill-posed (Kelvin-Helmholtz): without correction the perturbation grows.

Outcomes: ``blow-up`` (non-finite state, a depth negative beyond round-off, or the time
step collapsing; for problems with walls also a mass change above 1e-9, i.e. depths
clipped), ``growth`` (the interface perturbation max|h1 - mean h1| ends larger than it
started; shear only), ``stable`` otherwise. The dam break is first tried at very small CFL
numbers (0.0005-0.02), where the generic solvers' stiff regularised sources need them.
"""

from __future__ import annotations

import argparse
import math
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from ..numerics import layout as L
from ..numerics.advection import rate_single, rate_two_layer
from ..numerics.hyperbolicity import discriminant, lower_bound_fl, upper_bound_fr
from ..numerics.mol import source_rate_single, source_rate_two_layer
from ..numerics.splitting import source_stage_single, source_stage_two_layer

G = 9.81  #: gravity of all problems [m/s^2]


# --- variants ------------------------------------------------------------------------------

@dataclass(frozen=True)
class Variant:
    """A solver variant: py-pde solver name, model options, solver options."""

    solver: str
    """'fv-split' or a py-pde solver with a fixed-step form ('euler', 'runge-kutta')"""
    model: dict[str, Any] = field(default_factory=dict)
    """keyword arguments of the model class: flux, reconstruction, limiter, parameters"""
    options: dict[str, Any] = field(default_factory=dict)
    """keyword arguments of the solver (e.g. splitting='strang' for fv-split)"""
    description: str = ""


#: The variant table: add new variants here, by name.
VARIANTS: dict[str, Variant] = {
    "fv-split/exact": Variant("fv-split", {"hyperbolicity": "exact"},
                              description="the paper's scheme (HLL, Lie, exact test)"),
    "fv-split/bound": Variant("fv-split", {"hyperbolicity": "bound"},
                              description="hyperbolicity restored below F_L only"),
    "fv-split/none": Variant("fv-split", {"hyperbolicity": "none"},
                             description="no hyperbolicity correction"),
    "fv-split/rusanov": Variant("fv-split", {"flux": "rusanov"},
                                description="Rusanov flux, otherwise the paper's"),
    "fv-split/ifcp": Variant("fv-split", {"flux": "ifcp"},
                             description="IFCP flux, otherwise the paper's"),
    "fv-split/muscl": Variant("fv-split", {"reconstruction": "muscl"},
                              description="MUSCL (minmod) + SSP-RK2, otherwise the paper's"),
    "fv-split/strang": Variant("fv-split", options={"splitting": "strang"},
                               description="Strang splitting, otherwise the paper's"),
    "euler": Variant("euler", description="py-pde Euler, fixed dt, method of lines"),
    "runge-kutta": Variant("runge-kutta",
                           description="py-pde Runge-Kutta (RK4), fixed dt, method of lines"),
}

#: fixed-step method-of-lines schemes of :func:`mol_run`, by py-pde solver name
MOL_SCHEMES = {"euler": 0, "explicit": 0, "runge-kutta": 1}


# --- problems ------------------------------------------------------------------------------

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
        """PDE and initial state for ``variant``."""
        from pde import CartesianGrid

        from ..models import TwoLayerGranular

        grid = CartesianGrid([[0.0, self.length]], self.cells)
        model = dict(variant.model)
        params = {**self.params, **{k: v for k, v in model.items()
                                    if k not in ("flux", "reconstruction", "limiter")}}
        scheme = {k: v for k, v in model.items()
                  if k in ("flux", "reconstruction", "limiter")}
        eq = TwoLayerGranular(bc=self.bc, **scheme, **params)
        return eq, eq.make_state(grid, **self.profiles(grid.axes_coords[0]))


FRICTIONLESS = {"phi_int_deg": 1e-3, "phi_b_deg": 1e-3, "k": 0.0, "c": 0.0,
                "exchange_closure": "none"}


def dam_break(cells: int = 70) -> Problem:
    """Test 5.1 (default parameters) on ``cells`` cells over 7 m, 1 s."""

    def profiles(x: np.ndarray) -> dict[str, np.ndarray]:
        h2 = np.where(x < 1, np.minimum(2.0, (1 - x) * math.tan(math.radians(60))), 0.0)
        return {"h1": np.where(x < 1, 2.0 - h2, 0.0), "h2": h2}

    return Problem("dam-break", 7.0, cells, 1.0, ("wall", "wall"), {}, profiles)


H1, H2 = 0.3, 0.7  #: layer depths of the shear problem [m] (H = 1 m)


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


def band_edges(r: float, h1: float = H1, h2: float = H2) -> tuple[float, float]:
    """Exact edges (F_c1, F_c2) [m/s] of the non-hyperbolic band of |du| (bisection on the
    discriminant between F_L and F_R)."""
    fl = lower_bound_fl(h1, h2, G, r)
    fr = upper_bound_fr(h1, h2, G, r)
    du = np.linspace(fl, fr, 2001)
    bad = np.array([discriminant(h1, h2, d, 0.0, G, r) < 0 for d in du])
    if not bad.any():
        return math.nan, math.nan
    idx = np.nonzero(bad)[0]

    def edge(a: float, b: float) -> float:  # a hyperbolic, b not
        for _ in range(60):
            m = 0.5 * (a + b)
            if discriminant(h1, h2, m, 0.0, G, r) < 0:
                b = m
            else:
                a = m
        return 0.5 * (a + b)

    lo = edge(du[idx[0] - 1], du[idx[0]]) if idx[0] > 0 else du[0]
    hi = edge(du[idx[-1] + 1], du[idx[-1]]) if idx[-1] < du.size - 1 else du[-1]
    return lo, hi


# --- method-of-lines runs (py-pde's fixed-step loops, compiled) -----------------------------

@njit(cache=True)
def _mol_rate(q, out, work, dx, bc_left, bc_right, P, two_layer, flux, order, limiter):
    """The model's method-of-lines rate (as GranularPDE.make_evolution_rate) into out."""
    if two_layer:
        rate_two_layer(q, out, work, dx, bc_left, bc_right, P[L.G_Z], P[L.R], P[L.DRY],
                       flux, order, limiter)
        source_rate_two_layer(q, out, P)
    else:
        rate_single(q, out, work, dx, bc_left, bc_right, P[L.S_G_Z], P[L.S_DRY], flux,
                    order, limiter)
        source_rate_single(q, out, P)


@njit(cache=True)
def mol_run(q: np.ndarray, dt: float, steps: int, scheme: int, dx: float, bc_left: int,
            bc_right: int, P: np.ndarray, two_layer: bool, flux: int, order: int,
            limiter: int, diag: np.ndarray):
    """``steps`` fixed steps of py-pde's Euler (scheme 0) or Runge-Kutta (1) solver.

    The same arithmetic as py-pde's fixed-dt steppers (``state += dt rhs`` and classical
    RK4), followed by the model's post-step hook (source stage with dt = 0: clips round-off
    below zero, zeroes dry velocities). Before the hook the state is checked: returns
    ``(steps done, cell, status)`` with status 0 (all steps done), 1 (non-finite value in
    ``cell``) or 2 (depth negative beyond round-off in ``cell``); ``q`` then holds the
    failed state.
    """
    n_fields, n = q.shape
    work = np.empty((2, n_fields, n))
    k1 = np.empty_like(q)
    k2 = np.empty_like(q)
    k3 = np.empty_like(q)
    k4 = np.empty_like(q)
    tmp = np.empty_like(q)
    for step in range(steps):
        t = step * dt
        prev = q.copy()
        if scheme == 0:
            _mol_rate(q, k1, work, dx, bc_left, bc_right, P, two_layer, flux, order,
                      limiter)
            q += dt * k1
        else:
            _mol_rate(q, k1, work, dx, bc_left, bc_right, P, two_layer, flux, order,
                      limiter)
            k1 *= dt
            tmp[:, :] = q + 0.5 * k1
            _mol_rate(tmp, k2, work, dx, bc_left, bc_right, P, two_layer, flux, order,
                      limiter)
            k2 *= dt
            tmp[:, :] = q + 0.5 * k2
            _mol_rate(tmp, k3, work, dx, bc_left, bc_right, P, two_layer, flux, order,
                      limiter)
            k3 *= dt
            tmp[:, :] = q + k3
            _mol_rate(tmp, k4, work, dx, bc_left, bc_right, P, two_layer, flux, order,
                      limiter)
            k4 *= dt
            q += (k1 + 2 * k2 + 2 * k3 + k4) / 6
        for i in range(n):
            for k in range(n_fields):
                if not math.isfinite(q[k, i]):
                    return step + 1, i, 1
                if k % 2 == 0 and q[k, i] < -1e-12 * (1.0 + abs(prev[k, i])):
                    return step + 1, i, 2
        if two_layer:
            source_stage_two_layer(q, 0.0, t, P, diag)
        else:
            source_stage_single(q, 0.0, t, P, diag)
    return steps, -1, 0


# --- one run ---------------------------------------------------------------------------------

@dataclass
class Outcome:
    """Result of one run of a variant on a problem at a CFL number."""

    status: str
    """'stable', 'growth' or 'blow-up'"""
    detail: str = ""
    growth: float | None = None
    """max|h1 - h1_mean| at the end over its initial value (perturbation problems)"""
    steps: int = 0
    wall: float = 0.0
    """wall-clock time [s]"""


def _perturbation(q: np.ndarray) -> float:
    return float(np.max(np.abs(q[0] - np.mean(q[0]))))


def run(variant: Variant, problem: Problem, cfl: float, *,
        max_steps: int = 2_000_000) -> Outcome:
    """Run ``variant`` on ``problem`` at Courant number ``cfl`` and classify the result."""
    eq, state = problem.make(variant)
    q0 = state.data.copy()
    t0 = time.perf_counter()
    if variant.solver == "fv-split":
        out = _run_fv_split(variant, eq, state, problem, cfl, max_steps)
    elif variant.solver in MOL_SCHEMES:
        out = _run_mol(variant, eq, state, problem, cfl)
    else:
        raise ValueError(f"variant solver must be 'fv-split' or one of "
                         f"{sorted(MOL_SCHEMES)}, got {variant.solver!r}")
    out.wall = time.perf_counter() - t0
    if out.status == "blow-up":
        return out
    q = state.data
    if not np.all(np.isfinite(q)) or np.any(q[::2] < 0):
        return Outcome("blow-up", "non-finite or negative final state", steps=out.steps,
                       wall=out.wall)
    if problem.bc == ("wall", "wall"):
        r = eq.parameters.density_ratio
        m0 = np.sum(r * q0[0] + q0[2])
        err = abs(np.sum(r * q[0] + q[2]) - m0) / m0
        if err > 1e-9:
            return Outcome("blow-up", f"mass changed by {err:.2g} (depths clipped)",
                           steps=out.steps, wall=out.wall)
    if problem.perturbation:
        a0 = _perturbation(q0)
        out.growth = _perturbation(q) / a0
        if out.growth > 1.0:
            out.status = "growth"
            out.detail = f"perturbation x{out.growth:.3g}"
    return out


def _run_fv_split(variant: Variant, eq: Any, state: Any, problem: Problem, cfl: float,
                  max_steps: int) -> Outcome:
    from pde.trackers.base import FinishedSimulation

    from ..solvers.fv_split import FVSplitSolver, SimulationBlowUp

    solver = FVSplitSolver(eq, cfl=min(cfl, 0.5), max_steps=max_steps, **variant.options)
    solver.cfl = float(cfl)  # validation bypassed on purpose (module docstring)
    stepper = solver.make_stepper(state)
    try:
        t = stepper(state, 0.0, problem.t_end)
    except SimulationBlowUp as err:
        return Outcome("blow-up", f"step {err.step}, t={err.t:.3g} s, cell {err.cell}",
                       steps=int(solver.info["steps"]))
    except FinishedSimulation:
        return Outcome("stable", "at rest", steps=int(solver.info["steps"]))
    steps = int(solver.info["steps"])
    if t < problem.t_end:
        return Outcome("blow-up", f"time step collapsed ({steps} steps to t={t:.3g} s)",
                       steps=steps)
    return Outcome("stable", steps=steps)


def _run_mol(variant: Variant, eq: Any, state: Any, problem: Problem,
             cfl: float) -> Outcome:
    if problem.s_ref is None:
        reference_speed(problem)
    dt = cfl * problem.dx / problem.s_ref
    steps = max(1, round(problem.t_end / dt))  # as py-pde's fixed stepper
    flux, order, limiter = eq.scheme_codes
    done, cell, status = mol_run(state.data, dt, steps, MOL_SCHEMES[variant.solver],
                                 problem.dx, *eq.bc_codes, eq.parameter_array(),
                                 eq.two_layer, flux, order, limiter,
                                 eq.new_diagnostics(problem.cells))
    if status:
        kind = "non-finite value" if status == 1 else "negative depth"
        return Outcome("blow-up", f"{kind} in step {done} (t={done * dt:.3g} s), "
                                  f"cell {cell}", steps=done)
    return Outcome("stable", steps=done)


def reference_speed(problem: Problem) -> float:
    """Largest HLL wave-speed bound [m/s] over every step of the reference solution
    (fv-split, hyperbolicity 'exact', CFL 0.3); stored in ``problem.s_ref``."""
    from pde.trackers.base import FinishedSimulation

    from ..numerics.vectorized import advection_rate
    from ..solvers.fv_split import FVSplitSolver

    eq, state = problem.make(VARIANTS["fv-split/exact"])
    P = eq.parameter_array()
    stepper = FVSplitSolver(eq, cfl=0.3, max_steps=1).make_stepper(state)
    t, smax = 0.0, 0.0
    while t < problem.t_end:
        smax = max(smax, advection_rate(state.data, problem.dx, eq.bc_codes, P[L.G_Z],
                                        P[L.DRY], P[L.R])[1])
        try:
            t = stepper(state, t, problem.t_end)
        except FinishedSimulation:
            break
    problem.s_ref = smax
    return smax


# --- the map and the CFL search ---------------------------------------------------------------

DEFAULT_CFLS = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.4,
                1.6, 1.8, 2.0, 2.5)
SMALL_CFLS = (0.0005, 0.001, 0.002, 0.005, 0.01, 0.02)  #: tried first on 5.1 (stiff sources)
DEFAULT_RATIOS = (0.05, 0.15, 0.3, 0.45, 0.6, 0.67, 0.75, 0.85, 0.95, 0.99)
DEFAULT_DU = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0)


def cfl_problems(quick: bool = False) -> list[Problem]:
    """The problems of the CFL search: 5.1, and the shear flow at r = 0.67 below the
    band (du = 0.3 sqrt(gH), hyperbolic) and inside it (du = 1.0 sqrt(gH))."""
    cells = 100 if quick else 400
    t_end = 1.0 if quick else 4.0
    return [dam_break(), shear(0.67, 0.3, cells, t_end), shear(0.67, 1.0, cells, t_end)]


def largest_stable(results: dict[float, Outcome]) -> float | None:
    """Largest CFL c such that every tested CFL <= c is stable (None: not even the
    smallest)."""
    best = None
    for c in sorted(results):
        if results[c].status != "stable":
            break
        best = c
    return best


def cfl_search(variants: Sequence[str], problems: Sequence[Problem],
               cfls: Sequence[float] = DEFAULT_CFLS,
               log: Callable[[str], None] = print) -> dict[str, dict[str, dict]]:
    """Outcome per variant, problem and CFL number (stops a problem's scan after two
    consecutive failures above the first failure, to save time)."""
    out: dict[str, dict[str, dict]] = {}
    for name in variants:
        out[name] = {}
        for prob in problems:
            res: dict[float, Outcome] = {}
            fails = 0
            for c in (cfls if prob.perturbation else (*SMALL_CFLS, *cfls)):
                res[c] = run(VARIANTS[name], prob, c)
                fails = fails + 1 if res[c].status != "stable" else 0
                if fails >= 2:
                    break
            out[name][prob.name] = res
            log(f"  {name:18} {prob.name:28} largest stable CFL "
                f"{largest_stable(res)}")
    return out


def stability_map(variants: Sequence[str], ratios: Sequence[float] = DEFAULT_RATIOS,
                  dus: Sequence[float] = DEFAULT_DU, cfl: float = 0.3, cells: int = 400,
                  t_end: float = 4.0,
                  log: Callable[[str], None] = print) -> dict[str, dict[tuple, Outcome]]:
    """Outcome of the shear problem per variant over (r, du/sqrt(g H)) at ``cfl``."""
    out: dict[str, dict[tuple, Outcome]] = {}
    for name in variants:
        t0 = time.perf_counter()
        out[name] = {(r, d): run(VARIANTS[name], shear(r, d, cells, t_end), cfl)
                     for r in ratios for d in dus}
        counts = {s: sum(o.status == s for o in out[name].values())
                  for s in ("stable", "growth", "blow-up")}
        log(f"  {name:18} {counts} ({time.perf_counter() - t0:.1f} s)")
    return out


# --- extremes (heavy forms of the tests in tests/test_stress.py) ---------------------------------

def extremes(log: Callable[[str], None] = print) -> list[dict[str, Any]]:
    """Run the heavy extreme cases with fv-split (the paper's scheme); one row each."""
    from pde import CartesianGrid

    from ..models import SingleLayerGranular, TwoLayerGranular
    from ..solvers.fv_split import FVSplitSolver

    rows: list[dict[str, Any]] = []

    def column(n, length, L0, H0, two, x0=0.0, **params):
        g = CartesianGrid([[0.0, length]], n)
        x = g.axes_coords[0]
        inside = (x >= x0) & (x < x0 + L0)
        if not two:
            eq = SingleLayerGranular(bc=("wall", "wall"), **params)
            return eq, eq.make_state(g, h=np.where(inside, H0, 0.0))
        eq = TwoLayerGranular(bc=("wall", "wall"), **params)
        h2 = np.where(inside, np.minimum(H0, (x0 + L0 - x) * math.tan(math.radians(60))),
                      0.0)
        return eq, eq.make_state(g, h1=np.where(inside, H0 - h2, 0.0), h2=h2)

    def mass(eq, q):
        return float(np.sum(eq.parameters.density_ratio * q[0] + q[2]) if eq.two_layer
                     else np.sum(q[0]))

    def record(name, eq, st0, t_end, note=""):
        t0 = time.perf_counter()
        final, info = eq.solve(st0, t_range=t_end, solver="fv-split", cfl=0.3,
                               tracker=None, ret_info=True)
        wall = time.perf_counter() - t0
        q = final.data
        x = final.grid.axes_coords[0]
        H = q[0] + (q[2] if eq.two_layer else 0.0)
        wet = np.nonzero(H > 1e-3)[0]
        m0 = mass(eq, st0.data)
        row = {"case": name, "cells": q.shape[1], "steps": int(info["solver"]["steps"]),
               "rest_time": info["solver"].get("rest_time"),
               "front": float(x[wet[-1]] + 0.5 * (x[1] - x[0])) if wet.size else None,
               "mass_error": abs(mass(eq, q) - m0) / m0,
               "finite_nonneg": bool(np.all(np.isfinite(q)) and np.all(q[::2] >= 0)),
               "wall": wall, "note": note}
        rows.append(row)
        log(f"  {name}: {row}")
        return final, info

    record("5.1 column, 10^5 cells (dx = 7e-5 m), first 0.1 s",
           *column(100_000, 7.0, 1.0, 2.0, True), 0.1,
           "front at 0.1 s; 1.75 m with dx = 0.05 m")
    for two in (True, False):
        model = "two layers" if two else "one layer"
        record(f"aspect ratio 100 (L0 = 0.1 m, H0 = 10 m), {model}, dx = 2 mm",
               *column(20_000, 40.0, 0.1, 10.0, two), 30.0)
        record(f"aspect ratio 0.01 (L0 = 2 m, H0 = 2 cm), {model}, dx = 2 mm",
               *column(2_000, 4.0, 2.0, 0.02, two), 30.0)
    eq, st0 = column(140, 7.0, 1.0, 2.0, True)
    rest, info = record("5.1 column, dx = 0.05 m, to rest", eq, st0, 10.0)
    t_rest = info["solver"]["rest_time"]
    later = rest.copy()
    t0 = time.perf_counter()
    solver = FVSplitSolver(eq, cfl=0.3, stop_at_rest=False)
    solver.make_stepper(later)(later, t_rest, t_rest + 100.0)
    rows.append({"case": "... then left for 100 s (stop_at_rest off)", "cells": 140,
                 "steps": int(solver.info["steps"]),
                 "rest_time": t_rest,
                 "front": rows[-1]["front"],
                 "mass_error": abs(mass(eq, later.data) - mass(eq, rest.data))
                 / mass(eq, rest.data),
                 "finite_nonneg": bool(np.array_equal(later.data, rest.data)),
                 "wall": time.perf_counter() - t0,
                 "note": "deposit bitwise unchanged" if np.array_equal(later.data, rest.data)
                 else "deposit CHANGED"})
    log(f"  {rows[-1]}")
    for d in (-1.0, 1.0):
        record(f"column 1 m x 0.5 m on a slope phi_B {d:+g} deg (phi_B = 30), dx = 2 cm",
               *column(2500, 50.0, 1.0, 0.5, False, x0=1.0, theta_deg=30.0 + d,
                       phi_b_deg=30.0), 40.0 if d < 0 else 10.0)
    return rows


# --- output ---------------------------------------------------------------------------------------

STATUS_STYLE = {"stable": ("o", "tab:green"), "growth": ("^", "tab:orange"),
                "blow-up": ("x", "tab:red")}


def map_figure(maps: dict[str, dict[tuple, Outcome]], path: Path, cfl: float,
               cells: int = 400, t_end: float = 4.0) -> Path:
    """One panel per variant: outcome over (r, du/sqrt(gH)) with the band edges."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..io import atomic_path

    names = list(maps)
    cols = min(3, len(names))
    rows = math.ceil(len(names) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), sharex=True,
                             sharey=True, squeeze=False)
    rs = np.linspace(0.02, 0.995, 120)
    c = math.sqrt(G * (H1 + H2))
    edges = np.array([band_edges(r) for r in rs]) / c
    fl = np.array([lower_bound_fl(H1, H2, G, r) for r in rs]) / c
    fr = np.array([upper_bound_fr(H1, H2, G, r) for r in rs]) / c
    for ax, name in zip(axes.flat, names, strict=False):
        ax.fill_between(rs, edges[:, 0], edges[:, 1], color="0.85")
        ax.plot(rs, fl, "k--", lw=0.8)
        ax.plot(rs, fr, "k--", lw=0.8)
        for status, (marker, colour) in STATUS_STYLE.items():
            pts = [(r, d) for (r, d), o in maps[name].items() if o.status == status]
            if pts:
                a = np.array(pts)
                ax.scatter(a[:, 0], a[:, 1], marker=marker, c=colour, s=22)
        ax.set_title(name, fontsize=10)
        ax.set_ylim(0, max(d for _, d in maps[name]) * 1.05)
    for ax in axes[-1]:
        ax.set_xlabel("rho1/rho2")
    for ax in axes[:, 0]:
        ax.set_ylabel("|u1 - u2| / sqrt(g H)")
    for ax in axes.flat[len(names):]:
        ax.axis("off")
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(color="0.85", label="non-hyperbolic (exact)"),
               Line2D([], [], color="k", ls="--", lw=0.8, label="bounds F_L, F_R")]
    handles += [Line2D([], [], ls="", marker=m, color=c, label=s)
                for s, (m, c) in STATUS_STYLE.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8)
    fig.suptitle(f"shear flow h1 = {H1} m over h2 = {H2} m, {cells} cells, {t_end:g} s, "
                 f"CFL {cfl}", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


def cfl_figure(search: dict[str, dict[str, dict]], path: Path) -> Path:
    """Outcome per variant (rows) and CFL number (columns), one panel per problem."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    from ..io import atomic_path

    names = list(search)
    problems = list(next(iter(search.values())))
    cfls = sorted({c for v in search.values() for p in v.values() for c in p})
    code = {"stable": 0, "growth": 1, "blow-up": 2}
    cmap = ListedColormap(["tab:green", "tab:orange", "tab:red", "white"])
    fig, axes = plt.subplots(1, len(problems), figsize=(5.2 * len(problems),
                                                        0.42 * len(names) + 1.6),
                             squeeze=False)
    for ax, prob in zip(axes[0], problems, strict=True):
        img = np.full((len(names), len(cfls)), 3)
        for i, name in enumerate(names):
            for j, c in enumerate(cfls):
                o = search[name][prob].get(c)
                if o is not None:
                    img[i, j] = code[o.status]
        ax.imshow(img, cmap=cmap, vmin=0, vmax=3, aspect="auto")
        ax.set_xticks(range(len(cfls)), [f"{c:g}" for c in cfls], rotation=90, fontsize=7)
        ax.set_yticks(range(len(names)), names, fontsize=8)
        ax.axvline(cfls.index(1.0) + 0.5 if 1.0 in cfls else -1, color="k", lw=1)
        ax.set_xlabel("CFL number")
        ax.set_title(prob, fontsize=10)
    fig.suptitle("green stable, orange perturbation growth, red blow-up, white not run "
                 "(scan stops after two failures); fv-split validates CFL <= 1 (line)",
                 fontsize=9)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


def _fmt_cfl(res: dict[float, Outcome]) -> str:
    best = largest_stable(res)
    first = next((c for c in sorted(res) if res[c].status != "stable"), None)
    s = "none" if best is None else f"{best:g}"
    if first is None:
        return f"{s} (all tested stable)"
    return f"{s} (first failure at {first:g}: {res[first].status})"


def cfl_table(search: dict[str, dict[str, dict]]) -> str:
    """Markdown table: largest stable CFL per variant and problem."""
    problems = list(next(iter(search.values())))
    lines = ["| variant | " + " | ".join(problems) + " |",
             "|---|" + "---|" * len(problems)]
    for name, res in search.items():
        lines.append(f"| `{name}` | " + " | ".join(_fmt_cfl(res[p]) for p in problems)
                     + " |")
    return "\n".join(lines)


def map_table(maps: dict[str, dict[tuple, Outcome]]) -> str:
    """Markdown table: per variant and density ratio, the du/sqrt(gH) values that are
    not stable."""
    ratios = sorted({r for m in maps.values() for r, _ in m})
    lines = ["| variant | stable points | unstable du/sqrt(gH) per rho1/rho2 |", "|---|---|---|"]
    for name, m in maps.items():
        n_ok = sum(o.status == "stable" for o in m.values())
        parts = []
        for r in ratios:
            bad = [d for (rr, d), o in sorted(m.items()) if rr == r and o.status != "stable"]
            if bad:
                kinds = {m[(r, d)].status for d in bad}
                parts.append(f"{r:g}: {_ranges(bad)} ({', '.join(sorted(kinds))})")
        lines.append(f"| `{name}` | {n_ok}/{len(m)} | " + ("; ".join(parts) or "-") + " |")
    return "\n".join(lines)


def _ranges(values: list[float]) -> str:
    return f"{min(values):g}-{max(values):g}" if len(values) > 1 else f"{values[0]:g}"


def band_table(ratios: Sequence[float] = DEFAULT_RATIOS) -> str:
    """Markdown table of the band edges of the shear problem, in units of sqrt(g H)."""
    lines = ["| rho1/rho2 | F_L | F_c1 | F_c2 | F_R |", "|---|---|---|---|---|"]
    s = math.sqrt(G * (H1 + H2))
    for r in ratios:
        lo, hi = band_edges(r)
        lines.append(f"| {r:g} | {lower_bound_fl(H1, H2, G, r) / s:.3f} | {lo / s:.3f} "
                     f"| {hi / s:.3f} | {upper_bound_fr(H1, H2, G, r) / s:.3f} |")
    return "\n".join(lines)


def extremes_table(rows: list[dict[str, Any]]) -> str:
    lines = ["| case | cells | steps | at rest at [s] | front [m] | mass error | finite, "
             "h >= 0 | wall time [s] | note |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        rest = "-" if r["rest_time"] is None else f"{r['rest_time']:.3f}"
        front = "-" if r["front"] is None else f"{r['front']:.3f}"
        steps = "-" if not r["steps"] else str(r["steps"])
        lines.append(f"| {r['case']} | {r['cells']} | {steps} | {rest} | {front} | "
                     f"{r['mass_error']:.1e} | {'yes' if r['finite_nonneg'] else 'NO'} | "
                     f"{r['wall']:.2f} | {r['note']} |")
    return "\n".join(lines)


def replace_section(text: str, name: str, content: str) -> str:
    """Replace (or append) the generated section ``name`` of a markdown text."""
    begin = f"<!-- BEGIN stability:{name} (generated by python -m pdeflow.analysis.stability; " \
            "do not edit) -->"
    end = f"<!-- END stability:{name} -->"
    block = f"{begin}\n{content.rstrip()}\n{end}"
    pattern = re.compile(re.escape(begin.split(" (")[0]) + r".*?" + re.escape(end), re.S)
    if pattern.search(text):
        return pattern.sub(lambda _: block, text)
    return text.rstrip() + "\n\n" + block + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m pdeflow.analysis.stability",
        description="Stability map and largest stable CFL of the solver variants; "
                    "rewrites the generated sections of OUT/stability.md and its figures.")
    parser.add_argument("--out", default="docs", help="output directory (default: docs)")
    parser.add_argument("--variants", default=",".join(VARIANTS),
                        help="comma-separated variant names (default: all of VARIANTS)")
    parser.add_argument("--quick", action="store_true",
                        help="coarse map and short runs (a smoke test, not for the docs)")
    parser.add_argument("--extremes", action="store_true",
                        help="also run the heavy extreme cases (about two minutes)")
    args = parser.parse_args(argv)
    names = [v for v in args.variants.split(",") if v]
    unknown = [v for v in names if v not in VARIANTS]
    if unknown:
        parser.error(f"unknown variant(s) {unknown}; known: {list(VARIANTS)}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = out / "stability.md"
    text = md.read_text() if md.exists() else "# Stability\n"
    t0 = time.perf_counter()
    cfl_map = 0.3
    if args.quick:
        ratios, dus, cells, t_end = (0.3, 0.67, 0.95), (0.3, 1.0, 2.0), 100, 1.0
        cfls: Sequence[float] = (0.3, 0.9, 1.4)
    else:
        ratios, dus, cells, t_end, cfls = DEFAULT_RATIOS, DEFAULT_DU, 400, 4.0, DEFAULT_CFLS
    print("largest stable CFL:")
    problems = cfl_problems(args.quick)
    for p in problems:
        reference_speed(p)
    search = cfl_search(names, problems, cfls)
    print(f"stability map at CFL {cfl_map}:")
    maps = stability_map(names, ratios, dus, cfl_map, cells, t_end)
    map_png = map_figure(maps, out / "stability_map.png", cfl_map, cells, t_end)
    cfl_png = cfl_figure(search, out / "stability_cfl.png")
    elapsed = time.perf_counter() - t0
    refs = ", ".join(f"{p.name}: {p.s_ref:.3g} m/s" for p in problems)
    variants_md = "\n".join(f"* `{n}`: {VARIANTS[n].description}" for n in names)
    section = (
        f"Command: `python -m pdeflow.analysis.stability --out {args.out}` "
        f"({'--quick, ' if args.quick else ''}{elapsed:.0f} s on this machine).\n\n"
        f"Variants:\n\n{variants_md}\n\n"
        f"Reference wave speeds s_ref (the generic solvers' dt = CFL dx / s_ref): {refs}.\n\n"
        f"### Largest stable CFL\n\n{cfl_table(search)}\n\n"
        f"![largest stable CFL](stability_cfl.png)\n\n"
        f"`{cfl_png.name}`: outcome per variant and CFL number for each problem "
        f"(`python -m pdeflow.analysis.stability --out {args.out}`).\n\n"
        f"### Stable region in (rho1/rho2, relative velocity) at CFL {cfl_map}\n\n"
        f"{map_table(maps)}\n\n"
        f"![stability map](stability_map.png)\n\n"
        f"`{map_png.name}`: outcome of the shear problem per variant; grey: the exact "
        f"non-hyperbolic band, dashed: the bounds F_L, F_R "
        f"(`python -m pdeflow.analysis.stability --out {args.out}`).\n\n"
        f"Band edges for h1 = {H1} m, h2 = {H2} m, in units of sqrt(g H):\n\n"
        f"{band_table(ratios)}\n")
    text = replace_section(text, "map", section)
    if args.extremes:
        print("extremes:")
        rows = extremes()
        text = replace_section(
            text, "extremes",
            "Command: `python -m pdeflow.analysis.stability --out "
            f"{args.out} --extremes` (fv-split, the paper's scheme, CFL 0.3).\n\n"
            + extremes_table(rows) + "\n")
    from ..io import atomic_path

    with atomic_path(md) as tmp:
        tmp.write_text(text)
    print(f"wrote {md}, {map_png}, {cfl_png} ({elapsed:.0f} s)")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
