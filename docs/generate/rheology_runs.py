"""The runs of docs/rheology.md: every (geometry, model, law, grid, aspect ratio) point,
one run to rest each, cached row by row in a CSV (docs/rheology/sweep.csv).

A point is the planar collapse of test 5.2 (cases/collapse_sweep.toml, L0 = 0.1 m) or the
axisymmetric collapse (cases/axisymmetric_collapse_sweep.toml, R0 = 0.1 m) with one model
and one basal law set of :data:`LAW_SETS`, measured by
:func:`pdeflow.analysis.sweep.run_sweep` (one aspect ratio, one model). A later call runs
only the points missing from the cache; ``fill_cache(..., rerun=True)`` runs them all again.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path
from typing import Any

import run_cache

from pdeflow.analysis.sweep import run_sweep
from pdeflow.cases import load_case
from pdeflow.checks import RunWarning

ROOT = Path(__file__).resolve().parents[2]
CASES = {"planar": ROOT / "cases" / "collapse_sweep.toml",
         "axisymmetric": ROOT / "cases" / "axisymmetric_collapse_sweep.toml"}
LENGTH = {"planar": 30.0, "axisymmetric": 6.0}
"""domain length [m] per geometry: holds every run-out of every law (the longest, Voellmy's
at a = 24 planar, ends near 12 m; radial at a = 20 near 3.4 m)"""
MODELS = ("two_layer", "single_layer")
"""both models with the case files' parameters (the two-layer defaults; the law replaces
the lower layer's bed friction)"""
LAGREE_MU = (0.32, 0.28, 0.4)
"""mu_s, delta_mu, I0 of Lagree, Staron & Popinet (2011), as in granular.h of the first
author's Basilisk sandbox (basilisk.fr/sandbox/M1EMN/Exemples/granular.h), the counterpart
of the paper's Gerris case"""
LAGREE_D1 = math.degrees(math.atan(LAGREE_MU[0]))
LAGREE_D2 = math.degrees(math.atan(LAGREE_MU[0] + LAGREE_MU[1]))
LAGREE_I0 = LAGREE_MU[2]
LAW_SETS: dict[str, list[str]] = {
    "coulomb": ["friction_law='coulomb'"],
    "pouliquen": ["friction_law='pouliquen'"],
    "mu_i": ["friction_law='mu_i'"],
    "voellmy": ["friction_law='voellmy'"],
    "mu_i_lagree": ["friction_law='mu_i'", f"delta1_deg={LAGREE_D1!r}",
                    f"delta2_deg={LAGREE_D2!r}", f"mu_i_I0={LAGREE_I0!r}"],
}
"""law set name -> overrides of the model's keys: each law at its documented defaults, and
``mu_i_lagree``, mu_i with the mu(I) constants of Lagree, Staron & Popinet (2011) as their
first author's Basilisk code states them (:data:`LAGREE_MU`; d and phi stay the defaults:
the depth-averaged I needs them and their continuum's grain size is in the units of a
contact-dynamics column, not metres)"""
GEOMETRY_LAWS = {"planar": tuple(LAW_SETS),
                 "axisymmetric": ("coulomb", "pouliquen", "mu_i", "voellmy")}
"""the law sets run per geometry (Lagree et al.'s collapses are planar)"""
GRIDS = {"planar": (0.01, 0.005, 0.0025, 0.00125, 0.000625),
         "axisymmetric": (0.00125, 0.000625, 0.0003125, 0.00015625)}
"""dx [m] per geometry, coarse to fine: planar dx = 0.01 m (the paper's) / 1 .. 16, radial
R0/80 .. R0/640 (where the Coulomb sweep of docs/axisymmetric.md converged to 0.3 %)"""
RATIOS = {"planar": (2.0, 4.0, 8.0, 14.0, 24.0),
          "axisymmetric": (0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 7.0, 10.0, 14.0, 20.0)}
"""aspect ratios a = H0/L0 per geometry (radial: those of the axisymmetric sweep case)"""
FIELDS = ("geometry", "model", "law", "dx", "a", "r", "runout", "stop_time", "at_rest",
          "steps", "wall_time_s", "mass_relative_error", "H_inf_over_L0",
          "arrest_time_scaled", "warnings")
TEXT = ("geometry", "model", "law", "warnings")

Point = tuple[str, str, str, float, float]
"""(geometry, model, law set, dx [m], a)"""


def point_case(geometry: str, model: str, law: str, dx: float,
               length: float | None = None) -> Any:
    """The case of one geometry with ``model`` alone, law set ``law``, spacing dx [m]."""
    sets = [f"{model}.{s}" for s in LAW_SETS[law]]
    return load_case(CASES[geometry], [
        *sets, f"grid.dx={dx!r}", f"grid.length={length or LENGTH[geometry]!r}",
        f"case.models=['{model}']"])


def measure(point: Point, length: float | None = None) -> dict[str, Any]:
    """Run one point to rest and return its CSV row (run warnings, e.g. the domain's end
    reached, kept as text)."""
    geometry, model, law, dx, a = point
    case = point_case(geometry, model, law, dx, length)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RunWarning)
        run = run_sweep(case, [a], models=[model])["models"][model]["runs"][0]
    row: dict[str, Any] = dict(zip(("geometry", "model", "law", "dx", "a"), point,
                                   strict=True))
    row.update({k: run.get(k) for k in FIELDS if k not in row and k != "warnings"})
    row["warnings"] = " | ".join(sorted({str(w.message) for w in caught
                                         if issubclass(w.category, RunWarning)}))
    return row


def read_cache(path: Path) -> list[dict[str, Any]]:
    """The stored rows, numbers parsed (empty cells: None)."""
    return run_cache.read_rows(path, TEXT)


def key(row: dict[str, Any]) -> Point:
    """The point of a row."""
    return (row["geometry"], row["model"], row["law"], float(row["dx"]), float(row["a"]))


def fill_cache(points: list[Point], path: Path, rerun: bool = False,
               length: dict[str, float] | None = None,
               log: Any = sys.stderr) -> list[dict[str, Any]]:
    """Run every point of ``points`` not yet in ``path`` (all of them if ``rerun``: their
    old rows are dropped), appending each row as it ends; return all rows."""
    rows = read_cache(path)
    if rerun:
        todo = set(points)
        rows = [r for r in rows if key(r) not in todo]
        run_cache.write_rows(path, FIELDS, rows)
    return run_cache.fill_rows(
        points, path, FIELDS, rows, key=tuple, row_key=key,
        measure=lambda p: measure(p, (length or {}).get(p[0])),
        describe=lambda p, row, s: f"{p[0]:12} {p[1]:12} {p[2]:10} dx {p[3]:<10g} "
                                   f"a {p[4]:<5g} r {row['r']}  ({s:.1f} s)", log=log)


COST_WEIGHT = {"planar": 1.0, "axisymmetric": 8.0}
"""relative cost of a point per (cells)^2 (measured on this sweep: a radial point costs
about 8 times a planar one of as many cells, its runs last longer); orders the points"""


def all_points(grids: dict[str, tuple[float, ...]] = GRIDS,
               ratios: dict[str, tuple[float, ...]] = RATIOS,
               laws: dict[str, tuple[str, ...]] = GEOMETRY_LAWS,
               length: dict[str, float] = LENGTH) -> list[Point]:
    """Every point, whole grids in the order of their estimated cost
    ((length/dx)^2 times :data:`COST_WEIGHT`), cheapest first."""
    levels = sorted(((g, dx) for g, gs in grids.items() for dx in gs),
                    key=lambda p: COST_WEIGHT[p[0]] * (length[p[0]] / p[1]) ** 2)
    return [(g, m, law, dx, float(a)) for g, dx in levels for m in MODELS
            for law in laws[g] for a in ratios[g]]


STATIC_DEPTH = 0.01
"""depth [m] at which the page quotes each law's static friction angle: about the
deposits' depth (0.1 R0); Pouliquen's mu_stop(h) depends on h, the others do not"""


def static_angles(geometry: str = "planar",
                  depth: float = STATIC_DEPTH) -> dict[str, dict[str, float]]:
    """{model: {law set: the angle [deg] of the static friction bound of a layer
    ``depth`` deep}} with the case's and the laws' default parameters: Coulomb's phi_b,
    Pouliquen's mu_stop(h) = tan d1 + (tan d2 - tan d1)/(1 + h/L), mu(I)'s mu_s = tan d1,
    Voellmy's mu."""
    out: dict[str, dict[str, float]] = {}
    for model in MODELS:
        out[model] = {}
        for law in GEOMETRY_LAWS[geometry]:
            p = point_case(geometry, model, law, GRIDS[geometry][0]).make_pde(
                model).parameters
            mu1 = math.tan(math.radians(p.delta1_deg))
            mu = {"coulomb": math.tan(math.radians(p.phi_b_deg)),
                  "pouliquen": mu1 + (math.tan(math.radians(p.delta2_deg)) - mu1)
                  / (1 + depth / p.pouliquen_L),
                  "voellmy": p.voellmy_mu}.get(p.friction_law, mu1)
            out[model][law] = math.degrees(math.atan(mu))
    return out
