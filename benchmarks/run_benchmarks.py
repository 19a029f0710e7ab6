"""Run the work-precision studies and the benchmark suite; write docs/performance.md.

Usage (from the repository root)::

    python benchmarks/run_benchmarks.py                 # everything (~15-25 min)
    python benchmarks/run_benchmarks.py --only wp       # work precision only
    python benchmarks/run_benchmarks.py --only bench    # benchmark suite only
    python benchmarks/run_benchmarks.py --only studies  # pdeflow study on Dask (~25 min)
    python benchmarks/run_benchmarks.py --only cold --label after  # cold first run (~3 min)
    python benchmarks/run_benchmarks.py --only bed      # a long erodible bed at rest
    python benchmarks/run_benchmarks.py --only start    # warm start, kernel load, app (~4 min)
    python benchmarks/run_benchmarks.py --only pyclaw2d # 2D dam break against PyClaw (~3 min)
    PDEFLOW_AVAFRAME=PATH python benchmarks/run_benchmarks.py --only terrain  # a real path
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
import os
import platform
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT))

import cold_start  # noqa: E402
import study_scaling  # noqa: E402
import suite  # noqa: E402
from performance_doc import SECTIONS, render  # noqa: E402

RESULTS = ROOT / "benchmarks" / "measurements"  # not "results/": git-ignored
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
    from pdeflow.analysis.workprecision_outputs import plot
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
        fig = plot(res, figures / f"workprecision_{res.case}.png")
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
            skip = (name == "pyclaw2d" and args.no_pyclaw) or (
                name == "terrain" and args.only is None
                and not os.environ.get("PDEFLOW_AVAFRAME"))  # AvaFrame's DEM is the user's
            if args.only in (None, name) and not skip:
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
