"""The short table of a run's results that ``pdeflow run`` prints and the app shows: one
column per model, one row per summary number the models have
(:func:`pdeflow.simulate.summarize`), with units."""

from __future__ import annotations

import sys
from typing import Any

from .checks import mass_through_ends
from .simulate import summary_unit
from .summary_2d import lateral_cut


def _fmt(v: Any, unit: str = "") -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}{unit}"
    return f"{v}{unit}"


ROWS = (("stop time", "stop_time"), ("lower stop", "lower_stop_time"),
        ("upper stop", "upper_stop_time"), ("front", "front_position"),
        ("run-out", "runout"), ("front {q} mass", "front_mass_quantile"),
        ("run-out {q} mass", "runout_mass_quantile"),
        ("lateral spread", "lateral_spread"), ("deposit area", "deposit_area"),
        ("radius {q} mass", "mass_radius"), ("deepest cell", "max_depth"),
        ("max speed", "max_speed"), ("travel angle", "travel_angle"),
        ("affected area", "affected_area"), ("max pressure", "max_pressure"),
        ("max F_extra/rho1", "max_fextra_over_rho1"), ("flow duration", "flow_duration"),
        ("front speed max", "front_velocity_max"), ("bed eroded", "bed_eroded_volume"),
        ("bed eroded max", "bed_eroded_volume_max"),
        ("bed deposited", "bed_deposited_volume"),
        ("erosion depth", "bed_max_erosion_depth"), ("  at x", "bed_max_erosion_x"),
        ("  at t", "bed_max_erosion_time"), ("bed moving max", "bed_moving_volume_max"),
        ("mass error", "mass_relative_error"), ("mass outflow", "mass_outflow"),
        ("steps", "steps"), ("wall time", "wall_time_s"))
"""(label, summary key) of the table's rows, in order; '{q}' is the mass fraction."""


def cell_unit(key: str, geometry: str | None) -> str:
    """The unit a cell of ``key`` carries, as the table writes it (' m2/s2'; '' for
    counts and ratios): :func:`pdeflow.simulate.summary_unit`, the one table of units."""
    unit = summary_unit(key, geometry)
    return "" if unit in (None, "-") else " " + unit.replace("^", "")


def print_summary(summary: dict[str, Any], out: Any = None) -> None:
    """A short human-readable table of the per-model results."""
    out = out or sys.stdout
    models = summary["models"]
    axisymmetric = any(s.get("geometry") == "axisymmetric" for s in models.values())
    two_d = any(s.get("geometry") == "planar-2d" for s in models.values())
    geometry = "axisymmetric" if axisymmetric else "planar-2d" if two_d else "planar"
    rows = [(label, k, cell_unit(k, geometry)) for label, k in ROWS]
    if two_d:
        # the front and the run-out are along x (down the slope); the spread is across
        rows = [(label + " (x)" if k in ("front_position", "runout") else label, k, u)
                for label, k, u in rows]
    if axisymmetric:
        # the front and the run-out are radii: R_f and R_f - R0
        rows = [("front radius" if k == "front_position" else
                 "radius {q} mass" if k == "front_mass_quantile" else label, k, u)
                for label, k, u in rows]
    # the fraction of the mass-quantile rows, e.g. '99%' (the case's, one for all models)
    q = next((s["runout_mass_fraction"] for s in models.values()
              if s.get("runout_mass_fraction") is not None), None)
    rows = [(label.format(q=f"{100 * q:.4g}%" if q else ""), k, u) for label, k, u in rows]
    # rows no model of the run has (a single-layer case: no lower/upper stop)
    rows = [row for row in rows if any(row[1] in s for s in models.values())
            or (row[1] == "mass_outflow" and any(mass_through_ends(s) is not None
                                                 for s in models.values()))]
    print(f"case {summary['case']}", file=out)
    print(f"{'':18}" + "".join(f"{m:>16}" for m in models), file=out)
    for label, key, unit in rows:
        print(f"{label:18}" + "".join(f"{_cell(models[m], key, unit):>16}"
                                      for m in models), file=out)


def _cell(model_summary: dict[str, Any], key: str, unit: str) -> str:
    """A table cell; a front or run-out cut off by the end of the domain reads '>= ...';
    where mass left or entered through an open end, its share is the 'mass outflow'
    [%] and the 'mass error' (then no conservation error) is '-'."""
    through = mass_through_ends(model_summary)
    if key in ("mass_relative_error", "mass_outflow"):
        if (through is None) == (key == "mass_outflow"):
            return "-"
        if through is not None:
            return f"{100 * through:.4g} %"
    text = _fmt(model_summary.get(key), unit)
    if key in ("front_position", "runout", "front_mass_quantile", "runout_mass_quantile") \
            and model_summary.get("runout_lower_bound"):
        return ">= " + text
    if key == "lateral_spread" and lateral_cut(model_summary):
        return ">= " + text
    return text
