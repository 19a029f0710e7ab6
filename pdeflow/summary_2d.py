"""The summary of a run on a 2D grid (issue 36): what :func:`pdeflow.simulate.summarize`
is for 1D, from the 2D measures of :mod:`pdeflow.metrics_2d`.

Keys (besides the model's own numbers from its system, e.g. the stop times, and the
run's bookkeeping: model, solver, geometry 'planar-2d', t_final, at_rest, steps,
wall_time_s, stop_reason, flux_fallback_steps, positivity_retries, warnings):

* ``front_position`` [m]: the largest x reached (the downstream face of the last cell
  deeper than ``output.front_threshold``), ``runout`` [m] that minus the release's
  largest x (x0 + its semi-axis along x);
* ``lateral_spread`` [m]: the flow's extent across (y), the same threshold;
* ``deposit_area`` [m^2]: the area deeper than the threshold;
* ``mass_radius`` [m]: the radius about the release's centre (x0, y0) holding
  ``output.runout_mass_fraction`` (0.99: r99) of the mass, for radial spreads;
* ``max_depth`` [m]: the final state's deepest cell (all layers); ``max_speed`` [m/s]:
  the largest speed of any layer, sampled over the run
  (:class:`pdeflow.trackers.peaks.PeakTracker`);
* ``mass_relative_error``, ``mass_change`` [-] as in 1D; ``domain_ends``: the sides
  ('left', 'right' along x, 'y_low', 'y_high' across) whose outermost cells are deeper
  than the threshold at the end, and the mass lost through open ones.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import metrics_2d as m2
from .checks import MASS_WARN, result_warnings
from .initial_shapes_2d import release_centre, release_front

SIDES_2D = ("left", "right", "y_low", "y_high")
"""the sides of a 2D domain: x low and high, y low and high"""
KEYS_2D = ("lateral_spread", "deposit_area", "mass_radius", "max_depth", "max_speed")
"""the summary keys a 2D run adds to the 1D ones it shares"""
COMMON_KEYS_2D = ("model", "solver", "geometry", "t_final", "at_rest", "front_position",
                  "runout", *KEYS_2D, "runout_mass_fraction", "mass_relative_error",
                  "mass_change", "steps", "wall_time_s", "stop_reason",
                  "flux_fallback_steps", "positivity_retries", "domain_ends",
                  "runout_lower_bound", "warnings")
"""the keys of every 2D summary (:func:`summarize_2d`) besides the model's own
(:func:`pdeflow.simulate.summary_keys` adds those)"""


def sides_reached(depth: np.ndarray, threshold: float) -> list[str]:
    """The sides (:data:`SIDES_2D`) whose outermost row of cells has a cell deeper than
    ``threshold`` [m] (``depth`` of shape (nx, ny) [m])."""
    rows = (depth[0], depth[-1], depth[:, 0], depth[:, -1])
    return [side for side, row in zip(SIDES_2D, rows, strict=True)
            if np.any(row > threshold)]


def summarize_2d(res: Any, mass0: float, wall: float, peak_speed: float,
                 initial: np.ndarray) -> dict[str, Any]:
    """The summary of the 2D run ``res`` (a :class:`~pdeflow.simulate.RunResult`):
    ``mass0`` its initial mass [m^3], ``wall`` its wall time [s], ``peak_speed`` the
    sampled largest speed [m/s], ``initial`` the initial state data."""
    case, d = res.case, res.state.data
    x, y = res.state.grid.axes_coords
    params = res.pde.parameters
    area = case.dx * case.dy
    depth = m2.total_depth(d)
    thr = case.front_threshold
    front = m2.front_x(x, depth, thr, case.dx)
    x0, y0 = release_centre(case.initial)
    x0, y0 = case.x_start + x0, case.y_start + y0
    X, Y = np.meshgrid(x, y, indexing="ij")
    weights = res.pde.system.densities(params)
    mass1 = m2.mass(d, weights, area)
    out: dict[str, Any] = {
        "model": res.model, "solver": case.solver, "geometry": res.metric.geometry,
        "t_final": res.t_final, "at_rest": "rest_time" in res.info.get("solver", {}),
        "front_position": front,
        "runout": None if front is None
        else front - case.x_start - release_front(case.initial),
        "lateral_spread": m2.lateral_spread(y, depth, thr, case.dy),
        "deposit_area": m2.deposit_area(depth, thr, area),
        "mass_radius": m2.mass_radius(np.hypot(X - x0, Y - y0),
                                      m2.weighted_depth(d, weights),
                                      case.runout_mass_fraction),
        "runout_mass_fraction": case.runout_mass_fraction,
        "max_depth": float(depth.max()),
        "max_speed": peak_speed,
        "mass_relative_error": abs(mass1 - mass0) / mass0 if mass0 else 0.0,
        "mass_change": (mass1 - mass0) / mass0 if mass0 else 0.0,
        "steps": int(res.info.get("solver", {}).get("steps", 0)),
        "wall_time_s": wall,
        "stop_reason": res.info.get("controller", {}).get("stop_reason"),
    }
    diag = res.diagnostics
    if diag is not None:
        out["flux_fallback_steps"] = diag.flux_fallbacks
        out["positivity_retries"] = diag.positivity_retries
        out.update(res.pde.system.summarize(diag, res.t_final, out["at_rest"], x, d,
                                            res.metric))
    out["domain_ends"] = ends = _domain_ends(case, initial, depth, out["mass_change"])
    out["runout_lower_bound"] = ends["runout_lower_bound"]
    # 1D's warnings (mass, still moving) read the outflow; the sides are said in 2D terms
    out["warnings"] = [*result_warnings(case, res.model,
                                        {**out, "domain_ends": {**ends, "sides": []}}),
                       *_side_warnings(case, res.model, out)]
    return out


def lateral_cut(summary: dict[str, Any]) -> bool:
    """Whether the 2D run of ``summary`` reached a side across (y_low, y_high) that was
    clear at the start: its lateral spread is then a lower bound."""
    sides = (summary.get("domain_ends") or {}).get("sides", [])
    return "y_low" in sides or "y_high" in sides


def _domain_ends(case: Any, initial: np.ndarray, depth: np.ndarray,
                 mass_change: float) -> dict[str, Any]:
    """The 2D ``domain_ends`` (the 1D table's keys, so that the printed table reads it
    alike, :func:`pdeflow.checks.mass_through_ends`): the sides reached at the end that
    were clear at the start, the mass lost through open ones (relative), whether the
    front is cut off by the end of the domain along x."""
    thr = case.front_threshold
    start = set(sides_reached(m2.total_depth(initial), thr))
    sides = [s for s in sides_reached(depth, thr) if s not in start]
    (left, right), (low, high) = case.bc
    kinds = dict(zip(SIDES_2D, (left, right, low, high), strict=True))
    lost = -mass_change if mass_change < -1e-9 else 0.0
    outflow = lost if any(kinds[s] == "open" for s in sides) else 0.0
    return {"sides": sides, "outflow": outflow, "runout_lower_bound": "right" in sides,
            "open_through_material": [s for s in start if kinds[s] == "open"]}


def _side_warnings(case: Any, model: str, summary: dict[str, Any]) -> list[str]:
    """One sentence if material reached a side of the domain (a 2D run's domain is too
    small for its flow there)."""
    ends = summary["domain_ends"]
    if not ends["sides"]:
        return []
    left = (f", and {100 * ends['outflow']:.2g} % of the mass left the domain"
            if ends["outflow"] > MASS_WARN else "")
    bounds = [what for what, cut in (
        ("the front and the run-out (grid.length)", ends["runout_lower_bound"]),
        ("the lateral spread (grid.width)", lateral_cut(summary))) if cut]
    bound = (f": {' and '.join(bounds)} are lower bounds, enlarge the domain"
             if bounds else "")
    return [f"{case.name}, {model}: material reached the side(s) "
            f"{', '.join(ends['sides'])}{left}{bound}"]
