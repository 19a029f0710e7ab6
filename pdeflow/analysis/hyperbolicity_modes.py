"""Cost and effect of the hyperbolicity modes (exact, bound, none) on a two-layer case."""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..cases import PAPER_MODEL, Case
from ..simulate import Run
from ..variant import HYPERBOLICITY, Variant
from .points import case_on_grid, resolve_case


def hyperbolicity_study(case_path: str | Path | Case,
                        modes: Sequence[str] = HYPERBOLICITY,
                        grids: Sequence[float | int] | None = None, repeats: int = 3,
                        log: Any = None) -> list[dict[str, Any]]:
    """Cost and effect of the hyperbolicity modes on the two-layer model of a case.

    Each mode runs the case to rest (or t_end) with :func:`pdeflow.simulate.run_model`
    once to warm up and ``repeats`` times; rows give the median wall time [s], steps,
    ``max_fextra_over_rho1`` [m^2/s^2], ``hyperbolicity_events`` (cell-steps in which
    F_extra was applied), ``hyperbolicity_bisections`` (of those, how many needed the
    bisection fallback; on a 2D grid every search along du counts), stop times [s]
    and run-out [m]; on a 2D grid also ``cells_y`` and ``dy`` [m].
    """
    base = resolve_case(case_path)
    rows = []
    for gr in list(grids or [base.dx]):
        for mode in modes:
            c = case_on_grid(base, gr, Variant(hyperbolicity=mode))
            run = Run(c, PAPER_MODEL)
            run.execute()  # warm-up (compiles once per process)
            walls, s = [], {}
            for _ in range(max(1, repeats)):
                res = run.execute()
                walls.append(res.summary["wall_time_s"])
                s = res.summary
            row = {"mode": mode, "cells": c.cells, "dx": c.dx,
                   **({"cells_y": c.cells_y, "dy": c.dy} if c.is_2d else {}),
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
