"""The work-precision section of docs/performance.md (measured by
``run_benchmarks.measure_wp``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from doc_tables import fmt, md_table

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
"""a note under the heading of a work-precision case, by name"""


def wp_table(rows: list[dict[str, Any]]) -> str:
    """The table of one work-precision case: a row per model, variant and grid."""
    def line(r: dict[str, Any]) -> str:
        st = r["status"] if r["status"] == "ok" else f"{r['status']}: {r['note']}"
        return (f"| {r['model']} | {r['variant']} | {r['cells']} | "
                f"{fmt(r['err_h'], '.3e')} | {fmt(r['err_hu'], '.3e')} | "
                f"{fmt(r['order_h'], '.2f')} | {fmt(r['wall_s'] * 1e3, '.3g')} | "
                f"{fmt(r['compile_s'], '.2g')} | {r['steps']} | {st} |")

    return "\n".join(md_table(
        ["model", "variant", "cells", "L1 depth [m^2]", "L1 momentum [m^3/s]",
         "order (depth)", "wall [ms]", "compile [s]", "steps", "status"], "llrrrrrrrl",
        map(line, rows)))


def cheapest(rows: list[dict[str, Any]], model: str) -> str:
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


def render_wp(wp: dict[str, Any]) -> str:
    """The section "Work precision": every case's figure, cheapest variant and table,
    the mol-rk probe and the hyperbolicity modes."""
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
            line = cheapest(rows, model)
            if line:
                L.append(f"* {line}")
        L.append("")
        L.append(wp_table(rows) + "\n")
    p = wp.get("mol_probe", [])
    if p:
        L.append("### mol-rk on the two-layer 5.1 case: smaller steps\n")
        L.append("dx = 0.05 m to t = 0.4 s, compared with hll/first-order fv-split on "
                 "dx = 0.0125 m; the CFL number sets the fixed RK4 step; cap 30 s. For "
                 "comparison, fv-split hll/first-order needs about 0.01 s for this run.\n")
        L += md_table(["CFL", "dt [s]", "status", "L1 depth [m^2]", "wall [s]", "note"],
                    "rrlrrl",
                    (f"| {r['cfl']:g} | {fmt(r.get('dt'), '.3g')} | {r['status']} | "
                     f"{fmt(r['err_h'], '.3e')} | {fmt(r['wall_s'], '.3g')} | {r['note']} |"
                     for r in p))
        L.append("")
    h = wp.get("hyperbolicity", [])
    if h:
        L.append("### Hyperbolicity modes on 5.1 (two layers, to rest)\n")
        L += md_table(["mode", "cells", "wall [ms]", "steps", "max F_extra/rho1 [m^2/s^2]",
                     "hyperbolicity events (cell-steps)", "of which bisected",
                     "lower stop [s]", "upper stop [s]", "run-out [m]"], "l" + "r" * 9,
                    (f"| {r['mode']} | {r['cells']} | {r['wall_s'] * 1e3:.3g} | "
                     f"{r['steps']} | {fmt(r['max_fextra_over_rho1'], '.3g')} | "
                     f"{r['hyperbolicity_events']} | "
                     f"{r.get('hyperbolicity_bisections', '-')} | "
                     f"{fmt(r['lower_stop_time'], '.3f')} | "
                     f"{fmt(r['upper_stop_time'], '.3f')} | {fmt(r['runout'], '.3f')} |"
                     for r in h))
        L.append("")
    return "\n".join(L)


def crawl(wp: dict[str, Any]) -> str:
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
