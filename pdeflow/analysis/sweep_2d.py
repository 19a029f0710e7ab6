"""Aspect-ratio sweeps of a release on a 2D grid (issue 36): the measure and the table of
:func:`pdeflow.analysis.sweep.run_sweep` for a case with ``grid.width``.

The release's length L0 is its extent along x from its centre: a cylinder's or a cap's
radius, an ellipse's or a box's ``semi_x``, a polygon's largest vertex x minus its
centroid's (:func:`release_length`). For every aspect ratio a, H0 = a L0 (a cylinder's
height, a cap's peak). A point's row holds the 2D run's summary numbers
(:func:`pdeflow.summary_2d.summarize_2d`, not computed again here), normalised as the
1D sweep normalises its run-outs: r = runout / L0 (the run-out along x past the
release's front, so (R - L0)/L0 with R measured from the centre) and
r_mass = (mass_radius - L0) / L0 (mass_radius: r99 about the release's centre, the 2D
counterpart of the axisymmetric sweep's mass-quantile radius).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from ..cases import Case
from ..initial_shapes_2d import release_centre, release_front
from ..simulate import summary_unit
from ..summary_2d import KEYS_2D
from .points import Point

RUN_KEYS_2D = ("front_position", "runout", *KEYS_2D, "stop_time", "at_rest", "steps",
               "wall_time_s", "mass_relative_error", "runout_lower_bound")
"""the numbers of a 2D run's summary that a sweep's row keeps"""
TABLE_2D = ("a", "r", "r_mass", "front_position", "lateral_spread", "deposit_area",
            "mass_radius", "max_depth", "max_speed", "stop_time")
"""the columns ``pdeflow sweep`` prints for a 2D case, one row per aspect ratio"""


def release_length(case: Case) -> float:
    """L0 [m] of a 2D case's release: its extent along x from its centre (see the
    module docstring)."""
    return release_front(case.initial) - release_centre(case.initial)[0]


def row_2d(point: Point) -> dict[str, Any]:
    """Measure of :func:`pdeflow.analysis.sweep.run_sweep` on a 2D case: one release
    run to rest or t_end, its summary's :data:`RUN_KEYS_2D` and r, r_mass."""
    s = point.run().execute().summary
    L0 = release_length(point.case)
    radius = s["mass_radius"]
    row = {"r": None if s["runout"] is None else s["runout"] / L0,
           "r_mass": None if radius is None else (radius - L0) / L0,
           "runout_mass": None if radius is None else radius - L0}
    row.update({k: s.get(k) for k in RUN_KEYS_2D})
    return row


def _cell(v: Any) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def runs_table(rows: Iterable[dict[str, Any]]) -> str:
    """The Markdown table of a 2D sweep's rows of one model (:data:`TABLE_2D`, the
    units from :func:`pdeflow.simulate.summary_unit`)."""
    heads = []
    for key in TABLE_2D:
        unit = summary_unit(key, "planar-2d")
        heads.append(f"{key} [{unit}]" if unit not in (None, "-") else key)
    lines = ["| " + " | ".join(heads) + " |", "|" + "---:|" * len(TABLE_2D)]
    lines += ["| " + " | ".join(_cell(row.get(k)) for k in TABLE_2D) + " |"
              for row in rows]
    return "\n".join(lines)
