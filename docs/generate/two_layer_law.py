"""Regenerate docs/two_layer_law.md: the two-layer run-out law of test 5.2, searched,
checked on finer grids, and set against published laws.

    python docs/generate/two_layer_law.py            # everything, the studies included
    python docs/generate/two_layer_law.py --quick    # a coarse search, ~3 min
    python docs/generate/two_layer_law.py --reuse    # report from the stored CSVs, ~5 min

1. Search (the paper's grid dx = 0.01 m, first-order HLL, CFL 0.3): every set of a grid
   over the closure (paper; paper with du_reg; relaxed with tau_star), phi_B, k, c and the
   wedge angle gets test 5.1 (dx = 0.05 m, t_end = 10 s) and the 5.2 sweep
   (a = 2 .. 30). Criteria: the paper's 5.2 fit, exponent 0.84 +- 0.05 and prefactor
   1.61 +- 15 %; 5.1 at rest with the lower layer first; an upper layer 0.2-1 m thick
   (its deepest cell) at t = 0.1, 0.25, 0.4, 0.7 s.
2. Grid convergence of the 5.2 fit for representative sets (dx = 0.01 .. 0.00125 m), the
   converged-grid map and the study maps, and the single layer on the same grids
   (two_layer_law_single.py, cached in docs/two_layer_law_single_layer.csv).
3. The computed r(a) against the published planar-collapse laws
   (:data:`pdeflow.analysis.sweep.PUBLISHED_LAWS`, which cites the papers).

The page opens with the question and the answer (two_layer_law_answer.py), then how
we know, then the tables as an appendix.

Search and map are plain loops written before pdeflow had a study engine (about 45 min on
2 cores); the maps over each closure's regularisation (tau_star, du_reg) and the rest of
the parameter space are studies (cases/study_two_layer_law_*.toml), which the full run
runs (or resumes) on Dask like ``pdeflow study`` (about 3 CPU-hours from nothing) and
two_layer_law_maps.py reads. Every number in the report comes
from this file or that table. All results also go to docs/two_layer_law_search.csv.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from two_layer_law_answer import QUESTION, answer, figure_answer  # noqa: E402
from two_layer_law_maps import (  # noqa: E402
    STUDY_MAPS,
    TARGET_E,
    TOL_E,
    figure_study_convergence,
    law_answer,
    overall_answer,
    run_studies,
    set_params,
    stored_check,
    study_map_section,
)
from two_layer_law_single import (  # noqa: E402
    by_scheme,
    single_layer_rows,
    single_layer_table,
    single_layer_words,
)

from pdeflow.analysis.sweep import (  # noqa: E402
    PUBLISHED_EXPONENTS,
    PUBLISHED_LAWS,
    published_law,
    run_sweep,
)
from pdeflow.cases import load_case  # noqa: E402
from pdeflow.io import atomic_path, write_text  # noqa: E402
from pdeflow.plotting import ASPECT_TICKS, log_ticks, save  # noqa: E402
from pdeflow.simulate import run_model  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
CASE_52 = ROOT / "cases" / "collapse_sweep.toml"
TIMES = (0.1, 0.25, 0.4, 0.7)
TARGET_P, TOL_P = 1.61, 0.15

CLOSURES = {  # name -> [two_layer] keys
    "paper": {},
    "paper, du_reg 0.05": {"du_reg": 0.05},
    "paper, du_reg 0.2": {"du_reg": 0.2},
    "relaxed, tau* 0.1": {"exchange_closure": "relaxed", "tau_star": 0.1},
    "relaxed, tau* 0.3": {"exchange_closure": "relaxed", "tau_star": 0.3},
    "relaxed, tau* 1": {"exchange_closure": "relaxed", "tau_star": 1.0},
}
FULL = {"phi_b_deg": [28, 30, 32, 35, 38, 41, 46], "k": [0.3, 0.5, 0.65, 0.8],
        "c": [0.03, 0.1, 0.3, 1.0, 3.0], "wedge": [60, 75]}
QUICK = {"phi_b_deg": [30, 35, 41], "k": [0.5, 0.65], "c": [0.03, 0.3, 3.0],
         "wedge": [60, 75]}

# The fit on converged grids (MUSCL/mc, the scheme of the grid studies) over a
# sub-grid of the space, for the two regularised closures
MAP = {"closure": ["relaxed, tau* 0.1", "paper, du_reg 0.2"], "phi_b_deg": [30, 41],
       "k": [0.5, 0.8], "c": [0.1, 1.0, 3.0], "wedge": [60]}
MAP_DX = [0.0025, 0.00125]
# sets that are sub-linear on the finest MAP_DX grid but not converged get one more level
REFINE_DX = 0.000625
MUSCL = ["numerics.reconstruction='muscl'", "numerics.limiter='mc'"]

# Published planar-collapse laws, r = (R - L0)/L0 against a = H0/L0 (cited in
# pdeflow.analysis.sweep.PUBLISHED_LAWS and PUBLISHED_EXPONENTS)
LAWS = {name: partial(published_law, name, bridge=True) for name in PUBLISHED_LAWS}
EXPONENTS = PUBLISHED_EXPONENTS


def overrides(params: dict) -> list[str]:
    out = []
    for key, value in params.items():
        if key == "wedge":
            out.append(f"initial.wedge_angle_deg={value}")
        elif key == "closure":
            for k2, v2 in CLOSURES[value].items():
                out.append(f"two_layer.{k2}={v2!r}" if isinstance(v2, str)
                           else f"two_layer.{k2}={v2}")
        else:
            out.append(f"two_layer.{key}={value}")
    return out


def run_51(params: dict, *extra: str) -> dict:
    case = load_case(CASE_51, ["case.models=['two_layer']", "case.t_end=10",
                               f"output.snapshot_times={list(TIMES)}", *overrides(params),
                               *extra])
    res = run_model(case, "two_layer")
    s = res.summary
    row = {"lower_rest": s["lower_slow_time"], "upper_rest": s["upper_slow_time"],
           "at_rest": s["at_rest"], "front_51": s["front_position"],
           "fextra": s["max_fextra_over_rho1"]}
    for t in TIMES:
        data = res.snapshots[t][0]
        row[f"h1max_{t}"] = float(np.max(data[0]))
        wet = np.nonzero(data[0] + data[2] > 1e-3)[0]
        row[f"front_{t}"] = float(res.x[wet[-1]] + 0.5 * case.dx) if wet.size else None
    row["upper_ok"] = all(0.2 <= row[f"h1max_{t}"] <= 1.0 for t in TIMES)
    row["rest_ok"] = (row["lower_rest"] is not None and row["upper_rest"] is not None
                      and row["lower_rest"] <= row["upper_rest"])
    return row


def paper_51_figures(best: dict, meet52: list[dict]) -> list[str]:
    """The paper's figures of test 5.1 (from its text and figures: the layers' stop
    times, the upper layer's depth, F_extra, the run-outs) against the best set meeting
    every target (the shipped case), and the best any set meeting the 5.2 fit achieves."""
    single = run_model(load_case(CASE_51, ["case.models=['single_layer']", "case.t_end=10",
                                           "output.snapshot_times=[]"]), "single_layer")
    front_1 = single.summary["front_position"]
    lower = [r["lower_rest"] for r in meet52 if r["lower_rest"] is not None]
    upper = [r["upper_rest"] for r in meet52 if r["upper_rest"] is not None]
    h1 = [best[f"h1max_{t}"] for t in TIMES]

    def yes(ok: bool) -> str:
        return "yes" if ok else "**no**"

    return ["", f"The shipped set ({_set_name(best)}, `cases/paper_5_2_two_layer_law.toml`)"
            " against the paper's figures of 5.1 (dx = 0.05 m), and the closest any of the "
            f"{len(meet52)} sets meeting the 5.2 fit comes:", "",
            "| 5.1 figure | paper | shipped set | reproduced? | best of the sets meeting "
            "the 5.2 fit |", "|---|---|---|---|---|",
            f"| lower layer at rest | about 0.7 s | {_fmt(best['lower_rest'])} s | "
            f"{yes(abs(best['lower_rest'] - 0.7) <= 0.15)} | earliest "
            f"{min(lower):.2f} s |",
            f"| upper layer at rest | just before 1.5 s | {_fmt(best['upper_rest'])} s | "
            f"{yes(1.3 <= best['upper_rest'] <= 1.5)} | "
            f"{sum(1.3 <= u <= 1.5 for u in upper)} sets in 1.3-1.5 s |",
            f"| lower layer stops first | yes | "
            f"{'yes' if best['lower_rest'] <= best['upper_rest'] else 'no'} | "
            f"{yes(best['lower_rest'] <= best['upper_rest'])} | |",
            f"| upper layer 0.2-1 m deep (deepest cell, 0.1-0.7 s) | yes | "
            f"{min(h1):.2f}-{max(h1):.2f} m | {yes(best['upper_ok'])} | "
            f"{sum(r['upper_ok'] for r in meet52)} sets |",
            f"| max F_extra/rho1 | below 2 m^2/s^2 | {_fmt(best['fextra'])} | "
            f"{yes(best['fextra'] < 2)} | |",
            f"| two-layer run-out shorter than the single layer's | yes | "
            f"{_fmt(best['front_51'])} m against {front_1:.2f} m | "
            f"{yes(best['front_51'] < front_1)} | |"]


def run_52(params: dict, *extra: str, models: str = "two_layer") -> dict:
    case = load_case(CASE_52, [f"case.models=['{models}']", *overrides(params), *extra])
    m = run_sweep(case)["models"][models]
    # a run not at rest by t_end has no final run-out: left out (as by the fit)
    points = [[row["a"], row["r"] if row["at_rest"] else None] for row in m["runs"]]
    return {"prefactor": m["prefactor"], "exponent": m["exponent"],
            "sweep_at_rest": m["all_at_rest"], "points": points}


def _map_task(task: tuple[dict, float]) -> dict:
    params, dx = task
    t0 = time.perf_counter()
    r = run_52(params, f"grid.dx={dx}", *MUSCL)
    return {**params, "dx": dx, "prefactor": r["prefactor"], "exponent": r["exponent"],
            "sweep_at_rest": r["sweep_at_rest"], "wall": time.perf_counter() - t0}


def _map_key(row: dict) -> tuple:
    return (row["closure"], row["phi_b_deg"], row["k"], row["c"], row["wedge"])


def _finest_two(levels: dict) -> tuple[dict, dict]:
    """The rows of the two finest grids of one set (levels: dx -> row)."""
    d = sorted(levels)
    return levels[d[1]], levels[d[0]]


def _change(levels: dict) -> float | None:
    a, b = _finest_two(levels)
    if a["exponent"] is None or b["exponent"] is None:
        return None
    return abs(b["exponent"] - a["exponent"])


def _run_tasks(tasks: list[tuple[dict, float]], workers: int) -> list[dict]:
    # the finest (slowest) sweeps first, so that the pool ends evenly
    tasks = sorted(tasks, key=lambda t: t[1])
    if not tasks:
        return []
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(_map_task, tasks))


def converged_map(workers: int, done: list[dict]) -> list[dict]:
    """The converged map: the 5.2 fit of every MAP set on the MAP_DX grids, and on REFINE_DX for the
    sets that are sub-linear but not converged there; sweeps already in ``done`` (rows of
    the map CSV) are not rerun."""
    have = {(_map_key(r), r["dx"]) for r in done}
    keys = list(MAP)
    sets = [dict(zip(keys, values, strict=True))
            for values in itertools.product(*(MAP[k] for k in keys))]
    rows = list(done)
    rows += _run_tasks([(p, dx) for p in sets for dx in MAP_DX
                        if (_map_key(p), dx) not in have], workers)
    groups = _group(rows)
    refine = []
    for p in sets:
        levels = groups[_map_key(p)]
        change = _change(levels)
        finest = levels[min(levels)]
        if (change is not None and change >= 0.01 and finest["exponent"] < 0.95
                and min(levels) > REFINE_DX):
            refine.append((p, REFINE_DX))
    rows += _run_tasks(refine, workers)
    print(f"converged map: {len(rows) - len(done)} new sweeps", flush=True)
    return rows


def _group(rows: list[dict]) -> dict:
    """Map rows by set: key -> {dx: row}."""
    groups: dict = {}
    for r in rows:
        groups.setdefault(_map_key(r), {})[r["dx"]] = r
    return groups


def write_csv(rows: list[dict], path: Path) -> None:
    """All rows (without the r(a) points) as CSV, atomically."""
    keys = [k for k in rows[0] if k != "points"]
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


def meets_52(row: dict) -> bool:
    return (row["exponent"] is not None and abs(row["exponent"] - TARGET_E) <= TOL_E
            and abs(row["prefactor"] / TARGET_P - 1) <= TOL_P)


def search(grid: dict) -> list[dict]:
    rows = []
    keys = list(grid)
    combos = list(itertools.product(CLOSURES, *(grid[k] for k in keys)))
    t0 = time.perf_counter()
    for n, (closure, *values) in enumerate(combos):
        params = {"closure": closure, **dict(zip(keys, values, strict=True))}
        row = dict(params)
        row.update(run_51(params))
        r52 = run_52(params)
        row.update({k: r52[k] for k in ("prefactor", "exponent", "sweep_at_rest")})
        row["meets_52"] = meets_52(row)
        row["meets_all"] = row["meets_52"] and row["rest_ok"] and row["upper_ok"]
        rows.append(row)
        if n % 50 == 0:
            print(f"{n + 1}/{len(combos)} sets, {time.perf_counter() - t0:.0f} s",
                  flush=True)
    return rows


def _parse(row: dict) -> dict:
    """A row of the search CSV with its numbers, booleans and empty cells restored."""
    out: dict = {}
    for k, v in row.items():
        if v == "":
            out[k] = None
        elif v in ("True", "False"):
            out[k] = v == "True"
        elif k == "closure":
            out[k] = v
        else:
            out[k] = float(v) if any(ch in v for ch in ".en") else int(v)
    return out


def _score(row: dict) -> float:
    """Distance to the 5.2 targets in units of their tolerances."""
    if row["exponent"] is None:
        return math.inf
    return math.hypot((row["exponent"] - TARGET_E) / TOL_E,
                      (row["prefactor"] / TARGET_P - 1) / TOL_P)


def _fmt(v, nd=2) -> str:
    if v is None:
        return "moving"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.{nd}f}"
    return str(v)


def _set_name(row: dict) -> str:
    return (f"{row['closure']}, phi_B {row['phi_b_deg']}, k {row['k']}, c {row['c']}, "
            f"wedge {row['wedge']}")


def convergence(params: dict, dxs: list[float], muscl: bool) -> list[dict]:
    extra = ["numerics.reconstruction='muscl'", "numerics.limiter='mc'"] if muscl else []
    out = []
    for dx in dxs:
        t0 = time.perf_counter()
        r = run_52(params, f"grid.dx={dx}", *extra)
        out.append({"dx": dx, "prefactor": r["prefactor"], "exponent": r["exponent"],
                    "at_rest": r["sweep_at_rest"], "points": r["points"],
                    "wall": time.perf_counter() - t0})
    return out


def map_answer(groups: dict) -> list[str]:
    """The converged map in numbers: per closure, how many map sets converge (exponent change
    < 0.01 between the two finest grids, every run at rest) and how many of those are
    sub-linear (exponent < 0.95 on the finest grid), with the range of exponents."""
    out = ["Per closure, on the finest grid (every sweep at rest):", "",
           "| closure | sets | converged | converged and sub-linear | exponents of the "
           "converged sets |", "|---|---|---|---|---|"]
    for closure in MAP["closure"]:
        sets = [lv for key, lv in groups.items() if key[0] == closure]
        conv = []
        for lv in sets:
            a, b = _finest_two(lv)
            if (a["exponent"] is not None and b["exponent"] is not None
                    and a["sweep_at_rest"] and b["sweep_at_rest"]
                    and abs(b["exponent"] - a["exponent"]) < 0.01):
                conv.append(b["exponent"])
        sub = [e for e in conv if e < 0.95]
        rng = f"{min(conv):.3f} - {max(conv):.3f}" if conv else "-"
        out.append(f"| {closure} | {len(sets)} | {len(conv)} | {len(sub)} | {rng} |")
    return out


def answers(groups: dict, conv: dict) -> list[str]:
    """The questions of the converged map, answered from the numbers above."""
    sub, conv_sets = [], []
    for key, lv in groups.items():
        a, b = _finest_two(lv)
        if a["exponent"] is None or b["exponent"] is None:
            continue
        change = abs(b["exponent"] - a["exponent"])
        at_rest = a["sweep_at_rest"] and b["sweep_at_rest"]
        if change < 0.01 and at_rest:
            conv_sets.append((key, b["exponent"]))
        if b["exponent"] < 0.95:
            sub.append((key, b["exponent"], change))
    out = ["**What the map says.**", ""]
    if conv_sets:
        es = [e for _, e in conv_sets]
        out.append("* Converged (exponent change < 0.01 between the two finest grids): "
                   f"{len(conv_sets)} of {len(groups)} map sets, exponents "
                   f"{min(es):.3f} - {max(es):.3f}; sub-linear among them: "
                   f"{sum(e < 0.95 for e in es)}.")
    if sub:
        out.append(f"* Sub-linear on the finest grid (< 0.95): {len(sub)} sets, exponents "
                   f"{min(e for _, e, _ in sub):.3f} - {max(e for _, e, _ in sub):.3f}, "
                   f"all with phi_B in {sorted({k[1] for k, _, _ in sub})} and c in "
                   f"{sorted({k[3] for k, _, _ in sub})}; their exponents still change by "
                   f"{min(c for _, _, c in sub):.3f} - {max(c for _, _, c in sub):.3f} "
                   "between their two finest grids.")
    else:
        out.append("* No map set is sub-linear on the finest grid.")
    for label, (_, levels) in conv.items():
        e = [lv["exponent"] for lv in levels]
        if None in e:
            continue
        out.append(f"* {label}: exponent " + " -> ".join(f"{x:.3f}" for x in e)
                   + " from dx = " + " -> ".join(str(lv["dx"]) for lv in levels) + " m.")
    return out


def law_distances(points: list[list[float]]) -> dict:
    """RMS of log10(r / r_law) over a = 2 .. 30 for the laws with a prefactor."""
    a = np.array([p[0] for p in points], dtype=float)
    r = np.array([p[1] if p[1] else np.nan for p in points], dtype=float)
    ok = (a >= 2) & (a <= 30) & np.isfinite(r)
    return {name: float(np.sqrt(np.mean(np.log10(r[ok] / law(a[ok])) ** 2)))
            for name, law in LAWS.items()}


def figure_laws(curves: dict, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 5))
    a = np.geomspace(2, 30, 100)
    for name, law in LAWS.items():
        ax.plot(a, law(a), ls="--", lw=1, label=name)
    for name, (e, _) in EXPONENTS.items():
        ax.plot(a, 1.61 * (a / 2) ** e * 2 ** 0.84, ls=":", lw=1,
                label=f"{name}: slope {e}")
    ax.plot(a, 2.25 * a ** 1.06, color="0.5", lw=3, alpha=0.4, label="paper, one layer")
    ax.plot(a, 1.61 * a ** 0.84, color="tab:orange", lw=3, alpha=0.4,
            label="paper, two layers")
    for label, pts in curves.items():
        pa = [p[0] for p in pts if p[1]]
        pr = [p[1] for p in pts if p[1]]
        ax.plot(pa, pr, "o-", ms=4, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_ticks(ax.xaxis, ASPECT_TICKS)
    log_ticks(ax.yaxis, [2, 5, 10, 20, 50])
    ax.set_xlabel("a = H0 / L0")
    ax.set_ylabel("r = (R - L0) / L0")
    ax.legend(fontsize=6.5, loc="upper left")
    fig.tight_layout()
    save(fig, path)


def figure_convergence(conv: dict, map_rows: list[dict], path: Path) -> None:
    """Exponent against dx: the representative sets on four grids, the map's sets on
    the grids they were run on."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for key, levels in _group(map_rows).items():
        lv = [levels[dx] for dx in sorted(levels)]
        color = "tab:blue" if key[0].startswith("relaxed") else "tab:red"
        ax.plot([r["dx"] for r in lv], [r["exponent"] for r in lv], color=color, lw=0.8,
                alpha=0.5, marker=".")
    colors = ["k", "tab:orange", "tab:green", "tab:purple"]
    for (label, (muscl, levels)), color in zip(conv.items(), colors, strict=False):
        ax.plot([lv["dx"] for lv in levels], [lv["exponent"] for lv in levels], "o-",
                lw=2, color=color,
                label=f"{label.split(' (')[0]}{' (MUSCL)' if muscl else ''}")
    ax.plot([], [], color="tab:blue", lw=0.8, label="map: relaxed, MUSCL")
    ax.plot([], [], color="tab:red", lw=0.8, label="map: paper with du_reg, MUSCL")
    ax.axhspan(TARGET_E - TOL_E, TARGET_E + TOL_E, color="0.85", label="0.84 +- 0.05")
    ax.axhline(1.06, color="0.5", ls="--", lw=1, label="paper, one layer: 1.06")
    ax.set_xscale("log")
    log_ticks(ax.xaxis, [0.01, 0.005, 0.0025, 0.00125, REFINE_DX])
    ax.set_xlabel("dx [m]")
    ax.set_ylabel("5.2 exponent")
    ax.invert_xaxis()
    ax.legend(fontsize=7)
    fig.tight_layout()
    save(fig, path)


def figure_map(rows: list[dict], path: Path) -> None:
    """Exponent over (phi_B, c) per closure, best k and wedge at each point."""
    names = list(CLOSURES)
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.5), sharex=True, sharey=True)
    phis = sorted({r["phi_b_deg"] for r in rows})
    cs = sorted({r["c"] for r in rows})
    for ax, name in zip(axes.flat, names, strict=False):
        grid = np.full((len(cs), len(phis)), np.nan)
        for i, c in enumerate(cs):
            for j, pb in enumerate(phis):
                sel = [r for r in rows if r["closure"] == name and r["c"] == c
                       and r["phi_b_deg"] == pb and r["exponent"] is not None]
                if sel:
                    grid[i, j] = min(sel, key=_score)["exponent"]
        im = ax.imshow(grid, origin="lower", aspect="auto", cmap="coolwarm", vmin=0.6,
                       vmax=1.2)
        for i in range(len(cs)):
            for j in range(len(phis)):
                if np.isfinite(grid[i, j]):
                    ax.text(j, i, f"{grid[i, j]:.2f}", ha="center", va="center",
                            fontsize=6)
        ax.set_title(name, fontsize=9)
        ax.set_xticks(range(len(phis)))
        ax.set_xticklabels([str(p) for p in phis], fontsize=7)
        ax.set_yticks(range(len(cs)))
        ax.set_yticklabels([str(c) for c in cs], fontsize=7)
    for ax in axes[1]:
        ax.set_xlabel("phi_B [deg]")
    for ax in axes[:, 0]:
        ax.set_ylabel("c")
    fig.colorbar(im, ax=axes, label="5.2 exponent (k, wedge closest to the paper's fit)")
    save(fig, path)


def header(args: argparse.Namespace, n: int, seconds: float) -> list[str]:
    """The title and how the page was made."""
    how = (" (from the stored search, map and single-layer sweeps; without `--reuse` the "
           "full run takes about 45 min on 2 cores, plus about 3 CPU-hours for the studies "
           "if their directories are empty; the stored tables were computed by earlier "
           "versions of pdeflow, and the appendix measures how far the current code moves "
           "them)" if args.reuse else f" ({seconds / 60:.0f} min on this machine)")
    return ["# The run-out law of collapsing columns: one layer and two layers", "",
            f"Generated by `python docs/generate/two_layer_law.py"
            f"{' --quick' if args.quick else ''}{' --reuse' if args.reuse else ''}`{how}; "
            f"the data: all {n} searched "
            "two-layer sets with every measured number in "
            "[two_layer_law_search.csv](two_layer_law_search.csv), the converged-grid map "
            "in [two_layer_law_map.csv](two_layer_law_map.csv), the single layer in "
            "[two_layer_law_single_layer.csv](two_layer_law_single_layer.csv), the studies "
            "in [studies/](studies/).", ""]


def search_section(rows: list[dict], space: dict, meet52: list[dict],
                   meet_all: list[dict]) -> list[str]:
    """How many sets of the search reproduce the paper's fit at its grid, per closure,
    and the best of them against the paper's figures of test 5.1."""
    n = len(rows)
    lines = [
        "### The two-layer model at the paper's grid: a search", "",
        "The paper leaves four two-layer parameters open (its Table 1 is lost). A search "
        "at the paper's grid (5.2: dx = 0.01 m, a = 2, 3, 4, 6, 8, 10, 14, 18, 24, 30; "
        "5.1: dx = 0.05 m, t_end = 10 s), first-order HLL, CFL 0.3, over the closure "
        f"({'; '.join(CLOSURES)}) x phi_B {space['phi_b_deg']} x k {space['k']}"
        f" x c {space['c']} x wedge {space['wedge']} deg, asks for the paper's fit "
        f"(exponent {TARGET_E} +- {TOL_E}, prefactor {TARGET_P} +- {TOL_P:.0%}) and for "
        "what the paper shows of test 5.1: at rest (practical) with the lower layer first, "
        "the upper layer's deepest cell between 0.2 and 1 m at t = 0.1, 0.25, 0.4 and "
        "0.7 s (\"the upper layer flow depth ranges between 0.2 m and 1 m during almost "
        "the whole simulation\").", "",
        f"* {len(meet52)} of {n} sets give the paper's fit; "
        f"{sum(1 for r in meet52 if r['rest_ok'])} of those also bring 5.1 to rest with "
        f"the lower layer first; {len(meet_all)} meet every criterion (the tables of the "
        "best are in the appendix)."]
    by_closure: dict = {}
    for r in rows:
        d = by_closure.setdefault(r["closure"], [0, 0, 0, 0])
        d[0] += 1
        d[1] += r["meets_52"]
        d[2] += r["meets_52"] and r["rest_ok"]
        d[3] += r["meets_all"]
    lines += ["", "| closure | sets | 5.2 fit | + 5.1 at rest, lower first | + upper layer "
              "0.2-1 m |", "|---|---|---|---|---|"]
    lines += [f"| {k} | {v[0]} | {v[1]} | {v[2]} | {v[3]} |" for k, v in by_closure.items()]
    if meet_all:
        lines += paper_51_figures(meet_all[0], meet52)
    return lines + ["", "Exponent at dx = 0.01 m over phi_B and c for each closure (at each "
                    "point the k and wedge angle closest to the paper's fit):", "",
                    "![5.2 exponent maps](figures/two_layer_law_exponent_map.png)", ""]


def _table_row(r: dict) -> str:
    fit = "-" if r["exponent"] is None else f"{r['prefactor']:.2f} a^{r['exponent']:.3f}"
    h1 = " / ".join(_fmt(r[f"h1max_{t}"]) for t in TIMES)
    fr = " / ".join(_fmt(r[f"front_{t}"]) for t in TIMES)
    return (f"| {_set_name(r)} | {fit} | {_fmt(r['lower_rest'])} / "
            f"{_fmt(r['upper_rest'])} | {_fmt(r['front_51'])} | {h1} | {fr} | "
            f"{_fmt(r['fextra'])} |")


def search_tables(rows: list[dict], meet_all: list[dict]) -> list[str]:
    """The appendix's tables of the search: the ten sets closest to the paper's fit and
    the sets meeting every criterion."""
    head = ("| set | 5.2 fit | 5.1 lower / upper at rest [s] | front [m] | "
            "deepest upper cell at 0.1 / 0.25 / 0.4 / 0.7 s [m] | fronts at those times [m]"
            " | max F_extra/rho1 |")
    lines = ["### The search at the paper's grid", "",
             "The ten sets closest to the paper's fit:", "", head,
             "|---|---|---|---|---|---|---|", *(_table_row(r) for r in rows[:10])]
    if meet_all:
        lines += ["", "Sets meeting every criterion (best first):", "", head,
                  "|---|---|---|---|---|---|---|", *(_table_row(r) for r in meet_all[:10])]
    return lines


def convergence_section(conv: dict, dxs: list[float]) -> list[str]:
    """The representative sets of the search on finer grids."""
    lines = ["### The two-layer law on finer grids", "",
             "The representative sets of the search on finer grids (relaxed closure with "
             "MUSCL/mc, the paper's closure first order as in the paper; '*': a sweep with "
             "a run not at rest by t_end = 30 s, left out of the fit). A law counts as "
             "converged when its exponent changes by < 0.01 between the two finest grids.",
             "", "| set | " + " | ".join(f"dx {d}" for d in dxs) + " | change, finest two |",
             "|---|" + "---|" * (len(dxs) + 1)]
    for label, (muscl, levels) in conv.items():
        cells = [("-" if lv["exponent"] is None else
                  f"{lv['prefactor']:.2f} a^{lv['exponent']:.3f}"
                  + ("" if lv["at_rest"] else "*")) for lv in levels]
        e = [lv["exponent"] for lv in levels[-2:]]
        change = "-" if None in e else f"{abs(e[1] - e[0]):.3f}"
        lines.append(f"| {label}{' (MUSCL)' if muscl else ''} | " + " | ".join(cells)
                     + f" | {change} |")
    return lines


def _map_fit(r: dict | None) -> str:
    if r is None:
        return ""
    if r["exponent"] is None:
        return "-"
    return f"{r['prefactor']:.2f} a^{r['exponent']:.3f}{'' if r['sweep_at_rest'] else '*'}"


def map_section(map_rows: list[dict], conv: dict) -> tuple[list[str], list[str]]:
    """This script's converged-grid map: its summary (for the page) and its full table
    (for the appendix)."""
    if not map_rows:
        return [], []
    dxs_all = [*MAP_DX, REFINE_DX]
    groups = _group(map_rows)
    what = (f"phi_B {MAP['phi_b_deg']} x k {MAP['k']} x c {MAP['c']} (wedge "
            f"{MAP['wedge'][0]} deg) for the regularised closures, MUSCL/mc on dx = "
            f"{MAP_DX[0]} and {MAP_DX[1]} m, and on {REFINE_DX} m for the sets that are "
            "sub-linear there but not converged")
    table = ["", "### The converged-grid map", "", f"Map over {what} ('*': a sweep with a "
             "run not at rest by t_end = 30 s; the fit leaves such runs out):", "",
             "| closure | phi_B | k | c | " + " | ".join(f"fit, dx {d}" for d in dxs_all)
             + " | change of the exponent, finest two | converged (< 0.01)? | "
             "sub-linear (< 0.95)? |", "|---|---|---|---|" + "---|" * (len(dxs_all) + 3)]
    for key, lv in groups.items():
        d = _change(lv)
        if d is None:
            ch, conv_ok, sub = "-", "-", "-"
        else:
            ch, conv_ok = f"{d:.3f}", "yes" if d < 0.01 else "no"
            sub = "yes" if lv[min(lv)]["exponent"] < 0.95 else "no"
        table.append(f"| {key[0]} | {key[1]} | {key[2]} | {key[3]} | "
                     + " | ".join(_map_fit(lv.get(dx)) for dx in dxs_all)
                     + f" | {ch} | {conv_ok} | {sub} |")
    walls = [r["wall"] for r in map_rows]
    table += ["", f"({len(map_rows)} sweeps, {sum(walls) / 60:.0f} CPU-minutes.)"]
    page = ["", f"A map over {what} (the table is in the appendix):", "",
            *map_answer(groups), "", *answers(groups, conv)]
    return page, table


def map_found(map_rows: list[dict]) -> list[dict]:
    """The sets of this script's map in the form of the study maps' ``found``."""
    found = []
    for key, lv in _group(map_rows).items():
        d = _change(lv)
        if d is None:
            continue
        fine = lv[min(lv)]
        case = load_case(CASE_52, overrides(dict(zip(("closure", "phi_b_deg", "k", "c",
                                                      "wedge"), key, strict=True))))
        found.append({"closure": key[0], "set": _set_name(dict(zip(
            ("closure", "phi_b_deg", "k", "c", "wedge"), key, strict=True))),
            "exponent": fine["exponent"], "prefactor": fine["prefactor"], "change": d,
            "params": set_params(case),
            "levels": {dx: r["exponent"] for dx, r in lv.items()}})
    return found


def experiments_section(dist_rows: list[tuple[str, dict]]) -> list[str]:
    """The computed r(a) against the published laws."""
    lines = ["", "### Against experiments and DEM", "",
             "r = (R - L0)/L0 with R the front (last cell deeper than 1 mm) in every "
             "model; the experiments define R by the farthest grains of the deposit, "
             "which a 1 mm threshold approximates for these 0.1 m columns. Every fit on "
             "this page uses this threshold front (the stored tables predate the run-out "
             "holding 99 % of the mass, r_mass, that `pdeflow sweep` now fits too). RMS "
             "distance "
             "in log10 over a = 2 .. 30 (0.1 = a factor 1.26), and the fitted exponent "
             "against the exponent-only laws:", "",
             "| run | fit | " + " | ".join(LAWS) + " | "
             + " | ".join(f"{k}: {v[0]}" for k, v in EXPONENTS.items()) + " |",
             "|---|---|" + "---|" * (len(LAWS) + len(EXPONENTS))]
    for label, r in dist_rows:
        if r["exponent"] is None:
            continue
        d = law_distances(r["points"])
        lines.append(f"| {label} | {r['prefactor']:.2f} a^{r['exponent']:.3f} | "
                     + " | ".join(f"{d[k]:.3f}" for k in LAWS) + " | "
                     + " | ".join(f"{r['exponent'] - v[0]:+.2f}" for v in
                                  EXPONENTS.values()) + " |")
    return lines + ["", "![r(a) against the published laws](figures/two_layer_law_r_of_a.png)",
                    "", "The dotted lines show only the exponent-only laws' slopes (drawn "
                    "through the paper's two-layer fit at a = 2).", ""]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--docs", type=Path, default=ROOT / "docs", help="docs directory")
    ap.add_argument("--quick", action="store_true", help="coarse search grid (~3 min)")
    ap.add_argument("--reuse", action="store_true",
                    help="read the search from its CSV file in the docs directory instead "
                    "of rerunning it, and run only the map sweeps missing from the map CSV")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="worker processes for the converged-grid map (default: all cores)")
    args = ap.parse_args(argv)
    docs = args.docs
    t_start = time.perf_counter()
    space = QUICK if args.quick else FULL
    csv_path = docs / "two_layer_law_search.csv"
    if args.reuse:
        with open(csv_path) as fh:
            rows = [_parse(r) for r in csv.DictReader(fh)]
    else:
        rows = search(space)
    rows.sort(key=_score)
    write_csv(rows, csv_path)
    meet52 = [r for r in rows if r["meets_52"]]
    meet_all = [r for r in rows if r["meets_all"]]

    # representative sets for the grid study and the laws
    reps = {"defaults (paper, phi_B 41, k 0.65, c 0.03, wedge 60)":
            {"closure": "paper", "phi_b_deg": 41, "k": 0.65, "c": 0.03, "wedge": 60}}
    for label, pool in (("best of the search", rows), ("best meeting every criterion",
                                                       meet_all)):
        if pool:
            b = pool[0]
            reps[f"{label} ({_set_name(b)})"] = {k: b[k] for k in ("closure", "phi_b_deg",
                                                                    "k", "c", "wedge")}
    relaxed = [r for r in rows if r["closure"].startswith("relaxed") and r["sweep_at_rest"]]
    if relaxed:
        b = relaxed[0]
        reps[f"best relaxed ({_set_name(b)})"] = {k: b[k] for k in (
            "closure", "phi_b_deg", "k", "c", "wedge")}
    dxs = [0.01, 0.005, 0.0025] if args.quick else [0.01, 0.005, 0.0025, 0.00125]
    conv = {}
    for label, params in reps.items():
        muscl = CLOSURES[params["closure"]].get("exchange_closure") == "relaxed"
        conv[label] = (muscl, convergence(params, dxs, muscl))
        print(f"convergence done: {label}", flush=True)

    map_path = docs / "two_layer_law_map.csv"
    if args.quick:
        map_rows = []
    else:
        done = []
        if args.reuse and map_path.exists():
            with open(map_path) as fh:
                done = [_parse(r) for r in csv.DictReader(fh)]
        map_rows = converged_map(args.workers, done)
        write_csv(map_rows, map_path)

    single_01 = run_52({}, models="single_layer")
    curves = {f"one layer (phi_B 30), fit {single_01['prefactor']:.2f} a^"
              f"{single_01['exponent']:.2f}": single_01["points"]}
    dist_rows = [("one layer, phi_B 30, first order, dx 0.01", single_01)]
    for label, (muscl, levels) in conv.items():
        scheme = "MUSCL" if muscl else "first order"
        for lv in (levels[0], levels[-1]):
            dist_rows.append((f"{label}, {scheme}, dx {lv['dx']}", lv))
        lv = levels[0]
        if lv["exponent"] is not None:
            curves[f"{label.split(' (')[0]}, {scheme}, dx {lv['dx']}: "
                   f"{lv['prefactor']:.2f} a^{lv['exponent']:.2f}"] = lv["points"]
    figure_laws(curves, docs / "figures" / "two_layer_law_r_of_a.png")
    figure_map(rows, docs / "figures" / "two_layer_law_exponent_map.png")
    figure_convergence(conv, map_rows, docs / "figures" / "two_layer_law_convergence.png")

    single = single_layer_rows(docs / "two_layer_law_single_layer.csv",
                               run_missing=not args.quick)
    mu = by_scheme(single)["MUSCL/mc"][-1]
    dist_rows.append((f"one layer, phi_B 30, MUSCL/mc, dx {mu['dx']}",
                      {**mu, "points": [[float(a), float(r)] for a, r in
                                        (p.split(":") for p in mu["points"].split())]}))
    lines = header(args, len(rows), time.perf_counter() - t_start) + QUESTION
    search_lines = search_section(rows, space, meet52, meet_all)
    conv_lines = convergence_section(conv, dxs)
    map_lines, appendix_map = map_section(map_rows, conv)
    if not (args.reuse or args.quick):
        run_studies(docs, args.workers)
    found: list[dict] = []
    study_lines = [ln for name in STUDY_MAPS for ln in study_map_section(docs, name, found)]
    if found:
        figure_study_convergence(found, docs / "figures" /
                                 "two_layer_law_study_convergence.png")
    found_studies = list(found)
    found += map_found(map_rows)
    figure_answer(single, found, docs / "figures" / "two_layer_law_answer.png")
    lines += answer(single, found, len(rows), len(meet52))
    lines += ["## How we know", "", "### The single layer on the same grids", "",
              "`pdeflow sweep cases/collapse_sweep.toml --set \"case.models=['single_layer']"
              "\" --set grid.dx=D`, and the same with `--set \"numerics.reconstruction="
              "'muscl'\" --set \"numerics.limiter='mc'\"` (the scheme of the two-layer maps "
              "below); cached in [two_layer_law_single_layer.csv](two_layer_law_single_layer"
              ".csv) ('*': a sweep with a run not at rest by t_end):", "",
              *single_layer_table(single), "", single_layer_words(single), ""]
    lines += search_lines + conv_lines + map_lines
    if found_studies:
        lines += overall_answer(found_studies)
    lines += law_answer(found)
    lines += ["", "![the 5.2 exponent against dx](figures/two_layer_law_convergence.png)"]
    lines += experiments_section(dist_rows)
    lines += ["## Appendix: the tables", "", *search_tables(rows, meet_all), *appendix_map]
    if study_lines:
        lines += ["", "### The study maps", "", "The maps over each closure's "
                  "regularisation and the other parameters (studies run by `pdeflow "
                  "study`, read from their results tables):", *study_lines]
    if args.reuse:
        by_name = {_set_name(r): r for r in rows}
        lines += ["", "### Stored results against the current code", *stored_check(
            docs, conv, {label: by_name[name] for label in conv
                         if (name := label[label.find("(") + 1:-1]) in by_name})[1:]]
    out = docs / "two_layer_law.md"
    write_text(out, "\n".join(lines))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
