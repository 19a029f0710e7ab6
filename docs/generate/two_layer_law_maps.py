"""The converged maps of docs/two_layer_law.md from the study maps: the tables of the studies
``cases/study_two_layer_law_*.toml`` (run by ``pdeflow study``; this module only reads
their results tables), their summary, the exponent-against-dx figure and the answer
in words (used by docs/generate/two_layer_law.py)."""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt

from pdeflow.cases import load_case, tomllib
from pdeflow.plotting import log_ticks, save

ROOT = Path(__file__).resolve().parents[2]
TARGET_E, TOL_E = 0.84, 0.05  # the paper's two-layer exponent and the search's tolerance


STUDY_MAPS = {  # study name -> (varied keys, what the map above holds, closure, fixed)
    "two_layer_law_relaxed": (("two_layer.tau_star", "two_layer.phi_b_deg", "two_layer.c"),
                              "tau_star = 0.1", "relaxed closure", "k = 0.8, wedge 60 deg"),
    "two_layer_law_du_reg": (("two_layer.du_reg", "two_layer.phi_b_deg", "two_layer.c"),
                             "du_reg = 0.2 m/s", "paper's closure bounded by du_reg",
                             "k = 0.8, wedge 60 deg"),
    "two_layer_law_wedge_k": (("two_layer.k", "two_layer.c", "initial.wedge_angle_deg"),
                              None, "paper's closure bounded by du_reg = 0.05 m/s",
                              "phi_B = 41 deg"),
    "two_layer_law_phi_b_k": (("two_layer.phi_b_deg", "two_layer.k", "two_layer.c"),
                              None, "paper's closure bounded by du_reg = 0.05 m/s",
                              "wedge 60 deg"),
    "two_layer_law_relaxed_phi_b_k": (("two_layer.phi_b_deg", "two_layer.k", "two_layer.c"),
                                      None, "relaxed closure, tau_star = 0.1",
                                      "wedge 60 deg"),
}
"""maps over a closure's regularisation and the other parameters, studies: pdeflow study
cases/study_NAME.toml --out docs/studies/NAME (this script only reads their tables)"""
LABELS = {"phi_b_deg": "phi_B", "wedge_angle_deg": "wedge"}


def study_spec(name: str) -> dict:
    """The ``[study]`` table of ``cases/study_NAME.toml``."""
    return tomllib.loads((ROOT / "cases" / f"study_{name}.toml").read_text())["study"]


def study_rows(docs: Path, name: str) -> tuple[list[dict], list[Path]]:
    """The finished rows of the study NAME and of NAME_refine, NAME_refine2, ... (its
    sets one, two levels finer), and the refinements' results tables."""
    refines = sorted(docs.glob(f"studies/{name}_refine*/results.csv"))
    rows = []
    for p in (docs / "studies" / name / "results.csv", *refines):
        if p.exists():
            with open(p) as fh:
                rows += [r for r in csv.DictReader(fh) if r["status"] == "ok"]
    return rows, refines


def study_map_section(docs: Path, name: str, found: list[dict]) -> list[str]:
    """The converged map over one closure's regularisation, from a study's results table; appends
    every set whose finest two grids have a fit to ``found`` (closure, set name, its
    exponent on each grid, on the finest one and the change between the finest two)."""
    keys, held, closure, fixed = STUDY_MAPS[name]
    labels = [LABELS.get(k.split(".")[1], k.split(".")[1]) for k in keys]
    study = f"studies/{name}"
    if not (docs / study / "results.csv").exists():
        return []
    rows, refines = study_rows(docs, name)
    groups: dict = {}
    for r in rows:
        point = tuple(float(r[k]) for k in keys)
        e = r["sweep.two_layer.exponent"]
        groups.setdefault(point, {})[float(r["grid.dx"])] = {
            "exponent": float(e) if e else None,
            "prefactor": float(r["sweep.two_layer.prefactor"]) if e else None,
            "sweep_at_rest": r["sweep.two_layer.all_at_rest"] == "1"}
    dxs = sorted({dx for lv in groups.values() for dx in lv}, reverse=True)

    def named(point: tuple) -> str:
        return ", ".join(f"{lab} {v:g}" for lab, v in zip(labels, point, strict=True))

    spec = study_spec(name)

    def params(point: tuple) -> dict:
        case = load_case(ROOT / "cases" / spec["sweep_case"],
                         [*spec["set"], *(f"{k}={v}" for k, v in zip(keys, point,
                                                                       strict=True))])
        return set_params(case)

    over = labels[0] if held else ", ".join(labels)
    lines = ["", f"**{closure[0].upper() + closure[1:]} over {over}**"
             + (f" (the map above holds {held})" if held else "") + ": "
             f"the study `cases/study_{name}.toml`, run by `pdeflow study "
             f"cases/study_{name}.toml --out docs/{study}` "
             f"([report]({study}/report.md)"
             + "".join(f"; {p.parent.name[len(name) + 1:].replace('_', ' ')} (finer "
                       f"levels for some sets): [report]({p.parent.relative_to(docs)}/"
                       "report.md)" for p in refines)
             + f"), MUSCL/mc, {fixed}; the change is between each set's "
             "two finest grids:", "",
             "| " + " | ".join(labels) + " | " + " | ".join(f"fit, dx {d}" for d in dxs)
             + " | change of the exponent | converged (< 0.01)? | sub-linear (< 0.95)? |",
             "|" + "---|" * len(labels) + "---|" * (len(dxs) + 3)]
    conv_sub, conv_all, sub_all = [], [], []
    for point in sorted(groups):
        lv = groups[point]
        cells = []
        for dx in dxs:
            r = lv.get(dx)
            cells.append("" if r is None else "-" if r["exponent"] is None else
                         f"{r['prefactor']:.2f} a^{r['exponent']:.3f}"
                         + ("" if r["sweep_at_rest"] else "*"))
        e = [lv[dx]["exponent"] for dx in sorted(lv, reverse=True)[-2:]]  # finest two
        if len(e) < 2 or None in e:
            ch = ok = sub = "-"
        else:
            d = abs(e[1] - e[0])
            found.append({"closure": closure, "set": named(point), "exponent": e[1],
                          "prefactor": lv[min(lv)]["prefactor"], "change": d,
                          "params": params(point),
                          "levels": {dx: r["exponent"] for dx, r in lv.items()
                                     if r["exponent"] is not None}})
            ch, ok, sub = f"{d:.3f}", "yes" if d < 0.01 else "no", \
                "yes" if e[1] < 0.95 else "no"
            (conv_all if d < 0.01 else []).append(e[1])
            if e[1] < 0.95:
                sub_all.append((point, e[1], d))
                if d < 0.01:
                    conv_sub.append((point, e[1]))
        lines.append("| " + " | ".join(f"{v:g}" for v in point) + " | "
                     + " | ".join(cells) + f" | {ch} | {ok} | {sub} |")
    lines += ["", f"* {len(conv_all)} of {len(groups)} sets converged"
              + (f" (exponents {min(conv_all):.3f} - {max(conv_all):.3f})" if conv_all
                 else "") + f"; {len(conv_sub)} of them sub-linear"
              + (": " + ", ".join(f"{named(k)} ({e:.3f})" for k, e in conv_sub)
                 if conv_sub else "")
              + "."]
    if sub_all:
        lines.append("* Sub-linear on the finer grid: " + ", ".join(
            f"{named(k)} ({e:.3f}, change {d:.3f})" for k, e, d in sub_all) + ".")
    return lines


def set_params(case: Any) -> dict:
    """The two-layer set of a 5.2 case: closure and its regularisation, phi_B, k, c and
    the wedge angle."""
    p = case.make_pde("two_layer").parameters
    relaxed = p.exchange_closure == "relaxed"
    return {"closure": p.exchange_closure,
            "reg": ("tau_star", p.tau_star) if relaxed else ("du_reg", p.du_reg),
            "phi_b_deg": p.phi_b_deg, "k": p.k, "c": p.c,
            "wedge": float(case.data["initial"].get("wedge_angle_deg",
                                                    45.0 + p.phi_int_deg / 2))}


def span(values: list[float], unit: str = "") -> str:
    lo, hi = min(values), max(values)
    return f"{lo:g}{unit}" if lo == hi else f"{lo:g}-{hi:g}{unit}"


def distinct_sets(found: list[dict]) -> dict:
    """Every set mapped on two fine grids once (a set of this script's map and of a study
    map counts once, with its finest grids), by its parameters."""
    sets: dict = {}
    for f in found:
        p = f["params"]
        key = (p["closure"], p["reg"], p["phi_b_deg"], p["k"], p["c"], p["wedge"])
        if key not in sets or min(f["levels"]) < min(sets[key]["levels"]):
            sets[key] = f
    return sets


def law_summary(found: list[dict]) -> dict:
    """The converged sets per closure ('paper', 'relaxed'): all, sub-linear (< 0.95)
    and the rest; and how many distinct sets there are."""
    sets = distinct_sets(found)
    conv = [f for f in sets.values() if f["change"] < 0.01]
    out: dict = {"sets": len(sets), "converged": len(conv)}
    for closure in ("paper", "relaxed"):
        mine = [f for f in conv if f["params"]["closure"] == closure]
        out[closure] = {"converged": mine,
                        "sub": [f for f in mine if f["exponent"] < 0.95],
                        "super": [f for f in mine if f["exponent"] >= 0.95]}
    return out


def law_answer(found: list[dict]) -> list[str]:
    """The converged maps in words, from every set mapped on two fine grids (the map of
    this script and the study maps; a set mapped twice counts once, with its finest
    grids): where the converged law is sub-linear, and with which regularisation."""
    sets = distinct_sets(found)
    conv = [f for f in sets.values() if f["change"] < 0.01]
    out = ["", f"**In words.** {len(sets)} distinct sets were mapped on at least two "
           f"fine grids (MUSCL/mc); the exponent converged (change < 0.01 between the "
           f"finest two) in {len(conv)}."]
    for closure, name in (("paper", "the paper's closure bounded by du_reg"),
                          ("relaxed", "the relaxed closure")):
        mine = [f for f in conv if f["params"]["closure"] == closure]
        sub = [f for f in mine if f["exponent"] < 0.95]
        moving = [f for f in sets.values() if f["params"]["closure"] == closure
                  and f["change"] >= 0.01 and f["exponent"] < 0.95]
        text = f"* With {name}: {len(mine)} converged sets"
        if mine:
            text += f", exponents {span([round(f['exponent'], 3) for f in mine])}"
        if sub:
            ps = [f["params"] for f in sub]
            reg = ps[0]["reg"][0]
            corner = [f for f in mine if all(
                f["params"][k] >= min(p[k] for p in ps) for k in ("phi_b_deg", "k", "c"))]
            text += (f"; sub-linear: {len(sub)} of them, all with phi_B "
                     f"{span([p['phi_b_deg'] for p in ps], ' deg')}, k "
                     f"{span([p['k'] for p in ps])}, c {span([p['c'] for p in ps])}, "
                     f"{reg} {span([p['reg'][1] for p in ps])}, wedge "
                     f"{span([p['wedge'] for p in ps], ' deg')}: exponents "
                     f"{span([round(f['exponent'], 3) for f in sub])}, prefactors "
                     f"{span([round(f['prefactor'], 2) for f in sub])} (the paper at "
                     f"dx = 0.01 m: 1.61 a^0.84); of the converged sets with phi_B, k and "
                     f"c at least those lowest values, {len(sub)} of {len(corner)} are "
                     "sub-linear")
        else:
            text += "; none sub-linear"
        if moving:
            text += (f". {len(moving)} more are sub-linear on their finest grid but not "
                     f"converged (exponents {span([round(f['exponent'], 3) for f in moving])}"
                     f", changes {span([round(f['change'], 3) for f in moving])})")
        out.append(text + ".")
    relapsed = []
    for f in sets.values():
        e = [f["levels"][d] for d in sorted(f["levels"], reverse=True)]
        changes = [abs(b - a) for a, b in zip(e, e[1:], strict=False)]
        if any(c < 0.01 for c in changes[:-1]) and changes[-1] >= 0.01:
            relapsed.append(f"{f['closure']}, {f['set']}: "
                            + " -> ".join(f"{x:.3f}" for x in e))
    if relapsed:
        out.append("* Converged by that test is not final: refined once more, "
                   + "; ".join(relapsed) + " (exponents from the coarsest grid to the "
                   "finest).")
    return out


def overall_answer(found: list[dict]) -> list[str]:
    """The study maps together: per closure, the sets converged on the finest two
    grids, and which of them are sub-linear."""
    out = ["", "**The study maps together** (MUSCL/mc; converged: the exponent "
           "changes by < 0.01 between a set's two finest grids; the fits leave out runs "
           "not at rest by t_end):", "",
           "| closure | sets | converged | converged exponents | converged and "
           "sub-linear (< 0.95) |", "|---|---|---|---|---|"]
    for closure in dict.fromkeys(f["closure"] for f in found):
        sets = [f for f in found if f["closure"] == closure]
        conv = [f for f in sets if f["change"] < 0.01]
        sub = [f for f in conv if f["exponent"] < 0.95]
        es = [f["exponent"] for f in conv]
        out.append(f"| {closure} | {len(sets)} | {len(conv)} | "
                   + (f"{min(es):.3f} - {max(es):.3f}" if es else "-") + " | "
                   + ("; ".join(f"{f['set']}: {f['exponent']:.3f}" for f in sub)
                      or "none") + " |")
    return out + ["", "![the study maps' exponents against dx]"
                  "(figures/two_layer_law_study_convergence.png)"]


def figure_study_convergence(found: list[dict], path: Path) -> None:
    """Exponent against dx for every set of the study maps, one colour per closure;
    the sets sub-linear on their finest grid drawn bold."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    closures = list(dict.fromkeys(f["closure"] for f in found))
    shades = {True: ["tab:blue", "navy", "tab:cyan"], False: ["tab:red", "darkorange",
                                                              "tab:brown"]}
    colors = {c: shades[c.startswith("relaxed")].pop(0) for c in closures}
    for f in found:
        dxs = sorted(f["levels"])
        sub = f["exponent"] < 0.95
        ax.plot(dxs, [f["levels"][d] for d in dxs], color=colors[f["closure"]],
                lw=1.8 if sub else 0.7, alpha=0.9 if sub else 0.4, marker=".")
    for closure, color in colors.items():
        ax.plot([], [], color=color, label=closure)
    ax.axhspan(TARGET_E - TOL_E, TARGET_E + TOL_E, color="0.85", label="0.84 +- 0.05")
    ax.set_xscale("log")
    finest = sorted({d for f in found for d in f["levels"]})
    log_ticks(ax.xaxis, finest)
    ax.set_xlabel("dx [m]")
    ax.set_ylabel("5.2 two-layer exponent (MUSCL/mc)")
    ax.invert_xaxis()
    ax.legend(fontsize=7)
    fig.tight_layout()
    save(fig, path)


STORED_CHECKS = [  # (study, the set's varied values, grids): recomputed by stored_check
    ("two_layer_law_du_reg", {"two_layer.du_reg": 0.05, "two_layer.phi_b_deg": 41,
                              "two_layer.c": 1.0}, [0.00125, 0.000625]),
]
"""a converged sub-linear set of the maps, recomputed with the current code on every run of
the generator, against its stored study results"""


def stored_check(docs: Path, conv: dict[str, Any], stored: dict[str, dict]) -> list[str]:
    """The stored results (search, map, studies: computed once, possibly by an older
    version of pdeflow) against the current code: the representative sets of the
    search, whose dx = 0.01 m fits the convergence table above recomputes anyway, and
    the study sets of :data:`STORED_CHECKS`, recomputed here. ``stored``: the search
    row of each representative set, by its label in ``conv``."""
    from pdeflow.analysis.sweep import run_sweep

    out = ["", "**Stored results against the current code.** The search, the map and the "
           "studies are stored tables; the sets below are recomputed on every run of this "
           "generator (the 5.2 fit, two layers):", "",
           "| set | dx [m] | stored | current code | change of the exponent |",
           "|---|---|---|---|---|"]

    def fit(p: float | None, e: float | None) -> str:
        return "-" if e is None else f"{p:.2f} a^{e:.3f}"

    for label, (muscl, levels) in conv.items():
        if muscl or label not in stored:
            continue  # the search is first order
        s, lv = stored[label], levels[0]
        change = ("-" if None in (s["exponent"], lv["exponent"])
                  else f"{abs(lv['exponent'] - s['exponent']):.3f}")
        out.append(f"| {label} | {lv['dx']} | {fit(s['prefactor'], s['exponent'])} | "
                   f"{fit(lv['prefactor'], lv['exponent'])} | {change} |")
    for name, point, dxs in STORED_CHECKS:
        spec = study_spec(name)
        table = study_rows(docs, name)[0]
        for dx in dxs:
            row = next(r for r in table if float(r["grid.dx"]) == dx and all(
                float(r[k]) == v for k, v in point.items()))
            case = load_case(ROOT / "cases" / spec["sweep_case"],
                             [*spec["set"], *(f"{k}={v}" for k, v in point.items()),
                              f"grid.dx={dx}", "case.models=['two_layer']"])
            now = run_sweep(case)["models"]["two_layer"]
            e0 = float(row["sweep.two_layer.exponent"])
            out.append(f"| {name}: " + ", ".join(f"{k.split('.')[1]} {v:g}"
                                                 for k, v in point.items())
                       + f" | {dx} | {fit(float(row['sweep.two_layer.prefactor']), e0)} | "
                       f"{fit(now['prefactor'], now['exponent'])} | "
                       f"{abs(now['exponent'] - e0):.3f} |")
    return out



def run_studies(docs: Path, workers: int) -> None:
    """Run every study of the maps (``cases/study_two_layer_law*.toml``) into
    ``docs/studies/NAME`` and write its report, as ``pdeflow study`` does. A study
    directory that holds results already is resumed: only what is missing is computed
    (to recompute with another version of pdeflow, remove the directory first)."""
    from pdeflow.study.execute import run_study
    from pdeflow.study.report import write_report
    from pdeflow.study.spec import load_study

    for path in sorted((ROOT / "cases").glob("study_two_layer_law*.toml")):
        name = path.stem[len("study_"):]
        # a relative path, so that the report's commands read as typed from the root
        table = run_study(load_study(os.path.relpath(path)), str(docs / "studies" / name),
                          workers=workers, log=print)
        write_report(table, f"pdeflow study cases/{path.name} --out docs/studies/{name}")
