"""Cost of a radial (axisymmetric) run against a planar run of the same cells.

Both models run a smooth wave on a layer that is wet everywhere (every cell is visited in
every step, so the two runs do the same number of cell updates up to their time steps):
a Gaussian hump of 0.1 m at 1 m on a 0.5 m layer, frictionless, walls, 2000 cells on
[0, 2] m, to t = 0.3 s, once on a ``CartesianGrid`` and once on py-pde's ``PolarSymGrid``,
with the compiled fv-split stepper. The runs are interleaved (planar, radial, planar,
...) and the ratio is the median over rounds of ns per cell update radial / planar.

    python benchmarks/run_benchmarks.py --only geometry   # measure, then re-render
"""

from __future__ import annotations

import os
import statistics
import time
from typing import Any

import numpy as np

CELLS = 2000
T_END = 0.3
TARGET = 1.15
"""a radial cell update at most this many times a planar one"""


def _runner(model: str, geometry: str, reconstruction: str) -> Any:
    """A callable running the wave once; returns (steps, cells)."""
    from pde import CartesianGrid, PolarSymGrid
    from pde.trackers.base import FinishedSimulation

    import pdeflow
    from pdeflow import FVSplitSolver

    grid = (PolarSymGrid((0.0, 2.0), CELLS) if geometry == "axisymmetric"
            else CartesianGrid([[0.0, 2.0]], CELLS))
    x = grid.axes_coords[0]
    hump = 0.1 * np.exp(-((x - 1.0) / 0.2) ** 2)
    opts = {"bc": ("wall", "wall"), "reconstruction": reconstruction}
    if model == "single_layer":
        eq = pdeflow.SingleLayerGranular({"phi_b_deg": 1e-9}, **opts)
        state = eq.make_state(grid, h=0.5 + hump)
    else:
        eq = pdeflow.TwoLayerGranular({"phi_b_deg": 1e-9, "phi_int_deg": 1e-9, "k": 0.0,
                                       "c": 0.0, "exchange_closure": "none"}, **opts)
        state = eq.make_state(grid, h1=0.25 + hump, h2=0.25 + 0.5 * hump)

    def run() -> tuple[int, int]:
        solver = FVSplitSolver(eq, cfl=0.4, stop_at_rest=False)
        s = state.copy()
        stepper = solver.make_stepper(s)
        try:
            stepper(s, 0.0, T_END)
        except FinishedSimulation:  # pragma: no cover - it never comes to rest
            pass
        return int(solver.info["steps"]), CELLS

    return run


def measure(repeats: int = 7) -> dict[str, Any]:
    """ns per cell update of each model and reconstruction, planar and radial, and their
    ratio (medians over ``repeats`` interleaved rounds)."""
    rows = []
    for model in ("single_layer", "two_layer"):
        for reconstruction in ("first-order", "muscl"):
            runs = {g: _runner(model, g, reconstruction) for g in ("planar", "axisymmetric")}
            for run in runs.values():
                run()  # compile / load the kernels
            ns: dict[str, list[float]] = {g: [] for g in runs}
            for _ in range(repeats):
                for g, run in runs.items():
                    t0 = time.perf_counter()
                    steps, cells = run()
                    ns[g].append(1e9 * (time.perf_counter() - t0) / (steps * cells))
            ratios = [a / p for a, p in zip(ns["axisymmetric"], ns["planar"], strict=True)]
            rows.append({"model": model, "reconstruction": reconstruction,
                         "planar_ns": statistics.median(ns["planar"]),
                         "radial_ns": statistics.median(ns["axisymmetric"]),
                         "ratio": statistics.median(ratios), "repeats": repeats})
    return {"rows": rows, "load_avg": os.getloadavg(), "cells": CELLS, "t_end": T_END}


def render(data: dict[str, Any]) -> str:
    """The docs/performance.md section from :func:`measure`'s result."""
    load = data.get("load_avg")
    L = ["## Radial against planar\n",
         f"Measured by `python benchmarks/run_benchmarks.py --only geometry` "
         f"(`benchmarks/geometry_cost.py`): a smooth wave on a layer wet everywhere, "
         f"{data['cells']} cells, to t = {data['t_end']} s, the compiled fv-split "
         f"stepper, on a `CartesianGrid` and on py-pde's `PolarSymGrid` with the same "
         f"cells; runs interleaved, medians over {data['rows'][0]['repeats']} rounds"
         + (f", load average {load[0]:.1f} on 2 cores" if load else "") + ". Target: a "
         f"radial cell update at most {TARGET}x a planar one.\n",
         "| model | reconstruction | planar [ns / cell update] | radial [ns / cell update] "
         "| radial / planar | target |",
         "|---|---|---:|---:|---:|---|"]
    for r in data["rows"]:
        met = "met" if r["ratio"] <= TARGET else f"missed ({r['ratio']:.2f}x)"
        L.append(f"| {r['model']} | {r['reconstruction']} | {r['planar_ns']:.1f} | "
                 f"{r['radial_ns']:.1f} | {r['ratio']:.2f} | {met} |")
    return "\n".join(L) + "\n"
