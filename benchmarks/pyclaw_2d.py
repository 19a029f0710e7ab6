"""pdeflow against PyClaw (Clawpack) on a frictionless 2D dam break (issue 36).

Issue 36's target: per cell update, pdeflow's 2D single layer at least 2x faster than
PyClaw's 2D shallow-water solver (classic, first order) at equal grid.

Set-up, the same for both codes: a circular dam of radius ``RADIUS`` = 0.5 m and depth
``H0`` = 1 m in the middle of a 2 m x 2 m box with walls on every side, on a horizontal
plane, g = 9.81 m/s^2, run to ``T_END`` = 0.3 s (the bore reaches the middle of the
walls at about 0.1 s, the corners before 0.3 s: pdeflow, 128^2). PyClaw cannot
represent dry cells, so the 'dry' side carries a film of ``FILM`` = 1e-3 H0 in both
codes.

- **PyClaw**: ``ClawSolver2D`` with the Fortran HLLE Riemann solver
  ``riemann.shallow_hlle_2D`` (Einfeldt's speeds), first order (Godunov, no limiter),
  unsplit without transverse waves (donor cell: both axes' fluctuations from the same
  state, as pdeflow's advection stage), variable dt aiming at the Courant number
  ``CFL / 2`` per axis (steps above ``CFL_MAX_PYCLAW`` = 0.5, the donor cell's limit,
  are redone), walls. Its first dt is the CFL step of the initial state.
- **pdeflow**: ``SingleLayerGranular`` with friction off (phi_b = 1e-9 deg, as the
  Ritter-at-an-angle check of docs/two_d.md), hll/first-order (Davis' speeds), fv-split
  (Lie) through its stepper at ``CFL`` = 0.9, which bounds the *sum* of the two axes'
  Courant numbers (dt = 0.9 dx / (2 max|S|)): the same dt rule as PyClaw's 0.45 per
  axis. Two rows: *pdeflow* (the state at rest, as pdeflow runs it: film cells the
  flow has not reached are at rest and not visited, :mod:`pdeflow.numerics.resting`)
  and *pdeflow, every cell*: everything drifts at ``DRIFT`` = 1e-9 m/s along x (3e-10
  m by T_END), so that every cell is live and visited in every step, as PyClaw visits
  them. The drift also turns off pdeflow's rule for faces with no momentum on either
  side (no mass fluctuation: :mod:`pdeflow.numerics.hll`, what keeps a Coulomb heap at
  rest), which holds the dam's mass back for the first step; PyClaw has no such rule,
  so this row is the like-with-like one, in its work and in its scheme.

A cell update is one cell of the grid advanced by one step of that code (its own step
count). The runs are called once first (numba compilation, PyClaw's imports), then
timed in interleaved rounds (PyClaw, pdeflow, pdeflow every cell, ...) in one process;
medians. The codes are checked to solve the same problem: the L1 difference of their
final depths, mean |h_pdeflow - h_PyClaw| / H0 over the cells, is printed (first order,
different wave-speed estimates and time steps: of the order of the schemes' error).

Run: ``python benchmarks/pyclaw_2d.py [--cells 128 256] [--repeats 5] [--t-end 0.3]``
(needs ``pip install clawpack``, which builds Fortran with gfortran; without it the
command prints one line saying so and exits with status 1).
Units: depths [m], lengths [m], times [s], speeds [m/s].
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pyclaw_run  # noqa: E402
from doc_tables import md_table, verdict  # noqa: E402
from suite import interleaved_walls  # noqa: E402
from two_d_cost import stepper_run  # noqa: E402

SIDE = 2.0  #: the box's side [m], centred on the origin
H0 = 1.0  #: the dam's depth [m]
RADIUS = 0.5  #: the dam's radius [m]
FILM = 1e-3 * H0  #: depth of the film outside the dam [m], both codes
DRIFT = 1e-9  #: the film's velocity along x in pdeflow's 'every cell' row [m/s]
T_END = 0.3  #: [s]
G = 9.81  #: gravity [m/s^2]
CFL = 0.9  #: pdeflow's Courant number (bounds the sum over the two axes)
CFL_MAX_PYCLAW = 0.5  #: PyClaw redoes steps above this Courant number per axis
PHI_B = 1e-9  #: pdeflow's basal friction angle [deg]: friction off
SCHEME = "hll/first-order"
RIEMANN = "shallow_hlle_2D"  #: PyClaw's Riemann solver (clawpack.riemann)
TARGET = 2.0  #: issue 36: PyClaw's cost per cell update over pdeflow's, at least


def initial_depth(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Depth [m] at the cell centres ``x, y`` [m]: H0 inside the dam, the film outside."""
    return np.where(np.hypot(x, y) < RADIUS, H0, FILM)


def pyclaw_dam(n: int, t_end: float = T_END) -> dict[str, Any]:
    """PyClaw's run on n x n cells: {"wall" [s], "steps", "h" (n, n) [m]}."""
    from clawpack import pyclaw, riemann

    solver = pyclaw.ClawSolver2D(getattr(riemann, RIEMANN))
    pyclaw_run.first_order(solver, CFL / 2, CFL_MAX_PYCLAW)
    solver.dimensional_split = False
    solver.transverse_waves = 0  # donor cell (HLLE's transverse solver is a dummy)
    for side in (solver.bc_lower, solver.bc_upper):
        side[0] = side[1] = pyclaw.BC.wall
    dims = [pyclaw.Dimension(-SIDE / 2, SIDE / 2, n, name=a) for a in ("x", "y")]
    domain = pyclaw.Domain(dims)
    state = pyclaw.State(domain, 3)
    state.problem_data["grav"] = G
    x, y = state.p_centers
    state.q[0] = initial_depth(x, y)
    state.q[1:] = 0.0
    solver.dt_initial = (CFL / 2) * (SIDE / n) / math.sqrt(G * H0)
    wall, q, steps = pyclaw_run.run_controller(state, domain, solver, t_end)
    return {"wall": wall, "steps": steps, "h": q[0]}


def pdeflow_runs(n: int, t_end: float = T_END) -> dict[str, Callable[[], dict[str, Any]]]:
    """pdeflow's runs on n x n cells: the film at rest, and drifting (every cell)."""
    from pde import CartesianGrid

    import pdeflow

    half = SIDE / 2
    grid = CartesianGrid([[-half, half], [-half, half]], [n, n])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    h = initial_depth(x, y)
    eq = pdeflow.SingleLayerGranular(theta_deg=0.0, phi_b_deg=PHI_B, g=G, scheme=SCHEME,
                                      bc=(("wall", "wall"), ("wall", "wall")))
    drift = np.full_like(h, DRIFT)
    return {"pdeflow": stepper_run(eq, eq.make_state(grid, h=h), t_end, CFL),
            "pdeflow, every cell": stepper_run(eq, eq.make_state(grid, h=h, u=drift),
                                               t_end, CFL)}


PDEFLOW_ROWS = ("pdeflow", "pdeflow, every cell")
CELLS = (128, 256)  #: the grids (cells per side) of the performance doc's section


def measure_grid(n: int, repeats: int, t_end: float = T_END) -> dict[str, Any]:
    """Each run's steps and ns per cell update (median over ``repeats`` interleaved
    rounds), the median over rounds of PyClaw's time over each pdeflow run's per cell
    update, on n x n cells, and the L1 differences of the final depths / H0."""
    fns: dict[str, Callable[[], Any]] = {"PyClaw": lambda: pyclaw_dam(n, t_end)}
    fns.update(pdeflow_runs(n, t_end))
    first = {k: fn() for k, fn in fns.items()}  # also the warm-up (compilation)
    walls = dict(zip(fns, interleaved_walls(list(fns.values()), repeats), strict=True))
    ns = {k: [1e9 * w / (first[k]["steps"] * n * n) for w in walls[k]] for k in fns}
    rows = {k: {"steps": first[k]["steps"], "ns_per_update": statistics.median(ns[k])}
            for k in fns}
    for k in PDEFLOW_ROWS:
        rows[k]["round_ratio"] = statistics.median(
            c / p for c, p in zip(ns["PyClaw"], ns[k], strict=True))
    depth = {"PyClaw": first["PyClaw"]["h"]}
    depth.update({k: first[k]["data"][0].reshape(n, n) for k in PDEFLOW_ROWS})
    l1 = {k: float(np.abs(depth[k] - depth["PyClaw"]).mean() / H0) for k in PDEFLOW_ROWS}
    l1["film at rest vs every cell"] = float(
        np.abs(depth["pdeflow"] - depth["pdeflow, every cell"]).mean() / H0)
    return {"cells": n, "repeats": repeats, "t_end": t_end, "rows": rows, "l1": l1}


def ratio(grid: dict[str, Any], key: str = "pdeflow, every cell") -> float:
    """PyClaw's ns per cell update over pdeflow's (row ``key``) on one grid (medians)."""
    return grid["rows"]["PyClaw"]["ns_per_update"] / grid["rows"][key]["ns_per_update"]


def measure(repeats: int = 5, cells: tuple[int, ...] = CELLS) -> dict[str, Any]:
    """The performance doc's measurement: :func:`measure_grid` on each grid of ``cells``
    with the machine's load average before and after; ``{"available": False}`` without
    clawpack."""
    if not pyclaw_run.available(RIEMANN):
        return {"available": False}
    load_start = os.getloadavg()
    grids = [measure_grid(n, repeats) for n in cells]
    return {"available": True, "grids": grids, "repeats": repeats, "t_end": T_END,
            "date": time.strftime("%Y-%m-%d"), "load_avg": [load_start, os.getloadavg()]}


def target_row(data: dict[str, Any]) -> str:
    """The targets table's row: the like-with-like ratio on each grid."""
    name = "2D single layer >= 2x faster than PyClaw per cell update"
    if not data.get("available"):
        return f"| {name} | clawpack not installed | n/a |"
    ratios = {g["cells"]: ratio(g) for g in data["grids"]}
    text = ", ".join(f"{r:.2f}x ({n}^2)" for n, r in ratios.items())
    return (f"| {name} | {text} (see *Against PyClaw in 2D*) | "
            f"{verdict(min(ratios.values()) >= TARGET)} |")


def render(data: dict[str, Any]) -> str:
    """The docs/performance.md section from :func:`measure`'s result."""
    L = ["## Against PyClaw in 2D\n"]
    if not data.get("available"):
        return "\n".join(L + ["clawpack is not installed: not measured.\n"])
    (l0, l1), reps = data["load_avg"], data["repeats"]
    L.append(f"Measured by `python benchmarks/run_benchmarks.py --only pyclaw2d` "
             f"(`benchmarks/pyclaw_2d.py`, whose docstring gives the set-up; "
             f"`python benchmarks/pyclaw_2d.py --cells 128 256` prints such a table "
             f"without storing it) on "
             f"{data['date']}: a circular dam (H0 = {H0:g} m, radius {RADIUS:g} m) in a "
             f"{SIDE:g} m x {SIDE:g} m box with walls, horizontal, frictionless, a film of "
             f"{FILM / H0:g} H0 outside the dam in both codes, t = {data['t_end']} s. "
             f"PyClaw: classic `{RIEMANN}` (HLLE), first order, unsplit without "
             f"transverse waves, CFL {CFL / 2:g} per axis; pdeflow: {SCHEME}, fv-split at "
             f"CFL {CFL:g} over both axes (the same dt rule). *every cell*: the state "
             f"drifts at {DRIFT:g} m/s, so that pdeflow visits every cell in every step "
             f"and runs the flux without its rule for faces at rest, as PyClaw does; "
             f"*pdeflow* is the state at rest, whose film cells ahead of the bore are not "
             f"visited. Compiled first, then {reps} interleaved rounds in one process, "
             f"medians; 2 cores shared with other jobs, 1-min load average "
             f"{l0[0]:.1f} at the start, {l1[0]:.1f} at the end. Target (issue 36): "
             f"PyClaw / pdeflow >= {TARGET:g} per cell update.\n")
    rows = []
    for g in data["grids"]:
        r, n = g["rows"], g["cells"]
        rows.append(f"| {n}^2 | PyClaw | {r['PyClaw']['steps']} | "
                    f"{r['PyClaw']['ns_per_update']:.1f} | | | |")
        for k in PDEFLOW_ROWS:
            rows.append(f"| {n}^2 | {k} | {r[k]['steps']} | {r[k]['ns_per_update']:.1f} | "
                        f"{ratio(g, k):.2f} ({r[k]['round_ratio']:.2f}) | "
                        f"{g['l1'][k]:.2e} | {verdict(ratio(g, k) >= TARGET)} |")
    L += md_table(["cells", "run", "steps", "ns per cell update",
                   "PyClaw / pdeflow (median of rounds)", "L1 depth vs PyClaw / H0",
                   "target"], "llrrrrl", rows)
    diffs = " to ".join(f"{g['l1']['pdeflow, every cell']:.2e} ({g['cells']}^2)"
                        for g in data["grids"])
    L.append(f"\nThe L1 difference of the depths falls from {diffs} as the grid is "
             f"refined: two first-order schemes (Einfeldt's against Davis' wave speeds) "
             f"converging to one solution. The target row of *Targets* is the every-cell "
             f"ratio on each grid.")
    return "\n".join(L) + "\n"


def report(m: dict[str, Any]) -> list[str]:
    """The printed lines of one grid's measurement."""
    n, rows = m["cells"], m["rows"]
    lines = [f"{n} x {n} cells, t = {m['t_end']} s, median of {m['repeats']} rounds",
             f"{'run':<22}{'steps':>7}{'ns/update':>11}"]
    lines += [f"{k:<22}{r['steps']:>7}{r['ns_per_update']:>11.1f}" for k, r in rows.items()]
    for key in PDEFLOW_ROWS:
        met = "met" if ratio(m, key) >= TARGET else "missed"
        lines.append(f"PyClaw / {key}: {ratio(m, key):.2f} (target >= {TARGET:g}: {met}); "
                     f"L1 depth difference / H0 {m['l1'][key]:.2e}")
    lines.append(f"pdeflow film at rest vs every cell: L1 / H0 "
                 f"{m['l1']['film at rest vs every cell']:.1e}")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, nargs="+", default=list(CELLS),
                    help="cells per side (n x n grids), one or more")
    ap.add_argument("--repeats", type=int, default=5, help="interleaved rounds (>= 1)")
    ap.add_argument("--t-end", type=float, default=T_END, help="end time [s] (> 0)")
    args = ap.parse_args()
    if min(args.cells) < 4:
        ap.error(f"--cells must be >= 4, got {min(args.cells)}")
    if args.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")
    if not args.t_end > 0:
        ap.error(f"--t-end must be > 0 s, got {args.t_end}")
    if not pyclaw_run.available(RIEMANN):
        sys.exit(f"pyclaw_2d: {pyclaw_run.NEEDS_CLAWPACK}")
    print(f"PyClaw {RIEMANN} (classic, first order, unsplit, CFL {CFL / 2:g} per axis) "
          f"against pdeflow {SCHEME} (fv-split, CFL {CFL:g} over both axes)")
    for n in args.cells:
        print("\n".join(report(measure_grid(n, args.repeats, args.t_end))))


if __name__ == "__main__":
    main()
