r"""Work-precision harness: error against wall time for every numerical variant.

Every variant is run on a sequence of grids of one case and compared, at a fixed time,
with an exact solution or with a fine-grid reference; the result is a table (JSON and
Markdown) and a log-log work-precision diagram (error against wall time, PNG).

Usage::

    python -m pdeflow.analysis.workprecision CASE [CASE ...]
        [--variants hll/first-order rusanov/muscl/minmod ifcp/muscl/mc+strang mol-rk]
        [--grids 0.05 0.025 0.0125 | 100 200 400] [--reference auto|exact|fine|fine:VARIANT]
        [--t 0.4] [--repeats 3] [--cfl 0.45] [--mol-cap 20] [--out-dir results/workprecision]
        [--hyperbolicity]

``CASE`` is a TOML case file (``cases/*.toml``) or a built-in name: ``ritter``
(frictionless dam break onto a dry bed, Ritter's solution) or ``mangeney`` (dam break on
a 30 deg slope with a 20 deg Coulomb bed, Mangeney et al. 2000). The same function is
what ``pdeflow compare`` calls: :func:`compare`.

Variants
--------
Names are ``FLUX/RECONSTRUCTION[/LIMITER][+SPLITTING]``, e.g. ``hll/first-order``,
``rusanov/muscl/minmod``, ``ifcp/muscl/mc+strang`` (the ``fv-split`` solver; the limiter
defaults to minmod, the splitting to Lie), or ``mol-rk``: py-pde's ``runge-kutta`` solver
(classical RK4 with a fixed step) on the method-of-lines rate of the hll/first-order
discretisation, with dt = CFL dx / s_est and the a-priori speed bound
s_est = 2 max(|u| + sqrt(g_z H)) + g_x t over the initial state (exact for Ritter's
solution, whose front moves at 2 sqrt(g h0)). Its compiled run is stopped after
``mol_cap`` seconds of wall time (status ``capped``); a run that blows up (a non-finite
state, a depth above 1.5 times the initial maximum depth or a velocity above 5 s_est;
the post-step hook clips negative depths silently) is ``failed``.

Errors and timing
-----------------
* error: L1 norms at the time ``t`` of the depth, sum_k sum_i |h_k,i - h_k,ref,i| dx
  [m^2], and of the momentum, sum_k sum_i |(hu)_k,i - (hu)_k,ref,i| dx [m^3/s] (k runs
  over the layers). Exact solutions are averaged over each cell (8-point midpoint rule);
  a fine-grid reference is restricted to the coarse grid by cell averaging (exact
  integration of the piecewise-constant fine solution over each coarse cell).
* reference: ``exact`` for single-layer dam breaks onto a dry bed (Ritter with
  phi_B -> 0, Mangeney on a slope); otherwise ``fine``: the same variant and model on a
  grid with dx_ref = min(dx)/4 (``reference_dx``). ``fine:VARIANT`` uses one common
  reference variant for all. mol-rk is compared with the hll/first-order fv-split
  reference (the same spatial discretisation; a fine RK4 run would cost minutes).
* wall time: the median over ``repeats`` runs of the compiled stepper (more, up to 25,
  while the timed runs add up to less than 0.25 s: short runs are noisy), after one
  warm-up run that compiles (numba) and is not counted. The compile time of mol-rk (py-pde
  builds and compiles a new stepper and rate for every grid) is reported separately as
  ``compile_s``; for fv-split it is the warm-up run's excess over the median.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import statistics
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..cases import Case, CaseError, load_case

FLUXES = ("hll", "rusanov", "ifcp")
RECONSTRUCTIONS = ("first-order", "muscl")
LIMITERS = ("minmod", "mc")
MOL_RK = "mol-rk"
MIN_TIMING_S = 0.25
"""Short runs are repeated until their timed runs add up to this [s] (noise)."""
MAX_REPEATS = 25

DEFAULT_VARIANTS: tuple[str, ...] = (
    "hll/first-order", "rusanov/first-order", "ifcp/first-order",
    "hll/muscl/minmod", "rusanov/muscl/minmod", "ifcp/muscl/mc",
    "hll/first-order+strang", "hll/muscl/mc+strang", MOL_RK,
)
"""Variants run when none are named: every flux at first order, MUSCL with both
limiters, Strang splitting, and the method of lines with RK4."""

BUILTIN_CASES: dict[str, dict[str, Any]] = {
    "ritter": {
        "case": {"name": "ritter", "t_end": 0.5, "models": ["single_layer"],
                 "description": "Ritter: frictionless dam break, h0 = 0.1 m onto a dry "
                                "bed at x = 0, t = 0.5 s"},
        "grid": {"length": 2.5, "x_start": -1.0, "dx": 0.01},
        "boundaries": {"left": "open", "right": "open"},
        "initial": {"shape": "dam_break", "x_dam": 1.0, "h_left": 0.1, "h_right": 0.0},
        "numerics": {"cfl": 0.45},
        "single_layer": {"phi_b_deg": 1e-9},
    },
    "mangeney": {
        "case": {"name": "mangeney", "t_end": 0.5, "models": ["single_layer"],
                 "description": "Mangeney et al. 2000: dam break, h0 = 0.1 m, on a 30 deg "
                                "slope with a 20 deg Coulomb bed, t = 0.5 s"},
        "grid": {"length": 3.0, "x_start": -1.0, "dx": 0.01},
        "boundaries": {"left": "open", "right": "open"},
        "initial": {"shape": "dam_break", "x_dam": 1.0, "h_left": 0.1, "h_right": 0.0},
        "numerics": {"cfl": 0.45},
        "single_layer": {"theta_deg": 30.0, "phi_b_deg": 20.0},
    },
}
"""Built-in cases with exact solutions (names accepted wherever a case path is)."""

_VARIANT_RE = re.compile(
    r"^(?P<flux>[a-z]+)/(?P<rec>first-order|muscl)(?:/(?P<lim>[a-z]+))?"
    r"(?:\+(?P<split>lie|strang))?$")


@dataclass(frozen=True)
class Variant:
    """A numerical variant: the fv-split scheme's choices, or the method of lines."""

    name: str
    flux: str = "hll"
    reconstruction: str = "first-order"
    limiter: str = "minmod"
    splitting: str = "lie"
    solver: str = "fv-split"

    @property
    def numerics(self) -> dict[str, Any]:
        """The case file's ``[numerics]`` entries selecting this variant."""
        out: dict[str, Any] = {"flux": self.flux, "reconstruction": self.reconstruction,
                               "limiter": self.limiter}
        if self.solver == "fv-split":
            out["splitting"] = self.splitting
        return out


def parse_variant(name: str) -> Variant:
    """Parse a variant name (see the module docstring); ValueError if malformed."""
    name = name.strip()
    if name == MOL_RK:
        return Variant(MOL_RK, solver="runge-kutta")
    m = _VARIANT_RE.match(name)
    if not m:
        raise ValueError(f"variant {name!r} is not FLUX/RECONSTRUCTION[/LIMITER][+lie|"
                         f"+strang] or {MOL_RK!r} (fluxes {list(FLUXES)}, "
                         f"reconstructions {list(RECONSTRUCTIONS)}, limiters "
                         f"{list(LIMITERS)})")
    flux, rec, lim, split = m["flux"], m["rec"], m["lim"], m["split"] or "lie"
    if flux not in FLUXES:
        raise ValueError(f"variant {name!r}: flux must be one of {list(FLUXES)}")
    if lim is not None and rec != "muscl":
        raise ValueError(f"variant {name!r}: a limiter needs the muscl reconstruction")
    lim = lim or "minmod"
    if lim not in LIMITERS:
        raise ValueError(f"variant {name!r}: limiter must be one of {list(LIMITERS)}")
    return Variant(name, flux, rec, lim, split)


# --- cases and references --------------------------------------------------------------

def resolve_case(case_path: str | Path | Case) -> Case:
    """A :class:`~pdeflow.cases.Case` from a path, a built-in name or a Case."""
    if isinstance(case_path, Case):
        return case_path.copy()
    key = str(case_path)
    if key in BUILTIN_CASES:
        return Case.from_dict(BUILTIN_CASES[key], source=f"<builtin {key}>")
    return load_case(case_path)


def case_on_grid(case: Case, grid: float | int, variant: Variant,
                 cfl: float | None = None) -> Case:
    """Copy of ``case`` on the grid ``grid`` (int: cells, float: dx [m], rounded to a
    whole number of cells) with the
    numerics of ``variant`` (and ``cfl`` if given), without snapshots."""
    c = case.copy()
    g = c.data.setdefault("grid", {})
    g.pop("cells", None)
    g.pop("dx", None)
    if isinstance(grid, (int, np.integer)) and not isinstance(grid, bool):
        g["cells"] = int(grid)
    else:  # nearest whole number of cells (case files require length/dx integral)
        g["cells"] = max(1, round(c.length / float(grid)))
    num = c.data.setdefault("numerics", {})
    for key in ("flux", "reconstruction", "limiter", "splitting", "solver", "dt"):
        num.pop(key, None)
    num.update(variant.numerics)
    if cfl is not None:
        num["cfl"] = float(cfl)
    c.data.setdefault("output", {})["snapshot_times"] = []
    c.validate()
    return c


def exact_solution_for(case: Case, model: str) -> dict[str, Any] | None:
    """Parameters of the exact solution of ``case`` for ``model``, or None.

    Single-layer dam breaks onto a dry bed (``initial.shape = "dam_break"``,
    ``h_right = 0``) with phi_B <= theta have Mangeney's solution (Ritter's for
    theta = phi_B = 0), valid while the rarefaction stays inside the domain.
    """
    ini = case.initial
    if model != "single_layer" or ini.get("shape") != "dam_break":
        return None
    if float(ini.get("h_right", 0.0)) != 0.0:
        return None
    p = case.make_pde("single_layer").parameters
    if p.phi_b_deg > max(p.theta_deg, 0.0) + 1e-6:
        return None
    return {"h0": float(ini["h_left"]), "x0": case.x_start + float(ini["x_dam"]),
            "g": p.g, "theta_deg": p.theta_deg, "delta_deg": p.phi_b_deg}


def exact_cell_averages(params: dict[str, Any], edges: np.ndarray, t: float,
                        points: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Cell averages of (h [m], hu [m^2/s]) of Mangeney's solution between ``edges``."""
    from .exact import mangeney

    lo, hi = edges[:-1], edges[1:]
    frac = (np.arange(points) + 0.5) / points
    x = lo[:, None] + (hi - lo)[:, None] * frac[None, :]
    h, u = mangeney(x, t, params["h0"], x0=params["x0"], g=params["g"],
                    theta_deg=params["theta_deg"], delta_deg=params["delta_deg"])
    return h.mean(axis=1), (h * u).mean(axis=1)


def restrict(values: np.ndarray, fine_edges: np.ndarray,
             coarse_edges: np.ndarray) -> np.ndarray:
    """Average the piecewise-constant fine-grid ``values`` (last axis: cells) over the
    coarse cells: exact integration, nested or not, for grids on the same interval."""
    values = np.asarray(values, dtype=float)
    widths = np.diff(fine_edges)
    cum = np.concatenate([np.zeros((*values.shape[:-1], 1)),
                          np.cumsum(values * widths, axis=-1)], axis=-1)
    flat = cum.reshape(-1, cum.shape[-1])
    at = np.stack([np.interp(coarse_edges, fine_edges, row) for row in flat])
    out = np.diff(at, axis=-1) / np.diff(coarse_edges)
    return out.reshape(*values.shape[:-1], coarse_edges.size - 1)


def cell_edges(case: Case) -> np.ndarray:
    """Cell faces [m] of the case's grid."""
    return case.x_start + case.length * np.linspace(0.0, 1.0, case.cells + 1)


# --- running one variant on one grid ---------------------------------------------------

@dataclass
class RunTiming:
    """Outcome of timing one compiled run."""

    data: np.ndarray
    """state at time ``t`` (rows h, hu or h1, h1u1, h2, h2u2)"""
    t: float
    wall_s: list[float]
    compile_s: float
    steps: int
    status: str = "ok"
    note: str = ""
    info: dict[str, Any] = field(default_factory=dict)


def _repeat(run: Any, repeats: int) -> list[float]:
    """Wall times [s] of ``repeats`` calls of ``run()`` (more while they are short)."""
    walls: list[float] = []
    while len(walls) < repeats or (sum(walls) < MIN_TIMING_S and len(walls) < MAX_REPEATS):
        walls.append(run())
    return walls


def _fv_split_run(case: Case, model: str, t: float, repeats: int) -> RunTiming:
    from pde.trackers.base import FinishedSimulation

    from ..solvers import FVSplitSolver, SimulationBlowUp

    eq, state = case.make_state(model)

    def once() -> tuple[float, np.ndarray, int, dict]:
        solver = FVSplitSolver(eq, cfl=case.cfl, splitting=case.splitting)
        s = state.copy()
        stepper = solver.make_stepper(s)
        w0 = time.perf_counter()
        try:
            stepper(s, 0.0, float(t))
        except FinishedSimulation:
            pass  # at rest before t: the state is stationary
        wall = time.perf_counter() - w0
        return wall, s.data.copy(), int(solver.info["steps"]), dict(solver.info)

    try:
        warm, data, steps, info = once()
        walls = [warm] if repeats <= 0 else _repeat(lambda: once()[0], repeats)
    except SimulationBlowUp as err:
        return RunTiming(state.data.copy(), t, [math.nan], math.nan, 0, "failed",
                         str(err))
    med = statistics.median(walls)
    return RunTiming(data, t, walls, max(warm - med, 0.0), steps, info=info)


def mol_time_step(case: Case, model: str, t: float) -> float:
    """Fixed RK4 step [s]: CFL dx / s_est, s_est = 2 max(|u| + sqrt(g_z H)) + g_x t
    over the initial state, shortened so that a whole number of steps reaches ``t``."""
    eq, state = case.make_state(model)
    P = eq.parameter_array()
    gz, gx = float(P[0]), float(P[1])  # G_Z, G_X come first in both layouts
    d = state.data
    H = np.maximum(d[::2], 0.0).sum(axis=0)
    speed = 0.0
    for k in range(0, d.shape[0], 2):
        h = d[k]
        u = np.where(h > 1e-6, d[k + 1] / np.where(h > 1e-6, h, 1.0), 0.0)
        speed = max(speed, float(np.max(np.abs(u) + np.sqrt(gz * H))))
    s_est = 2.0 * speed + abs(gx) * t
    dt = case.cfl * case.dx / s_est
    return t / math.ceil(t / dt)


def _mol_run(case: Case, model: str, t: float, repeats: int, cap: float) -> RunTiming:
    from pde.solvers import RungeKuttaSolver

    eq, state = case.make_state(model)
    h_max0 = float(np.max(np.maximum(state.data[::2], 0.0).sum(axis=0)))
    s_est = case.cfl * case.dx / mol_time_step(case, model, t)

    def broken(d: np.ndarray) -> bool:
        """Blow-up: non-finite, a depth above 1.5 x the initial one, or a velocity
        above 5 x the speed bound (the hook clips negative depths silently)."""
        if not np.all(np.isfinite(d)):
            return True
        if np.max(d[::2]) > 1.5 * h_max0:
            return True
        h = d[::2]
        u = np.abs(d[1::2]) / np.maximum(h, 1e-3)
        return bool(np.max(u) > 5.0 * s_est)

    dt = mol_time_step(case, model, t)
    n_steps = round(t / dt)
    chunk = max(1, math.ceil(n_steps / 50))
    c0 = time.perf_counter()
    solver = RungeKuttaSolver(eq, backend="numba")
    stepper = solver.make_stepper(state, dt)
    compile_s = time.perf_counter() - c0

    def once() -> tuple[float, np.ndarray, str, str, float]:
        s = state.copy()
        done = 0
        w0 = time.perf_counter()
        status, note = "ok", ""
        with np.errstate(all="ignore"):
            while done < n_steps:
                k = min(chunk, n_steps - done)
                stepper(s, done * dt, (done + k) * dt)
                done += k
                elapsed = time.perf_counter() - w0
                d = s.data
                if broken(d):
                    status = "failed"
                    note = f"blow-up at t = {done * dt:.4g} s (dt = {dt:.3g} s)"
                    break
                if elapsed > cap and done < n_steps:
                    status = "capped"
                    note = (f"wall-time cap {cap:g} s reached at t = {done * dt:.4g} s of "
                            f"{t:g} s; projected {elapsed * n_steps / done:.3g} s")
                    break
        wall = time.perf_counter() - w0
        return wall, s.data.copy(), status, note, done * dt

    warm, data, status, note, t_reached = once()
    walls = [warm]
    if status == "ok":
        walls = []
        budget = cap
        for _ in range(max(1, repeats)):
            w = once()[0]
            walls.append(w)
            budget -= w
            if budget <= 0:
                break
        compile_s += max(warm - statistics.median(walls), 0.0)
    return RunTiming(data, t_reached, walls, compile_s, n_steps if status == "ok" else
                     round(t_reached / dt), status, note, {"dt": dt})


def run_variant(case: Case, model: str, variant: Variant, t: float, repeats: int = 3,
                mol_cap: float = 20.0) -> RunTiming:
    """Time ``variant`` of ``model`` on ``case`` (already on its grid) up to ``t`` [s]."""
    if variant.solver == "fv-split":
        return _fv_split_run(case, model, t, repeats)
    return _mol_run(case, model, t, repeats, mol_cap)


# --- the harness -----------------------------------------------------------------------

@dataclass
class CompareResult:
    """Rows of a work-precision study and the files written."""

    case: str
    t: float
    rows: list[dict[str, Any]]
    files: dict[str, str] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def _errors(data: np.ndarray, ref: np.ndarray, dx: float) -> tuple[float, float]:
    depth = float(np.abs(data[::2] - ref[::2]).sum() * dx)
    mom = float(np.abs(data[1::2] - ref[1::2]).sum() * dx)
    return depth, mom


def compare(case_path: str | Path | Case, variants: Sequence[str] | None = None,
            grids: Sequence[float | int] | None = None, reference: str = "auto",
            out_dir: str | Path | None = "results/workprecision", *,
            t: float | None = None, repeats: int = 3, models: Sequence[str] | None = None,
            cfl: float | None = None, reference_dx: float | None = None,
            mol_cap: float = 20.0, label: str | None = None,
            log: Any = None) -> CompareResult:
    """Run every variant on every grid of a case and measure error against wall time.

    Args:
        case_path: a TOML case file, a built-in name (``"ritter"``, ``"mangeney"``,
            see :data:`BUILTIN_CASES`) or a :class:`~pdeflow.cases.Case`.
        variants: variant names (see :func:`parse_variant`); default
            :data:`DEFAULT_VARIANTS`.
        grids: the grid sequence, each an int (number of cells) or a float (dx [m]);
            default: the case's dx, dx/2, dx/4.
        reference: ``"auto"`` (exact where :func:`exact_solution_for` knows one, else
            fine), ``"exact"``, ``"fine"`` (same variant on a grid with
            ``reference_dx``) or ``"fine:VARIANT"`` (one common reference variant).
        out_dir: directory for ``<case>_workprecision.{json,md,png}``; None writes
            nothing.
        t: time [s] at which errors are measured (default: the case's t_end).
        repeats: timed runs per point; the median wall time is reported.
        models: models to run (default: the case's ``case.models``).
        cfl: Courant number for every variant (default: the case's).
        reference_dx: grid spacing [m] of fine references (default min(dx)/4).
        mol_cap: wall-time cap [s] of one compiled mol-rk run.
        log: a stream for progress lines (e.g. ``sys.stderr``), or None.

    Returns:
        A :class:`CompareResult`; each row has ``case, model, variant, solver,
        splitting, cells, dx [m], t [s], err_h [m^2], err_hu [m^3/s], rel_err_h,
        wall_s`` (median [s]), ``walls`` (all repeats), ``compile_s, steps,
        cell_updates, status, note, reference`` and ``order_h`` (observed L1 order
        against the previous grid of the same variant).
    """
    base = resolve_case(case_path)
    names = list(variants or DEFAULT_VARIANTS)
    parsed = [parse_variant(v) for v in names]
    grids = list(grids or [base.dx, base.dx / 2, base.dx / 4])
    t_eval = float(t if t is not None else base.t_end)
    models = list(models or base.models)
    if reference not in ("auto", "exact", "fine") and not reference.startswith("fine:"):
        raise ValueError(f"reference must be auto, exact, fine or fine:VARIANT, got "
                         f"{reference!r}")
    common_ref = parse_variant(reference[5:]) if reference.startswith("fine:") else None

    def dx_of(gr: float | int) -> float:
        if isinstance(gr, (int, np.integer)) and not isinstance(gr, bool):
            return base.length / int(gr)
        return float(gr)

    ref_dx = reference_dx or min(dx_of(gr) for gr in grids) / 4
    fine_cache: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, str]] = {}

    def say(msg: str) -> None:
        if log is not None:
            print(msg, file=log, flush=True)

    def fine_reference(model: str, v: Variant) -> tuple[np.ndarray, np.ndarray, str]:
        rv = common_ref or (v if v.solver == "fv-split" else parse_variant("hll/first-order"))
        key = (model, rv.name)
        if key not in fine_cache:
            fc = case_on_grid(base, ref_dx, rv, cfl)
            say(f"  reference {model} {rv.name} dx={ref_dx:g} ({fc.cells} cells)")
            run = run_variant(fc, model, rv, t_eval, repeats=0)
            if run.status != "ok":
                raise RuntimeError(f"fine reference {rv.name} failed: {run.note}")
            fine_cache[key] = (run.data, cell_edges(fc), f"fine {rv.name} dx={ref_dx:g} m")
        return fine_cache[key]

    rows: list[dict[str, Any]] = []
    for model in models:
        exact = exact_solution_for(base, model)
        if reference == "exact" and exact is None:
            raise ValueError(f"no exact solution for {model} on {base.name}")
        use_exact = exact is not None and reference in ("auto", "exact")
        for v in parsed:
            prev: dict[str, Any] | None = None
            for gr in grids:
                c = case_on_grid(base, gr, v, cfl)
                edges = cell_edges(c)
                say(f"{base.name} {model} {v.name} cells={c.cells}")
                run = run_variant(c, model, v, t_eval, repeats, mol_cap)
                if use_exact:
                    h, hu = exact_cell_averages(exact, edges, t_eval)
                    ref = np.stack([h, hu])
                    ref_name = ("exact Ritter" if exact["theta_deg"] == 0 else
                                "exact Mangeney")
                else:
                    fdata, fedges, ref_name = fine_reference(model, v)
                    ref = restrict(fdata, fedges, edges)
                dx = c.length / c.cells
                if run.status == "ok":
                    eh, ehu = _errors(run.data, ref, dx)
                else:
                    eh = ehu = math.nan
                norm = float(np.abs(ref[::2]).sum() * dx)
                row = {
                    "case": base.name, "model": model, "variant": v.name,
                    "solver": v.solver, "splitting": v.splitting if v.solver == "fv-split"
                    else None, "cells": c.cells, "dx": dx, "t": t_eval,
                    "err_h": eh, "err_hu": ehu,
                    "rel_err_h": eh / norm if norm > 0 else math.nan,
                    "wall_s": statistics.median(run.wall_s), "walls": run.wall_s,
                    "compile_s": run.compile_s, "steps": run.steps,
                    "cell_updates": run.steps * c.cells, "status": run.status,
                    "note": run.note, "reference": ref_name, "order_h": None,
                }
                if v.solver != "fv-split":
                    row["dt"] = run.info.get("dt")
                if (prev is not None and prev["status"] == "ok" and run.status == "ok"
                        and eh > 0 and prev["err_h"] > 0):
                    row["order_h"] = math.log(prev["err_h"] / eh) / math.log(
                        prev["dx"] / dx)
                say(f"    err_h={eh:.3e} m^2 err_hu={ehu:.3e} m^3/s "
                    f"wall={row['wall_s'] * 1e3:.2f} ms {run.status} {run.note}")
                rows.append(row)
                prev = row
    result = CompareResult(label or base.name, t_eval, rows)
    if out_dir is not None:
        write_outputs(result, Path(out_dir))
    return result


# --- outputs ---------------------------------------------------------------------------

def _fmt(v: Any, spec: str) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return format(v, spec)


def markdown_table(result: CompareResult) -> str:
    """The rows of ``result`` as a Markdown table."""
    lines = ["| model | variant | cells | L1 depth [m^2] | L1 momentum [m^3/s] | order | "
             "wall [ms] | steps | status |",
             "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in result.rows:
        status = r["status"] if r["status"] == "ok" else f"{r['status']}: {r['note']}"
        lines.append(
            f"| {r['model']} | {r['variant']} | {r['cells']} | {_fmt(r['err_h'], '.3e')} | "
            f"{_fmt(r['err_hu'], '.3e')} | {_fmt(r['order_h'], '.2f')} | "
            f"{_fmt(r['wall_s'] * 1e3, '.3g')} | {r['steps']} | {status} |")
    return "\n".join(lines) + "\n"


def plot(result: CompareResult, path: str | Path) -> Path:
    """Work-precision diagram: L1 depth and momentum errors against the median wall
    time, log-log, one line per variant, one column per model."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    models = list(dict.fromkeys(r["model"] for r in result.rows))
    variants = list(dict.fromkeys(r["variant"] for r in result.rows))
    fig, axes = plt.subplots(2, len(models), figsize=(5.5 * len(models), 8), squeeze=False)
    markers = "osD^v<>phX*"
    for j, model in enumerate(models):
        for i, (key, label) in enumerate((("err_h", "L1 depth error [m$^2$]"),
                                          ("err_hu", "L1 momentum error [m$^3$/s]"))):
            ax = axes[i, j]
            for k, v in enumerate(variants):
                rs = [r for r in result.rows if r["model"] == model and r["variant"] == v
                      and r["status"] == "ok" and r[key] > 0]
                if not rs:
                    continue
                ls = "--" if "strang" in v else (":" if v == MOL_RK else "-")
                ax.loglog([r["wall_s"] for r in rs], [r[key] for r in rs],
                          marker=markers[k % len(markers)], ls=ls, label=v)
            ax.set_xlabel("median wall time of the compiled run [s]")
            ax.set_ylabel(label)
            ax.set_title(f"{result.case}: {model}, t = {result.t:g} s")
            ax.grid(True, which="both", alpha=0.3)
        axes[0, j].legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_outputs(result: CompareResult, out_dir: Path) -> dict[str, str]:
    """Write ``<case>_workprecision.json``, ``.md`` and ``.png`` into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = out_dir / f"{result.case}_workprecision"
    png = plot(result, stem.with_suffix(".png"))
    md = stem.with_suffix(".md")
    md.write_text(f"# Work precision: {result.case}, t = {result.t:g} s\n\n"
                  + markdown_table(result))
    result.files = {"png": str(png), "md": str(md), "json": str(stem.with_suffix(".json"))}
    stem.with_suffix(".json").write_text(json.dumps(result.to_json(), indent=1,
                                                    default=float))
    return result.files


# --- hyperbolicity modes ---------------------------------------------------------------

def hyperbolicity_study(case_path: str | Path | Case,
                        modes: Sequence[str] = ("exact", "bound", "none"),
                        grids: Sequence[float | int] | None = None, repeats: int = 3,
                        log: Any = None) -> list[dict[str, Any]]:
    """Cost and effect of the hyperbolicity modes on the two-layer model of a case.

    Each mode runs the case to rest (or t_end) with :func:`pdeflow.simulate.run_model`
    once to warm up and ``repeats`` times; rows give the median wall time [s], steps,
    ``max_fextra_over_rho1`` [m^2/s^2], ``hyperbolicity_events`` (cell-steps in which
    F_extra was applied), ``hyperbolicity_bisections`` (of those, how many needed the
    bisection fallback), stop times [s] and run-out [m].
    """
    from ..simulate import run_model

    base = resolve_case(case_path)
    rows = []
    for gr in list(grids or [base.dx]):
        for mode in modes:
            c = case_on_grid(base, gr, parse_variant("hll/first-order"))
            c.data.setdefault("two_layer", {})["hyperbolicity"] = mode
            c.validate()
            run_model(c, "two_layer")  # warm-up (compiles once per process)
            walls, s = [], {}
            for _ in range(max(1, repeats)):
                res = run_model(c, "two_layer")
                walls.append(res.summary["wall_time_s"])
                s = res.summary
            row = {"mode": mode, "cells": c.cells, "dx": c.dx,
                   "wall_s": statistics.median(walls), "walls": walls,
                   "steps": s["steps"], "t_final": s["t_final"],
                   "max_fextra_over_rho1": s["max_fextra_over_rho1"],
                   "hyperbolicity_events": s["hyperbolicity_events"],
                   "hyperbolicity_bisections": s["hyperbolicity_bisections"],
                   "lower_stop_time": s["lower_stop_time"],
                   "upper_stop_time": s["upper_stop_time"], "runout": s["runout"]}
            if log is not None:
                print(f"hyperbolicity {mode} cells={c.cells}: {row}", file=log, flush=True)
            rows.append(row)
    return rows


# --- command line ----------------------------------------------------------------------

def _grid_value(text: str) -> float | int:
    """'200' -> 200 cells; '0.05' or '5e-2' -> dx = 0.05 m."""
    if re.fullmatch(r"\d+", text):
        return int(text)
    return float(text)


def build_parser(prog: str = "python -m pdeflow.analysis.workprecision"
                 ) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog,
        description="Work-precision study: runs every numerical variant (flux, "
                    "reconstruction, splitting, or a py-pde solver) on a sequence of grids "
                    "and measures its error against an exact solution or a fine-grid "
                    "reference, and its wall time; writes the error-against-wall-time "
                    "diagram (PNG) and table (JSON, Markdown). To compare stored runs "
                    "with each other, use `pdeflow plot RUN.h5 RUN.h5`.")
    p.add_argument("cases", nargs="+", help="case TOML files or built-in names "
                   f"({', '.join(BUILTIN_CASES)})")
    p.add_argument("--variants", nargs="+", default=None,
                   help="variant names, e.g. hll/first-order rusanov/muscl/minmod "
                        "ifcp/muscl/mc+strang mol-rk (default: a set of 9)")
    p.add_argument("--grids", nargs="+", type=_grid_value, default=None,
                   help="grids: integers are cell counts, decimals are dx [m] "
                        "(default: the case's dx, dx/2, dx/4)")
    p.add_argument("--reference", default="auto",
                   help="auto | exact | fine | fine:VARIANT (default auto)")
    p.add_argument("--t", type=float, default=None, help="evaluation time [s] "
                   "(default: the case's t_end)")
    p.add_argument("--repeats", type=int, default=3, help="timed repeats (median)")
    p.add_argument("--models", nargs="+", default=None, help="models (default: case's)")
    p.add_argument("--cfl", type=float, default=None, help="Courant number for all")
    p.add_argument("--reference-dx", type=float, default=None,
                   help="dx [m] of fine references (default min(dx)/4)")
    p.add_argument("--mol-cap", type=float, default=20.0,
                   help="wall-time cap [s] of one mol-rk run (default 20)")
    p.add_argument("--out-dir", default="results/workprecision",
                   help="output directory (default results/workprecision)")
    p.add_argument("--hyperbolicity", action="store_true",
                   help="also compare the hyperbolicity modes exact/bound/none "
                        "(two-layer cases)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    return p


def main(argv: list[str] | None = None,
         prog: str = "python -m pdeflow.analysis.workprecision") -> int:
    """Command-line entry point (``prog`` names it in the help); returns the exit status."""
    args = build_parser(prog).parse_args(argv)
    log = None if args.quiet else sys.stderr
    try:
        for case in args.cases:
            res = compare(case, args.variants, args.grids, args.reference, args.out_dir,
                          t=args.t, repeats=args.repeats, models=args.models,
                          cfl=args.cfl, reference_dx=args.reference_dx,
                          mol_cap=args.mol_cap, log=log)
            print(f"## {res.case} (t = {res.t:g} s)\n")
            print(markdown_table(res))
            print(f"written: {', '.join(res.files.values())}\n")
            if args.hyperbolicity:
                rows = hyperbolicity_study(case, log=log, repeats=args.repeats)
                path = Path(args.out_dir) / f"{res.case}_hyperbolicity.json"
                path.write_text(json.dumps(rows, indent=1))
                print(f"hyperbolicity modes written to {path}")
    except (CaseError, ValueError, RuntimeError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
