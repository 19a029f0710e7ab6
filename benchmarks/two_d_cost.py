"""What a cell update costs on a 2D grid (issue 36's performance targets).

Set-up: a circular dam of radius L/4 and depth 1 m in the middle of an L x L box of
material 0.5 m deep (L = 2 m, walls on every side) on a plane inclined at THETA = 45
deg along x, steeper than every friction angle (the paper's phi_b is 41 deg), so every
cell is wet and moving and none is skipped (neither dry nor at rest): the cost per cell
update is the scheme's alone. The single layer has Coulomb friction with phi_b = 20
deg, the two layers the paper's parameters with 40 % of the depth upper layer. Each run
goes to ``T_END`` with fv-split (Lie) through its stepper (no py-pde controller),
hll/first-order, CFL 0.9. Cost = wall time / (steps x cells).

Rows (each the median over ``--repeats`` interleaved rounds, one process):
- pdeflow's 2D single layer against the hand-written 2D loop of :mod:`baseline_2d`
  (which must reproduce pdeflow's depths: their largest difference is printed);
- pdeflow's 1D single layer on the same set-up's section through the dam (n^2 cells
  of the same dx, so that the arrays are as large);
- pdeflow's 2D two layers against its 2D single layer, and the 1D two layers on the
  section (the same ratio in 1D, for comparison).
``--memory N`` runs an N x N single-layer run in a fresh process and prints its peak
resident memory: 5 steps in one call of the stepper (the state between outputs), and
6 calls 0.5 ms apart (3 outputs, each between the states before and after a step).

Run: ``python benchmarks/two_d_cost.py [--cells 256] [--repeats 5] [--memory 1000]``
(``--memory 1000 --memory-only``: the peak memory alone, which the machine's load does
not change).
"""

from __future__ import annotations

import argparse
import math
import statistics
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from suite import interleaved_walls  # noqa: E402

SIDE = 2.0  #: the box's side [m]
T_END = 0.3  #: [s]
THETA = 45.0  #: the plane's slope along x [deg]
CFL = 0.9
SCHEME = "hll/first-order"
PHI_B = 20.0  #: the single layer's basal friction angle [deg]
WALLS = (("wall", "wall"), ("wall", "wall"))


def dam(r: np.ndarray) -> np.ndarray:
    """Total depth [m] at distance ``r`` [m] from the box's centre."""
    return np.where(r < SIDE / 4, 1.0, 0.5)


def stepper_run(eq: Any, state: Any, t_end: float = T_END, cfl: float = CFL,
                threads: int = 1) -> Callable[[], dict[str, Any]]:
    """A callable running ``eq`` from ``state`` to ``t_end`` [s] with fv-split's stepper
    (Lie splitting) at Courant number ``cfl`` on ``threads`` threads."""
    from pde.trackers.base import FinishedSimulation

    from pdeflow import FVSplitSolver

    def run() -> dict[str, Any]:
        solver = FVSplitSolver(eq, cfl=cfl, splitting="lie", threads=threads)
        s = state.copy()
        try:
            solver.make_stepper(s)(s, 0.0, t_end)
        except FinishedSimulation:  # at rest before t_end (as the baseline stops)
            pass
        return {"steps": int(solver.info["steps"]), "data": s.data,
                "cells": s.data.shape[-1] if s.data.ndim == 2 else s.grid.num_cells}

    return run


def setups_2d(n: int) -> tuple[np.ndarray, dict[str, tuple[Any, Any]]]:
    """The dam's depth [m] on n x n cells and the two models' (PDE, initial state) on
    it: "single layer", "two layers" (the material split 0.4 / 0.6 into h1 / h2)."""
    from pde import CartesianGrid

    import pdeflow

    grid = CartesianGrid([[0, SIDE], [0, SIDE]], [n, n])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    h = dam(np.hypot(x - SIDE / 2, y - SIDE / 2))
    one = pdeflow.SingleLayerGranular(theta_deg=THETA, phi_b_deg=PHI_B, scheme=SCHEME,
                                      bc=WALLS)
    two = pdeflow.TwoLayerGranular(theta_deg=THETA, scheme=SCHEME, bc=WALLS)
    return h, {"single layer": (one, one.make_state(grid, h=h)),
               "two layers": (two, two.make_state(grid, h1=0.4 * h, h2=0.6 * h))}


def runs(n: int) -> dict[str, Callable[[], Any]]:
    """The timed runs on n x n cells (and the 1D one on n^2 cells)."""
    import baseline_2d
    from pde import CartesianGrid

    import pdeflow

    h, setups = setups_2d(n)
    one = setups["single layer"][0]
    dx = SIDE / n
    line = CartesianGrid([[0, dx * n * n]], [n * n])
    h1d = dam(np.abs(line.axes_coords[0] - dx * n * n / 2))
    one_1d = pdeflow.SingleLayerGranular(theta_deg=THETA, phi_b_deg=PHI_B, scheme=SCHEME,
                                         bc=("wall", "wall"))
    two_1d = pdeflow.TwoLayerGranular(theta_deg=THETA, scheme=SCHEME, bc=("wall", "wall"))
    P = one.parameters
    theta = math.radians(THETA)
    g_z, g_x = P.g * math.cos(theta), P.g * math.sin(theta)
    tan_b = math.tan(math.radians(PHI_B))

    def base() -> dict[str, Any]:
        hb, zero = h.copy(), np.zeros_like(h)
        m, v = zero.copy(), zero.copy()
        _, steps = baseline_2d.run_to_rest(hb, m, v, dx, dx, T_END, g_z, g_x, tan_b, CFL,
                                           np.ones(4, dtype=np.bool_), P.dry_tolerance)
        return {"steps": steps, "data": np.stack([hb, m, v]), "cells": n * n}

    return {"single 2D": stepper_run(*setups["single layer"]),
            "baseline 2D": base,
            "single 1D": stepper_run(one_1d, one_1d.make_state(line, h=h1d)),
            "two layers 2D": stepper_run(*setups["two layers"]),
            "two layers 1D": stepper_run(two_1d, two_1d.make_state(line, h1=0.4 * h1d,
                                                                   h2=0.6 * h1d))}


def measure(n: int, repeats: int) -> dict[str, dict[str, float]]:
    """ns per cell update of each run (median), its steps, and the baseline's largest
    depth difference from pdeflow's single layer [m]."""
    fns = runs(n)
    first = {k: fn() for k, fn in fns.items()}  # also the warm-up (compilation)
    walls = interleaved_walls(list(fns.values()), repeats)
    out = {}
    for (key, o), w in zip(first.items(), walls, strict=True):
        out[key] = {"steps": o["steps"], "cells": o["cells"],
                    "ns_per_update": 1e9 * statistics.median(w) / (o["steps"] * o["cells"])}
    h2d = first["single 2D"]["data"][0].reshape(n, n)
    out["baseline 2D"]["max_depth_diff"] = float(np.abs(first["baseline 2D"]["data"][0]
                                                        - h2d).max())
    return out


MEMORY_SCRIPT = """
import resource, sys
import numpy as np
from pde import CartesianGrid
import pdeflow
from pdeflow import FVSplitSolver
n = int(sys.argv[1])
grid = CartesianGrid([[0, 2.0], [0, 2.0]], [n, n])
x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
h = np.where(np.hypot(x - 1.0, y - 1.0) < 0.5, 1.0, 0.5)
eq = pdeflow.SingleLayerGranular(theta_deg=45.0, phi_b_deg=20.0, scheme="hll/first-order",
                                 bc=(("wall", "wall"), ("wall", "wall")))
state = eq.make_state(grid, h=h)
del x, y, h
if sys.argv[2] == "outputs":  # interpolated outputs: a step ahead of each is kept
    solver = FVSplitSolver(eq, cfl=0.9, t_end=1.0)
    stepper = solver.make_stepper(state)
    t = 0.0
    for k in range(6):
        t = stepper(state, t, t + 0.0005)
else:
    solver = FVSplitSolver(eq, cfl=0.9, max_steps=5)
    stepper = solver.make_stepper(state)
    try:
        stepper(state, 0.0, 1.0)
    except Exception as err:  # max_steps ends the run
        print("ended:", type(err).__name__, file=sys.stderr)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def peak_memory_mb(n: int, outputs: bool = False) -> float:
    """Peak resident memory [MB] of a fresh process running 5 steps on n x n cells
    (``outputs``: 6 calls 0.5 ms apart, about 10 steps, with interpolated outputs)."""
    out = subprocess.run([sys.executable, "-c", MEMORY_SCRIPT, str(n),
                          "outputs" if outputs else "steps"], check=True,
                         capture_output=True, text=True)
    return float(out.stdout.strip().splitlines()[-1])


def print_memory(n: int) -> None:
    """Print both peak memories of an n x n run."""
    print(f"peak memory, {n} x {n} single layer: {peak_memory_mb(n):.0f} MB "
          f"(target < 300); with interpolated outputs {peak_memory_mb(n, True):.0f} MB")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=256, help="cells per side (n)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--memory", type=int, default=0,
                    help="also the peak memory of an N x N run (0: not measured)")
    ap.add_argument("--memory-only", action="store_true",
                    help="the peak memory alone (--memory N), no timings")
    args = ap.parse_args()
    if args.memory_only:
        print_memory(args.memory)
        return
    rows = measure(args.cells, args.repeats)
    print(f"{args.cells} x {args.cells} cells, t = {T_END} s, {SCHEME}, "
          f"median of {args.repeats}")
    print(f"{'run':<16}{'steps':>7}{'ns/update':>11}")
    for key, r in rows.items():
        print(f"{key:<16}{r['steps']:>7}{r['ns_per_update']:>11.1f}")
    ns = {k: r["ns_per_update"] for k, r in rows.items()}
    print(f"single 2D / baseline 2D: {ns['single 2D'] / ns['baseline 2D']:.2f} "
          f"(target <= 1.3; depths differ by at most "
          f"{rows['baseline 2D']['max_depth_diff']:.2g} m)")
    print(f"single 2D / single 1D:   {ns['single 2D'] / ns['single 1D']:.2f} "
          f"(target <= 2.2)")
    print(f"two layers / single 2D:  {ns['two layers 2D'] / ns['single 2D']:.2f} "
          f"(target <= 3.5; in 1D {ns['two layers 1D'] / ns['single 1D']:.2f})")
    if args.memory:
        print_memory(args.memory)


if __name__ == "__main__":
    main()
