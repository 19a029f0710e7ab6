"""The text of docs/axisymmetric.md from the numbers of docs/generate/axisymmetric.py.

:func:`render_page` is a pure function of the numbers (docs/axisymmetric/numbers.json), so
that tests/test_axisymmetric_docs.py can check that the page says what the runs gave.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from axisymmetric import BREAK, PROFILE_DX, PROFILE_RATIOS, R0, SETS, lube_runout
from axisymmetric_figures import figures  # noqa: F401  (main() calls page.figures)
from axisymmetric_sources import SOURCES

from pdeflow.analysis.sweep import run_sweep
from pdeflow.cases import load_case

CONVERGED = 0.01
"""largest relative change of r(a) between the finest two grids that counts as converged"""
SHAPES = ((0.7, "flat-topped"), (1.5, "cone"), (math.inf, "steep centre on a thin skirt"))
"""slope ratio (inner half / outer half of the deposit) below which a shape is so named
(a deposit that keeps an undisturbed top at H0 is a truncated cone whatever its ratio)"""


def shape_numbers(x: np.ndarray, h: np.ndarray, H0: float, threshold: float = 1e-3) -> dict:
    """A deposit's shape [x, h in m]: its summit over R0, the radius of its undisturbed
    top over R0 (depth still H0), the ratio of its mean slope over the inner half of its
    radius to that over the outer half (a cone 1, a flat top < 1, a peak on a skirt > 1),
    its run-out at a tenth of ``threshold`` [m], the share of its volume beyond the
    run-out at ``threshold``, and its raised ring: how far [over R0] and where [r/R0] the
    depth climbs again on the way out (0 for a deposit that only falls)."""
    wet = np.nonzero(h > threshold)[0]
    rf = float(x[wet[-1]]) if wet.size else float(x[0])
    mid = float(np.interp(rf / 2, x, h))
    inner, outer = (float(h[0]) - mid) / (rf / 2), mid / (rf / 2)
    top = np.nonzero(np.abs(h - H0) <= 1e-9)[0]
    ratio = inner / outer if outer > 0 else math.inf
    top_radius = float(x[top[-1]]) / R0 if top.size else 0.0
    name = ("truncated cone" if top_radius > 0.05 else
            next(n for bound, n in SHAPES if ratio < bound))
    dx = float(x[1] - x[0])
    thin = np.nonzero(h > threshold / 10)[0]
    rise = h - np.minimum.accumulate(h)  # how far the depth climbs again outwards
    ring = int(np.argmax(rise))
    return {"ring": float(rise[ring]) / R0, "ring_radius": float(x[ring]) / R0,
            "summit": float(h[0]) / R0, "top_radius": top_radius, "slope_ratio": ratio,
            "shape": name, "r_01mm": (float(x[thin[-1]]) + dx / 2 - R0) / R0,
            "beyond": float(np.sum((h * x)[x > rf]) / np.sum(h * x))}


def profile_numbers(profiles: dict[str, Any]) -> dict[str, Any]:
    """Per set and a of the profile runs: shape, stop times and the time the front took to
    reach 95 % of its final run-out, all times over (H0/g)^(1/2)."""
    out = {}
    for key, p in profiles.items():
        a = float(key.split("|")[1])
        scale = math.sqrt(a * R0 / 9.81)
        front = np.asarray(p["front"])
        t95 = float(p["t"][np.nonzero(front >= 0.95 * front[-1])[0][0]]) / scale
        entry = shape_numbers(p["x"], p["h"], a * R0)
        entry.update({"t95": t95, "stop": p["stop_time"] / scale, "r": float(front[-1]),
                      "lower_stop": (p["lower_stop_time"] or math.nan) / scale,
                      "upper_stop": (p["upper_stop_time"] or math.nan) / scale})
        out[key] = entry
    return out


def planar_law_check(grids: tuple[float, ...] = (0.01, 0.0025)) -> list[list[float]]:
    """The planar law set of cases/paper_5_2_two_layer_law.toml (two layers, a = 2 .. 30):
    [dx, prefactor, exponent] of its planar fit on each grid."""
    from law_set import LAW_CASE

    out = []
    for dx in grids:
        case = load_case(LAW_CASE, [f"grid.dx={dx!r}", "case.models=['two_layer']"])
        res = run_sweep(case)["models"]["two_layer"]
        out.append([dx, res["prefactor"], res["exponent"]])
    return out


def _law(fit: list[float]) -> str:
    return f"{fit[0]:.2f} a^{fit[1]:.2f}"


def _pct(x: float) -> str:
    return f"{100 * x:.0f} %" if abs(x) >= 0.095 else f"{100 * x:.1f} %"


def _converged(res: dict[str, Any]) -> str:
    c = res["changes"][-1]
    word = "converged" if c[2] < CONVERGED else "not converged to 1 %"
    return f"{_pct(c[2])} between dr = {c[0]:g} and {c[1]:g} m ({word})"


def _answer(numbers: dict[str, Any]) -> str:
    """The answer paragraph; every verdict in it follows from the numbers."""
    s = numbers["sets"]
    one, two, law = s["single layer"], s["two layers, defaults"], s["two layers, planar law set"]
    planar = numbers["planar_law"]
    close = law["d_runout"] < 0.25 and abs(law["fits"]["high"][1] - 0.5) < 0.1
    removed = abs(law["ratio_a20"] - 1) < 0.25
    drift = abs(planar[-1][2] - planar[0][2]) > 0.05
    low_heights = all(res["H"][-1] < 0.8 * 0.88 * 20 ** (1 / 6) for res in s.values())
    return (
        f"At a = 20 the single Coulomb layer runs out {one['ratio_a20']:.1f} times as far as "
        f"the law of Lube et al.; above a = {BREAK} its run-out grows as "
        f"{_law(one['fits']['high'])}, against the experiments' a^0.5. The two-layer model "
        f"with its defaults (calibrated on the planar dam break) brings that to "
        f"{two['ratio_a20']:.1f} times, growing as {_law(two['fits']['high'])}. With the "
        f"set that gives the paper's planar law at the paper's grid (phi_B 32 deg, k 0.8, "
        f"c 1, du_reg 0.05 m/s, 75 deg wedge) the two-layer run-out is "
        f"{_law(law['fits']['high'])} above a = {BREAK} and {_law(law['fits']['low'])} "
        f"below (the experiments: 1.6 a^0.5 and 1.24 a), {_pct(law['d_runout'])} from "
        f"Lube's law over a = 0.5 .. 20 on average (the single layer {_pct(one['d_runout'])}, "
        f"the defaults {_pct(two['d_runout'])}), {law['ratio_a20']:.2f} times it at a = 20"
        + (": the two-layer model " + ("removes" if removed else "reduces")
           + " the single layer's over-prediction at high a" + (", and its exponent is the "
           "experiments'" if close else "") + ", but only with that set. " if close or removed
           else ": it does not remove the single layer's over-prediction. ")
        + _fragile(numbers)
        + (f"That set's planar law ({_law(planar[0][1:])} at dx = {planar[0][0]:g} m) "
           f"belongs to the coarse planar grid: at dx = {planar[-1][0]:g} m it is "
           f"{_law(planar[-1][1:])}. So no parameter set here gives both laws on converged "
           "grids: this one gives the axisymmetric law on the finest radial grids we ran, "
           "where it has not yet converged to 1 %, and the "
           "planar law only on the paper's coarse planar grid. "
           if drift else f"The same set gives the planar law {_law(planar[-1][1:])} at "
           f"dx = {planar[-1][0]:g} m too. ")
        + ("No set gives the experiments' final heights: every deposit's summit saturates "
           f"near a constant H_inf/R0 ({one['H'][-1]:.2f}, {two['H'][-1]:.2f} and "
           f"{law['H'][-1]:.2f} at a = 20) where the law as remembered reaches "
           f"{0.88 * 20 ** (1 / 6):.2f}." if low_heights else
           "The final heights are compared below."))


def _fragile(numbers: dict[str, Any]) -> str:
    """What the planar law set's agreement rests on: its grid convergence and the depth
    that defines the deposit's edge (the profile runs at a = 10)."""
    name = "two layers, planar law set"
    law, p = numbers["sets"][name], numbers["profiles"][f"{name}|10"]
    one = numbers["profiles"]["single layer|10"]
    change = law["changes"][-1][2]
    single = numbers["sets"]["single layer"]["changes"][-1][2]
    out = []
    if change >= CONVERGED:
        out.append(f"Its r(a) has not converged: it still changes by {_pct(change)} between "
                   f"the finest two grids (dr = {law['changes'][-1][0]:g} and "
                   f"{law['dx']:g} m), against {_pct(single)} for the single layer.")
    if p["r_01mm"] > 1.5 * p["r"]:
        out.append(f"And the agreement rests on where the edge of the deposit is drawn: at "
                   f"a = 10 its run-out is r = {p['r']:.2f} at 1 mm depth but "
                   f"{p['r_01mm']:.2f} at 0.1 mm ({_pct(p['beyond'])} of the volume lies "
                   f"in that thin sheet), where the single layer's goes from "
                   f"{one['r']:.2f} to {one['r_01mm']:.2f}.")
    return " ".join(out) + (" " if out else "")


def _low_sentence(numbers: dict[str, Any]) -> str:
    """The short columns (a < 1.7) against Lube's 1.24 a, where Mangeney-Castelnau et al.
    found their single layer consistent with the experiments."""
    ratios = {}
    for name, res in numbers["sets"].items():
        a, r = np.array(res["a"]), np.array(res["r"])
        low = a < BREAK
        ratios[name] = float(np.exp(np.mean(np.log(r[low] / lube_runout(a[low])))))
    one = ratios["single layer"]
    verdict = ("so at phi_B = 30 deg the single layer does not show the agreement at "
               "small a that Mangeney-Castelnau et al. (2005) report with their friction "
               "angle (which we could not confirm, see Sources)" if abs(one - 1) > 0.2 else
               "close to the agreement at small a that Mangeney-Castelnau et al. (2005) "
               "report")
    return ("Below a = 1.7 the run-out is on average " + ", ".join(
        f"{v:.2f} times Lube's 1.24 a ({n})" for n, v in ratios.items()) + f"; {verdict}.")


def _fit_table(numbers: dict[str, Any]) -> list[str]:
    lines = ["| | finest dr [m] | r, a < 1.7 | r, a > 1.7 | r, all a | distance to Lube's "
             "r(a) | r/r_Lube at a = 20 | distance to Lube's H_inf/R0 | convergence of r(a) |",
             "|---|---|---|---|---|---|---|---|---|",
             "| Lube et al. 2004 (as remembered) | | 1.24 a^1.00 | 1.60 a^0.50 | | | | | |"]
    for name, res in numbers["sets"].items():
        f = res["fits"]
        lines.append(f"| {name} | {res['dx']:g} | {_law(f['low'])} | {_law(f['high'])} | "
                     f"{_law(f['all'])} | {_pct(res['d_runout'])} | {res['ratio_a20']:.2f} | "
                     f"{_pct(res['d_height'])} | {_converged(res)} |")
    return lines


def _convergence_table(numbers: dict[str, Any]) -> list[str]:
    grids = numbers["grids"]
    head = " | ".join(f"{c:g} -> {f:g}" for c, f in zip(grids[:-1], grids[1:], strict=True))
    lines = [f"| max over a of the change of r [dr in m] | {head} |",
             "|---|" + "---|" * (len(grids) - 1)]
    for name, res in numbers["sets"].items():
        cells = {(c, f): v for c, f, v in res["changes"]}
        row = " | ".join(_pct(cells[(c, f)]) if (c, f) in cells else "—"
                         for c, f in zip(grids[:-1], grids[1:], strict=True))
        lines.append(f"| {name} | {row} |")
    return lines


def _point_table(numbers: dict[str, Any]) -> list[str]:
    names = list(numbers["sets"])
    a = numbers["sets"][names[0]]["a"]
    lines = ["| a | Lube r | " + " | ".join(f"r, {n}" for n in names) + " | "
             + " | ".join(f"H_inf/R0, {n}" for n in names) + " | "
             + " | ".join(f"t_stop/(H0/g)^(1/2), {n}" for n in names) + " |",
             "|---|---|" + "---|" * (3 * len(names))]
    for i, ai in enumerate(a):
        s = numbers["sets"]
        lines.append(f"| {ai:g} | {float(lube_runout(np.array([ai]))[0]):.2f} | "
                     + " | ".join(f"{s[n]['r'][i]:.3f}" for n in names) + " | "
                     + " | ".join(f"{s[n]['H'][i]:.3f}" for n in names) + " | "
                     + " | ".join(f"{s[n]['t'][i]:.2f}" for n in names) + " |")
    return lines


def _shape_table(numbers: dict[str, Any]) -> list[str]:
    lines = ["| a | set | shape (slope ratio) | summit H_inf/R0 | undisturbed top r/R0 | "
             "r at 1 mm | r at 0.1 mm | volume beyond R_inf | front at 95 % | "
             "stop (lower, upper) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for a in PROFILE_RATIOS:
        for name in SETS:
            p = numbers["profiles"][f"{name}|{a:g}"]
            layers = ("" if name == "single layer" else
                      f" ({p['lower_stop']:.2f}, {p['upper_stop']:.2f})")
            ring = (f", a ring {p['ring']:.2f} R0 high at r = {p['ring_radius']:.1f} R0"
                    if p["ring"] > 0.02 else "")
            lines.append(f"| {a:g} | {name} | {p['shape']} ({p['slope_ratio']:.2f}){ring} | "
                         f"{p['summit']:.2f} | {p['top_radius']:.2f} | {p['r']:.2f} | "
                         f"{p['r_01mm']:.2f} | {_pct(p['beyond'])} | {p['t95']:.2f} | "
                         f"{p['stop']:.2f}{layers} |")
    return lines


def _saturation(sets: dict[str, Any]) -> str:
    spread = max((max(r["H"][2:]) - min(r["H"][2:])) / max(r["H"][2:]) for r in sets.values())
    return ("is nearly constant (within " + _pct(spread) + ")" if spread < 0.1 else
            "varies (by up to " + _pct(spread) + ")")


def _top_sentence(numbers: dict[str, Any]) -> str:
    tops = {n: numbers["profiles"][f"{n}|0.5"]["top_radius"] for n in SETS}
    kept = [n for n, t in tops.items() if t > 0.05]
    radii = ", ".join(f"{n} {t:.2f}" for n, t in tops.items())
    if len(kept) == len(tops):
        return ("every deposit keeps an undisturbed top at H0, a truncated cone as in the "
                f"experiments (its radius over R0: {radii}).")
    return f"the undisturbed top at H0 has the radius over R0 {radii}."


def _sheet_sentence(numbers: dict[str, Any]) -> str:
    """How much R_inf depends on the 1 mm depth that defines the edge."""
    p = numbers["profiles"]
    worst = max(p, key=lambda k: p[k]["r_01mm"] / p[k]["r"])
    w = p[worst]
    name, a = worst.split("|")
    return (f"R_inf is the edge of the deposit at 1 mm depth (1 % of R0, about a grain "
            "of the experiments). Thinner sheets lie beyond it: at 0.1 mm the run-out "
            f"grows most for {name} at a = {a}, from r = {w['r']:.2f} to {w['r_01mm']:.2f} "
            f"({_pct(w['beyond'])} of the volume beyond R_inf). Where the two-layer front "
            "falls back within one frame (the front figure), the likely cause is the "
            "deposition of the upper layer: upper films thinner than film_depth = 1 mm are "
            "deposited whole into the lower layer, whose density is higher, so a sheet "
            "about 1 mm deep loses a third of its depth (the density ratio 0.67) and drops "
            "below the edge. We did not isolate this further. " + _rings(p))


def _rings(p: dict[str, Any]) -> str:
    ringed = sorted({k.split("|")[0] for k, v in p.items() if v["ring"] > 0.02})
    return ("Raised rings (more than 0.02 R0 above the lowest depth inside them) appear "
            f"only in the deposits of {', '.join(ringed)}; we did not look into how they "
            "form." if ringed else "No deposit has a raised ring.")


def _times(numbers: dict[str, Any]) -> str:
    parts = []
    for name, res in numbers["sets"].items():
        parts.append(f"{name} {min(res['t']):.1f}-{max(res['t']):.1f}")
    return "; ".join(parts)


def _intro(numbers: dict[str, Any]) -> list[str]:
    """Title, question and answer."""
    return [
        "# Axisymmetric collapses of granular columns: both models against the experiments",
        "",
        "Generated by `python docs/generate/axisymmetric.py` (every number and figure; "
        f"{numbers['points']} runs cached in [axisymmetric/sweep.csv](axisymmetric/sweep.csv), "
        "the whole page "
        f"{numbers['generator_wall_s']:g} s when the cache is full).",
        "",
        "## The question",
        "",
        "A cylinder of grains, radius R0 and height H0, is released on a rough horizontal "
        "plane and spreads into a deposit of radius R_inf and height H_inf. The experiments "
        "of Lube et al. (2004) and Lajeunesse et al. (2004) found that the normalised "
        "run-out r = (R_inf - R0)/R0 depends on the aspect ratio a = H0/R0 alone: linearly "
        "for short columns, as a square root for tall ones. A single depth-averaged layer "
        "with Coulomb friction (Mangeney-Castelnau et al. 2005) agrees for small a and runs "
        "out too far for large a; the two-layer model (a fast upper layer over a slow lower "
        "layer that stops first) was proposed to explain why. Does it remove the "
        "over-prediction, and can one parameter set give both the planar and the "
        "axisymmetric laws?",
        "",
        "## The answer",
        "",
        _answer(numbers),
        "",
        "![r(a): both models and Lube's law](axisymmetric/runout.png)",
        "",
    ]


def _how(numbers: dict[str, Any]) -> list[str]:
    """How we know: runs, convergence, laws, heights, deposits, arrest, checks."""
    s = numbers["sets"]
    one, two, law = s["single layer"], s["two layers, defaults"], s["two layers, planar law set"]
    planar = numbers["planar_law"]
    return [
        "## How we know",
        "",
        "**The runs.** `cases/axisymmetric_collapse_sweep.toml`: R0 = 0.1 m, H0 = a R0 for "
        f"a = {', '.join(f'{a:g}' for a in one['a'])}, radial flow on py-pde's PolarSymGrid "
        "over r = 0 .. 6 m (the axis a wall, the outer end open, never reached), first-order "
        "HLL, CFL 0.3, each run to rest; R_inf is the outer face of the last cell deeper "
        "than 1 mm (the threshold front, in every fit and figure of this page; the cached "
        "runs predate the radius holding 99 % of the mass, `front_mass_quantile`, which "
        "converges faster and which a regeneration without the cache would add). Three "
        "parameter sets: the single layer (phi_B = 30 deg), the two-layer "
        "defaults (phi_B 41 deg, k 0.65, c 0.03, the lower layer a 60 deg cone), and the "
        "two-layer set of `cases/paper_5_2_two_layer_law.toml`. Every point on "
        f"dr = {', '.join(f'{g:g}' for g in numbers['grids'])} m (R0/20 .. "
        f"R0/{round(R0 / numbers['grids'][-1])}"
        + ("; the finest only where the next coarser ones had not converged: " + ", ".join(
            f"{n} to dr = {r['dx']:g} m" for n, r in s.items())
           if len({r["dx"] for r in s.values()}) > 1 else "") + "); one column: "
        "`pdeflow run cases/axisymmetric_collapse.toml`.",
        "",
        "**Convergence.** r(a) changes by at most " + "; ".join(
            f"{name}: {_converged(res)}" for name, res in s.items())
        + ". The per-grid changes are in the appendix.",
        "",
        "**Run-out law.** Fits r = p a^e below and above a = 1.7 on the finest grid "
        "(distance: exp of the rms of ln(r/r_Lube) over the points, minus 1):",
        "",
        *_fit_table(numbers),
        "",
        _low_sentence(numbers),
        "",
        "**Final height.** Lube et al.'s final height grows slowly with a (0.88 a^(1/6) "
        "as remembered); Mangeney-Castelnau et al. (2005) describe a saturation. The "
        f"computed H_inf/R0 {_saturation(s)} over a = 1 .. 20: single layer "
        f"{min(one['H'][2:]):.2f}-{max(one['H'][2:]):.2f}, two-layer defaults "
        f"{min(two['H'][2:]):.2f}-{max(two['H'][2:]):.2f}, planar law set "
        f"{min(law['H'][2:]):.2f}-{max(law['H'][2:]):.2f}. That level is set by the basal "
        "friction: no slope of a deposit at rest is steeper than phi_B, and H_inf/(R0 "
        "tan phi_B) at a = 20 is " + ", ".join(
            f"{res['H'][-1] / math.tan(math.radians(numbers['phi_b_deg'][n])):.2f} ({n}, "
            f"phi_B {numbers['phi_b_deg'][n]:g} deg)" for n, res in s.items())
        + ". At a = 0.5 " + _top_sentence(numbers),
        "",
        "![final height against a](axisymmetric/final_height.png)",
        "",
        f"**Deposits** (dr = {PROFILE_DX:g} m; lower layer dotted; the dashed line is the "
        "straight cone through Lube's final height and run-out, an outline, not a measured "
        "profile; the grey line the initial column's edge; r shown to 15 % beyond the radius "
        "holding 95 % of the two-layer deposits' mass or Lube's R_inf, a deposit reaching "
        "farther named at the panel's edge). A deposit that keeps an undisturbed top at H0 "
        "is named a truncated cone; the others by the ratio of the mean slope of the "
        "inner half of the deposit to that of the outer half: below 0.7 flat-topped, "
        "0.7-1.5 a cone, above 1.5 a steep centre on a thin skirt (the look of the "
        "experiments' \"Mexican hat\", whose description we could not check, see "
        "Sources).",
        "",
        "![deposits at a = 0.5, 2, 5, 10](axisymmetric/deposits.png)",
        "",
        *_shape_table(numbers),
        "",
        _sheet_sentence(numbers),
        "",
        "**Arrest.** t_stop/(H0/g)^(1/2) over a = 0.5 .. 20: " + _times(numbers) + ". "
        "Lube et al. (as remembered, not confirmed) end the motion at about 3. The front "
        "first reaches 95 % of its final run-out earlier (table above; times in "
        "(H0/g)^(1/2)):",
        "",
        "![front against time](axisymmetric/fronts.png)",
        "",
        "**Planar and axisymmetric with one set.** The planar law set, run on the planar "
        "test 5.2 (a = 2 .. 30) by this command: "
        + "; ".join(f"r = {_law(p[1:])} at dx = {p[0]:g} m" for p in planar)
        + " (the paper: 1.61 a^0.84). Its axisymmetric r(a) is "
        + f"{_law(law['fits']['all'])} over all a on the finest radial grid, "
        f"{_converged(law)}.",
        "",
        "**Checks.** Every run ended at rest: "
        + ", ".join(f"{n} {'yes' if r['all_at_rest'] else 'NO'}" for n, r in s.items())
        + f"; largest mass error {max(r['max_mass_error'] for r in s.values()):.1e}; "
        "warnings other than the cost estimate: "
        + (", ".join(w for r in s.values() for w in r["warnings"]
                     if "cell updates" not in w) or "none") + ".",
        "",
    ]


def _tail(numbers: dict[str, Any]) -> list[str]:
    """Sources and the appendix's tables."""
    return [
        "## Sources",
        "",
        SOURCES,
        "## Appendix: tables",
        "",
        *_convergence_table(numbers),
        "",
        "r, H_inf/R0 and t_stop/(H0/g)^(1/2) on the finest grid of each set:",
        "",
        *_point_table(numbers),
        "",
    ]


def render_page(numbers: dict[str, Any]) -> str:
    """docs/axisymmetric.md from the numbers of docs/generate/axisymmetric.py."""
    return "\n".join([*_intro(numbers), *_how(numbers), *_tail(numbers)])
