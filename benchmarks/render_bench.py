"""The benchmark-suite section of docs/performance.md (``suite.py``, measured by
``run_benchmarks.measure_bench``)."""

from __future__ import annotations

import math
from typing import Any

from doc_tables import fmt, loads_text, md_table


def render_bench(b: dict[str, Any]) -> str:
    """The section "Benchmarks": cell updates, friction laws, compilation, 5.1 to rest,
    the large grid, the 5.2-like sweep and what is skipped."""
    L = ["## Benchmarks\n", "### Cell updates per second (5.1 case, dx = 0.0125 m, "
         "t = 0.4 s, compiled stepper)\n"]
    L += md_table(["model", "variant", "cells", "steps", "wall [ms]", "cell updates/s",
                 "ns/update"], "llrrrrr",
                (f"| {r['model']} | {r['variant']} | {r['cells']} | {r['steps']} | "
                 f"{r['wall_s'] * 1e3:.3g} | {r['cell_updates_per_s']:.3g} | "
                 f"{r['ns_per_cell_update']:.3g} |" for r in b["rates"]))
    if b.get("friction_laws"):  # measured since issue 23
        L += ["", "### Basal friction laws (a dam break onto a wet 30 deg slope, "
              "hll/first-order, interleaved with Coulomb; target for pouliquen: <= "
              "1.2x)\n"]
        L += md_table(["model", "law", "Coulomb ns/update", "law ns/update", "ratio",
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
                  f"{loads_text(c.get('load_avg_at_start'))} at the start and "
                  f"{loads_text(c.get('load_avg_at_end'))} at the end on {c.get('cores')} "
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
        L.append(f"| {k} | {fmt(r.get('import_s'))} | {fmt(r.get('single_layer_first_s'))} | "
                 f"{fmt(r.get('single_layer_second_s'))} | {fmt(r.get('two_layer_first_s'))} "
                 f"| {fmt(r.get('two_layer_second_s'))} | {fmt(r.get('process_s'))} | "
                 f"{r.get('cache_hits')} / {r.get('cache_misses')} |")
    L += ["", ("The cold first run compiles the stepping loop (one kernel for both "
               "models) and the kernels of the case's scheme (see the cold first run "
               "below)." if "max_signatures" in b["sweep"] else
               "The cold first run compiles every kernel reached from `advance_split` "
               "(both models share one dispatcher; the first run of either model compiles "
               "it, the other then finds it compiled).") + "\n",
          "### The 5.1 case to rest (dx = 0.05 m, 140 cells)\n"]
    L += md_table(["model", "steps", "rest at [s]", "run_model [ms]", "stepper alone [ms]"],
                "lrrrr",
                (f"| {r['model']} | {r['steps']} | {r['t_rest']:.3f} | "
                 f"{r['wall_s'] * 1e3:.3g} | {r['stepper_wall_s'] * 1e3:.3g} |"
                 for r in b["case_5_1"]))
    if "large_grid" in b:  # measurements older than this table lack it
        L += render_large_grid(b["large_grid"])
    L += _sweep_table(b["sweep"])
    L += _skipping_tables(b)
    L.append("")
    return "\n".join(L)



def _sweep_table(s: dict[str, Any]) -> list[str]:
    """The 5.2-like sweep: per height and in total, pdeflow, the baseline, PyClaw."""
    L: list[str] = []
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
    return L


def _skipping_tables(b: dict[str, Any]) -> list[str]:
    """What a scene does not need: the wet region only, stopping at rest."""
    L: list[str] = []
    L += ["### Skipping what a scene does not need\n",
          "**Wet region only** (same collapse on a domain 10x longer, same dx):\n"]
    L += md_table(["model", "cells", "steps", "wall [ms]", "cells (10x)", "steps", "wall [ms]",
                 "ratio"], "lrrrrrrr",
                (f"| {r['model']} | {r['cells']} | {r['steps']} | {r['wall_s'] * 1e3:.3g} | "
                 f"{r['cells_long']} | {r['steps_long']} | {r['wall_long_s'] * 1e3:.3g} | "
                 f"{r['ratio']:.2f}x |" for r in b["wet_region"]))
    L += ["", "**Stopping at rest** (5.1 with t_end = 5 s, `FVSplitSolver(stop_at_rest=...)`):"
          "\n"]
    L += md_table(["model", "rest at [s]", "steps (stop)", "wall [ms]", "steps (no stop)",
                 "wall [ms]", "saved"], "lrrrrrr",
                (f"| {r['model']} | {r['t_rest']:.3f} | {r['steps_on']} | "
                 f"{r['wall_on_s'] * 1e3:.3g} | {r['steps_off']} | "
                 f"{r['wall_off_s'] * 1e3:.3g} | {100 * r['saving']:.0f} % |"
                 for r in b["stop_at_rest"]))
    return L

def render_large_grid(rows: list[dict[str, Any]]) -> list[str]:
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
            *md_table(["model", "cells", "steps", "reached t [s]", "wall [ms]",
                     "ns/update"], "lrrrrr",
                    (f"| {r['model']} | {r['cells']} | {r['steps']} | {r['t']:.3g} | "
                     f"{r['wall_s'] * 1e3:.3g} | {r['ns_per_cell_update']:.3g} |"
                     for r in rows))]


def hyperbolicity_share(b: dict[str, Any]) -> str:
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
