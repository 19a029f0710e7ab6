"""Cost of the two-layer model against the single layer, per cell update.

Two workloads, each with the compiled fv-split stepper (no py-pde controller, no trackers;
``suite.fv_stepper_run``):

* **5.1**: the dam break of cases/paper_5_1_dam_break.toml at dx = 0.0125 m to
  t = 0.4 s, hll/first-order (the cell-update table's case);
* **sweep**: the 5.2-like collapses of the benchmark sweep (L0 = 0.1 m, H0 = 0.2 .. 3 m,
  dx = 0.01 m, to rest; ``suite.sweep_case``), cell updates and wall times summed over
  the heights (the definition of the sweep's ``ratio_two_vs_single_per_update``).

Each workload runs the single layer, the two layers, and the two layers with
``hyperbolicity = "none"`` (no F_extra: the restoration's share), interleaved (one call
of each per round, so that a change of the machine's load hits all alike); the ns per
cell update are medians over rounds, the ratios those of the medians; the median of the
per-round ratios is kept as well. A cell update is one cell of the grid advanced by one
step (cells x steps, dry cells included).

    python benchmarks/run_benchmarks.py --only layers   # measure, then re-render
"""

from __future__ import annotations

import os
import statistics
from collections.abc import Callable
from typing import Any

import suite

TARGET = 3.0
"""the two-layer cost per cell update at most this many times the single layer's"""
VARIANTS = ("single_layer", "two_layer", "two_layer, hyperbolicity none")


def _runs(workload: str) -> list[tuple[str, Callable[[], dict[str, Any]]]]:
    """(variant, run) of every variant (and sweep height) of a workload, as
    ``suite.fv_stepper_run`` callables."""
    from pdeflow.analysis.points import case_on_grid, resolve_case
    from pdeflow.variant import Variant

    out = []
    for variant in VARIANTS:
        model = variant.split(",")[0]
        if workload == "5.1":
            cases = [case_on_grid(resolve_case(suite.CASE_5_1), 0.0125,
                                  Variant.parse("hll/first-order"))]
        else:
            cases = [suite.sweep_case(H0, model) for H0 in suite.SWEEP_H0]
        for case in cases:
            if variant.endswith("none"):
                case.data.setdefault("two_layer", {})["hyperbolicity"] = "none"
            out.append((variant, suite.fv_stepper_run(case, model,
                                                      0.4 if workload == "5.1" else None)))
    return out


def _measure_workload(workload: str, repeats: int) -> dict[str, Any]:
    """ns per cell update of every variant of ``workload`` and the ratios to one layer."""
    runs = _runs(workload)
    outs = [run() for _, run in runs]  # warm-up: compiles or loads the kernels
    walls = suite.interleaved_walls([run for _, run in runs], repeats)
    rows: dict[str, dict[str, Any]] = {}
    for variant in VARIANTS:
        mine = [k for k, (v, _) in enumerate(runs) if v == variant]
        updates = sum(outs[k]["steps"] * outs[k]["cells"] for k in mine)
        rounds = [sum(walls[k][j] for k in mine) for j in range(repeats)]
        rows[variant] = {"cell_updates": updates, "steps": [outs[k]["steps"] for k in mine],
                         "wall_s": statistics.median(rounds), "walls": rounds,
                         "ns_per_update": 1e9 * statistics.median(rounds) / updates}
    one = rows["single_layer"]
    for row in rows.values():
        row["ratio"] = row["ns_per_update"] / one["ns_per_update"]
        per_round = [(w / row["cell_updates"]) / (w1 / one["cell_updates"])
                     for w, w1 in zip(row["walls"], one["walls"], strict=True)]
        row["ratio_rounds_median"] = statistics.median(per_round)
    return {"rows": rows, "repeats": repeats}


def measure(repeats: int = 9) -> dict[str, Any]:
    """Both workloads (the 5.1 case with three times the rounds: its runs are short),
    with the 1-min load average before and after each."""
    out: dict[str, Any] = {"workloads": {}}
    for workload, rounds in (("5.1", 3 * repeats), ("sweep", repeats)):
        start = os.getloadavg()[0]
        data = _measure_workload(workload, rounds)
        data["load_avg"] = [start, os.getloadavg()[0]]
        out["workloads"][workload] = data
    return out


def ratios(data: dict[str, Any]) -> dict[str, float]:
    """Two layers over one layer per cell update, per workload."""
    return {w: d["rows"]["two_layer"]["ratio"] for w, d in data["workloads"].items()}


def target_row(data: dict[str, Any]) -> str:
    """The row of the Targets table: met when both workloads are at most TARGET."""
    parts = []
    for w, d in data["workloads"].items():
        one, two = d["rows"]["single_layer"], d["rows"]["two_layer"]
        parts.append(f"{w}: {two['ratio']:.2f}x ({two['ns_per_update']:.1f} vs "
                     f"{one['ns_per_update']:.1f} ns, load {d['load_avg'][0]:.1f})")
    ok = max(ratios(data).values()) <= TARGET
    return (f"| two-layer <= {TARGET:g}x the single-layer cost per cell update | "
            f"{'; '.join(parts)} (see *Two layers against one*) | "
            f"{'**met**' if ok else '**missed**'} |")


def finding(data: dict[str, Any]) -> str:
    """Sentence of the Findings on the restoration's share (the ``none`` rows)."""
    out = []
    for w, d in data["workloads"].items():
        one, two = d["rows"]["single_layer"], d["rows"]["two_layer"]
        none = d["rows"]["two_layer, hyperbolicity none"]
        out.append(f"{w}: {two['ns_per_update']:.0f} ns per cell update against "
                   f"{none['ns_per_update']:.0f} ns with `hyperbolicity = \"none\"` "
                   f"({none['ns_per_update'] / one['ns_per_update']:.1f}x one layer)")
    return (" Without the restoration (*Two layers against one*): " + "; ".join(out)
            + ". Most of the two-layer time goes to the source stage: chains of dependent "
            "divisions and square roots (the exchange, the coupled friction solve, and in "
            "a restored cell the band edge's Halley iteration and a second friction "
            "solve).")


def render(data: dict[str, Any]) -> str:
    """The docs/performance.md section from :func:`measure`'s result."""
    L = ["## Two layers against one: cost per cell update\n",
         "Measured by `python benchmarks/run_benchmarks.py --only layers` "
         "(`benchmarks/layer_cost.py`) with the compiled fv-split stepper: **5.1** is "
         "cases/paper_5_1_dam_break.toml at dx = 0.0125 m to t = 0.4 s (hll/first-order), "
         "**sweep** the benchmark sweep's collapses (L0 = 0.1 m, H0 = 0.2 .. 3 m, "
         "dx = 0.01 m, to rest), summed over the heights. The variants of a workload run "
         "interleaved; ns per cell update (cells x steps) are medians over rounds. "
         f"Target: two layers at most {TARGET:g}x one layer on both. The ratio depends on "
         "the machine's load: the two cores are shared (and may be two threads of one "
         "core), and the single layer's loops suffer more from a busy neighbour than the "
         "two-layer source stage, whose cost is chains of dependent divisions and square "
         "roots; compare ratios measured at similar loads. Which kernels the time goes "
         "to: `python benchmarks/kernel_profile.py` (perf's samples on the compiled "
         "kernels, `--model single_layer` for one layer).\n",
         "| workload | rounds | load (start, end) | variant | cell updates | ns per update "
         "| / single layer | median of per-round ratios |",
         "|---|---:|---|---|---:|---:|---:|---:|"]
    for w, d in data["workloads"].items():
        load = ", ".join(f"{x:.1f}" for x in d["load_avg"])
        for variant, row in d["rows"].items():
            L.append(f"| {w} | {d['repeats']} | {load} | {variant} | {row['cell_updates']} "
                     f"| {row['ns_per_update']:.1f} | {row['ratio']:.2f} "
                     f"| {row['ratio_rounds_median']:.2f} |")
    return "\n".join(L) + "\n"
