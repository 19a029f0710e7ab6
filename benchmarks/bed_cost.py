"""Cost of a long erodible bed at rest: a collapse on a bed 10x longer than its run-out
against the same collapse on a bed just long enough.

The case is cases/erodible_bed.toml (two layers: the bed is the lower layer, at rest
ahead of the flow) at dx = 2 mm, first order and MUSCL. The short domain ends 0.1 m
beyond the deposit's front; the long one carries the bed ten times as far past the
column (L0 + 10 (L_short - L0)). Both runs take the same steps to rest (checked); the
fv-split loop visits only the live cells and their stencil
(:mod:`pdeflow.numerics.resting`), so the long bed should cost almost nothing. Runs
interleaved (short, long, short, ...), medians over rounds of the ratio of wall times of
the compiled run (``Run.execute`` without other trackers), once with the erosion series
off (the solver alone) and once on (the default of bed cases: frames of the whole state).

    python benchmarks/run_benchmarks.py --only bed   # measure, then re-render
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "erodible_bed.toml"
DX = 0.002
TARGET = 1.1
"""the long bed at most this many times the short one"""


def _case(length: float, reconstruction: str, series: str) -> Any:
    from pdeflow.cases import load_case

    extra = ["numerics.cfl=0.4"] if reconstruction == "muscl" else []
    return load_case(CASE, [f"grid.length={length}", f"grid.dx={DX}",
                            "output.snapshot_times=[]", "case.models=['two_layer']",
                            f"numerics.reconstruction='{reconstruction}'",
                            f"output.erosion_series='{series}'", *extra])


def _time(case: Any) -> tuple[float, dict[str, Any]]:
    from pdeflow.simulate import Run

    run = Run(case, "two_layer")
    t0 = time.perf_counter()
    res = run.execute(None)
    return time.perf_counter() - t0, res.summary


def measure(repeats: int = 7) -> dict[str, Any]:
    """Wall times of the short and the long bed per reconstruction (medians over
    ``repeats`` interleaved rounds) and their ratio."""
    rows = []
    for reconstruction, series in (("first-order", "off"), ("muscl", "off"),
                                   ("first-order", "on"), ("muscl", "on")):
        probe = _case(3.0, reconstruction, series)
        _, s = _time(probe)  # compiles or loads the kernels; finds the front
        L0 = probe.L0
        short = round(s["front_position"] + 0.1, 3)
        long = round(L0 + 10 * (short - L0), 3)
        cases = {"short": _case(short, reconstruction, series),
                 "long": _case(long, reconstruction, series)}
        walls: dict[str, list[float]] = {k: [] for k in cases}
        summaries = {}
        for _ in range(repeats):
            for k, case in cases.items():
                wall, summaries[k] = _time(case)
                walls[k].append(wall)
        if summaries["short"]["steps"] != summaries["long"]["steps"]:
            raise RuntimeError("the long bed changed the run: "
                               f"{summaries['short']['steps']} against "
                               f"{summaries['long']['steps']} steps")
        ratios = [b / a for a, b in zip(walls["short"], walls["long"], strict=True)]
        rows.append({"reconstruction": reconstruction, "series": series,
                     "short_m": short, "long_m": long,
                     "cells_short": cases["short"].cells, "cells_long": cases["long"].cells,
                     "steps": summaries["short"]["steps"],
                     "runout_m": summaries["short"]["runout"],
                     "short_ms": 1e3 * statistics.median(walls["short"]),
                     "long_ms": 1e3 * statistics.median(walls["long"]),
                     "ratio": statistics.median(ratios), "repeats": repeats})
    return {"rows": rows, "load_avg": os.getloadavg(), "dx": DX}


def render(data: dict[str, Any]) -> str:
    """The docs/performance.md section from :func:`measure`'s result."""
    load = data.get("load_avg")
    L = ["## A long erodible bed at rest\n",
         "Measured by `python benchmarks/run_benchmarks.py --only bed` "
         "(`benchmarks/bed_cost.py`): cases/erodible_bed.toml with two layers (the bed "
         f"is their lower layer, at rest ahead of the flow), dx = {data['dx'] * 1e3:g} mm, "
         "on a domain ending 0.1 m past the deposit's front and on one carrying the bed "
         "ten times as far past the column; the same steps to rest; runs interleaved, "
         f"medians over {data['rows'][0]['repeats']} rounds"
         + (f", load average {load[0]:.1f} on 2 cores" if load else "") + ". The loop "
         "visits only moving or changing cells and their stencil "
         "(`pdeflow/numerics/resting.py`); the time step is that of a full sweep, so the "
         f"results are identical bit for bit. Target: the long bed at most {TARGET}x. "
         "Rows with the erosion series on add what a bed case records by default "
         "(`output.erosion_series`: a frame of the whole state every t_end/200, for "
         "the diagnostics of docs/erodible_bed.md): copies of every cell, so they grow "
         "with the domain; a run that needs no time series turns it off.\n",
         "| reconstruction | erosion series | run-out [m] | steps | short bed [m] | cells "
         "| wall [ms] | long bed [m] | cells | wall [ms] | long / short | target |",
         "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in data["rows"]:
        met = "met" if r["ratio"] <= TARGET else f"missed ({r['ratio']:.2f}x)"
        L.append(f"| {r['reconstruction']} | {r.get('series', 'on')} | "
                 f"{r['runout_m']:.3g} | {r['steps']} | "
                 f"{r['short_m']:g} | {r['cells_short']} | {r['short_ms']:.3g} | "
                 f"{r['long_m']:g} | {r['cells_long']} | {r['long_ms']:.3g} | "
                 f"{r['ratio']:.2f} | {met} |")
    return "\n".join(L) + "\n"
