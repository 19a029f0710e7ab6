"""Regenerate docs/axisymmetric.md: axisymmetric collapses of granular columns, both
models, against the experiments.

    python docs/generate/axisymmetric.py            # runs what the cache lacks, then the page
    python docs/generate/axisymmetric.py --runs-only  # fill the cache only (resumable)
    python docs/generate/axisymmetric.py --no-runs    # the page from the cache as it is

Every point (parameter set, grid dr, aspect ratio a) of cases/axisymmetric_collapse_sweep.toml
is one run to rest; its numbers go to docs/axisymmetric/sweep.csv as soon as it ends, and
a later call runs only the points missing there. The profiles and fronts (a = 0.5, 2, 5,
10 on the profile grid) are run every time (seconds). The page's numbers are computed from
the CSV and those runs by :func:`page_numbers`, stored in docs/axisymmetric/numbers.json
and written into the page by axisymmetric_page.render_page: tests/test_axisymmetric_docs.py
checks that the page is that rendering of those numbers.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import run_cache
from law_set import law_set_overrides

from pdeflow.analysis.sweep import deposit_numbers, fit_power_law
from pdeflow.cases import load_case, tomllib
from pdeflow.checks import RunWarning
from pdeflow.metrics import front_position
from pdeflow.simulate import run_model

ROOT = Path(__file__).resolve().parents[2]
SWEEP_CASE = ROOT / "cases" / "axisymmetric_collapse_sweep.toml"
OUT = ROOT / "docs" / "axisymmetric"
CSV = OUT / "sweep.csv"
R0 = 0.1
"""radius of the columns [m] (initial.L0 of the sweep case)"""
GRIDS = (0.005, 0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625)
"""dr [m]: R0/20 .. R0/640"""
FINER = {"two layers, planar law set": (0.000078125,)}
"""dr [m] of further grids for the sets whose r(a) still changed by more than 1 % between
the finest two of GRIDS"""
PROFILE_DX = 0.000625
"""dr [m] of the deposit profiles and front histories"""
PROFILE_RATIOS = (0.5, 2.0, 5.0, 10.0)
BREAK = 1.7
"""a of the regime change of Lube et al. (2004): fits below and above it"""
FIELDS = ("set", "dx", "a", "r", "runout", "final_height", "H_inf_over_L0", "H_inf_over_H0",
          "top_radius_over_L0", "arrest_time_scaled", "stop_time", "at_rest", "steps",
          "wall_time_s", "mass_relative_error", "warnings")


SETS: dict[str, tuple[str, list[str]]] = {
    "single layer": ("single_layer", []),
    "two layers, defaults": ("two_layer", []),
    "two layers, planar law set": ("two_layer", law_set_overrides()),
}
"""name -> (model, overrides of the sweep case)"""


def point_case(name: str, dx: float, a: float, extra: list[str] | None = None) -> Any:
    """The sweep case for one point: parameter set ``name``, cell size dx [m], H0 = a R0."""
    model, sets = SETS[name]
    return load_case(SWEEP_CASE, [*sets, f"grid.dx={dx!r}", f"initial.H0={a * R0!r}",
                                  f"case.models=['{model}']", *(extra or [])])


def measure_point(name: str, dx: float, a: float,
                  extra: list[str] | None = None) -> dict[str, Any]:
    """Run one point to rest: run-out r = (R_inf - R0)/R0, the deposit's numbers
    (pdeflow.analysis.sweep.deposit_numbers), cost, and the run warnings (e.g. the
    domain's end reached), as one CSV row."""
    case = point_case(name, dx, a, extra)
    model = case.models[0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RunWarning)
        res = run_model(case, model)
    s = res.summary
    row: dict[str, Any] = {"set": name, "dx": dx, "a": a,
                           "r": None if s["runout"] is None else s["runout"] / R0}
    row.update({k: s[k] for k in ("runout", "stop_time", "at_rest", "steps", "wall_time_s",
                                  "mass_relative_error")})
    row.update(deposit_numbers(res.x, res.state.data[::2].sum(axis=0), R0, a * R0,
                               s["stop_time"]))
    row["warnings"] = " | ".join(str(w.message) for w in caught
                                 if issubclass(w.category, RunWarning))
    return row


def read_cache(path: Path = CSV) -> list[dict[str, Any]]:
    """The stored rows, numbers parsed (empty cells: None)."""
    return run_cache.read_rows(path, ("set", "warnings"))


def fill_cache(points: list[tuple[str, float, float]], path: Path = CSV,
               log: Any = sys.stderr) -> list[dict[str, Any]]:
    """Run every (set, dx, a) of ``points`` not yet in ``path``, appending each row as it
    ends (an interrupted call loses at most the run under way); return all rows."""
    return run_cache.fill_rows(
        points, path, FIELDS, read_cache(path), key=tuple,
        row_key=lambda r: (r["set"], r["dx"], r["a"]), measure=lambda p: measure_point(*p),
        describe=lambda p, row, s: f"{p[0]:28} dr {p[1]:<10g} a {p[2]:<5g} "
                                   f"r {row['r']:.4g}  ({s:.1f} s)", log=log)


def sweep_points(grids: tuple[float, ...] = GRIDS) -> list[tuple[str, float, float]]:
    """Every (set, dx, a) of the page, coarse grids first, then the :data:`FINER` ones."""
    ratios = tomllib.loads(SWEEP_CASE.read_text())["sweep"]["aspect_ratios"]
    return ([(name, dx, float(a)) for dx in grids for name in SETS for a in ratios]
            + [(name, dx, float(a)) for name, more in FINER.items() for dx in more
               for a in ratios])


# --- the experiments --------------------------------------------------------------------

def lube_runout(a: np.ndarray) -> np.ndarray:
    """r(a) of Lube et al. (2004) as remembered: 1.24 a below a = 1.7, 1.6 a^(1/2) above."""
    a = np.asarray(a, dtype=float)
    return np.where(a < BREAK, 1.24 * a, 1.6 * np.sqrt(a))


def lube_height(a: np.ndarray) -> np.ndarray:
    """H_inf/R0 of Lube et al. (2004) as remembered: a below a = 0.74, 0.88 a^(1/6) above."""
    a = np.asarray(a, dtype=float)
    return np.where(a < 0.74, a, 0.88 * a ** (1 / 6))


def log_distance(model: np.ndarray, reference: np.ndarray) -> float:
    """exp(rms(ln model/reference)) - 1: the typical relative distance of two positive
    curves on the same points (0.1: 10 % off on average, either way)."""
    q = np.log(np.asarray(model, float) / np.asarray(reference, float))
    return float(np.exp(np.sqrt(np.mean(q**2))) - 1)


# --- numbers of the page ----------------------------------------------------------------

def _curve(rows: list[dict[str, Any]], name: str, dx: float, key: str) -> tuple[np.ndarray, ...]:
    sel = sorted((r for r in rows if r["set"] == name and r["dx"] == dx),
                 key=lambda r: r["a"])
    return (np.array([r["a"] for r in sel]), np.array([r[key] for r in sel], dtype=float))


def set_numbers(rows: list[dict[str, Any]], name: str, grids: tuple[float, ...]) -> dict:
    """One parameter set on its finest grid: fits below/above a = 1.7, distances to Lube's
    laws, and the convergence of r(a) (max relative change between successive grids)."""
    have = [dx for dx in grids if any(r["set"] == name and r["dx"] == dx for r in rows)]
    fine = have[-1]
    a, r = _curve(rows, name, fine, "r")
    _, h = _curve(rows, name, fine, "H_inf_over_L0")
    _, t = _curve(rows, name, fine, "arrest_time_scaled")
    lo, hi = a < BREAK, a >= BREAK
    fits = {k: fit_power_law(a[m], r[m]) for k, m in (("low", lo), ("high", hi), ("all", a > 0))}
    changes = []
    for coarse, finer in zip(have[:-1], have[1:], strict=True):
        _, rc = _curve(rows, name, coarse, "r")
        _, rf = _curve(rows, name, finer, "r")
        changes.append([coarse, finer, float(np.max(np.abs(rf - rc) / rf))])
    sel = [x for x in rows if x["set"] == name and x["dx"] == fine]
    return {"dx": fine, "a": a.tolist(), "r": r.tolist(), "H": h.tolist(), "t": t.tolist(),
            "fits": {k: list(v) for k, v in fits.items()}, "changes": changes,
            "d_runout": log_distance(r, lube_runout(a)),
            "d_height": log_distance(h, lube_height(a)),
            "ratio_a20": float(r[-1] / lube_runout(a[-1:])[0]),
            "all_at_rest": all(x["at_rest"] for x in sel),
            "warnings": sorted({x["warnings"] for x in sel if x["warnings"]}),
            "max_mass_error": max(x["mass_relative_error"] for x in sel),
            "wall_s": sum(x["wall_time_s"] for x in rows if x["set"] == name)}


def profile_runs(dx: float = PROFILE_DX, ratios: tuple[float, ...] = PROFILE_RATIOS,
                 names: tuple[str, ...] = tuple(SETS), dt: float = 0.01,
                 t_max: float = 2.5) -> dict:
    """Deposits and front histories: for every set and a, the final r [m], total and
    lower-layer depths [m] and the front (R(t) - R0)/R0 at t = 0, dt, ... [s] up to rest
    (or t_max [s])."""
    out: dict[str, Any] = {}
    for name in names:
        for a in ratios:
            times = [round(dt * k, 6) for k in range(1, round(t_max / dt) + 1)]
            case = point_case(name, dx, a, [f"output.snapshot_times={times!r}"])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RunWarning)
                res = run_model(case, case.models[0])
            d = res.state.data
            ts = sorted(res.snapshots)
            fronts = [(front_position(res.x, res.snapshots[t][0], case.front_threshold, dx)
                       - R0) / R0 for t in ts]
            final = (front_position(res.x, d, case.front_threshold, dx) - R0) / R0
            out[f"{name}|{a:g}"] = {
                "x": res.x, "h": d[::2].sum(axis=0), "h_lower": d[-2],
                "t": np.array([0.0, *ts, res.t_final]),
                "front": np.array([0.0, *fronts, final]),
                "stop_time": res.summary["stop_time"],
                "lower_stop_time": res.summary.get("lower_stop_time"),
                "upper_stop_time": res.summary.get("upper_stop_time")}
    return out


def complete(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows of the (set, dr) whose every aspect ratio of the sweep case has run (a
    grid still running or cut off is left out)."""
    ratios = {float(a) for a in tomllib.loads(SWEEP_CASE.read_text())["sweep"]["aspect_ratios"]}
    have: dict[tuple[str, float], set[float]] = {}
    for r in rows:
        have.setdefault((r["set"], r["dx"]), set()).add(r["a"])
    return [r for r in rows if have[(r["set"], r["dx"])] >= ratios]


def page_numbers(rows: list[dict[str, Any]], grids: tuple[float, ...] = GRIDS) -> dict:
    """Every number the page quotes from the sweep rows (JSON-ready; only complete grids
    count, :func:`complete`)."""
    rows = complete(rows)
    phi = {name: float(point_case(name, GRIDS[0], 1.0).make_pde(SETS[name][0])
                       .parameters.phi_b_deg) for name in SETS}
    run = {r["dx"] for r in rows}
    every = tuple(g for g in sorted({*grids, *(g for m in FINER.values() for g in m)},
                                    reverse=True) if g in run)
    return {"sets": {name: set_numbers(rows, name, every) for name in SETS},
            "grids": list(every), "R0": R0, "points": len(rows), "phi_b_deg": phi}


def main(argv: list[str] | None = None) -> int:
    """Fill the cache, then (unless --runs-only) write the page, its figures and numbers."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs-only", action="store_true", help="fill the cache, no page")
    ap.add_argument("--no-runs", action="store_true",
                    help="the page from the cache as it is (complete grids only)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = read_cache() if args.no_runs else fill_cache(sweep_points())
    if args.runs_only:
        return 0
    import axisymmetric_page as page

    numbers = page_numbers(rows)
    numbers["planar_law"] = page.planar_law_check()
    profiles = profile_runs()
    numbers["profiles"] = page.profile_numbers(profiles)
    before = run_cache.snapshot(OUT.glob("*.png"))
    page.figures(rows, numbers, profiles, OUT)
    print(run_cache.publish(numbers, t0, OUT / "numbers.json",
                            ROOT / "docs" / "axisymmetric.md", page.render_page, before))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
