"""Studies on Dask: speed-up from 1 to 2 local workers, scheduling overhead, cost model.

Measured by ``python benchmarks/run_benchmarks.py --only studies`` (stored in
``benchmarks/measurements/studies.json``, rendered into docs/performance.md):

* **5.1 study**: a Latin hypercube of 512 points over phi_B, k, c of test 5.1 at
  dx = 0.05 m (two layers), run by ``pdeflow.study`` with 1 and with 2 local workers,
  interleaved over ``repeats`` rounds; wall time of the evaluation loop (the cluster's
  start is reported apart) and the speed-up of the medians.
* **5.2 sweeps**: ``sweeps`` points of the same space, each the whole 5.2 sweep at
  dx = 0.0025 m (two layers, MUSCL/mc, relaxed closure, as in the converged maps), once
  with 1 and once with 2 workers.
* **Overhead**: a function of 5 ms (``ishigami`` with ``delay = 0.005``) over 2000
  points on 2 workers: overhead per evaluation = (wall x workers - busy) / evaluations,
  busy being the time measured inside the evaluations.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tests.helpers import ishigami_study  # noqa: E402

PARAMETERS = """[parameters]
"two_layer.phi_b_deg" = { range = [30, 46] }
"two_layer.k" = { range = [0.2, 0.8] }
"two_layer.c" = { range = [0.01, 3], scale = "log" }
"""
"""the space of both case studies: the two-layer closure's phi_B [deg], k and c"""


def case_study(name: str, samples: int, seed: int, settings: list[str],
               quantities: list[str], sweep: bool = False) -> str:
    """The text of a Latin-hypercube study over ``PARAMETERS`` of test 5.1 (with
    ``sweep``, of the whole 5.2 sweep built on it), the case changed by ``settings``."""
    lines = ["[study]", f'name = "{name}"', f'case = "{CASES.as_posix()}/paper_5_1_dam_break.toml"',
             *([f'sweep_case = "{CASES.as_posix()}/collapse_sweep.toml"'] if sweep else []),
             f"set = {_toml_strings(settings)}", 'design = "lhs"', f"samples = {samples}",
             f"seed = {seed}", f"quantities = {_toml_strings(quantities)}"]
    return "\n".join(lines) + "\n" + PARAMETERS


def _toml_strings(items: list[str]) -> str:
    return "[" + ", ".join(f'"{x}"' for x in items) + "]"


def study_51(samples: int) -> str:
    """5.1 at dx = 0.05 m: lower-layer stop time and run-out (two layers)."""
    return case_study("bench_51", samples, 11, ["grid.dx=0.05"],
                      ["two_layer.lower_slow_time", "two_layer.runout"])


def study_52(samples: int, dx: float = 0.0025) -> str:
    """The 5.2 sweep at ``dx`` [m], MUSCL/mc, relaxed closure: the run-out exponent."""
    return case_study("bench_52", samples, 12,
                      [f"grid.dx={dx}", "two_layer.exchange_closure='relaxed'",
                       "numerics.reconstruction='muscl'", "numerics.limiter='mc'"],
                      ["sweep.two_layer.exponent"], sweep=True)


def study_delay(samples: int) -> str:
    """``ishigami`` with a fixed 5 ms per evaluation: the scheduling overhead."""
    return ishigami_study("lhs", samples, 13, delay=0.005, name="bench_overhead")


def _run(text: str, workers: int, tmp: Path, tag: str) -> dict[str, Any]:
    """One study run into a fresh directory: its execution record (meta.json)."""
    from pdeflow.study import load_study
    from pdeflow.study.execute import run_study

    path = tmp / f"{tag}.toml"
    path.write_text(text)
    out = tmp / f"{tag}_out"
    t0 = time.perf_counter()
    table = run_study(load_study(path), str(out), workers=workers, log=lambda m: None)
    info = dict(table.meta["executions"][-1])
    info["total_s"] = time.perf_counter() - t0
    return info


def measure(quick: bool = False, repeats: int = 3, sweeps: int = 20) -> dict[str, Any]:
    """The measurements of the module docstring."""
    n51 = 64 if quick else 512
    n52 = 2 if quick else sweeps
    out: dict[str, Any] = {"samples_51": n51, "sweeps_52": n52}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        # warm the numba cache of this process tree before anything is timed
        _run(study_51(4), 1, tmp, "warm")
        rounds: dict[int, list[dict[str, Any]]] = {1: [], 2: []}
        for r in range(repeats):
            for w in (1, 2):
                rounds[w].append(_run(study_51(n51), w, tmp, f"s51_{r}_{w}"))
        out["study_51"] = rounds
        med = {w: statistics.median(x["wall_s"] for x in rounds[w]) for w in rounds}
        out["speedup_51"] = med[1] / med[2]
        # quick: a smoke run of the code path, not a measurement
        text52 = study_52(n52, 0.01 if quick else 0.0025)
        s52 = {w: _run(text52, w, tmp, f"s52_{w}") for w in (1, 2)}
        out["study_52"] = s52
        out["speedup_52"] = s52[1]["wall_s"] / s52[2]["wall_s"]
        out["eval_52_s"] = s52[1]["evaluation_s"] / s52[1]["evaluations"]
        n_delay = 200 if quick else 2000
        out["overhead"] = _run(study_delay(n_delay), 2, tmp, "delay")
    return out


def render(s: dict[str, Any]) -> str:
    """The docs/performance.md section (``s`` as read back from JSON: string keys)."""
    r51, r52, ov = s["study_51"], s["study_52"], s["overhead"]

    def med(rows: list[dict[str, Any]], key: str) -> float:
        return statistics.median(x[key] for x in rows)

    L = ["## Studies on Dask\n",
         "Measured by `python benchmarks/run_benchmarks.py --only studies` "
         "(`benchmarks/study_scaling.py`): `pdeflow.study` on a `LocalCluster` of 1 and 2 "
         "worker processes on this 2-core machine; *loop* = wall time from the cluster "
         "being ready to the last row written, *busy* = time inside evaluations, "
         "*overhead per evaluation* = (loop x workers - busy) / evaluations.\n",
         "| study | evaluations | workers | cluster start [s] | loop [s] | busy [s] | "
         "overhead / evaluation [ms] | speed-up |",
         "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for w in ("1", "2"):
        rows = r51[w]
        sp = "" if w == "1" else f"{s['speedup_51']:.2f}x"
        L.append(f"| 5.1 at dx = 0.05 m (median of {len(rows)}) | {rows[0]['evaluations']} "
                 f"| {w} | {med(rows, 'startup_s'):.2f} | {med(rows, 'wall_s'):.2f} | "
                 f"{med(rows, 'evaluation_s'):.2f} | "
                 f"{1e3 * med(rows, 'overhead_per_evaluation_s'):.2f} | {sp} |")
    for w in ("1", "2"):
        x = r52[w]
        sp = "" if w == "1" else f"{s['speedup_52']:.2f}x"
        L.append(f"| 5.2 sweep at dx = 0.0025 m (MUSCL, relaxed) | {x['evaluations']} | {w} "
                 f"| {x['startup_s']:.2f} | {x['wall_s']:.1f} | {x['evaluation_s']:.1f} | "
                 f"{1e3 * x['overhead_per_evaluation_s']:.1f} | {sp} |")
    eff = ov["evaluation_s"] / (ov["wall_s"] * ov["workers"])
    L.append(f"| 5 ms function (`ishigami`, `delay = 0.005`) | {ov['evaluations']} | "
             f"{ov['workers']} | {ov['startup_s']:.2f} | {ov['wall_s']:.2f} | "
             f"{ov['evaluation_s']:.2f} | {1e3 * ov['overhead_per_evaluation_s']:.2f} | |")
    L.append("")
    ev1 = med(r51["1"], "evaluation_s") / r51["1"][0]["evaluations"]
    L.append(f"* One 5.1 evaluation costs {1e3 * ev1:.1f} ms; one 5.2 sweep at dx = 0.0025 m "
             f"{s['eval_52_s']:.1f} s. With 5 ms evaluations the scheduling overhead is "
             f"{1e3 * ov['overhead_per_evaluation_s']:.2f} ms per evaluation, "
             f"{100 * (1 - eff):.1f} % of the loop (target < 10 %): batches of about "
             "0.5 s of work make it one Dask task per ~100 evaluations.")
    b1, b2 = med(r51["1"], "evaluation_s"), med(r51["2"], "evaluation_s")
    L.append(f"* Speed-up 1 -> 2 workers (target >= 1.7x): {s['speedup_51']:.2f}x for 5.1, "
             f"{s['speedup_52']:.2f}x for the sweeps. What keeps 5.1 from 2x is not "
             f"scheduling: the same evaluations take {b2 / b1 - 1:.0%} longer when both "
             f"cores work (busy {b1:.2f} s on one worker, {b2:.2f} s on two), the cores "
             "sharing caches and memory bandwidth; for the sweeps it is the end of the "
             "study, where one worker finishes its last sweep alone.")
    t = s["eval_52_s"] * 4  # dx halved: twice the cells, twice the steps
    L.append(f"* **Cost model** for N workers: T = start + n t_eval / (N e), with e the "
             f"efficiency measured above (busy / (loop x workers): "
             f"{med(r51['2'], 'evaluation_s') / (med(r51['2'], 'wall_s') * 2):.2f} "
             "for 5.1 on 2 workers) and a start of seconds locally, about a minute for a "
             "batch-queue cluster. A Sobol study of the converged 5.2 law (10^4 sweeps at "
             f"dx = 0.00125 m, about 4 x {s['eval_52_s']:.0f} s = {t:.0f} s each on this "
             "machine's cores) costs "
             + ", ".join(f"{_hours(1e4 * t / n / 0.95)} on {n} core{'s' if n > 1 else ''}"
                         for n in (1, 16, 128))
             + " (e = 0.95; 128 cores stay busy for a 10^4-point design, 78 sweeps each).")
    L.append("")
    return "\n".join(L)


def _hours(seconds: float) -> str:
    if seconds >= 86400 * 2:
        return f"{seconds / 86400:.0f} days"
    return f"{seconds / 3600:.1f} h"
