"""Run the work-precision studies and the benchmark suite; write docs/performance.md.

Usage (from the repository root)::

    python benchmarks/run_benchmarks.py                 # everything (~15-25 min)
    python benchmarks/run_benchmarks.py --only wp       # work precision only
    python benchmarks/run_benchmarks.py --only bench    # benchmark suite only
    python benchmarks/run_benchmarks.py --only studies  # pdeflow study on Dask (~25 min)
    python benchmarks/run_benchmarks.py --only cold --label after  # cold first run (~3 min)
    python benchmarks/run_benchmarks.py --only bed      # a long erodible bed at rest
    python benchmarks/run_benchmarks.py --only start    # warm start, kernel load, app (~4 min)
    python benchmarks/run_benchmarks.py --render        # re-render the doc from JSON
    python benchmarks/run_benchmarks.py --quick         # smoke run into TMPDIR, ~3 min

Measurements go to
``benchmarks/measurements/{workprecision,bench,studies,cold_start,start_up}.json``
(each part can be re-measured alone; the doc is rendered from all of them; the cold
first run is kept per ``--label``, e.g. before and after a change, and ``--tree`` measures
another checkout with this harness), figures to
``docs/figures/workprecision_*.png``, the report to ``docs/performance.md``. PyClaw is
used when ``clawpack`` imports (``--no-pyclaw`` to skip).
"""

from __future__ import annotations

import argparse
import datetime
import json
import logging
import math
import os
import platform
import sys
import tempfile
import time
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT))

import bed_cost  # noqa: E402
import cold_start  # noqa: E402
import geometry_cost  # noqa: E402
import layer_cost  # noqa: E402
import start_up  # noqa: E402
import study_scaling  # noqa: E402
import suite  # noqa: E402

RESULTS = ROOT / "benchmarks" / "measurements"  # not "results/": git-ignored
SECTIONS: dict[str, tuple[Any, str, int]] = {
    "start": (start_up, "start_up.json", 9),
    "geometry": (geometry_cost, "geometry.json", 7),
    "bed": (bed_cost, "bed.json", 7),
    "layers": (layer_cost, "layers.json", 9),
}
"""the parts that are one module each: ``--only NAME`` -> (the module, with
``measure(repeats)`` and ``render(data)``; its stored results; the least repeats), in
the order of the doc's sections after the cold first run"""
FIGURES = ROOT / "docs" / "figures"
DOC = ROOT / "docs" / "performance.md"

WP_CASES: dict[str, dict[str, Any]] = {
    # the exact-solution cases on a domain that holds the waves until t, at CFL 0.45
    "ritter": {"case": "cases/ritter_dam_break.toml", "grids": [125, 250, 500, 1000],
               "t": 0.5, "set": ["grid.length=2.5", "numerics.cfl=0.45"]},
    "mangeney": {"case": "cases/mangeney_dam_break_slope.toml",
                 "grids": [150, 300, 600, 1200], "t": 0.5,
                 "set": ["grid.length=3.0", "numerics.cfl=0.45", "case.t_end=0.5"]},
    "paper_5_1_dam_break": {"case": str(suite.CASE_5_1.relative_to(ROOT)),
                            "grids": [0.05, 0.025, 0.0125], "t": 0.4},
    # the same against one common reference: do the variants converge to one solution?
    "paper_5_1_common_reference": {"case": str(suite.CASE_5_1.relative_to(ROOT)),
                                   "grids": [0.05, 0.025, 0.0125], "t": 0.4,
                                   "reference": "fine:ifcp/muscl/mc"},
}
NOTES = {
    "paper_5_1_dam_break": (
        "Each variant against its *own* fine-grid solution (dx = 0.05/16 m; mol-rk "
        "against hll/first-order): this measures self-convergence, not accuracy. A "
        "variant that converges to a different limit (the closure's exchange depends on "
        "dx and on how the sources are split) can look good here: compare with the next "
        "study."),
    "paper_5_1_common_reference": (
        "Every variant against one reference, ifcp/muscl/mc (the most accurate variant on "
        "Ritter and Mangeney) on dx = 0.05/16 m. Errors that stop falling with refinement "
        "mean that variant converges to a different solution."),
}
MOL_PROBE_CFL = (0.3, 0.03, 0.003, 0.0003)


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def conditions() -> dict[str, Any]:
    """Machine, versions and load at the time of the run."""
    import numba
    import numpy
    import pde

    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    return {"date": datetime.datetime.now().isoformat(timespec="seconds"),
            "python": platform.python_version(), "numpy": numpy.__version__,
            "numba": numba.__version__, "py-pde": pde.__version__,
            "cpu": platform.processor() or platform.machine(), "cores": os.cpu_count(),
            "load_avg_at_start": load}


# --- measuring -------------------------------------------------------------------------

def measure_wp(quick: bool, repeats: int, results: Path = RESULTS) -> dict[str, Any]:
    """Work-precision studies, the mol-rk stiffness probe and the hyperbolicity modes."""
    from pdeflow.analysis import workprecision as wp
    from pdeflow.analysis.hyperbolicity_modes import hyperbolicity_study
    from pdeflow.cases import load_case

    out: dict[str, Any] = {"conditions": conditions(), "cases": {}}
    figures = results / "figures" if quick else FIGURES
    figures.mkdir(parents=True, exist_ok=True)
    for label, cfg in WP_CASES.items():
        grids = cfg["grids"][:2] if quick else cfg["grids"]
        variants = (["hll/first-order", "hll/muscl/minmod", "mol-rk"] if quick
                    else list(wp.DEFAULT_VARIANTS))
        case = cfg["case"]
        res = wp.compare(load_case(ROOT / case, cfg.get("set", [])), variants, grids,
                         cfg.get("reference", "auto"), None,
                         t=cfg["t"], repeats=repeats, label=label, log=sys.stderr)
        fig = wp.plot(res, figures / f"workprecision_{res.case}.png")
        out["cases"][res.case] = {"source": " --set ".join([case, *cfg.get("set", [])]),
                                  "t": res.t, "rows": res.rows,
                                  "figure": str(fig.relative_to(ROOT) if fig.is_relative_to(ROOT)
                                                else fig)}
    # mol-rk on the two-layer 5.1 case with ever smaller time steps: fail or crawl
    probe = []
    for cfl in MOL_PROBE_CFL[:2] if quick else MOL_PROBE_CFL:
        res = wp.compare(suite.CASE_5_1, ["mol-rk"], [0.05], "fine:hll/first-order", None,
                         t=0.4, repeats=1, models=["two_layer"], cfl=cfl,
                         reference_dx=0.0125, mol_cap=10.0 if quick else 30.0,
                         log=sys.stderr)
        probe.append({"cfl": cfl, **res.rows[0]})
    out["mol_probe"] = probe
    out["hyperbolicity"] = hyperbolicity_study(
        suite.CASE_5_1, grids=[0.05] if quick else [0.05, 0.0125], repeats=repeats,
        log=sys.stderr)
    return out


def measure_laws(repeats: int) -> dict[str, Any]:
    """The basal friction laws against Coulomb (suite.friction_law_costs, paired and
    interleaved in one run), with the machine's load before and after."""
    _log("basal friction laws against Coulomb ...")
    before = conditions()
    rows = suite.friction_law_costs(repeats)
    return {"friction_laws": rows, "friction_laws_conditions": {
        **before, "repeats": repeats,
        "load_avg_at_end": os.getloadavg() if hasattr(os, "getloadavg") else None}}


def measure_bench(quick: bool, repeats: int, pyclaw: bool) -> dict[str, Any]:
    """The benchmark suite (see suite.py)."""
    from pdeflow.numerics import compiled

    out: dict[str, Any] = {"conditions": conditions()}
    t0 = time.perf_counter()
    _log("compile times (subprocesses, cold and warm numba cache) ...")
    out["compile"] = suite.compile_times()
    _log(json.dumps(out["compile"], default=str)[:400])
    _log("cell update rates ...")
    out["rates"] = suite.cell_update_rates(
        suite.BENCH_VARIANTS[:2] if quick else suite.BENCH_VARIANTS, repeats=repeats)
    out.update(measure_laws(repeats))
    _log("5.1 to rest ...")
    out["case_5_1"] = suite.case_5_1_to_rest(repeats)
    _log("10^5 cells, 200 steps ...")
    out["large_grid"] = suite.large_grid_steps(repeats)
    _log("5.2-like sweep ...")
    out["sweep"] = suite.sweep(repeats, suite.SWEEP_H0[:2] if quick else suite.SWEEP_H0,
                               pyclaw=pyclaw, log=sys.stderr)
    _log("wet region and stop at rest ...")
    out["wet_region"] = suite.wet_region_savings(repeats)
    out["stop_at_rest"] = suite.stop_at_rest_savings(repeats)
    out["max_signatures_end"] = max(len(k.signatures) for k in compiled.kernels())
    out["elapsed_s"] = time.perf_counter() - t0
    out["conditions"]["load_avg_at_end"] = os.getloadavg()
    return out


# --- rendering -------------------------------------------------------------------------

def _f(v: Any, spec: str = ".3g") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return format(v, spec)


def _met(ok: bool | None) -> str:
    return "n/a" if ok is None else ("**met**" if ok else "**missed**")


def _cond(c: dict[str, Any]) -> str:
    load = c.get("load_avg_at_start")
    lt = f"{load[0]:.2f}" if load else "?"
    le = c.get("load_avg_at_end")
    lend = f", at the end {le[0]:.2f}" if le else ""
    return (f"{c['date']}, Python {c['python']}, numpy {c['numpy']}, numba {c['numba']}, "
            f"py-pde {c['py-pde']}, {c['cores']} cores shared with other jobs (1-min load "
            f"average at the start {lt}{lend})")


def _table(columns: Sequence[str], align: str, rows: Iterable[str]) -> list[str]:
    """A markdown table: the header cells ``columns``, ``align`` one letter per column
    ("l" left, "r" right), then the ``rows`` (formatted lines "| a | b |")."""
    rule = "".join("---:|" if a == "r" else "---|" for a in align)
    return ["| " + " | ".join(columns) + " |", "|" + rule, *rows]


def _wp_table(rows: list[dict[str, Any]]) -> str:
    def line(r: dict[str, Any]) -> str:
        st = r["status"] if r["status"] == "ok" else f"{r['status']}: {r['note']}"
        return (f"| {r['model']} | {r['variant']} | {r['cells']} | "
                f"{_f(r['err_h'], '.3e')} | {_f(r['err_hu'], '.3e')} | "
                f"{_f(r['order_h'], '.2f')} | {_f(r['wall_s'] * 1e3, '.3g')} | "
                f"{_f(r['compile_s'], '.2g')} | {r['steps']} | {st} |")

    return "\n".join(_table(
        ["model", "variant", "cells", "L1 depth [m^2]", "L1 momentum [m^3/s]",
         "order (depth)", "wall [ms]", "compile [s]", "steps", "status"], "llrrrrrrrl",
        map(line, rows)))


def _best(rows: list[dict[str, Any]], model: str) -> str:
    """Cheapest variant reaching the error of hll/first-order on its finest grid."""
    ok = [r for r in rows if r["model"] == model and r["status"] == "ok"]
    ref = [r for r in ok if r["variant"] == "hll/first-order"]
    if not ref:
        return ""
    target = min(r["err_h"] for r in ref)
    base_wall = min(r["wall_s"] for r in ref if r["err_h"] == target)
    cands = [r for r in ok if r["err_h"] <= target]
    best = min(cands, key=lambda r: r["wall_s"])
    if best["variant"] == "hll/first-order":
        return (f"{model}: no variant reaches the error of hll/first-order on its finest "
                f"grid ({target:.3e} m^2) in less wall time than hll/first-order itself "
                f"({base_wall * 1e3:.3g} ms).")
    return (f"{model}: the error of hll/first-order on its finest grid "
            f"({target:.3e} m^2, {base_wall * 1e3:.3g} ms) is reached most cheaply by "
            f"{best['variant']} on {best['cells']} cells in {best['wall_s'] * 1e3:.3g} ms "
            f"({base_wall / best['wall_s']:.3g}x less wall time).")


def render(wp: dict[str, Any] | None, bench: dict[str, Any] | None,
           studies: dict[str, Any] | None = None,
           cold: dict[str, Any] | None = None,
           sections: dict[str, dict[str, Any]] | None = None) -> str:
    """docs/performance.md from the stored measurements (``sections``: those of
    :data:`SECTIONS` by name)."""
    sections = sections or {}
    start = sections.get("start")
    L: list[str] = []
    a = L.append
    a("# Performance: work precision and benchmarks\n")
    a("*Generated by `python benchmarks/run_benchmarks.py` (all of it; `--only wp` or "
      "`--only bench` re-measures one part, `--render` re-renders from "
      "`benchmarks/measurements/*.json`). Do not edit by hand: edit the template in "
      "`benchmarks/run_benchmarks.py`.*\n")
    a("## How it is measured\n")
    a("* **Wall time** is `time.perf_counter` around the *compiled* run: one warm-up run "
      "first (numba compilation excluded; compile times are measured separately in fresh "
      "subprocesses), then the median over repeats (at least 3, more while the repeats "
      "add up to less than 0.25 s). Work-precision runs call the `fv-split` stepper "
      "directly (no py-pde controller); the sweep and the 5.1 case are also timed through "
      "`pdeflow.simulate.run_model`, which is what `pdeflow run` does.")
    a("* **Ratios** (pdeflow vs the baseline, vs PyClaw, two vs one layer) are measured in "
      "the same process with the runs interleaved (A B C A B C ...), medians over rounds. "
      "The machine has 2 cores shared with other jobs: absolute times vary by 2x or more "
      "between runs; ratios measured together are far more stable.")
    a("* A **cell update** is one cell advanced by one time step: (cells of the grid) x "
      "(steps). Dry cells count, though no stage visits them (beyond the wet region's "
      "stencil).")
    a("* **Errors**: L1 norms at a fixed time, summed over the layers: depth "
      "sum |h - h_ref| dx [m^2], momentum sum |hu - (hu)_ref| dx [m^3/s]; against the "
      "cell averages of the exact solution, or against a fine-grid run of the same "
      "variant (dx_ref = min dx / 4) averaged onto the coarse cells.")
    a("* The harness: `pdeflow compare CASE --variants ... "
      "--grids ...` (function `pdeflow.analysis.workprecision.compare`, see its "
      "docstring); the suite: `benchmarks/suite.py`, pytest-benchmark tests in "
      "`benchmarks/test_benchmarks.py` (`python -m pytest benchmarks`, not part of the "
      "default test run; `pip install \".[bench]\"`).")
    a("* **PyClaw** (optional): `apt-get install gfortran && pip install clawpack` "
      "(builds the Fortran Riemann solvers, about 7 minutes here); without it the PyClaw "
      "column and target are skipped.\n")
    if bench:
        a(f"Benchmark conditions: {_cond(bench['conditions'])}.\n")
    if wp:
        a(f"Work-precision conditions: {_cond(wp['conditions'])}.\n")
    if bench:
        a(_render_targets(bench, cold_runs=cold, start=start, layers=sections.get("layers")))
    if wp:
        a(_render_wp(wp))
    if bench:
        a(_render_bench(bench))
    if cold:
        a(cold_start.render(cold))
    for name, (module, _, _) in SECTIONS.items():
        if sections.get(name):
            a(module.render(sections[name]))
    if studies:
        a(f"Studies conditions: {_cond(studies['conditions'])}.\n")
        a(study_scaling.render(studies))
    a(_findings(wp, bench, sections.get("layers")))
    return "\n".join(L) + "\n"


def _most_signatures(sweep: dict[str, Any]) -> int:
    """Most signatures of one kernel after the sweep (measurements before the kernels
    were specialised counted those of the one stepping kernel, ``advance_split``)."""
    return sweep.get("max_signatures", len(sweep.get("advance_split_signatures", [])))


def _render_targets(b: dict[str, Any], cold_runs: dict[str, Any] | None = None,
                    start: dict[str, Any] | None = None,
                    layers: dict[str, Any] | None = None) -> str:
    s = b["sweep"]
    L = ["## Targets\n", "| target | measured | |", "|---|---|---|"]
    r1 = s["ratio_single_vs_baseline_stepper"]
    r1m = s["ratio_single_vs_baseline_run_model"]
    L.append(f"| single-layer sweep <= 2x the hand-written baseline | {r1:.2f}x (stepper), "
             f"{r1m:.2f}x (through run_model) | {_met(r1m <= 2.0)} |")
    if s.get("pyclaw"):
        rc = s["ratio_pyclaw_vs_single_run_model"]
        rcs = s["ratio_pyclaw_vs_single_stepper"]
        L.append(f"| single-layer sweep >= 6x faster than PyClaw | {rc:.2f}x (run_model), "
                 f"{rcs:.2f}x (stepper) | {_met(rc >= 6.0)} |")
    else:
        L.append("| single-layer sweep >= 6x faster than PyClaw | clawpack not installed "
                 "| n/a |")
    if layers:  # the section of its own (benchmarks/layer_cost.py) is the newer one
        L.append(layer_cost.target_row(layers))
    else:
        r2 = s["ratio_two_vs_single_per_update"]
        L.append(f"| two-layer <= 3x the single-layer cost per cell update | {r2:.2f}x "
                 f"({s['ns_per_update_two']:.1f} vs {s['ns_per_update_single']:.1f} ns) | "
                 f"{_met(r2 <= 3.0)} |")
    c = b["compile"]
    cold = c.get("cold", {})
    sw, sig = cold.get("signatures_sweep"), cold.get("signatures")
    most = _most_signatures(s)
    L.append(f"| no kernel compiled more than once per process for a sweep | "
             f"stepping loop: {sw} signature(s) after a run_model sweep in a fresh "
             f"process, {sig} once a run with snapshot times follows; at most {most} per "
             f"kernel in the benchmark process | {_met(sig == 1 and most == 1)} |")
    warm = c.get("warm", {})
    ok = warm.get("cache_misses") == 0 and warm.get("cache_hits", 0) > 0
    L.append(f"| numba cache reused across processes | warm process: "
             f"{warm.get('cache_hits')} cache hits, {warm.get('cache_misses')} misses; first "
             f"run of the process {_f(warm.get('single_layer_first_s'))} s vs "
             f"{_f(c.get('cold', {}).get('single_layer_first_s'))} s cold | {_met(ok)} |")
    if cold_runs:
        label, d = cold_start.latest(cold_runs)
        plain = d["commands"]["python -m pdeflow run"]
        walls = ", ".join(f"{w:.1f}" for w in sorted(plain.get("walls", [])))
        L.append(f"| cold first run of `pdeflow run cases/paper_5_1_dam_break.toml` <= 8 s "
                 f"| {plain['wall_s']:.1f} s median (*{label}*: {walls} s; see *Cold first "
                 f"run*) | {_met(plain['wall_s'] <= 8.0)} |")
        L.append(f"| the same <= 8 s of CPU (user + system) | {plain['cpu_s']:.1f} s median "
                 f"(*{label}*) | {_met(plain['cpu_s'] <= 8.0)} |")
    if start:
        L.extend(start_up.target_rows(start))
    return "\n".join(L) + "\n"


def _render_wp(wp: dict[str, Any]) -> str:
    L = ["## Work precision\n",
         "Variants: `FLUX/RECONSTRUCTION[/LIMITER][+strang]` run with `fv-split` at the "
         "case's CFL number (0.45 for Ritter and Mangeney, 0.3 for 5.1); `mol-rk` is "
         "py-pde's `runge-kutta` solver (classical RK4, fixed dt = CFL dx / s_est with "
         "s_est = 2 max(|u| + sqrt(g_z H)) + g_x t from the initial state) on the "
         "method-of-lines rate of hll/first-order, with a 20 s wall-time cap per run. "
         "Its compile column is py-pde's compilation of a new stepper for every grid "
         "(excluded from the wall time, as for the others).\n"]
    for name, c in wp["cases"].items():
        rows = c["rows"]
        refs = sorted({r["reference"].split(" dx=")[0] for r in rows})
        ref = ("fine grid of the same variant" if len(refs) > 2 else ", ".join(refs))
        if rows and " dx=" in rows[0]["reference"]:
            ref += f" (dx = {rows[0]['reference'].split(' dx=')[1]})"
        L.append(f"### {name} (t = {c['t']:g} s; reference: {ref})\n")
        if name in NOTES:
            L.append(NOTES[name] + "\n")
        fig = Path(c["figure"])
        rel = fig.relative_to("docs") if fig.parts[0] == "docs" else fig
        L.append(f"![work precision {name}]({rel})\n")
        for model in dict.fromkeys(r["model"] for r in rows):
            line = _best(rows, model)
            if line:
                L.append(f"* {line}")
        L.append("")
        L.append(_wp_table(rows) + "\n")
    p = wp.get("mol_probe", [])
    if p:
        L.append("### mol-rk on the two-layer 5.1 case: smaller steps\n")
        L.append("dx = 0.05 m to t = 0.4 s, compared with hll/first-order fv-split on "
                 "dx = 0.0125 m; the CFL number sets the fixed RK4 step; cap 30 s. For "
                 "comparison, fv-split hll/first-order needs about 0.01 s for this run.\n")
        L += _table(["CFL", "dt [s]", "status", "L1 depth [m^2]", "wall [s]", "note"],
                    "rrlrrl",
                    (f"| {r['cfl']:g} | {_f(r.get('dt'), '.3g')} | {r['status']} | "
                     f"{_f(r['err_h'], '.3e')} | {_f(r['wall_s'], '.3g')} | {r['note']} |"
                     for r in p))
        L.append("")
    h = wp.get("hyperbolicity", [])
    if h:
        L.append("### Hyperbolicity modes on 5.1 (two layers, to rest)\n")
        L += _table(["mode", "cells", "wall [ms]", "steps", "max F_extra/rho1 [m^2/s^2]",
                     "hyperbolicity events (cell-steps)", "of which bisected",
                     "lower stop [s]", "upper stop [s]", "run-out [m]"], "l" + "r" * 9,
                    (f"| {r['mode']} | {r['cells']} | {r['wall_s'] * 1e3:.3g} | "
                     f"{r['steps']} | {_f(r['max_fextra_over_rho1'], '.3g')} | "
                     f"{r['hyperbolicity_events']} | "
                     f"{r.get('hyperbolicity_bisections', '-')} | "
                     f"{_f(r['lower_stop_time'], '.3f')} | "
                     f"{_f(r['upper_stop_time'], '.3f')} | {_f(r['runout'], '.3f')} |"
                     for r in h))
        L.append("")
    return "\n".join(L)


def _loads(v: Any) -> str:
    return "-" if not v else ", ".join(f"{x:.2f}" for x in v)


def _render_bench(b: dict[str, Any]) -> str:
    L = ["## Benchmarks\n", "### Cell updates per second (5.1 case, dx = 0.0125 m, "
         "t = 0.4 s, compiled stepper)\n"]
    L += _table(["model", "variant", "cells", "steps", "wall [ms]", "cell updates/s",
                 "ns/update"], "llrrrrr",
                (f"| {r['model']} | {r['variant']} | {r['cells']} | {r['steps']} | "
                 f"{r['wall_s'] * 1e3:.3g} | {r['cell_updates_per_s']:.3g} | "
                 f"{r['ns_per_cell_update']:.3g} |" for r in b["rates"]))
    if b.get("friction_laws"):  # measured since issue 23
        L += ["", "### Basal friction laws (a dam break onto a wet 30 deg slope, "
              "hll/first-order, interleaved with Coulomb; target for pouliquen: <= "
              "1.2x)\n"]
        L += _table(["model", "law", "Coulomb ns/update", "law ns/update", "ratio",
                     "load avg (1 min)"],
                    "llrrrr", (f"| {r['model']} | {r['law']} | {r['coulomb_ns']:.3g} | "
                               f"{r['law_ns']:.3g} | {r['ratio']:.2f}x | "
                               f"{r.get('load_avg', math.nan):.2f} |"
                               for r in b["friction_laws"]))
        c = b.get("friction_laws_conditions")
        if c:
            L += ["", f"Measured {c['date']} (`python benchmarks/run_benchmarks.py --only "
                  f"laws`, medians of {c.get('repeats', '?')} interleaved pairs after a "
                  f"warm-up), load average (1, 5, 15 min) "
                  f"{_loads(c.get('load_avg_at_start'))} at the start and "
                  f"{_loads(c.get('load_avg_at_end'))} at the end on {c.get('cores')} "
                  "cores shared with other users: the ratio of a pair is what is "
                  "compared, not the absolute times."]
    c = b["compile"]
    L += ["", "### Compilation (fresh subprocesses, own NUMBA_CACHE_DIR)\n",
          "| | import [s] | single layer 1st run [s] | 2nd run [s] | two layers 1st run "
          "[s] | 2nd run [s] | whole process [s] | cache hits / misses |",
          "|---|---:|---:|---:|---:|---:|---:|---|"]
    for k in ("cold", "warm"):
        r = c.get(k, {})
        if "error" in r:
            L.append(f"| {k} | error: {r['error'][-200:]} |")
            continue
        L.append(f"| {k} | {_f(r.get('import_s'))} | {_f(r.get('single_layer_first_s'))} | "
                 f"{_f(r.get('single_layer_second_s'))} | {_f(r.get('two_layer_first_s'))} "
                 f"| {_f(r.get('two_layer_second_s'))} | {_f(r.get('process_s'))} | "
                 f"{r.get('cache_hits')} / {r.get('cache_misses')} |")
    L += ["", ("The cold first run compiles the stepping loop (one kernel for both "
               "models) and the kernels of the case's scheme (see the cold first run "
               "below)." if "max_signatures" in b["sweep"] else
               "The cold first run compiles every kernel reached from `advance_split` "
               "(both models share one dispatcher; the first run of either model compiles "
               "it, the other then finds it compiled).") + "\n",
          "### The 5.1 case to rest (dx = 0.05 m, 140 cells)\n"]
    L += _table(["model", "steps", "rest at [s]", "run_model [ms]", "stepper alone [ms]"],
                "lrrrr",
                (f"| {r['model']} | {r['steps']} | {r['t_rest']:.3f} | "
                 f"{r['wall_s'] * 1e3:.3g} | {r['stepper_wall_s'] * 1e3:.3g} |"
                 for r in b["case_5_1"]))
    if "large_grid" in b:  # measurements older than this table lack it
        L += _render_large_grid(b["large_grid"])
    s = b["sweep"]
    claw = s.get("pyclaw")
    L += ["", "### 5.2-like sweep (L0 = 0.1 m, dx = 0.01 m, to rest; medians of "
          "interleaved rounds)\n",
          "Domain length L0 + 3 H0 + 0.5 m. *baseline*: `benchmarks/baseline.py`, the same "
          "first-order HLL + implicit Coulomb scheme hand-written in one numba loop (its "
          "deposits equal pdeflow's to round-off: column *max |dh|*). *PyClaw*: "
          "`benchmarks/pyclaw_run.py`, Fortran HLLE, first order, Coulomb friction in "
          "`step_source`, 1e-6 m film on the dry bed, run to pdeflow's rest time.\n",
          "| H0 [m] | cells | steps 1L | steps 2L | 1L run_model [ms] | 1L stepper [ms] | "
          "baseline [ms] | max abs(dh) [m] | " + ("PyClaw [ms] | " if claw else "")
          + "2L run_model [ms] | 2L stepper [ms] |",
          "|---:|---:|---:|---:|---:|---:|---:|---:|" + ("---:|" if claw else "")
          + "---:|---:|"]
    for r in s["rows"]:
        L.append(f"| {r['H0']:g} | {r['cells']} | {r['steps_single']} | {r['steps_two']} | "
                 f"{r['single_run_model_s'] * 1e3:.3g} | {r['single_stepper_s'] * 1e3:.3g} "
                 f"| {r['baseline_s'] * 1e3:.3g} | {r['baseline_max_depth_diff']:.1e} | "
                 + (f"{r['pyclaw_s'] * 1e3:.3g} | " if claw else "")
                 + f"{r['two_run_model_s'] * 1e3:.3g} | {r['two_stepper_s'] * 1e3:.3g} |")
    t = s["totals_s"]
    L.append(f"| **total** | | | | {t['single_run_model_s'] * 1e3:.3g} | "
             f"{t['single_stepper_s'] * 1e3:.3g} | {t['baseline_s'] * 1e3:.3g} | | "
             + (f"{t['pyclaw_s'] * 1e3:.3g} | " if claw else "")
             + f"{t['two_run_model_s'] * 1e3:.3g} | {t['two_stepper_s'] * 1e3:.3g} |")
    L.append("")
    L.append(f"Per cell update: single layer {s['ns_per_update_single']:.1f} ns, baseline "
             f"{s['ns_per_update_baseline']:.1f} ns, two layers {s['ns_per_update_two']:.1f}"
             " ns.\n")
    L += ["### Skipping what a scene does not need\n",
          "**Wet region only** (same collapse on a domain 10x longer, same dx):\n"]
    L += _table(["model", "cells", "steps", "wall [ms]", "cells (10x)", "steps", "wall [ms]",
                 "ratio"], "lrrrrrrr",
                (f"| {r['model']} | {r['cells']} | {r['steps']} | {r['wall_s'] * 1e3:.3g} | "
                 f"{r['cells_long']} | {r['steps_long']} | {r['wall_long_s'] * 1e3:.3g} | "
                 f"{r['ratio']:.2f}x |" for r in b["wet_region"]))
    L += ["", "**Stopping at rest** (5.1 with t_end = 5 s, `FVSplitSolver(stop_at_rest=...)`):"
          "\n"]
    L += _table(["model", "rest at [s]", "steps (stop)", "wall [ms]", "steps (no stop)",
                 "wall [ms]", "saved"], "lrrrrrr",
                (f"| {r['model']} | {r['t_rest']:.3f} | {r['steps_on']} | "
                 f"{r['wall_on_s'] * 1e3:.3g} | {r['steps_off']} | "
                 f"{r['wall_off_s'] * 1e3:.3g} | {100 * r['saving']:.0f} % |"
                 for r in b["stop_at_rest"]))
    L.append("")
    return "\n".join(L)


def _render_large_grid(rows: list[dict[str, Any]]) -> list[str]:
    """The 10^5-cell table (suite.large_grid_steps)."""
    r0 = rows[0]
    return ["", f"### {r0['cells']} cells: the first {r0['steps']} steps of the 5.1 column "
            f"(dx = {r0['dx']:.2g} m)\n",
            "The size of the run whose results `tests/test_stress.py::"
            "test_1e5_cells_short_run` checks, timed here (the case file's parameters): "
            "the compiled stepper, not stopping at rest. Every cell counts in the "
            "cost per cell update, although after the first step (which cleans the whole "
            "initial state) only the wet region, about a seventh of the domain, is "
            "visited: it is not comparable with the per-update cost on 140 cells.\n",
            *_table(["model", "cells", "steps", "reached t [s]", "wall [ms]",
                     "ns/update"], "lrrrrr",
                    (f"| {r['model']} | {r['cells']} | {r['steps']} | {r['t']:.3g} | "
                     f"{r['wall_s'] * 1e3:.3g} | {r['ns_per_cell_update']:.3g} |"
                     for r in rows))]


def _hyp_share(b: dict[str, Any]) -> str:
    """Sentence on the two-layer cost without hyperbolicity restoration."""
    rates = {(r["model"], r["variant"]): r["ns_per_cell_update"] for r in b["rates"]}
    one = rates.get(("single_layer", "hll/first-order"))
    two = rates.get(("two_layer", "hll/first-order"))
    none = rates.get(("two_layer", "hll/first-order, hyperbolicity none"))
    strang = rates.get(("two_layer", "hll/first-order+strang"))
    if not (one and two and none):
        return ""
    out = (f" On the 5.1 grid (cell-update table) the two-layer hll/first-order step costs "
           f"{two:.0f} ns per cell update, {two / one:.1f}x the single layer; with "
           f"`hyperbolicity = \"none\"` it costs {none:.0f} ns, {none / one:.1f}x: the "
           f"hyperbolicity check and restoration take {100 * (1 - none / two):.0f} % of "
           "the two-layer time there.")
    if strang:
        out += (f" With Strang splitting it costs {strang:.0f} ns: with half source steps "
                "on either side of the advection the restoration is needed in fewer cells.")
    return out


def _crawl(wp: dict[str, Any]) -> str:
    """mol-rk's slowest successful probe run against fv-split hll/first-order."""
    ok = [r for r in wp.get("mol_probe", []) if r["status"] == "ok"]
    ref = [r for c in wp["cases"].values() for r in c["rows"]
           if r["case"] == "paper_5_1_dam_break" and r["model"] == "two_layer"
           and r["variant"] == "hll/first-order" and r["cells"] == 140]
    if not ok or not ref:
        return "much slower than fv-split"
    fast = min(ok, key=lambda r: r["wall_s"])
    return (f"{fast['wall_s']:.3g} s at CFL {fast['cfl']:g} against "
            f"{ref[0]['wall_s'] * 1e3:.3g} ms for fv-split hll/first-order on the same grid, "
            f"{fast['wall_s'] / ref[0]['wall_s']:.0f}x, for a similar error")


def _findings(wp: dict[str, Any] | None, b: dict[str, Any] | None,
              layers: dict[str, Any] | None = None) -> str:
    L = ["## Findings\n"]
    if b:
        most = _most_signatures(b["sweep"])
        if most > 1:
            L.append(
                f"* **A kernel is compiled {most} times per process.** py-pde's "
                "controller passes `t_start = 0` as an int when the run starts (a float "
                "after a tracker interrupt, or from a direct stepper call), and "
                "`FVSplitSolver.make_stepper` hands it to the kernel unconverted, so numba "
                "compiles an `int64` and a `float64` version of the whole stepping loop. "
                "Cold, that doubles the compile time of the first runs; warm, both load "
                "from the cache. Fix (in `pdeflow/solvers/fv_split.py`): "
                "`advance(state.data, float(t_start), float(t_end))`.")
        two = b["sweep"]["ratio_two_vs_single_per_update"]
        cost = f"{two:.2f}x"
        if layers:
            r = layer_cost.ratios(layers)
            two = max(r.values())
            cost = " and ".join(f"{v:.2f}x ({w})" for w, v in r.items())
        L.append(
            f"* **The two-layer model costs {cost} the single layer per cell update** "
            f"(target 3x: {'met' if two <= 3 else 'missed'}). Part of it is inherent (4 "
            "fields, the path-conservative coupling, the coupled implicit friction, the "
            "mass exchange); the hyperbolicity stage is measured in the cell-update table "
            "(`none` against `exact`). It was 7.2x (2026-11-22) while the restoration "
            "searched F_extra by bracketing and bisection, re-solving the implicit "
            "friction at every trial. It is now a direct solve: "
            "the test is a quartic in (du)^2 with coefficients from h1/H and r; the band "
            "edge F_c1 is its root (Halley's method from the current du, 2-3 iterations); "
            "the closed-form friction step is inverted for the F_extra that lands du on "
            "it, and one friction solve confirms the branch."
            + (layer_cost.finding(layers) if layers else _hyp_share(b)))
        wet = ", ".join(f"{r['model']} {r['ratio']:.2f}x" for r in b["wet_region"])
        L.append(
            f"* **Dry cells: a 10x longer domain (same collapse, same dx) costs {wet}** "
            "(it was 4.6x for one layer and 1.8x for two on 2026-11-22, when only the "
            "advection loops skipped dry cells). Every stage of the stepping loop now "
            "visits only the wet region plus the stencil (the state backup, the update, "
            "the source stage, the MUSCL predictor); the first step visits all cells once "
            "to clean the initial state, and the wet region is searched in a window two "
            "cells wider than the last one. A test checks that the dry cells change "
            "nothing, bit for bit (`tests/test_active_region.py`).")
        r1 = b["sweep"]["ratio_single_vs_baseline_stepper"]
        L.append(
            "* **A scheme is compiled once; parameters and grids never recompile.** The "
            "stepping loop is one kernel per reconstruction order and splitting, for "
            "both models and every flux; the model's advection stage (one per model, "
            "flux, reconstruction and limiter), source stage and predictor are its "
            "arguments. Parameters are an array and the grid an argument, so a sweep "
            "over them never recompiles, and a run compiles only what its scheme calls "
            "(see *Cold first run*). What "
            "a scene does not need is skipped by branches: dry cells and absent layers "
            "(the loops' range and per-cell tests), the hyperbolicity stage where a layer "
            "is absent, F_extra writes except where it is applied, the time after rest "
            "(stop-at-rest table), trackers between their interrupts (one kernel call "
            "per interval). The price of that generality is measured against the "
            "hand-written single-layer loop, which is specialised to its one scheme: "
            f"{r1:.2f}x on the sweep. The loop allocates nothing per step: its scratch "
            "arrays come from the solver, and a test counts numba's allocations over a "
            "short and a ten times longer run "
            "(`tests/test_active_region.py::test_the_stepping_loop_allocates_nothing_per_step`).")
    if wp:
        probe = wp.get("mol_probe", [])
        rows = [r for c in wp["cases"].values() for r in c["rows"]
                if r["variant"] == "mol-rk"]
        ok_cases = sorted({(r["case"], r["model"]) for r in rows if r["status"] == "ok"})
        bad_cases = sorted({(r["case"], r["model"]) for r in rows if r["status"] != "ok"})
        L.append(
            "* **mol-rk** (py-pde's RK4 on the method-of-lines rate) works where the "
            "sources are mild: " + ", ".join(f"{c} ({m})" for c, m in ok_cases)
            + ". It fails on " + (", ".join(f"{c} ({m})" for c, m in bad_cases) or "none")
            + ": the regularised Coulomb and exchange terms (sgn(u) ~ u/mol_eps, closure "
            "denominator max(|du|, du_reg, mol_eps), mol_eps = 1e-3 m/s) have rates of "
            "order g tan(phi)/mol_eps ~ 10^4 1/s, far beyond what an explicit step of the "
            "CFL size can follow."
            + (" With smaller fixed steps (table above): " + "; ".join(
                f"CFL {r['cfl']:g}: {r['status']}" + (f" ({r['note']})" if r['note'] else
                                                      f", {r['wall_s']:.3g} s")
                for r in probe) + ": it runs once dt is 100x below the CFL step, then "
                f"crawls ({_crawl(wp)}; the cap stops anything slower)." if probe else "")
            + (" Every grid also pays for a new py-pde compilation of the stepper and the "
               "rate (`make_evolution_rate` builds a fresh, uncached numba closure), "
               "seconds per grid." if rows else ""))
    return "\n".join(L) + "\n"


# --- main ------------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", choices=("wp", "bench", "studies", "cold", "laws", *SECTIONS),
                   default=None, help="one part ('laws': only the friction-law rows of the "
                   "benchmark suite, merged into its stored results)")
    p.add_argument("--label", default="after",
                   help="name of the cold-start measurement (e.g. before, after)")
    p.add_argument("--tree", default=str(ROOT),
                   help="checkout whose cold first run is measured (default: this one)")
    p.add_argument("--commit", default=None,
                   help="commit of --tree, if it is no git checkout")
    p.add_argument("--sweeps", type=int, default=20,
                   help="5.2 sweeps at dx = 0.0025 m in the studies benchmark")
    p.add_argument("--render", action="store_true", help="only re-render the doc")
    p.add_argument("--quick", action="store_true", help="small smoke run")
    p.add_argument("--repeats", type=int, default=None, help="repeats (default 5; 2 quick)")
    p.add_argument("--no-pyclaw", action="store_true", help="skip PyClaw")
    p.add_argument("--doc", default=None,
                   help="report path (default docs/performance.md; with --quick "
                        "TMPDIR/pdeflow-bench-quick/performance.md)")
    args = p.parse_args(argv)
    repeats = args.repeats or (2 if args.quick else 5)
    results = Path(tempfile.gettempdir()) / "pdeflow-bench-quick" if args.quick else RESULTS
    results.mkdir(parents=True, exist_ok=True)
    doc = args.doc or str(results / "performance.md" if args.quick else DOC)
    wp_path, bench_path = results / "workprecision.json", results / "bench.json"
    studies_path = results / "studies.json"
    cold_path = results / "cold_start.json"
    paths = {name: results / file for name, (_, file, _) in SECTIONS.items()}
    if not args.render:
        import pyclaw_run

        pyclaw_run.available()  # importing clawpack configures logging: quieten py-pde
        logging.getLogger("pde").setLevel(logging.WARNING)
        logging.getLogger().setLevel(logging.WARNING)
        if args.only in (None, "bench"):
            b = measure_bench(args.quick, repeats, not args.no_pyclaw)
            bench_path.write_text(json.dumps(b, indent=1, default=str))
        if args.only == "laws":
            b = json.loads(bench_path.read_text()) if bench_path.exists() else {}
            b.update(measure_laws(repeats))
            bench_path.write_text(json.dumps(b, indent=1, default=str))
        if args.only in (None, "studies"):
            st = study_scaling.measure(args.quick, max(3, repeats // 2 + 1), args.sweeps)
            st["conditions"] = conditions()
            studies_path.write_text(json.dumps(st, indent=1, default=str))
        if args.only in (None, "cold"):
            c = json.loads(cold_path.read_text()) if cold_path.exists() else {}
            c[args.label] = cold_start.measure(max(3, repeats // 2 + 1), Path(args.tree),
                                               log=sys.stderr, commit_id=args.commit)
            cold_path.write_text(json.dumps(c, indent=1, default=str))
        for name, (module, _, least) in SECTIONS.items():
            if args.only in (None, name):
                paths[name].write_text(json.dumps(module.measure(max(repeats, least)),
                                                  indent=1, default=str))
        if args.only in (None, "wp"):
            w = measure_wp(args.quick, max(3, repeats) if not args.quick else repeats,
                           results)
            wp_path.write_text(json.dumps(w, indent=1, default=str))
    wp = json.loads(wp_path.read_text()) if wp_path.exists() else None
    bench = json.loads(bench_path.read_text()) if bench_path.exists() else None
    studies = json.loads(studies_path.read_text()) if studies_path.exists() else None
    cold = json.loads(cold_path.read_text()) if cold_path.exists() else None
    sections = {name: json.loads(path.read_text()) for name, path in paths.items()
                if path.exists()}
    Path(doc).write_text(render(wp, bench, studies, cold, sections))
    _log(f"written {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
