"""The text of docs/rheology.md from its numbers (docs/rheology/numbers.json).

:func:`render_page` is a pure function of the numbers and the figure paths, so that
tests/test_rheology.py can check that the page says what the runs gave.
"""

from __future__ import annotations

import math
from typing import Any

from rheology_numbers import Q_MAX
from rheology_sources import LAGREE, PARAMETERS

GEOMETRY_TEXT = {
    "planar": ("Planar collapses (test 5.2)", "Lube et al. (2005), r = 1.9 a^(2/3) for "
               "a > 2.8 (Lube, Huppert, Sparks & Freundt 2005, *Collapses of "
               "two-dimensional granular columns*, Phys. Rev. E 72, 041301)",
               "mean |ln(r/r_Lube)| over a > 2.8"),
    "axisymmetric": ("Axisymmetric collapses", "Lube et al. (2004) as docs/axisymmetric.md "
                     "uses it, r = 1.24 a below a = 1.7 and 1.6 a^(1/2) above (remembered, "
                     "not confirmed there)",
                     "exp(rms of ln(r/r_Lube) over a = 0.5 .. 20) - 1"),
}


def _fit(f: list[float] | None) -> str:
    return "-" if not f else f"{f[0]:.3g} a^{f[1]:.3g}"


def _pct(x: float | None) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{x:.1%}"


def _from(m: dict[str, Any], law: str) -> str:
    g = m["convergence"][law]["converged_from"]
    return "not yet" if g is None else f"{g:g} m"


def _changes(m: dict[str, Any], law: str) -> str:
    c = m["convergence"][law]["changes"]
    return ", ".join(_pct(x) for x in c) if c else "-"


def summary_lines(numbers: dict[str, Any]) -> list[str]:
    """The answer: per geometry and model, the closest law on the finest grid, from which
    grid the ranking holds, and how far the run-outs have converged."""
    out = []
    for geometry in ("planar", "axisymmetric"):
        for model, m in numbers[geometry].items():
            fine = repr(m["grids"][-1])
            best = m["rankings"][-1][0]
            mis = m["per_grid"][best][fine]["misfit"]
            stable = m["ranking_stable_from"]
            last = {law: m["convergence"][law]["changes"][-1] for law in m["laws"]
                    if m["convergence"][law]["changes"]}
            worst = max(last, key=last.get) if last else None
            conv = [law for law, c in last.items() if c <= numbers["converged_threshold"]]
            rank = " < ".join(m["rankings"][-1])
            stable_txt = (f"the same on every grid from dx = {stable:g} m on"
                          if stable is not None else
                          "**not yet stable** (it changed between the finest two grids)")
            conv_txt = (f"the run-outs changed by at most {_pct(last[worst])} ({worst}) in "
                        f"the last halving (to dx = {m['grids'][-1]:g} m); within "
                        f"{numbers['converged_threshold']:.0%}: "
                        f"{', '.join(conv) if conv else 'none'}" if worst else
                        "one grid only: convergence not measured")
            close = "; ".join(f"{a} and {b} differ by {gap:.3g}, less than their last "
                              f"change {ch:.3g}" for a, b, gap, ch in m["close_pairs"])
            part = "; ".join(f"dx = {g:g} m begun ({n} of {n_all} runs, left out until "
                             "complete: the next call resumes it)"
                             for g, n, n_all in m.get("partial_grids", []))
            out.append(f"* **{geometry}, {model}**: closest is **{best}** (distance "
                       f"{mis:.3f} on dx = {m['grids'][-1]:g} m); ranking {rank}, "
                       f"{stable_txt}" + (f" (but {close})" if close else "")
                       + f"; {conv_txt}" + (f"; {part}" if part else "") + ".")
    return out


def static_lines(numbers: dict[str, Any]) -> list[str]:
    """The ranking next to the laws' static friction angles (what mostly sets it)."""
    out = [f"Read the ranking with each law's static friction angle (a layer "
           f"{numbers['static_depth'] * 1000:g} mm deep, default parameters; Coulomb's is "
           "the model's phi_b, the two-layer one the lower layer's bed):", ""]
    for geometry in ("planar", "axisymmetric"):
        for model, m in numbers[geometry].items():
            ang = numbers["static_angles"][geometry][model]
            by_angle = sorted(m["laws"], key=lambda law: -ang[law])
            rank = m["rankings"][-1]
            moved = [law for law, other in zip(rank, by_angle, strict=True) if law != other]
            same = ("the same order" if not moved else
                    f"the same order except {', '.join(moved)}")
            angles = ", ".join(f"{law} {ang[law]:.1f}" for law in by_angle)
            out.append(f"* {geometry}, {model}: {angles} deg (highest first); the ranking "
                       f"on the finest grid is {same}.")
    spread = max(max(v.values()) - min(v.values())
                 for g in numbers["static_angles"].values() for v in g.values())
    over = all(m["per_grid"][law][repr(m["grids"][-1])]["bias"] > 1
               for g in ("planar", "axisymmetric") for m in numbers[g].values()
               for law in m["laws"])
    out += ["", "So at their defaults the comparison mostly ranks the laws' static "
            f"friction, which differs by up to {spread:.0f} deg between them, and less "
            "their rate dependence: a law with a lower static angle spreads further"
            + (", and every law here over-predicts the experiments' run-out (every "
               "r/r_Lube above 1), so the highest static angle comes closest" if over
               else "") + ". A comparison of the laws at one common static angle (each "
            "law's rate dependence alone) was not run.", ""]
    return out


def planar_table(m: dict[str, Any], model: str) -> list[str]:
    grids = m["grids"]
    head = ("| law | fit r = p a^e (finest) | " + " | ".join(
        f"misfit dx={g:g}" for g in grids) + " | r/r_Lube (finest) | change per halving "
        "| <= 1 % per halving from | tail estimate | at rest |")
    lines = [head, "|---|---|" + "---:|" * len(grids) + "---:|---|---|---:|---|"]
    for law in m["laws"]:
        p = m["per_grid"][law]
        fine = p[repr(grids[-1])]
        lines.append(
            f"| {law} | {_fit(fine['fit'])} | " + " | ".join(
                f"{p[repr(g)]['misfit']:.3f}" for g in grids)
            + f" | {fine['bias']:.2f} | {_changes(m, law)} | {_from(m, law)} | "
            f"{_pct(m['convergence'][law]['tail'])} | "
            f"{all(p[repr(g)]['all_at_rest'] for g in grids)} |")
    return [f"**{model}**", "", *lines, ""]


def axisymmetric_table(m: dict[str, Any], model: str) -> list[str]:
    grids = m["grids"]
    head = ("| law | fit a < 1.7 | fit a > 1.7 | " + " | ".join(
        f"distance dr={g:g}" for g in grids) + " | r/r_Lube at a = 20 | distance of "
        "H_inf/R0 | change per halving | <= 1 % per halving from | tail estimate | at rest |")
    lines = [head, "|---|---|---|" + "---:|" * len(grids) + "---:|---:|---|---|---:|---|"]
    for law in m["laws"]:
        p = m["per_grid"][law]
        fine = p[repr(grids[-1])]
        lines.append(
            f"| {law} | {_fit(fine['fit_low'])} | {_fit(fine['fit_high'])} | "
            + " | ".join(f"{p[repr(g)]['misfit']:.0%}" for g in grids)
            + f" | {fine['bias']:.2f} | {fine['d_height']:.0%} | {_changes(m, law)} | "
            f"{_from(m, law)} | {_pct(m['convergence'][law]['tail'])} | "
            f"{all(p[repr(g)]['all_at_rest'] for g in grids)} |")
    return [f"**{model}**", "", *lines, ""]


def ranking_lines(numbers: dict[str, Any]) -> list[str]:
    out = ["| geometry | model | " + "ranking per grid, coarse to fine (closest first) |",
           "|---|---|---|"]
    for geometry in ("planar", "axisymmetric"):
        for model, m in numbers[geometry].items():
            per = "; ".join(f"dx {g:g}: {' < '.join(r)}" for g, r in zip(
                m["grids"], m["rankings"], strict=True))
            out.append(f"| {geometry} | {model} | {per} |")
    return out


def lagree_lines(numbers: dict[str, Any]) -> list[str]:
    """Our planar mu_i with Lagree et al.'s constants against their findings."""
    out = [LAGREE]
    for model, m in numbers["planar"].items():
        if "mu_i_lagree" not in m["laws"]:
            continue
        fine = repr(m["grids"][-1])
        lg, df = m["per_grid"]["mu_i_lagree"][fine], m["per_grid"]["mu_i"][fine]
        out.append(
            f"* {model} (dx = {m['grids'][-1]:g} m): mu_i with their constants gives "
            f"r = {_fit(lg['fit'])}, {lg['bias']:.2f} times Lube et al.'s law on average "
            f"over a > 2.8 (misfit {lg['misfit']:.3f}); with the glass-bead defaults "
            f"{_fit(df['fit'])}, {df['bias']:.2f} times.")
    fines = [m["per_grid"][law][repr(m["grids"][-1])] for m in numbers["planar"].values()
             for law in m["laws"]]
    over = all(f["bias"] > 1 for f in fines)
    steeper = all(f["fit"][1] > 2 / 3 for f in fines)
    exps = sorted(f["fit"][1] for f in fines)
    away = all(abs(math.log(m["per_grid"]["mu_i_lagree"][repr(m["grids"][-1])]["bias"]))
               > abs(math.log(m["per_grid"]["mu_i"][repr(m["grids"][-1])]["bias"]))
               for m in numbers["planar"].values() if "mu_i_lagree" in m["laws"])
    out += ["", "Where they find a continuum that *under*-predicts the discrete run-out and "
            "recovers the experimental scalings, the depth-averaged laws here "
            + ("*over*-predict the experimental run-out (every ratio above 1)" if over else
               "do not all under-predict it")
            + (" and grow faster than a^(2/3)" if steeper else " and not all as a^(2/3)")
            + f" (exponents {exps[0]:.2f}-{exps[-1]:.2f} on the finest planar grid). "
            "Their continuum resolves the column's vertical structure; a depth-averaged "
            "model sees the flow only through its basal friction, which suggests that the "
            "disagreement lies in the model class rather than in the mu(I) constants: "
            "with their constants the run-out moves "
            + ("*away from*" if away else "towards") + " the experiments (the lines above). "
            "The contact-dynamics simulations of Staron & Hinch (2005, J. Fluid Mech. 545), "
            "which Gerris's column example (gfs.sourceforge.net/examples/examples/column) "
            "compares its mu(I) run with, agree with the experiments by their abstract "
            "(https://vdocuments.mx/discrete-simulation-of-the-collapse-of-granular-columns-"
            "damtp.html).", ""]
    return out


def cost_lines(cost: dict[str, Any] | None) -> list[str]:
    """The stored friction-law benchmark (docs/performance.md) against issue 23's target."""
    if not cost:
        return ["Not measured yet (`python benchmarks/run_benchmarks.py --only laws`)."]
    c = cost.get("conditions") or {}
    load = c.get("load_avg_at_start")
    per = "; ".join(f"{r['model']} {r['law']} {r['ratio']:.2f}x" for r in cost["rows"])
    met = {r["model"]: r["ratio"] <= 1.2 for r in cost["rows"] if r["law"] == "pouliquen"}
    verdict = ", ".join(f"{m}: {'met' if ok else 'missed'}" for m, ok in met.items())
    return [f"Time per cell update against Coulomb's, paired and interleaved in one run "
            f"(docs/performance.md, `python benchmarks/run_benchmarks.py --only laws`, "
            f"{c.get('date', '?')}, load average {load[0]:.2f} on {c.get('cores')} shared "
            f"cores at the start): {per}. Issue 23's target, pouliquen at most 1.2x: "
            f"{verdict}. On a machine this loaded the ratios differ from run to run (docs/"
            "model.md lists earlier measurements), so one run decides little."
            if load else f"Per cell update against Coulomb's: {per}."]


def render_page(numbers: dict[str, Any], figs: dict[str, str]) -> str:
    """docs/rheology.md."""
    lines = [
        "# Basal friction laws on the planar and axisymmetric collapses\n",
        "Generated by `python docs/generate/rheology.py` (do not edit by hand; every "
        f"number and figure; {numbers['runs']} runs to rest cached in "
        f"docs/rheology/sweep.csv, {numbers['wall_s']:g} s of run time; `--rerun` runs "
        "them all again, `--no-runs` renders the cache as it is). Both models (the two-layer "
        "one at its defaults, not the planar law set of docs/axisymmetric.md; the law "
        "replaces its lower layer's bed friction), each basal "
        "law (`<model>.friction_law`) at its documented defaults, on the planar collapse "
        "of test 5.2 (cases/collapse_sweep.toml, L0 = 0.1 m, a 30 m domain) and the "
        "axisymmetric collapse (cases/axisymmetric_collapse_sweep.toml, R0 = 0.1 m, "
        "6 m), on successively halved grids; the planar sweep also runs `mu_i` with the "
        "mu(I) constants of Lagree, Staron & Popinet (2011) (`mu_i_lagree`). The laws are "
        "not calibrated to the experiments: this compares their shapes at their papers' "
        "values. The run-out r = (R - L0)/L0 uses the threshold front R (the downstream "
        "face of the last cell deeper than 1 mm) in every fit, distance and figure; the "
        "cached rows predate the run-out holding 99 % of the mass (`runout_mass_quantile`), "
        "which `--rerun` would be needed to add.\n",
        "## The answer\n", *summary_lines(numbers), "",
        f"Checks: every run ended at rest: {numbers['all_at_rest']}; largest relative mass "
        f"error {numbers['max_mass_error']:.1e}; run warnings other than the cost "
        f"estimate: {'; '.join(numbers['other_warnings']) or 'none'}.\n", *static_lines(numbers),
        "\"Distance\" is the planar misfit or the axisymmetric distance of the tables "
        "below. Change per halving: the largest |r_fine/r_coarse - 1| over the aspect "
        "ratios, for each halving of dx, coarse to fine. Tail estimate (Richardson-type, "
        "stated as such): if each point's change keeps shrinking by the ratio q of its "
        "last two changes, the finest grid is off by change q/(1 - q); '-' where some "
        f"point's q exceeds {Q_MAX:g} (the changes not shrinking steadily yet). A run-out "
        "is resolved to one cell (dx/L0 in r), so changes of a cell or two are at the "
        "resolution.\n"]
    for geometry, table in (("planar", planar_table), ("axisymmetric", axisymmetric_table)):
        title, law, metric = GEOMETRY_TEXT[geometry]
        lines += [f"## {title}\n", f"Against {law}; distance: {metric}.\n",
                  f"![r(a) per law, {geometry}]({figs[geometry]})\n"]
        for model, m in numbers[geometry].items():
            lines += table(m, model)
    lines += ["## Ranking and convergence per grid\n", *ranking_lines(numbers), "",
              f"![change per halving]({figs['convergence']})\n", *lagree_lines(numbers),
              PARAMETERS,
              "## Cost\n", *cost_lines(numbers.get("cost")), ""]
    return "\n".join(lines)
