"""docs/performance.md's section on a real avalanche path over its DEM (issue 37).

``python benchmarks/run_benchmarks.py --only terrain`` with ``PDEFLOW_AVAFRAME`` set to
a checkout of AvaFrame's repository (its DEMs are not copied here): AvaFrame's avaHit
(a 5 m DEM, 525 x 445 cells) run by the single layer over its bed on 2 threads
(:func:`real_path.measure_path`: Coulomb 20 deg, the release shapefile's 1 m slope-normal,
to rest or until the kinetic energy falls below 1 % of its peak, com1DFA's rule); the
wall time is the median over the repeats (at most 3: a run takes minutes), the load
average beside it.
"""

from __future__ import annotations

import os
import statistics
from pathlib import Path
from typing import Any

from real_path import measure_path

PATHS = ("avaHit",)
"""AvaFrame's paths measured"""
MAX_REPEATS = 3


def measure(repeats: int = 3) -> dict[str, Any]:
    """The runs of :data:`PATHS` (medians of the wall times over ``repeats``, at most
    :data:`MAX_REPEATS`)."""
    root = os.environ.get("PDEFLOW_AVAFRAME")
    if not root:
        raise RuntimeError("set PDEFLOW_AVAFRAME to a checkout of AvaFrame's repository")
    rows = []
    for path in PATHS:
        runs = [measure_path(Path(root), path) for _ in range(min(repeats, MAX_REPEATS))]
        row = {k: v for k, v in runs[-1].items() if not k.startswith("_")}
        row["walls_s"] = [r["wall_s"] for r in runs]
        row["wall_s"] = statistics.median(row["walls_s"])
        row["loads"] = [r["load_avg"][0] for r in runs]
        rows.append(row)
    return {"rows": rows}


def render(data: dict[str, Any]) -> str:
    """The section from :func:`measure`'s result."""
    L = ["## A real avalanche path over its DEM\n",
         "Measured by `PDEFLOW_AVAFRAME=PATH python benchmarks/run_benchmarks.py --only "
         "terrain` (`benchmarks/terrain_path.py`, the runs of `benchmarks/real_path.py`; "
         "docs/terrain.md): AvaFrame's path on its DEM, the grid's corners on the DEM's "
         "cell centres, the single layer over the bed (Coulomb, the release shapefile's "
         "thickness slope-normal), fv-split on 2 threads, compiled before the timed run; "
         "the run ends at rest or when the kinetic energy has fallen below 1 % of its "
         "peak (com1DFA's stopping rule). Wall time: the median over the repeats; the "
         "load average (2 cores) at the end of each.\n",
         "| path | cells | dx [m] | released [m^3] | phi [deg] | ended | t [s] | steps "
         "| wall [s] | cell updates/s | load | travel angle [deg] | affected [ha] |",
         "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---|---:|---:|"]
    for r in data["rows"]:
        cells = r["cells"][0] * r["cells"][1]
        loads = ", ".join(f"{v:.1f}" for v in r["loads"])
        L.append(f"| {r['path']} | {r['cells'][0]} x {r['cells'][1]} | {r['dx']:.2f} | "
                 f"{r['volume_m3']:.3g} | {r['phi_deg']:g} | {r['ended']} | "
                 f"{r['t_end_s']:.0f} | {r['steps']} | {r['wall_s']:.1f} | "
                 f"{cells * r['steps'] / r['wall_s']:.3g} | {loads} | "
                 f"{r['travel_angle_deg']:.1f} | {r['affected_ha']:.0f} |")
    return "\n".join(L) + "\n"
