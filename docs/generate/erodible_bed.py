"""Regenerate docs/erodible_bed.md: collapses over erodible beds, both models, the slope
and the bed's thickness swept, against the trend of the channel experiments.

    python docs/generate/erodible_bed.py             # runs what the cache lacks, then the page
    python docs/generate/erodible_bed.py --runs-only # fill the cache only (resumable)
    python docs/generate/erodible_bed.py --no-runs   # the page from the cache as it is
    python docs/generate/erodible_bed.py --rerun     # empty the cache first, run it all

Every point (parameter set, closure, slope theta, bed thickness e_i, grid dx) is one
run of cases/erodible_bed.toml to rest; its numbers go to docs/erodible_bed/sweep.csv as
soon as it ends, and a later call runs only the points missing there. The coarse grid
(dx = 5 mm) covers the whole sweep; the key points (theta = 22 and 25 deg, and 2 deg
below each set's basal friction angle, at e_i = 0, 5, 14 mm) are refined. The page's
numbers (docs/erodible_bed/numbers.json) are computed from the CSV by
:func:`page_numbers`; the side view and the stresses at the erosion front come from two
runs made every time (seconds).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import run_cache
from law_set import law_set_overrides

from pdeflow.cases import load_case
from pdeflow.checks import RunWarning
from pdeflow.simulate import run_model

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "erodible_bed.toml"
OUT = ROOT / "docs" / "erodible_bed"
CSV = OUT / "sweep.csv"
H0 = 0.14
"""column height [m] (initial.H0 of the case)"""
THETAS = (0.0, 10.0, 16.0, 19.0, 22.0, 25.0)
"""slopes of the sweep [deg]: the experiments' range 0-25 deg"""
NEAR = (4.0, 2.0, 1.0)
"""slopes below each set's basal friction angle phi_B [deg]: where the model's bed is
close to failing, as the experiments' bed is near its repose angle"""
BEDS = (0.0, 0.002, 0.005, 0.01, 0.014)
"""bed thicknesses e_i [m]: 0 to H0/10"""
DU_REG = 0.05
"""the du_reg bound [m/s] of the 'du_reg' closure: the planar law set's value
(cases/paper_5_2_two_layer_law.toml), in the converged corner of two_layer_law.md"""
COARSE = 0.005
"""dx [m] of the whole sweep (H0/28; the column is 40 cells long)"""
REFINE = (0.0025, 0.00125, 0.000625)
"""dx [m] of the key points at 22 and 25 deg (three halvings)"""
REFINE_NEAR = (0.0025, 0.00125)
"""dx [m] of the key points 2 deg below phi_B (their runs are long: two halvings)"""
KEY_BEDS = (0.0, 0.005, 0.014)
KEY_THETAS = (22.0, 25.0)
SERIES_EVERY = 0.01
"""frames of the erosion series [s]: the flow duration is resolved to 10 ms"""
MAIN = {"length": 3.0, "t_end": 10.0}
"""domain [m] and end time [s] of the sweep's slopes (every run out < 1.5 m, at rest by 3 s)"""
NEAR_RUN = {"length": 8.0, "t_end": 30.0}
"""the same near phi_B, where the flows run metres and last seconds"""
CLOSURES: dict[str, list[str]] = {
    "paper": ["two_layer.exchange_closure='paper'", "two_layer.du_reg=0.0"],
    "du_reg": ["two_layer.exchange_closure='paper'", f"two_layer.du_reg={DU_REG!r}"],
    "relaxed": ["two_layer.exchange_closure='relaxed'", "two_layer.du_reg=0.0"],
}
"""the exchange closures: the paper's (25), the same bounded by du_reg, the relaxed one
(tau_star 1, its default)"""
FIELDS = ("set", "closure", "theta", "e_i", "dx", "runout", "flow_duration", "stop_time",
          "at_rest", "runout_lower_bound", "front_velocity_max", "bed_eroded_volume_max",
          "bed_eroded_volume", "bed_deposited_volume", "bed_max_erosion_depth",
          "bed_moving_volume_max", "booked_eroded", "erosion_lead", "max_fextra",
          "steps", "wall_time_s", "mass_relative_error", "warnings")


SETS: dict[str, tuple[str, list[str]]] = {
    "single layer": ("single_layer", []),
    "two layers, defaults": ("two_layer", []),
    # the planar law set but its closure (du_reg): the bed runs the default one
    "two layers, planar law set": ("two_layer", law_set_overrides(omit=("du_reg",))),
    "two layers, pouliquen": ("two_layer", ["two_layer.friction_law='pouliquen'"]),
    "two layers, mu_i": ("two_layer", ["two_layer.friction_law='mu_i'"]),
}
"""name -> (model, overrides): the shipped parameter sets (docs/parameters.md), and the
defaults with a rate-dependent law for the lower layer's bed, Pouliquen's mu(h, Fr) and
the depth-averaged mu(I) (pdeflow/models/friction_laws.py at their glass-bead defaults;
docs/rheology.md)"""
LAW_SETS = ("two layers, pouliquen", "two layers, mu_i")
"""the sets with a rate-dependent bed law. Their static angle depends on the depth
(pouliquen) or is tan d1 (mu_i), so their phi_B is the angle at which the thickest bed of
the sweep stands on its own (:func:`phi_b`). Their coarse sweep has no near-phi_B slopes:
that angle is 21-22 deg, so the sweep's 19 and 22 deg already bracket it (and the near
runs would need the 8 m channel). Their key points are refined twice (LAW_REFINE), at
e_i = 0 and H0/10 only (LAW_KEY_BEDS), and at LAW_KEY_THETAS: 22 and 25 deg as for the
other sets, and 16 and 19 deg, the steepest slopes below the law's static angle, where
their flows stop inside the channel"""
LAW_KEY_BEDS = (0.0, 0.014)
LAW_KEY_THETAS = (16.0, 19.0, 22.0, 25.0)
LAW_REFINE = (0.0025, 0.00125)


def static_angle(name: str, depth: float) -> float:
    """The bed law's static friction angle [deg] of the set ``name`` for a layer
    ``depth`` [m] deep: Pouliquen's mu_stop(h) = tan d1 + (tan d2 - tan d1)/(1 + h/L)
    (the inverse of h_stop; pdeflow.numerics.rheology.POULIQUEN.static_mu), mu_i's tan d1, and
    Coulomb's phi_b_deg."""
    model, sets = SETS[name]
    p = load_case(CASE, sets).make_pde(model).parameters
    if p.friction_law == "coulomb":
        return float(p.phi_b_deg)
    t1 = math.tan(math.radians(p.delta1_deg))
    t2 = math.tan(math.radians(p.delta2_deg))
    mu = t1 + (t2 - t1) / (1.0 + depth / p.pouliquen_L) if p.friction_law == "pouliquen" \
        else t1
    return math.degrees(math.atan(mu))


def phi_b(name: str) -> float:
    """The basal friction angle [deg] of the set ``name``: Coulomb's phi_b_deg, or for a
    rate-dependent law its static angle for the thickest bed, e_i = H0/10 (the steepest
    slope on which every bed of the sweep stands on its own), to 0.01 deg."""
    if name in LAW_SETS:
        return round(static_angle(name, max(BEDS)), 2)
    return static_angle(name, 0.0)


def point_case(name: str, closure: str, theta: float, e_i: float, dx: float,
               extra: list[str] | None = None) -> Any:
    """The case of one point (the single layer takes no closure: ``closure`` '-')."""
    model, sets = SETS[name]
    run = NEAR_RUN if theta > max(THETAS) else MAIN
    over = [*sets, *(CLOSURES[closure] if model == "two_layer" else []),
            f"{model}.theta_deg={theta!r}", f"initial.bed_thickness={e_i!r}",
            f"grid.dx={dx!r}", f"grid.length={run['length']!r}",
            f"case.t_end={run['t_end']!r}", f"case.models=['{model}']",
            "output.snapshot_times=[]", f"output.series_every={SERIES_EVERY!r}"]
    return load_case(CASE, [*over, *(extra or [])])


def erosion_lead(series: Any) -> float | None:
    """How far [m] the erosion front ran ahead of the flow front at most (negative:
    it stayed behind it); None where nothing was eroded."""
    if series.erosion_front is None or not np.isfinite(series.erosion_front).any():
        return None
    return float(np.nanmax(series.erosion_front - series.front))


def measure_point(name: str, closure: str, theta: float, e_i: float,
                  dx: float) -> dict[str, Any]:
    """Run one point to rest: its summary's numbers and the run warnings, as a CSV row."""
    case = point_case(name, closure, theta, e_i, dx)
    model = case.models[0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RunWarning)
        res = run_model(case, model)
    s = res.summary
    row: dict[str, Any] = {"set": name, "closure": closure, "theta": theta, "e_i": e_i,
                           "dx": dx, "booked_eroded": s.get("eroded_volume"),
                           "erosion_lead": erosion_lead(res.series),
                           "max_fextra": s.get("max_fextra_over_rho1")}
    for key in FIELDS:
        if key in s:
            row[key] = s[key]
    row["warnings"] = " | ".join(sorted({str(w.message) for w in caught
                                         if issubclass(w.category, RunWarning)}))
    return row


def _key(row: dict[str, Any]) -> tuple:
    return (row["set"], row["closure"], float(row["theta"]), float(row["e_i"]),
            float(row["dx"]))


def read_cache(path: Path = CSV) -> list[dict[str, Any]]:
    """The stored rows, numbers parsed (empty cells: None)."""
    return run_cache.read_rows(path, ("set", "closure", "warnings"),
                               ("at_rest", "runout_lower_bound"))


def fill_cache(points: list[tuple], path: Path = CSV,
               log: Any = sys.stderr) -> list[dict[str, Any]]:
    """Run every point not yet in ``path``, appending each row as it ends; all rows."""
    return run_cache.fill_rows(
        points, path, FIELDS, read_cache(path),
        key=lambda p: (p[0], p[1], float(p[2]), float(p[3]), float(p[4])), row_key=_key,
        measure=lambda p: measure_point(*p),
        describe=lambda p, row, s: f"{p[0]:27} {p[1]:8} theta {p[2]:<4g} e_i {p[3]:<6g} "
                                   f"dx {p[4]:<9g} run-out {row['runout']:.4g} ({s:.1f} s)",
        log=log)


def sweep_points() -> list[tuple]:
    """Every (set, closure, theta, e_i, dx) of the page: the coarse sweep, then the
    refined key points."""
    pts: list[tuple] = []
    for name, (model, _) in SETS.items():
        closures = list(CLOSURES) if model == "two_layer" else ["-"]
        near = [phi_b(name) - d for d in NEAR]
        beds = BEDS if model == "two_layer" else (0.0,)  # the single layer has no bed
        if name in LAW_SETS:
            near = []
        for closure in closures:
            pts += [(name, closure, th, e, COARSE) for th in (*THETAS, *near) for e in beds]
    keys = [p for p in pts if p[2] in KEY_THETAS and p[3] in KEY_BEDS
            and p[0] not in LAW_SETS]
    near_keys = [p for p in pts if p[2] == phi_b(p[0]) - 2.0 and p[3] in KEY_BEDS]
    law_keys = [p for p in pts if p[0] in LAW_SETS and p[2] in LAW_KEY_THETAS
                and p[3] in LAW_KEY_BEDS]
    pts += [(*p[:4], dx) for dx in REFINE for p in keys]
    pts += [(*p[:4], dx) for dx in REFINE_NEAR for p in near_keys]
    pts += [(*p[:4], dx) for dx in LAW_REFINE for p in law_keys]
    return pts


def main(argv: list[str] | None = None) -> int:
    """Fill the cache, then (unless --runs-only) write the page, its figures and numbers."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs-only", action="store_true", help="fill the cache, no page")
    ap.add_argument("--no-runs", action="store_true", help="the page from the cache")
    ap.add_argument("--rerun", action="store_true", help="empty the cache first")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    if args.rerun and CSV.is_file():
        CSV.unlink()
    rows = read_cache() if args.no_runs else fill_cache(sweep_points())
    if args.runs_only:
        return 0
    import matplotlib

    matplotlib.use("Agg")  # files only
    import erodible_bed_page as page

    numbers = page.page_numbers(rows)
    before = run_cache.snapshot(OUT.glob("*.png"))
    numbers.update(page.figures(rows, numbers, OUT))
    numbers["points"] = len(rows)
    print(run_cache.publish(numbers, t0, OUT / "numbers.json",
                            ROOT / "docs" / "erodible_bed.md", page.render_page, before))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
