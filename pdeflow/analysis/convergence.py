"""Self-convergence of quantities of interest under grid refinement.

``pdeflow converge CASE.toml --levels N`` (or :func:`converge`) runs a case on N
successive halvings of dx and reports, per level, the quantities of interest (QoIs):
upper-layer volume V1(t) at fixed times, the lower and upper stop times (exactly u = 0,
and |u| < 1 cm/s where h > 1 mm), the run-out, and the largest F_extra/rho1 with where
and when it occurred. For every QoI it gives the relative change between the two finest
grids and, with three or more levels, the observed order
p = log2(|Q_h - Q_h/2| / |Q_h/2 - Q_h/4|) and the Richardson estimate
Q_h/4 + (Q_h/4 - Q_h/2)/(2^p - 1) where the last three values are monotone, p > 0, and
the estimate keeps their sign (:func:`richardson`). It prints stop times, run-out,
F_extra and wall time; ``--all`` every quantity, ``--summary`` writes all as JSON.

For sweep cases (with a ``[sweep]`` section) it refines the sweep and reports the
fitted run-out prefactor and exponent per level.

A 2D case (``grid.width``) is refined along x and y together (dx and dy halved:
:func:`~pdeflow.analysis.points.refined`); its QoIs are the 2D summary's
(:func:`pdeflow.summary_2d.summarize_2d`: stop times, run-out along x, lateral spread,
deposit area, r99 about the release's centre, deepest cell, largest speed, F_extra),
without the volumes V1(t) (a 2D run takes no snapshots yet).

Both are :class:`~pdeflow.study.core.Study` definitions: points = the grid levels,
measure = the quantities of one run (:func:`qoi_row`) or the fit of one sweep
(:func:`fit_row`). ``python docs/generate/convergence.py`` regenerates
``docs/convergence.md`` from them.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence
from functools import partial
from typing import Any

import numpy as np

from .. import systems
from ..cases import PAPER_MODEL, Case, CaseError, load_case
from ..numerics.warmup import prepare
from ..simulate import case_steppers, summary_unit
from ..study.core import Executor, Study, serial
from ..summary_2d import KEYS_2D
from .points import Point, refined

QOI_KEYS = ("lower_stop_time", "upper_stop_time", "lower_slow_time", "upper_slow_time",
            "stop_time", "runout", "runout_mass_quantile", "max_fextra_over_rho1")
QOI_KEYS_2D = (*QOI_KEYS[:5], "runout", "front_position", *KEYS_2D, "max_fextra_over_rho1")
"""the QoIs of a 2D case: the stop times, the 2D summary's lengths, area and peaks"""


def qoi_row(point: Point, volume_times: tuple[float, ...]) -> dict[str, Any]:
    """Measure of :func:`converge`: the QoIs of one run, and the upper-layer volume
    V1(t) [m^2] at ``volume_times`` (None for one layer)."""
    c = point.case
    res = point.run().execute()
    s = res.summary
    row: dict[str, Any] = {"dx": c.dx, "cells": c.cells,
                           **({"cells_y": c.cells_y} if c.is_2d else {}),
                           "steps": s["steps"], "wall_time_s": s["wall_time_s"]}
    for key in QOI_KEYS_2D if c.is_2d else QOI_KEYS:
        row[key] = s.get(key)
    row["max_fextra_x"] = s.get("max_fextra_x")
    row["max_fextra_time"] = s.get("max_fextra_time")
    for t in volume_times:
        snap = res.snapshots.get(round(float(t), 9))
        if snap is not None:
            data = snap[0]
        elif t >= res.t_final and s["at_rest"]:
            data = res.state.data  # stationary from t_final on
        else:
            data = None
        # the volume of the top layer of a layered model (the upper layer of the paper's)
        layered = len(systems.get(point.model).layers) > 1
        row[f"V1({t:g})"] = (float(np.sum(data[0]) * c.dx)
                             if data is not None and layered else None)
    return row


def converge(case: Case, levels: int, model: str = PAPER_MODEL,
             volume_times: tuple[float, ...] = (0.01, 0.1, 0.25, 0.5, 1.0),
             executor: Executor = serial, progress: bool = False) -> dict[str, Any]:
    """Run ``model`` of ``case`` on ``levels`` halvings of dx (2D: of dx and dy); QoIs
    per level (``progress``: a bar over the levels on stderr)."""
    if case.is_2d:
        volume_times = ()  # V1(t) needs snapshots, which a 2D run does not take yet
    points = []
    for level in range(levels):
        c = refined(case, level)
        c.data.setdefault("output", {})["snapshot_times"] = [
            t for t in volume_times if t <= c.t_end]
        points.append(Point(c, model))
    rows = Study(points, partial(qoi_row, volume_times=volume_times)).execute(
        executor, "grid levels" if progress else None)
    qois = [k for k in rows[0] if k not in ("dx", "cells", "cells_y", "steps",
                                             "wall_time_s", "max_fextra_x",
                                             "max_fextra_time")]
    return {"case": case.name, "model": model, "levels": rows,
            "analysis": {k: richardson([r[k] for r in rows]) for k in qois}}


#: observed orders taken as the asymptotic range of the schemes (first order: 1, MUSCL
#: up to 2, both about 1/2 at discontinuities); outside it no extrapolation is given
ORDER_RANGE = (0.5, 3.0)


def _order(v: Sequence[float]) -> tuple[float | None, str | None]:
    """Observed order of three values, or (None, why there is none)."""
    d1 = v[1] - v[0]
    d2 = v[2] - v[1]
    if d1 == 0 or d2 == 0:
        return None, "no change"
    p = math.log2(abs(d1) / abs(d2))
    if d1 * d2 < 0:
        return p, "not monotone"
    return p, None


def richardson(values: list[float | None]) -> dict[str, Any]:
    """Change between the finest two values, observed order and extrapolation.

    The relative change is |Q_h/4 - Q_h/2| / |Q_h/4|: None where the finest value is 0
    and the one before is not (no relative change of a zero), 0 where both are 0. The
    order p = log2(|Q_h - Q_h/2| / |Q_h/2 - Q_h/4|) needs three values; the Richardson
    estimate Q_h/4 + (Q_h/4 - Q_h/2)/(2^p - 1) is given only in the asymptotic range:
    the last three values monotone, p within :data:`ORDER_RANGE`, with four or more
    values the order of the three before also there and within a factor 2 of p (the
    ratios of differences consistent), and the estimate keeping the sign of the
    values (stop times, run-outs and volumes are not negative). Otherwise
    ``extrapolated`` is None and ``reason`` says why (a short phrase).
    """
    out: dict[str, Any] = {"finest": values[-1], "relative_change": None,
                           "order": None, "extrapolated": None, "reason": None}
    v = values
    if len(v) >= 2 and v[-1] is not None and v[-2] is not None:
        change = abs(v[-1] - v[-2])
        if v[-1] != 0:
            out["relative_change"] = change / abs(v[-1])
        elif change == 0:
            out["relative_change"] = 0.0
    if len(v) < 3 or None in v[-3:]:
        out["reason"] = "fewer than 3 values"
        return out
    p, why = _order(v[-3:])
    out["order"] = p
    lo_p, hi_p = ORDER_RANGE
    if why is None and not lo_p <= p <= hi_p:
        why = f"order {p:.2g} outside [{lo_p:g}, {hi_p:g}]"
    if why is None and len(v) >= 4 and None not in v[-4:]:
        p0, why0 = _order(v[-4:-1])
        if why0 is not None or not (lo_p <= p0 <= hi_p and 0.5 <= p / p0 <= 2.0):
            why = "orders of the last two triples disagree"
    if why is None:
        estimate = v[-1] + (v[-1] - v[-2]) / (2**p - 1)
        lo, hi = min(v[-3:]), max(v[-3:])
        if (lo < 0 < hi or (lo >= 0 and estimate >= 0)
                or (hi <= 0 and estimate <= 0)):
            out["extrapolated"] = estimate
        else:
            why = "estimate changes sign"
    out["reason"] = why
    return out


def fit_row(point: Point) -> dict[str, Any]:
    """Measure of :func:`converge_sweep`: the run-out law fitted by one sweep."""
    from .sweep import run_sweep

    t0 = time.perf_counter()
    res = run_sweep(point.case, models=[point.model])["models"][point.model]
    return {"dx": point.case.dx, "prefactor": res["prefactor"],
            "exponent": res["exponent"], "prefactor_mass": res["prefactor_mass"],
            "exponent_mass": res["exponent_mass"], "all_at_rest": res["all_at_rest"],
            "points": res["points"], "wall_time_s": time.perf_counter() - t0}


def converge_sweep(case: Case, levels: int, model: str = PAPER_MODEL,
                   executor: Executor = serial, progress: bool = False) -> dict[str, Any]:
    """Refine a sweep case; fitted prefactor and exponent per level (``progress``: a
    bar over the levels on stderr)."""
    points = [Point(refined(case, level), model) for level in range(levels)]
    rows = Study(points, fit_row).execute(executor, "grid levels" if progress else None)
    return {"case": case.name, "model": model, "levels": rows,
            "analysis": {k: richardson([r[k] for r in rows])
                         for k in ("prefactor", "exponent", "prefactor_mass",
                                   "exponent_mass")}}


def _fmt(v: Any) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


#: the columns ``pdeflow converge`` prints by default (``--all``: every quantity)
SHORT_VIEW = ("dx", "cells", "stop_time", "lower_stop_time", "upper_stop_time", "runout",
              "runout_mass_quantile", "max_fextra_over_rho1", "wall_time_s")
SHORT_VIEW_2D = ("dx", "cells", "cells_y", "stop_time", "lower_stop_time",
                 "upper_stop_time", "runout", "lateral_spread", "mass_radius",
                 "deposit_area", "max_depth", "wall_time_s")
SWEEP_VIEW = ("dx", "prefactor", "exponent", "exponent_mass", "all_at_rest", "wall_time_s")


def header(key: str) -> str:
    """A column header with its unit: 'runout [m]', 'stop_time [s]', 'V1(0.1) [m^2]'.

    A run's numbers take their unit from :func:`pdeflow.simulate.summary_unit`; the
    grid's dx and the upper-layer volumes V1(t) (sum of h1 dx, m^2 per unit width) are
    this table's own; counts ('-') show none."""
    if key == "dx":
        unit: str | None = "m"
    elif key.startswith("V1("):
        unit = "m^2"
    else:
        unit = summary_unit(key)
    name = "wall_time" if key == "wall_time_s" else key
    return f"{name} [{unit}]" if unit not in (None, "-") else name


def table(result: dict[str, Any], keys: Sequence[str] | None = None) -> str:
    """Markdown table: one row per level, then the change/order/extrapolation rows."""
    rows = result["levels"]
    keys = list(keys or [k for k in rows[0] if k != "points"])
    lines = ["| " + " | ".join(header(k) for k in keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(k)) for k in keys) + " |")
    ana = result["analysis"]
    for label, field in (("rel. change (finest two)", "relative_change"),
                         ("observed order", "order"), ("Richardson", "extrapolated"),
                         ("no Richardson because", "reason")):
        cells = [label] + [_fmt(ana[k].get(field)) if k in ana else "" for k in keys[1:]]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("case", nargs="?", help="case file (a sweep case refines the sweep)")
    ap.add_argument("--levels", type=int, default=4, help="number of grids (dx halved)")
    ap.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                    help="override a case value (repeatable)")
    ap.add_argument("--model", default=PAPER_MODEL, choices=list(systems.names()))
    ap.add_argument("--summary", metavar="OUT.json", help="write the results as JSON")
    ap.add_argument("--force", action="store_true",
                    help="run even a finest grid estimated beyond a day or half the "
                    "machine's memory (refused otherwise)")
    ap.add_argument("--all", action="store_true",
                    help="print every quantity (default: stop times, run-out, F_extra, "
                    "wall time)")


def cmd_converge(args: argparse.Namespace) -> int:
    from ..io import write_json
    from ..outpaths import check_file

    if not args.case:
        raise CaseError("pdeflow converge: a case file is required")
    if args.levels < 2:
        raise CaseError(f"--levels must be an integer >= 2 (the number of grids), got "
                        f"{args.levels}")
    check_file(args.summary, "--summary", (".json",))
    case = load_case(args.case, args.set)
    if not case.data.get("sweep"):
        from ..sizecheck import check_size

        dx = case.dx / 2 ** (args.levels - 1)
        remedy = (f"the finest grid (level {args.levels} of --levels {args.levels}, "
                  f"dx = {dx:.3g} m) is too fine: use fewer --levels")
        try:
            finest = refined(case, args.levels - 1)
        except CaseError as err:  # more memory than the machine has
            raise CaseError(f"{err}; {remedy}") from None
        check_size(finest, args.force, remedy)
    prepare(case_steppers(case), log=sys.stderr)
    progress = sys.stderr.isatty()
    if case.data.get("sweep"):
        res = converge_sweep(case, args.levels, args.model, progress=progress)
        print(table(res, SWEEP_VIEW))
    else:
        res = converge(case, args.levels, args.model, progress=progress)
        view = SHORT_VIEW_2D if case.is_2d else SHORT_VIEW
        keys = None if args.all else [k for k in view if k in res["levels"][0]
                                      and any(r[k] is not None for r in res["levels"])]
        print(table(res, keys))
        if not args.all:
            volumes = "" if case.is_2d else ", with the upper-layer volumes V1(t)"
            print(f"(--all: every quantity{volumes}; "
                  "--summary OUT.json: all of it as JSON)")
    if args.summary:
        write_json(args.summary, res)
    return 0
