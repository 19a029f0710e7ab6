"""Benchmark measurements of pdeflow (plain timing with medians; see docs/performance.md).

Every function returns plain dicts (JSON-ready) and is called by ``run_benchmarks.py``;
``test_benchmarks.py`` wraps a few of them for pytest-benchmark. Wall times are
``time.perf_counter`` seconds of compiled runs after a warm-up (numba compilation is
measured separately, in subprocesses with their own ``NUMBA_CACHE_DIR``). Ratios are
taken between runs interleaved in the same process (A B A B ...), medians over rounds,
because the machine is shared and noisy.

Units: times [s], lengths [m], rates [cell updates/s]; a *cell update* is one cell
advanced by one time step (cells of the whole grid x steps).
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASE_5_1 = ROOT / "cases" / "paper_5_1_dam_break.toml"
SWEEP_H0 = (0.2, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0)
"""column heights of the 5.2-like sweep [m] (L0 = 0.1 m: aspect ratios 2 to 30)"""
SWEEP_L0 = 0.1
SWEEP_DX = 0.01
BENCH_VARIANTS = ("hll/first-order", "rusanov/first-order", "ifcp/first-order",
                  "hll/muscl/minmod", "rusanov/muscl/minmod", "ifcp/muscl/mc",
                  "hll/first-order+strang", "hll/muscl/mc+strang")

if str(ROOT / "benchmarks") not in sys.path:
    sys.path.insert(0, str(ROOT / "benchmarks"))


def median_time(fn: Callable[[], Any], repeats: int = 5, min_total: float = 0.2,
                max_repeats: int = 50) -> tuple[float, list[float]]:
    """Median wall time [s] of ``fn()`` after one warm-up call (more repeats, up to
    ``max_repeats``, while the timed calls add up to less than ``min_total`` s)."""
    fn()
    walls: list[float] = []
    while len(walls) < repeats or (sum(walls) < min_total and len(walls) < max_repeats):
        t0 = time.perf_counter()
        fn()
        walls.append(time.perf_counter() - t0)
    return statistics.median(walls), walls


def interleaved_walls(fns: Sequence[Callable[[], Any]], repeats: int) -> list[list[float]]:
    """Wall times [s] of every ``fn`` over ``repeats`` rounds, the calls interleaved
    (A B C A B C ...) so that a change of the machine's load hits all of them alike
    (no warm-up: call each once before)."""
    walls: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, w in zip(fns, walls, strict=True):
            t0 = time.perf_counter()
            fn()
            w.append(time.perf_counter() - t0)
    return walls


# --- cases -----------------------------------------------------------------------------

def sweep_length(H0: float, L0: float = SWEEP_L0) -> float:
    """Domain length [m] of the sweep for a column H0 x L0 [m]: L0 + 3 H0 + 0.5,
    rounded up to 0.1 m (the single-layer run-out at phi_B = 30 deg is about 2.7 H0)."""
    return math.ceil((L0 + 3.0 * H0 + 0.5) * 10 - 1e-9) / 10


def sweep_case(H0: float, model: str, length: float | None = None,
               dx: float = SWEEP_DX, t_end: float = 20.0):
    """The 5.2-like collapse: the 5.1 case file with L0 = 0.1 m, height H0 [m]."""
    from pdeflow.cases import load_case

    length = length or sweep_length(H0)
    cells = round(length / dx)
    return load_case(CASE_5_1, [
        f"initial.L0={SWEEP_L0}", f"initial.H0={H0}", f"grid.length={length}",
        f"grid.cells={cells}", f"case.models=['{model}']", "output.snapshot_times=[]",
        f"case.t_end={t_end}"])


def fv_stepper_run(case: Any, model: str, t_end: float | None = None,
                   stop_at_rest: bool = True,
                   max_steps: int = 100_000_000) -> Callable[[], dict[str, Any]]:
    """A callable running ``model`` of ``case`` with the fv-split stepper directly
    (no py-pde controller), to ``t_end`` [s] or rest or ``max_steps`` steps: returns
    steps, final time, the final state, cells and dx."""
    from pde.trackers.base import FinishedSimulation

    from pdeflow import FVSplitSolver

    eq, state = case.make_state(model)
    t1 = float(case.t_end if t_end is None else t_end)

    def run() -> dict[str, Any]:
        solver = FVSplitSolver(eq, cfl=case.cfl, splitting=case.splitting,
                               stop_at_rest=stop_at_rest, max_steps=max_steps)
        s = state.copy()
        stepper = solver.make_stepper(s)
        try:
            t = stepper(s, 0.0, t1)
        except FinishedSimulation:
            t = solver.info["rest_time"]
        return {"steps": int(solver.info["steps"]), "t": float(t), "data": s.data,
                "cells": s.data.shape[1], "dx": float(s.grid.discretization[0])}

    return run


# --- benchmarks ------------------------------------------------------------------------

def cell_update_rates(variants: Sequence[str] = BENCH_VARIANTS, dx: float = 0.0125,
                      t_end: float = 0.4, repeats: int = 5) -> list[dict[str, Any]]:
    """Cell updates per second of every model and variant on the 5.1 case (dx [m],
    run to ``t_end`` [s]), with the compiled fv-split stepper."""
    from pdeflow.analysis.points import case_on_grid, resolve_case
    from pdeflow.variant import Variant

    base = resolve_case(CASE_5_1)
    rows = []
    for model in ("single_layer", "two_layer"):
        for name in variants:
            c = case_on_grid(base, dx, Variant.parse(name))
            rows.append({"model": model, "variant": name,
                         **_cell_update_cost(fv_stepper_run(c, model, t_end), repeats)})
    # where the two-layer cost goes: the same run without restoring hyperbolicity
    c = case_on_grid(base, dx, Variant.parse("hll/first-order"))
    c.data.setdefault("two_layer", {})["hyperbolicity"] = "none"
    rows.append({"model": "two_layer", "variant": "hll/first-order, hyperbolicity none",
                 **_cell_update_cost(fv_stepper_run(c, "two_layer", t_end), repeats)})
    return rows


CASE_WET_SLOPE = ROOT / "cases" / "mangeney_dam_break_slope.toml"


def friction_law_costs(repeats: int = 5, cells: int = 2000, t_end: float = 0.3,
                       laws: Sequence[str] = ("pouliquen", "mu_i", "voellmy")
                       ) -> list[dict[str, Any]]:
    """ns per cell update of each basal friction law against Coulomb, every model: the
    dam break on a 30 deg slope onto a wet bed (h_right = 0.02 m, so that every cell is
    wet and updated in both runs; ``cells`` cells, to ``t_end`` [s], hll/first-order;
    both layers on the slope for the two-layer model), the runs interleaved (Coulomb,
    law, Coulomb, law, ...) so that the machine's load hits both alike; ``ratio`` is the
    law's median over Coulomb's (issue 23's target for pouliquen: 1.2)."""
    from pdeflow.cases import load_case

    sets = [f"grid.cells={cells}", "initial.h_right=0.02", "output.snapshot_times=[]",
            "case.models=['single_layer', 'two_layer']", "two_layer.theta_deg=30.0",
            "two_layer.phi_b_deg=20.0", f"case.t_end={t_end!r}"]
    base = load_case(CASE_WET_SLOPE, sets)
    rows = []
    for model in ("single_layer", "two_layer"):
        for law in laws:
            case = load_case(CASE_WET_SLOPE, [*sets, f"{model}.friction_law='{law}'"])
            runs = [fv_stepper_run(base, model, t_end, stop_at_rest=False),
                    fv_stepper_run(case, model, t_end, stop_at_rest=False)]
            outs = [run() for run in runs]  # warm-up (compiles)
            walls = interleaved_walls(runs, repeats)
            ns = [1e9 * statistics.median(w) / (o["steps"] * o["cells"])
                  for w, o in zip(walls, outs, strict=True)]
            rows.append({"model": model, "law": law, "coulomb_ns": ns[0], "law_ns": ns[1],
                         "ratio": ns[1] / ns[0], "steps": [o["steps"] for o in outs],
                         "load_avg": os.getloadavg()[0]})
    return rows


def _cell_update_cost(run: Callable[[], dict[str, Any]], repeats: int) -> dict[str, Any]:
    """Cells, dx [m], steps, final time [s], median wall time [s] (and all walls) of
    ``run`` (an ``fv_stepper_run``), cell updates per second and ns per cell update."""
    out = run()
    med, walls = median_time(run, repeats)
    updates = out["steps"] * out["cells"]
    return {"cells": out["cells"], "dx": out["dx"], "steps": out["steps"], "t": out["t"],
            "wall_s": med, "walls": walls, "cell_updates_per_s": updates / med,
            "ns_per_cell_update": 1e9 * med / updates}


def large_grid_steps(repeats: int = 3, cells: int = 100_000,
                     steps: int = 200) -> list[dict[str, Any]]:
    """The first ``steps`` steps of the 5.1 column on ``cells`` cells (10^5: dx = 7e-5 m)
    per model, with the compiled stepper: the size of the large-grid run whose results
    tests/test_stress.py checks (``test_1e5_cells_short_run``: the same column and grid,
    the models' default parameters).
    Every cell counts as updated in every step, although after the first step (which
    cleans the whole initial state) only the wet region, about a seventh of the domain
    here, is visited."""
    return [{"model": model, **_cell_update_cost(large_grid_run(model, cells, steps),
                                                 repeats)}
            for model in ("two_layer", "single_layer")]


def large_grid_run(model: str, cells: int = 100_000,
                   steps: int = 200) -> Callable[[], dict[str, Any]]:
    """``fv_stepper_run`` of the first ``steps`` steps of the 5.1 case (7 m) on ``cells``
    cells, not stopping at rest."""
    from pdeflow.cases import load_case

    case = load_case(CASE_5_1, ["output.snapshot_times=[]", f"grid.cells={cells}"])
    return fv_stepper_run(case, model, stop_at_rest=False, max_steps=steps)


_COMPILE_SCRIPT = r"""
import json, sys, time
t0 = time.perf_counter()
import pdeflow
from pdeflow.cases import load_case
from pdeflow.simulate import run_model
from pdeflow.numerics import compiled, layout as L
from pdeflow.models.two_layer.kernels import KERNELS as TWO_LAYER
from pdeflow.numerics.splitting import scheme_stepper
t_import = time.perf_counter() - t0
loop = scheme_stepper(TWO_LAYER, L.FLUX_HLL, 1, L.LIMITER_MINMOD, False,
                      L.GEOMETRY_PLANAR).loop  # both models
c = load_case(sys.argv[1], ["output.snapshot_times=[]", "grid.dx=0.05"])
out = {"import_s": t_import}
for model in ("single_layer", "two_layer"):
    for k in ("first", "second"):
        t0 = time.perf_counter()
        run_model(c, model)
        out[f"{model}_{k}_s"] = time.perf_counter() - t0
# a sweep in the same process: both models, several heights and grids
for H0 in (0.5, 1.0, 2.0):
    for model in ("single_layer", "two_layer"):
        cc = load_case(sys.argv[1], ["output.snapshot_times=[]", "initial.L0=0.1",
                                     f"initial.H0={H0}", "grid.length=4.0", "grid.dx=0.02"])
        run_model(cc, model)
out["signatures_sweep"] = len(loop.signatures)
# the case as `pdeflow run` runs it: with snapshot times (tracker interrupts)
t0 = time.perf_counter()
run_model(load_case(sys.argv[1]), "two_layer")
out["with_snapshots_s"] = time.perf_counter() - t0
sigs = [str(s) for s in loop.signatures]
st = loop.stats
out.update(signatures=len(sigs), signature_list=sigs,
           cache_hits=sum(st.cache_hits.values()), cache_misses=sum(st.cache_misses.values()),
           max_signatures=max(len(k.signatures) for k in compiled.kernels()))
print("RESULT" + json.dumps(out))
"""


def compile_times(cache_dir: str | None = None) -> dict[str, Any]:
    """Compile cost in fresh subprocesses: cold (empty ``NUMBA_CACHE_DIR``) and warm
    (the same cache again). Each runs the 5.1 case (dx 0.05 m) twice per model, a
    small sweep (``signatures_sweep``: signatures of the stepping loop after it, one
    kernel for both models), then the 5.1 case with its snapshot times as ``pdeflow
    run`` does; reports import time, first and second run [s], the signatures of the
    stepping loop compiled or loaded, numba's cache hits/misses of it and the most
    signatures of any kernel (``max_signatures``)."""
    own = cache_dir is None
    tmp = tempfile.mkdtemp(prefix="pdeflow-numba-") if own else cache_dir
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp)}
    out: dict[str, Any] = {"cache_dir": str(tmp)}
    for label in ("cold", "warm"):
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", _COMPILE_SCRIPT, str(CASE_5_1)],
                              env=env, capture_output=True, text=True, cwd=ROOT,
                              timeout=1800)
        total = time.perf_counter() - t0
        line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT")]
        if proc.returncode != 0 or not line:
            out[label] = {"error": proc.stderr[-2000:]}
            continue
        res = json.loads(line[0][6:])
        res["process_s"] = total
        out[label] = res
    if own:
        import shutil

        shutil.rmtree(tmp, ignore_errors=True)
    return out


def case_5_1_to_rest(repeats: int = 5) -> list[dict[str, Any]]:
    """Wall time of the 5.1 case to rest per model, through ``run_model`` (the py-pde
    controller, as ``pdeflow run`` does) and with the stepper alone."""
    from pdeflow.cases import load_case
    from pdeflow.simulate import run_model

    case = load_case(CASE_5_1, ["output.snapshot_times=[]"])
    rows = []
    for model in ("two_layer", "single_layer"):
        res = run_model(case, model)
        med, walls = median_time(lambda m=model: run_model(case, m), repeats)
        kmed, _ = median_time(fv_stepper_run(case, model), repeats)
        rows.append({"model": model, "cells": case.cells, "steps": res.summary["steps"],
                     "t_rest": res.t_final, "wall_s": med, "walls": walls,
                     "stepper_wall_s": kmed})
    return rows


def _pkg_vs_baseline(case: Any) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import baseline

    eq, state = case.make_state("single_layer")
    P = eq.parameters
    g_z = P.g * math.cos(math.radians(P.theta_deg))
    g_x = P.g * math.sin(math.radians(P.theta_deg))
    tan_b = math.tan(math.radians(P.phi_b_deg))
    wall_l, wall_r = (b == "wall" for b in case.bc)
    dx = case.length / case.cells

    def base() -> tuple[float, int, np.ndarray]:
        h = state.data[0].copy()
        m = state.data[1].copy()
        t, steps = baseline.run_to_rest(h, m, dx, case.t_end, g_z, g_x, tan_b, case.cfl,
                                        wall_l, wall_r, P.dry_tolerance)
        return t, steps, h

    return fv_stepper_run(case, "single_layer"), base


def sweep(repeats: int = 5, heights: Sequence[float] = SWEEP_H0, pyclaw: bool = True,
          log: Any = None) -> dict[str, Any]:
    """The 5.2-like sweep (L0 = 0.1 m, H0 = ``heights``, dx = 0.01 m, to rest).

    Per height: pdeflow through ``run_model`` (what a user runs) and with the stepper
    alone, for both models; the hand-written baseline (single layer); PyClaw (single
    layer, to pdeflow's rest time) when installed. All in interleaved rounds; medians.
    Also checks that the baseline reproduces pdeflow's deposit.
    """
    import pyclaw_run

    from pdeflow.numerics import compiled
    from pdeflow.simulate import run_model

    have_claw = pyclaw and pyclaw_run.available()
    rows = []
    for H0 in heights:
        row: dict[str, Any] = {"H0": H0, "length": sweep_length(H0)}
        cs = sweep_case(H0, "single_layer")
        ct = sweep_case(H0, "two_layer")
        pkg1, base = _pkg_vs_baseline(cs)
        pkg2 = fv_stepper_run(ct, "two_layer")
        o1, o2, ob = pkg1(), pkg2(), base()
        row.update(cells=cs.cells, steps_single=o1["steps"], t_rest_single=o1["t"],
                   steps_two=o2["steps"], t_rest_two=o2["t"], steps_baseline=ob[1],
                   t_rest_baseline=ob[0],
                   baseline_max_depth_diff=float(np.max(np.abs(ob[2] - o1["data"][0]))))
        runs: dict[str, Callable[[], Any]] = {
            "single_run_model": lambda c=cs: run_model(c, "single_layer"),
            "two_run_model": lambda c=ct: run_model(c, "two_layer"),
            "single_stepper": pkg1, "two_stepper": pkg2, "baseline": base}
        if have_claw:
            t_claw = o1["t"]
            runs["pyclaw"] = lambda H=H0, t=t_claw, L=row["length"]: pyclaw_run.collapse(
                SWEEP_L0, H, L, SWEEP_DX, t)
        for fn in runs.values():
            fn()  # warm-up
        walls = interleaved_walls(list(runs.values()), repeats)
        for key, w in zip(runs, walls, strict=True):
            row[key + "_s"] = statistics.median(w)
        if have_claw:
            _, hc, steps_c = pyclaw_run.collapse(SWEEP_L0, H0, row["length"], SWEEP_DX,
                                                 o1["t"])
            row["pyclaw_steps"] = steps_c
            front = np.nonzero(hc > 1e-3)[0]
            row["pyclaw_front"] = float((front[-1] + 1) * SWEEP_DX) if front.size else None
        front = np.nonzero(o1["data"][0] > 1e-3)[0]
        row["front_single"] = float((front[-1] + 1) * SWEEP_DX) if front.size else None
        if log is not None:
            print(f"sweep H0={H0}: " + ", ".join(
                f"{k}={v:.4g}" for k, v in row.items() if isinstance(v, float)),
                file=log, flush=True)
        rows.append(row)
    tot = {k: sum(r[k] for r in rows) for k in rows[0] if k.endswith("_s")}
    upd1 = sum(r["steps_single"] * r["cells"] for r in rows)
    upd2 = sum(r["steps_two"] * r["cells"] for r in rows)
    out: dict[str, Any] = {
        "rows": rows, "totals_s": tot, "pyclaw": have_claw,
        "cell_updates_single": upd1, "cell_updates_two": upd2,
        "ns_per_update_single": 1e9 * tot["single_stepper_s"] / upd1,
        "ns_per_update_two": 1e9 * tot["two_stepper_s"] / upd2,
        "ns_per_update_baseline": 1e9 * tot["baseline_s"] / sum(
            r["steps_baseline"] * r["cells"] for r in rows),
        "max_signatures": max(len(k.signatures) for k in compiled.kernels()),
    }
    out["ratio_single_vs_baseline_stepper"] = tot["single_stepper_s"] / tot["baseline_s"]
    out["ratio_single_vs_baseline_run_model"] = tot["single_run_model_s"] / tot["baseline_s"]
    out["ratio_two_vs_single_per_update"] = (out["ns_per_update_two"]
                                             / out["ns_per_update_single"])
    if have_claw:
        out["ratio_pyclaw_vs_single_stepper"] = tot["pyclaw_s"] / tot["single_stepper_s"]
        out["ratio_pyclaw_vs_single_run_model"] = tot["pyclaw_s"] / tot["single_run_model_s"]
    return out


def wet_region_savings(repeats: int = 5, factor: int = 10) -> list[dict[str, Any]]:
    """Cost of the same collapse on a domain ``factor`` times longer (same dx): the
    advection loops visit only the wet region, the other stages every cell."""
    from pdeflow.cases import load_case

    rows = []
    for model, case in (
            ("single_layer", sweep_case(1.0, "single_layer")),
            ("two_layer", load_case(CASE_5_1, ["output.snapshot_times=[]"]))):
        long = case.copy()
        long.data["grid"].pop("dx", None)
        long.data["grid"]["length"] = case.length * factor
        long.data["grid"]["cells"] = case.cells * factor
        long.validate()
        a, b = fv_stepper_run(case, model), fv_stepper_run(long, model)
        oa, ob = a(), b()
        ma, mb = map(statistics.median, interleaved_walls((a, b), repeats))
        rows.append({"model": model, "cells": case.cells, "cells_long": long.cells,
                     "steps": oa["steps"], "steps_long": ob["steps"], "wall_s": ma,
                     "wall_long_s": mb, "ratio": mb / ma})
    return rows


def stop_at_rest_savings(repeats: int = 5) -> list[dict[str, Any]]:
    """5.1 to t_end = 5 s with ``stop_at_rest=True`` (ends at rest) and ``False``."""
    from pdeflow.cases import load_case

    case = load_case(CASE_5_1, ["output.snapshot_times=[]"])
    rows = []
    for model in ("two_layer", "single_layer"):
        on, off = fv_stepper_run(case, model), fv_stepper_run(case, model,
                                                             stop_at_rest=False)
        o_on, o_off = on(), off()
        m_on, m_off = map(statistics.median, interleaved_walls((on, off), repeats))
        rows.append({"model": model, "t_end": case.t_end, "t_rest": o_on["t"],
                     "steps_on": o_on["steps"], "steps_off": o_off["steps"],
                     "wall_on_s": m_on, "wall_off_s": m_off, "saving": 1 - m_on / m_off})
    return rows
