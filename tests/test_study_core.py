"""The Study under every study: points, a measure, and a pluggable executor."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from pdeflow.analysis.convergence import converge
from pdeflow.analysis.study import Point, Study, pool_executor, serial
from pdeflow.analysis.sweep import run_sweep
from pdeflow.cases import load_case

ROOT = Path(__file__).resolve().parents[1]


def _no_walls(rows):
    return [{k: v for k, v in r.items() if k != "wall_time_s"} for r in rows]


def _cells(point: Point) -> dict:
    return {"cells": point.case.cells, "variant": point.run().variant.name}


def test_rows_keep_the_order_and_labels_of_the_points():
    case = load_case(ROOT / "cases" / "ritter_dam_break.toml")
    points = [Point(case, "single_layer", None, {"i": i}) for i in range(3)]
    assert Study(points, _cells).execute(serial) == [
        {"i": i, "cells": 400, "variant": "hll/first-order"} for i in range(3)]


def test_a_process_pool_gives_the_serial_results():
    """Execution is pluggable: the same convergence study and sweep on two processes."""
    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml",
                     ["case.models=['two_layer']", "case.t_end=0.3", "grid.dx=0.1",
                      "output.snapshot_times=[]"])
    sweep = load_case(ROOT / "cases" / "collapse_sweep.toml",
                      ["grid.dx=0.05", "sweep.aspect_ratios=[1, 2]",
                       "case.models=['single_layer']"])
    with ProcessPoolExecutor(2) as pool:
        par = converge(case, 2, volume_times=(0.1,), executor=pool_executor(pool))
        par_sweep = run_sweep(sweep, executor=pool_executor(pool))
    ser = converge(case, 2, volume_times=(0.1,))
    assert _no_walls(par["levels"]) == _no_walls(ser["levels"])
    ser_sweep = run_sweep(sweep)["models"]["single_layer"]
    assert par_sweep["models"]["single_layer"]["points"] == ser_sweep["points"]
