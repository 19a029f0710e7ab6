"""The one Study under every study: points, a measure, and a pluggable executor (this
process, a process pool, Dask)."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

from pdeflow.analysis.convergence import converge
from pdeflow.analysis.points import Point
from pdeflow.analysis.sweep import run_sweep
from pdeflow.cases import load_case
from pdeflow.study.core import Study, dask_cluster, pool_executor, serial

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


def _square(point: Point) -> dict:
    """A measure that fails on the label i = 3 (module level: it must pickle)."""
    if point.labels["i"] == 3:
        raise ValueError("no three")
    return {"square": point.labels["i"] ** 2}


def _failed(point: Point, err: Exception) -> dict:
    return {"error": str(err)}


def test_a_failing_point_raises_or_gives_the_failed_row():
    """(Five points on one worker: one point per batch, so only the point fails.)"""
    case = load_case(ROOT / "cases" / "ritter_dam_break.toml")
    points = [Point(case, "single_layer", None, {"i": i}) for i in range(5)]
    with pytest.raises(ValueError, match="no three"):
        Study(points, _square).execute()
    rows = Study(points, _square, failed=_failed).execute()
    assert rows == [{"i": 0, "square": 0}, {"i": 1, "square": 1}, {"i": 2, "square": 4},
                    {"i": 3, "error": "no three"}, {"i": 4, "square": 16}]


def test_rows_arrive_batch_by_batch_and_come_back_in_order():
    """Many short points on two processes: batched, every row handed over once as it
    arrives, and the rows returned in the order of the points."""
    case = load_case(ROOT / "cases" / "ritter_dam_break.toml")
    points = [Point(case, "single_layer", None, {"i": i}) for i in range(200) if i != 3]
    seen: list[dict] = []
    with ProcessPoolExecutor(2) as pool:
        run = Study(points, _square).run(pool_executor(pool, 2), on_rows=seen.extend)
    assert run.complete
    assert run.rows == [{"i": p.labels["i"], "square": p.labels["i"] ** 2} for p in points]
    assert sorted(r["i"] for r in seen) == [p.labels["i"] for p in points]


def test_a_dask_cluster_gives_the_serial_results():
    pytest.importorskip("distributed")
    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml",
                     ["case.models=['two_layer']", "case.t_end=0.3", "grid.dx=0.1",
                      "output.snapshot_times=[]"])
    with dask_cluster(workers=2) as executor:
        assert executor.workers == 2
        par = converge(case, 2, volume_times=(0.1,), executor=executor)
    ser = converge(case, 2, volume_times=(0.1,))
    assert _no_walls(par["levels"]) == _no_walls(ser["levels"])
