"""Every number docs/rheology.md quotes, computed from the cached rows of the law sweeps
(docs/generate/rheology_runs.py): fits, distances to the experiments' laws, the change of
the run-outs per grid halving and the ranking of the laws on every grid.

The experiments' laws: planar, Lube et al. (2005), r = 1.9 a^(2/3) above a = 2.8
(:data:`pdeflow.analysis.sweep.PUBLISHED_LAWS`, which cites the paper); axisymmetric, Lube et
al. (2004) as docs/axisymmetric.md uses it (:func:`axisymmetric.lube_runout`, not confirmed
there). The distances are those of docs/rheology.md's planar table before (mean |ln(r /
r_Lube)| over a > 2.8) and of docs/axisymmetric.md (exp of the rms of ln(r / r_Lube) minus 1).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from axisymmetric import BREAK, log_distance, lube_height, lube_runout

from pdeflow.analysis.sweep import fit_power_law, published_law

LUBE_PLANAR = "Lube et al. 2005"
LUBE_FROM = 2.8
"""a above which the planar law's power-law branch holds (and the planar misfit counts)"""
Q_MAX = 0.8
"""largest ratio of successive changes for which the tail estimate is given: nearer 1 the
geometric tail q/(1 - q) explodes, and a run-out is only resolved to one cell (dx/L0), so
a ratio of two changes of a cell or two is noise"""
COST_NOTE = "time steps to the estimated stop time"
"""a phrase of the run's cost-estimate warning (not a problem of the run)"""
CONVERGED = 0.01
"""largest relative change of r(a) per grid halving that counts as converged (the
threshold of docs/axisymmetric.md)"""


def planar_misfit(a: np.ndarray, r: np.ndarray) -> float:
    """Mean |ln(r / r_Lube)| over the points with a > LUBE_FROM (nan if none)."""
    m = a > LUBE_FROM
    if not m.any():
        return math.nan
    return float(np.mean(np.abs(np.log(r[m] / published_law(LUBE_PLANAR, a[m])))))


def planar_bias(a: np.ndarray, r: np.ndarray) -> float:
    """Geometric mean of r / r_Lube over a > LUBE_FROM: > 1 over-predicts (nan if none)."""
    m = a > LUBE_FROM
    if not m.any():
        return math.nan
    return float(np.exp(np.mean(np.log(r[m] / published_law(LUBE_PLANAR, a[m])))))


def curve(rows: list[dict[str, Any]], geometry: str, model: str, law: str,
          dx: float) -> tuple[np.ndarray, np.ndarray]:
    """(a, r) of one law sweep on one grid, sorted by a (runs without a run-out left out)."""
    sel = sorted((x for x in rows if (x["geometry"], x["model"], x["law"], x["dx"])
                  == (geometry, model, law, dx) and x["r"]), key=lambda x: x["a"])
    return np.array([x["a"] for x in sel]), np.array([x["r"] for x in sel], dtype=float)


def grid_numbers(rows: list[dict[str, Any]], geometry: str, model: str, law: str,
                 dx: float) -> dict[str, Any]:
    """Fits and distances of one law sweep on one grid."""
    a, r = curve(rows, geometry, model, law, dx)
    sel = [x for x in rows if (x["geometry"], x["model"], x["law"], x["dx"])
           == (geometry, model, law, dx)]
    out: dict[str, Any] = {"a": a.tolist(), "r": r.tolist(),
                           "fit": list(fit_power_law(a, r)) if a.size > 1 else None,
                           "all_at_rest": all(x["at_rest"] for x in sel),
                           "warnings": sorted({x["warnings"] for x in sel if x["warnings"]}),
                           "wall_s": sum(x["wall_time_s"] or 0.0 for x in sel)}
    if geometry == "planar":
        out["misfit"] = planar_misfit(a, r)
        out["bias"] = planar_bias(a, r)
    else:
        lo, hi = a < BREAK, a >= BREAK
        out["fit_low"] = list(fit_power_law(a[lo], r[lo])) if lo.sum() > 1 else None
        out["fit_high"] = list(fit_power_law(a[hi], r[hi])) if hi.sum() > 1 else None
        out["misfit"] = log_distance(r, lube_runout(a))
        out["bias"] = float(r[-1] / lube_runout(a[-1:])[0])  # at the largest a
        h = np.array([x["H_inf_over_L0"] for x in sorted(sel, key=lambda x: x["a"])
                      if x["r"]], dtype=float)
        out["d_height"] = log_distance(h, lube_height(a))
    return out


def convergence(rows: list[dict[str, Any]], geometry: str, model: str, law: str,
                grids: list[float]) -> dict[str, Any]:
    """Per grid halving the largest relative change of r over a; ``converged_from``, the
    coarsest grid from which on every halving changes r by at most CONVERGED (None: the
    last one changed it more); and a Richardson-type
    tail: if every point's change keeps shrinking by the factor q of its last two
    changes, the finest grid is off by change * q / (1 - q) (None when q > Q_MAX at some
    a: not yet in the range where the changes shrink steadily)."""
    curves = [curve(rows, geometry, model, law, g)[1] for g in grids]
    changes = [float(np.max(np.abs(f - c) / np.abs(f))) for c, f in zip(
        curves[:-1], curves[1:], strict=True)]
    tail = None
    if len(curves) >= 3:
        c1 = np.abs(curves[-2] - curves[-3])
        c2 = np.abs(curves[-1] - curves[-2])
        q = np.divide(c2, c1, out=np.zeros_like(c2), where=c1 > 0)
        q[(c1 == 0) & (c2 > 0)] = math.inf
        if np.all(q <= Q_MAX):
            tail = float(np.max(c2 * q / (1 - q) / np.abs(curves[-1])))
    k = len(changes)
    while k > 0 and changes[k - 1] <= CONVERGED:
        k -= 1
    return {"changes": changes, "tail": tail,
            "converged": bool(changes) and changes[-1] <= CONVERGED,
            "converged_from": grids[k] if k < len(changes) else None}


def ranking(per_grid: dict[str, dict[str, Any]]) -> list[str]:
    """The law sets ordered by misfit on one grid, closest first."""
    return sorted(per_grid, key=lambda law: per_grid[law]["misfit"])


def stable_from(rankings: list[list[str]], grids: list[float]) -> float | None:
    """The coarsest grid from which on the ranking no longer changes (None: it changes
    between the finest two)."""
    if len(rankings) < 2 or rankings[-1] != rankings[-2]:
        return None
    k = len(rankings) - 1
    while k > 0 and rankings[k - 1] == rankings[-1]:
        k -= 1
    return grids[k]


def close_pairs(per: dict[str, dict[float, dict[str, Any]]], rank: list[str],
                grids: list[float]) -> list[list[Any]]:
    """Neighbours of the finest ranking whose misfits differ by less than either moved
    in the last halving (a pair the next grid could still swap): [law, law, gap,
    larger last change]."""
    if len(grids) < 2:
        return []
    moved = {law: abs(per[law][grids[-1]]["misfit"] - per[law][grids[-2]]["misfit"])
             for law in rank}
    out = []
    for a, b in zip(rank[:-1], rank[1:], strict=True):
        gap = per[b][grids[-1]]["misfit"] - per[a][grids[-1]]["misfit"]
        if gap <= max(moved[a], moved[b]):
            out.append([a, b, gap, max(moved[a], moved[b])])
    return out


def geometry_numbers(rows: list[dict[str, Any]], geometry: str) -> dict[str, Any]:
    """Every number of one geometry: per model the grids, per law set and grid the
    :func:`grid_numbers`, the :func:`convergence`, and the ranking per grid."""
    out: dict[str, Any] = {}
    for model in sorted({x["model"] for x in rows if x["geometry"] == geometry}):
        mine = [x for x in rows if x["geometry"] == geometry and x["model"] == model]
        laws = list(dict.fromkeys(x["law"] for x in mine))
        ratios = {x["a"] for x in mine}
        grids = sorted({x["dx"] for x in mine}, reverse=True)
        grids = [g for g in grids if all(  # complete grids only (every law, every a)
            {x["a"] for x in mine if x["law"] == law and x["dx"] == g} == ratios
            for law in laws)]
        partial = [[g, sum(1 for x in mine if x["dx"] == g), len(laws) * len(ratios)]
                   for g in sorted({x["dx"] for x in mine}, reverse=True) if g not in grids]
        per = {law: {g: grid_numbers(rows, geometry, model, law, g) for g in grids}
               for law in laws}
        ranks = [ranking({law: per[law][g] for law in laws}) for g in grids]
        out[model] = {
            "grids": grids, "laws": laws, "partial_grids": partial,
            "per_grid": {law: {repr(g): v for g, v in per[law].items()} for law in laws},
            "convergence": {law: convergence(rows, geometry, model, law, grids)
                            for law in laws},
            "rankings": ranks, "ranking_stable_from": stable_from(ranks, grids),
            "close_pairs": close_pairs(per, ranks[-1], grids)}
    return out


def page_numbers(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """All numbers of the page (JSON-ready)."""
    return {"planar": geometry_numbers(rows, "planar"),
            "axisymmetric": geometry_numbers(rows, "axisymmetric"),
            "runs": len(rows),
            "all_at_rest": all(x["at_rest"] for x in rows),
            "max_mass_error": max((x["mass_relative_error"] or 0.0 for x in rows),
                                  default=0.0),
            "other_warnings": sorted({w for x in rows for w in x["warnings"].split(" | ")
                                      if w and COST_NOTE not in w}),
            "wall_s": round(sum(x["wall_time_s"] or 0.0 for x in rows), 1),
            "converged_threshold": CONVERGED}
