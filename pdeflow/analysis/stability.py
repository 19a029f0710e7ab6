"""Stability of the solver variants: largest stable CFL number and the region of
(rho1/rho2, relative velocity) where each variant stays stable.

``python docs/generate/stability.py`` runs the study and writes ``docs/stability.md``'s
tables and figures; this module holds the runs, the CFL search and the map, the problems
are in :mod:`pdeflow.analysis.stability_problems`.

Variants
--------
Every variant is a name of :class:`~pdeflow.variant.Variant` (:data:`VARIANTS`, the
docs' grammar, e.g. ``hll/first-order@bound``, ``mol-rk``); to add one, add its name.

* fv-split variants run the solver itself (CFL-limited steps). Its CFL number is
  validated to (0, 1] ((0, 0.5] with MUSCL); to find where the scheme really fails,
  larger CFL numbers are run with that validation bypassed (the attribute is set after
  construction).
* Method-of-lines variants (``mol-euler``, ``mol-rk``) run py-pde's own solver (Euler,
  classical RK4) with the numba backend and a fixed time step dt = CFL dx / s_ref on the
  model's rate and post-step hook; s_ref is the largest wave speed of the problem's
  reference solution (:func:`~pdeflow.analysis.stability_problems.reference_speed`).
  py-pde compiles the stepper anew for every run (its dt and the model's parameters
  are compile-time constants), a few seconds each.

Outcomes: ``blow-up`` (fv-split: a non-finite state, a step that would have left a depth
negative beyond round-off (rejected and retried by the solver's safety net, so the run
goes on, but the scheme is not stable there), or the time step collapsing; method of
lines: a step after which the model's post-step hook found a non-finite value or a
depth below -1e-12 m, counted in its diagnostics before it clips; for problems with
walls also a mass change above 1e-9, i.e. depths clipped),
``growth`` (the interface perturbation max|h1 - mean h1| ends larger than it started;
shear only), ``stable`` otherwise. The dam break is first tried at very small CFL numbers
(0.0005-0.02), where the method of lines' stiff regularised sources need them.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from pde.trackers.base import FinishedSimulation

from ..numerics import layout as L
from ..solvers.fv_split import FVSplitSolver, SimulationBlowUp
from ..study.core import Executor, Study, serial
from ..variant import Variant
from .stability_problems import Problem, reference_speed, shear

#: The variants of the study, by name: add new variants here.
VARIANTS: tuple[str, ...] = (
    "hll/first-order", "hll/first-order@bound", "hll/first-order@none",
    "rusanov/first-order", "ifcp/first-order", "hll/muscl/minmod",
    "hll/first-order+strang", "mol-euler", "mol-rk")

DEFAULT_CFLS = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.4,
                1.6, 1.8, 2.0, 2.5)
SMALL_CFLS = (0.0005, 0.001, 0.002, 0.005, 0.01, 0.02)  #: tried first on 5.1 (stiff sources)
DEFAULT_RATIOS = (0.05, 0.15, 0.3, 0.45, 0.6, 0.67, 0.75, 0.85, 0.95, 0.99)
DEFAULT_DU = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0)
MOL_CHUNKS = 50  #: a method-of-lines run checks the hook's count this often, and stops


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


def run(variant: Variant | str, problem: Problem, cfl: float, *,
        max_steps: int = 2_000_000) -> Outcome:
    """Run ``variant`` on ``problem`` at Courant number ``cfl`` and classify the result."""
    variant = variant if isinstance(variant, Variant) else Variant.parse(variant)
    eq, state = problem.make(variant)
    q0 = state.data.copy()
    t0 = time.perf_counter()
    if variant.is_mol:
        out = _run_mol(variant, eq, state, problem, cfl)
    else:
        out = _run_fv_split(variant, eq, state, problem, cfl, max_steps)
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
        out.growth = _perturbation(q) / _perturbation(q0)
        if out.growth > 1.0:
            out.status = "growth"
            out.detail = f"perturbation x{out.growth:.3g}"
    return out


def _run_fv_split(variant: Variant, eq: Any, state: Any, problem: Problem, cfl: float,
                  max_steps: int) -> Outcome:
    solver = FVSplitSolver(eq, cfl=min(cfl, 0.5), max_steps=max_steps,
                           splitting=variant.splitting)
    solver.cfl = float(cfl)  # validation bypassed on purpose (module docstring)
    stepper = solver.make_stepper(state)
    try:
        t = stepper(state, 0.0, problem.t_end)
    except SimulationBlowUp as err:
        return Outcome("blow-up", f"step {err.step}, t={err.t:.3g} s, cell {err.cell}",
                       steps=int(solver.info["steps"]))
    except FinishedSimulation:
        t = problem.t_end  # at rest: nothing more to do
    steps = int(solver.info["steps"])
    rejected = int(solver.diagnostics[L.D_RETRIES])
    if rejected:
        # the safety net kept the run going; the scheme itself is not stable here
        return Outcome("blow-up", f"{rejected} step(s) rejected (a depth would have turned "
                       "negative) and retried with dt/2", steps=steps)
    if t < problem.t_end:
        return Outcome("blow-up", f"time step collapsed ({steps} steps to t={t:.3g} s)",
                       steps=steps)
    return Outcome("stable", "at rest" if "rest_time" in solver.info else "",
                   steps=steps)


def _run_mol(variant: Variant, eq: Any, state: Any, problem: Problem,
             cfl: float) -> Outcome:
    """py-pde's fixed-step solver, in chunks: a chunk after which the post-step hook has
    counted a bad step ends the run (what the hook clipped is not looked at again)."""
    from pde.solvers.base import SolverBase

    if problem.s_ref is None:
        reference_speed(problem)
    dt = cfl * problem.dx / problem.s_ref
    steps = max(1, round(problem.t_end / dt))  # as py-pde's fixed stepper
    solver = SolverBase.from_name(variant.solver, eq, backend="numba")
    stepper = solver.make_stepper(state, dt)
    chunk = max(1, -(-steps // MOL_CHUNKS))
    done = 0
    while done < steps:
        k = min(chunk, steps - done)
        stepper(state, done * dt, (done + k) * dt)
        done += k
        if solver.info["post_step_data"][L.D_BAD_STEPS]:
            return Outcome("blow-up", f"non-finite value or negative depth by step {done} "
                                      f"(t={done * dt:.3g} s)", steps=done)
    return Outcome("stable", steps=done)


def largest_stable(results: dict[float, Outcome]) -> float | None:
    """Largest CFL c such that every tested CFL <= c is stable (None: not even the
    smallest)."""
    best = None
    for c in sorted(results):
        if results[c].status != "stable":
            break
        best = c
    return best


@dataclass
class _Scan:
    """A point of :func:`cfl_search`: one variant on one problem, over CFL numbers."""

    variant: str
    problem: Problem
    cfls: tuple[float, ...]

    @property
    def labels(self) -> dict[str, Any]:
        return {"variant": self.variant, "problem": self.problem.name}


def scan(point: _Scan) -> dict[str, Any]:
    """Measure of :func:`cfl_search`: the outcome per CFL number, in increasing order,
    until two consecutive failures (beyond the first failure nothing more is learnt)."""
    res: dict[float, Outcome] = {}
    fails = 0
    for c in point.cfls:
        res[c] = run(point.variant, point.problem, c)
        fails = fails + 1 if res[c].status != "stable" else 0
        if fails >= 2:
            break
    return {"outcomes": res}


def cfl_search(variants: Sequence[str], problems: Sequence[Problem],
               cfls: Sequence[float] = DEFAULT_CFLS,
               log: Callable[[str], None] = print,
               executor: Executor = serial) -> dict[str, dict[str, dict]]:
    """Outcome per variant, problem and CFL number: a :class:`~pdeflow.study.core.Study`
    of every variant on every problem, measured by :func:`scan` (the dam break tries
    :data:`SMALL_CFLS` first)."""
    points = [_Scan(name, prob, tuple(cfls) if prob.perturbation else (*SMALL_CFLS, *cfls))
              for name in variants for prob in problems]

    def said(rows: list[dict[str, Any]]) -> None:
        for r in rows:
            log(f"  {r['variant']:22} {r['problem']:28} largest stable CFL "
                f"{largest_stable(r['outcomes'])}")

    out: dict[str, dict[str, dict]] = {name: {} for name in variants}
    for r in Study(points, scan).run(executor, on_rows=said).rows:
        out[r["variant"]][r["problem"]] = r["outcomes"]
    return out


@dataclass
class _Shear:
    """A point of :func:`stability_map`: one variant on the shear problem (r, du)."""

    variant: str
    r: float
    du: float

    @property
    def labels(self) -> dict[str, Any]:
        return {"r": self.r, "du": self.du}


def shear_outcome(point: _Shear, cfl: float, cells: int, t_end: float) -> dict[str, Any]:
    """Measure of :func:`stability_map`: the outcome of one shear problem at ``cfl``."""
    return {"outcome": run(point.variant, shear(point.r, point.du, cells, t_end), cfl)}


def stability_map(variants: Sequence[str], ratios: Sequence[float] = DEFAULT_RATIOS,
                  dus: Sequence[float] = DEFAULT_DU, cfl: float = 0.3, cells: int = 400,
                  t_end: float = 4.0, log: Callable[[str], None] = print,
                  executor: Executor = serial) -> dict[str, dict[tuple, Outcome]]:
    """Outcome of the shear problem per variant over (r, du/sqrt(g H)) at ``cfl``: a
    :class:`~pdeflow.study.core.Study` per variant over the (r, du) grid."""
    out: dict[str, dict[tuple, Outcome]] = {}
    measure = partial(shear_outcome, cfl=cfl, cells=cells, t_end=t_end)
    for name in variants:
        t0 = time.perf_counter()
        points = [_Shear(name, r, d) for r in ratios for d in dus]
        out[name] = {(row["r"], row["du"]): row["outcome"]
                     for row in Study(points, measure).execute(executor)}
        counts = {s: sum(o.status == s for o in out[name].values())
                  for s in ("stable", "growth", "blow-up")}
        log(f"  {name:22} {counts} ({time.perf_counter() - t0:.1f} s)")
    return out
