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

``python -m pdeflow.analysis.convergence --report docs`` regenerates
``docs/convergence.md`` and its figures: the paper's closure next to the relaxed one,
for test 5.1 (dx = 0.05 .. 0.003125 m) and test 5.2 (dx = 0.01 .. 0.00125 m).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..cases import Case, CaseError, load_case
from ..simulate import load_case_kernels, run_model

QOI_KEYS = ("lower_stop_time", "upper_stop_time", "lower_slow_time", "upper_slow_time",
            "stop_time", "runout", "max_fextra_over_rho1")


def _refined(case: Case, level: int, dx0: float) -> Case:
    c = case.copy()
    grid = c.data.setdefault("grid", {})
    grid.pop("cells", None)
    grid["dx"] = dx0 / 2**level
    c.validate()
    return c


def converge(case: Case, levels: int, model: str = "two_layer",
             volume_times: tuple[float, ...] = (0.01, 0.1, 0.25, 0.5, 1.0)
             ) -> dict[str, Any]:
    """Run ``model`` of ``case`` on ``levels`` halvings of dx; QoIs per level."""
    dx0 = case.dx
    rows = []
    for level in range(levels):
        c = _refined(case, level, dx0)
        c.data.setdefault("output", {})["snapshot_times"] = [
            t for t in volume_times if t <= c.t_end]
        res = run_model(c, model)
        s = res.summary
        row: dict[str, Any] = {"dx": c.dx, "cells": c.cells, "steps": s["steps"],
                               "wall_time_s": s["wall_time_s"]}
        for key in QOI_KEYS:
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
            row[f"V1({t:g})"] = (float(np.sum(data[0]) * c.dx)
                                 if data is not None and model == "two_layer" else None)
        rows.append(row)
    qois = [k for k in rows[0] if k not in ("dx", "cells", "steps", "wall_time_s",
                                             "max_fextra_x", "max_fextra_time")]
    return {"case": case.name, "model": model, "levels": rows,
            "analysis": {k: richardson([r[k] for r in rows]) for k in qois}}


def richardson(values: list[float | None]) -> dict[str, float | None]:
    """Change between the finest two values, observed order and extrapolation.

    The relative change is |Q_h/4 - Q_h/2| / |Q_h/4|: None where the finest value is 0
    and the one before is not (no relative change of a zero), 0 where both are 0. The
    order p = log2(|Q_h - Q_h/2| / |Q_h/2 - Q_h/4|) needs three values; the Richardson
    estimate Q_h/4 + (Q_h/4 - Q_h/2)/(2^p - 1) is given only where the last three
    values are monotone, p > 0, and the estimate keeps the sign of the values (stop
    times, run-outs and volumes are not negative): elsewhere the sequence is not in its
    asymptotic range and an extrapolation would mislead.
    """
    out: dict[str, float | None] = {"finest": values[-1], "relative_change": None,
                                    "order": None, "extrapolated": None}
    v = values
    if len(v) >= 2 and v[-1] is not None and v[-2] is not None:
        change = abs(v[-1] - v[-2])
        if v[-1] != 0:
            out["relative_change"] = change / abs(v[-1])
        elif change == 0:
            out["relative_change"] = 0.0
    if len(v) >= 3 and None not in v[-3:]:
        d1 = v[-2] - v[-3]
        d2 = v[-1] - v[-2]
        if d1 != 0 and d2 != 0:
            p = math.log2(abs(d1) / abs(d2))
            out["order"] = p
            if p > 0 and d1 * d2 > 0:  # converging and monotone
                estimate = v[-1] + d2 / (2**p - 1)
                lo, hi = min(v[-3:]), max(v[-3:])
                if (lo < 0 < hi or (lo >= 0 and estimate >= 0)
                        or (hi <= 0 and estimate <= 0)):
                    out["extrapolated"] = estimate
    return out


def converge_sweep(case: Case, levels: int, model: str = "two_layer") -> dict[str, Any]:
    """Refine a sweep case; fitted prefactor and exponent per level."""
    from ..sweep import run_sweep

    dx0 = case.dx
    rows = []
    for level in range(levels):
        c = _refined(case, level, dx0)
        t0 = time.perf_counter()
        res = run_sweep(c, models=[model])["models"][model]
        rows.append({"dx": c.dx, "prefactor": res["prefactor"], "exponent": res["exponent"],
                     "all_at_rest": res["all_at_rest"], "points": res["points"],
                     "wall_time_s": time.perf_counter() - t0})
    return {"case": case.name, "model": model, "levels": rows,
            "analysis": {k: richardson([r[k] for r in rows])
                         for k in ("prefactor", "exponent")}}


def _fmt(v: Any) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


#: units of the quantities, for table headers
UNITS = {"dx": "m", "wall_time_s": "s", "runout": "m", "max_fextra_over_rho1": "m^2/s^2",
         "max_fextra_x": "m", "max_fextra_time": "s"}
#: the columns ``pdeflow converge`` prints by default (``--all``: every quantity)
SHORT_VIEW = ("dx", "cells", "stop_time", "lower_stop_time", "upper_stop_time", "runout",
              "max_fextra_over_rho1", "wall_time_s")
SWEEP_VIEW = ("dx", "prefactor", "exponent", "all_at_rest", "wall_time_s")


def header(key: str) -> str:
    """A column header with its unit: 'runout [m]', 'stop_time [s]', 'V1(0.1) [m^2]'."""
    unit = UNITS.get(key)
    if unit is None and (key == "stop_time" or key.endswith(("_stop_time", "_slow_time"))):
        unit = "s"
    if unit is None and key.startswith("V1("):
        unit = "m^2"
    name = "wall_time" if key == "wall_time_s" else key
    return f"{name} [{unit}]" if unit else name


def table(result: dict[str, Any], keys: Sequence[str] | None = None) -> str:
    """Markdown table: one row per level, then the change/order/extrapolation rows."""
    rows = result["levels"]
    keys = list(keys or [k for k in rows[0] if k != "points"])
    lines = ["| " + " | ".join(header(k) for k in keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(k)) for k in keys) + " |")
    ana = result["analysis"]
    for label, field in (("rel. change (finest two)", "relative_change"),
                         ("observed order", "order"), ("Richardson", "extrapolated")):
        cells = [label] + [_fmt(ana[k][field]) if k in ana else "" for k in keys[1:]]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def volume_figure(results: dict[str, dict[str, Any]], path: Path) -> None:
    """Upper-layer volume at fixed times against dx, one panel per closure."""
    import matplotlib.pyplot as plt

    from ..plotting import save

    fig, axes = plt.subplots(1, len(results), figsize=(5 * len(results), 3.8),
                             sharey=True, squeeze=False)
    for ax, (name, res) in zip(axes[0], results.items(), strict=True):
        rows = res["levels"]
        dx = [r["dx"] for r in rows]
        for key in [k for k in rows[0] if k.startswith("V1(")]:
            vals = [r[key] for r in rows]
            ax.semilogx(dx, vals, "o-", label=key.replace("V1(", "t = ").rstrip(")") + " s")
        ax.set_title(name)
        ax.set_xlabel("dx [m]")
        ax.invert_xaxis()
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("upper-layer volume V1 [m^2]")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    save(fig, path)


DIAGNOSIS = """## Diagnosis

Closure (25) gives M/rho2 = [c du^2 - (1 - k) r g h1 tan(phi_int)] / |du|. Inside the
column both layers start at rest and move together wherever the collapse has not yet
sheared them, so |du| is zero or tiny there, the deposition rate is unbounded, and the
limited exchange (31) deposits the upper layer down to its equilibrium depth h1_eq ~ 0
within a step. Upper material survives only where the shear has arrived within the first
steps, a region a fixed number of *cells* wide: the surviving upper volume scales with dx
(V1 halves each time dx halves, table below). Everything tied to the upper layer inherits
this: its stop time, the run-out (less upper material reaches the front), the 5.2 exponent
(which drifts towards the single-layer value as dx -> 0), and the maximum of F_extra, a
start-up transient at the toe of the wedge that sharpens like 1/dx.

## The relaxed closure

`exchange_closure = "relaxed"` bounds the exchange by a relaxation towards h1_eq on the
flow's own time scale tau = tau_star sqrt(H/g) (H the local total depth; default
tau_star = 1, i.e. the free-fall time of the local column): over a step, the depth change
is the smaller of the paper's explicit change and the exactly integrated relaxation
(h1_eq - h1)(1 - exp(-dt/tau)). Where the layers shear, the paper's rate is the slower one
and is used unchanged; as du -> 0 the rate stays bounded by h1/tau instead of diverging.
Mass is conserved to round-off (the same exchange as before, only smaller), depths stay
non-negative (exact relaxation never crosses h1_eq or empties the lower layer), and a
layer still comes to rest in finite time (films thinner than `film_depth` are deposited
whole). Its one parameter, tau_star, is dimensionless and of order one; values 0.3-3 were
tried (the grid study below uses 1).
"""


TARGETS_NOTE = """What the table says. The paper's closure drifts in everything tied
to the upper layer (its volume halves with dx, see below). The relaxed closure removes
that drift: V1(t) converges in both schemes. With the first-order scheme the run-out
and the stop times still drift by a few per cent per level, as the single layer's
run-out does: the front of a first-order Coulomb collapse creeps outwards with
refinement (numerical diffusion), which is the scheme, not the closure. With MUSCL the
run-out, the stop time of the run, the upper layer's stop times (both definitions) and
the practical stop time of the lower layer change by less than 2 %, and the 5.2
exponent by less than 0.01 (tests/test_validation.py checks both). The one quantity
that does not settle is the lower layer's *exact* stop time (u2 = 0 in every cell):
after the lower layer has stopped (about 1.0 s), the upper layer still flowing over it
re-mobilises single cells at mm/s (interface stress briefly above basal friction where
the lower layer is thin), and the time of the last such event depends on the grid. The
practical definition (|u| < 1 cm/s where h > 1 mm) is the robust one for the lower
layer, as far as the parameters allow: with k = 0.8 the re-mobilisation exceeds 1 cm/s
on fine grids and even the practical stop time changes by more than 10 % on dx/2
(calibration_relaxed.md).

The maximum of F_extra/rho1 occurs at the toe of the initial column within the first
few steps (its time halves with dx): a start-up transient at the corner of the
discontinuous initial state. With the paper's closure it grows like 1/dx; with the
relaxed closure and the first-order scheme its size converges (change about 1 %
between the finest grids); with MUSCL, which resolves the corner more sharply, it is
larger and still grows slowly, so for MUSCL runs it is not a converging quantity.
"""


MUSCL = ["numerics.reconstruction='muscl'", "numerics.limiter='mc'"]
CONFIGS: dict[str, list[str]] = {
    "paper closure, first order (the paper's scheme)": [
        "two_layer.exchange_closure='paper'"],
    "relaxed closure, first order": ["two_layer.exchange_closure='relaxed'"],
    "relaxed closure, MUSCL (hll/muscl/mc)": ["two_layer.exchange_closure='relaxed'",
                                              *MUSCL],
}
TARGET_KEYS = ("runout", "stop_time", "upper_stop_time", "upper_slow_time",
               "lower_slow_time", "lower_stop_time")


def targets_table(r51: dict[str, dict[str, Any]], r52: dict[str, dict[str, Any]],
                  names: list[str]) -> str:
    """The issue's targets for the configurations ``names``: relative change of the
    5.1 run-out and stop times between the two finest grids (< 2 %) and the absolute
    change of the 5.2 exponent (< 0.01)."""
    lines = ["| quantity | target | " + " | ".join(names) + " |",
             "|---|---|" + "---|" * len(names)]

    def cell(v: float | None, limit: float) -> str:
        return "-" if v is None else f"{v:.3g} ({'met' if v < limit else 'missed'})"

    for key in TARGET_KEYS:
        vals = [r51[n]["analysis"][key]["relative_change"] for n in names]
        lines.append(f"| 5.1 {key} | < 0.02 | " + " | ".join(cell(v, 0.02) for v in vals)
                     + " |")
    vals = []
    for n in names:
        ex = [row["exponent"] for row in r52[n]["levels"]]
        vals.append(abs(ex[-1] - ex[-2]) if None not in ex[-2:] else None)
    lines.append("| 5.2 exponent (absolute change) | < 0.01 | "
                 + " | ".join(cell(v, 0.01) for v in vals) + " |")
    return "\n".join(lines)


def report(out_dir: str | Path, levels_51: int = 5, levels_52: int = 4,
           case_51: str = "cases/paper_5_1_dam_break.toml",
           case_52: str = "cases/collapse_sweep.toml") -> Path:
    """Regenerate docs/convergence.md and its figure (paper vs relaxed closure, the
    latter with the first-order and the MUSCL scheme)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    r51 = {name: converge(load_case(case_51, over), levels_51)
           for name, over in CONFIGS.items()}
    r52 = {name: converge_sweep(load_case(case_52, over), levels_52)
           for name, over in CONFIGS.items()}
    single = {name: converge(load_case(case_51, ["case.models=['single_layer']", *over]),
                             levels_51, model="single_layer")
              for name, over in (("first order", []), ("MUSCL", MUSCL))}
    volume_figure(r51, out_dir / "convergence_v1.png")
    lines = ["# Grid convergence of the two-layer results", "",
             "Generated by `python -m pdeflow.analysis.convergence --report docs` "
             f"({levels_51} levels for 5.1, {levels_52} for 5.2). Stop times in s, run-out "
             "in m, F_extra/rho1 in m^2/s^2, volumes in m^2. The same tool runs any case: "
             "`pdeflow converge CASE.toml --levels N` (`--set numerics.reconstruction="
             "'muscl'` etc. for another scheme).", "", DIAGNOSIS,
             "## Targets", "",
             "Relative change between the two finest grids (dx = 0.00625 and 0.003125 m "
             "for 5.1; the 5.2 exponent between dx = 0.0025 and 0.00125 m). The paper's "
             "closure is shown side by side.", "",
             targets_table(r51, r52, list(CONFIGS)), "", TARGETS_NOTE]
    for name, res in r51.items():
        lines += [f"## Test 5.1, {name}", "", table(res), ""]
    lines += ["![upper-layer volume against dx](convergence_v1.png)", ""]
    lines += ["## Context: the single-layer model on the same grids", "",
              "The run-out is measured with a depth threshold (1 mm) on the thin deposit "
              "tail. For the single Coulomb layer it converges slowly with the first-order "
              "scheme (numerical diffusion spreads the front), and at the finest grids "
              "its front reaches the open end of the 7 m domain (run-out 6 m): part of a "
              "run-out drift is the scheme and the front definition, not the exchange "
              "closure.", ""]
    for name, res in single.items():
        lines += [f"Single layer, {name}:", "",
                  table(res, ["dx", "cells", "steps", "stop_time", "runout"]), ""]
    for name, res in r52.items():
        lines += [f"## Test 5.2 run-out fit, {name}", "",
                  table(res, SWEEP_VIEW), ""]
    path = out_dir / "convergence.md"
    from ..io import atomic_path

    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return path


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("case", nargs="?", help="case file (a sweep case refines the sweep)")
    ap.add_argument("--levels", type=int, default=4, help="number of grids (dx halved)")
    ap.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                    help="override a case value (repeatable)")
    ap.add_argument("--model", default="two_layer", choices=["two_layer", "single_layer"])
    ap.add_argument("--summary", metavar="OUT.json", help="write the results as JSON")
    ap.add_argument("--all", action="store_true",
                    help="print every quantity (default: stop times, run-out, F_extra, "
                    "wall time)")
    ap.add_argument("--report", metavar="DIR",
                    help="regenerate DIR/convergence.md (paper vs relaxed closure)")


def cmd_converge(args: argparse.Namespace) -> int:
    from ..io import check_output, write_json

    if args.report:
        print(f"wrote {report(args.report)}")
        return 0
    if not args.case:
        raise CaseError("pdeflow converge: a case file (or --report DIR) is required")
    if args.levels < 2:
        raise CaseError(f"--levels must be an integer >= 2 (the number of grids), got "
                        f"{args.levels}")
    check_output(args.summary, "--summary")
    case = load_case(args.case, args.set)
    load_case_kernels(case, sys.stderr)
    if case.data.get("sweep"):
        res = converge_sweep(case, args.levels, args.model)
        print(table(res, SWEEP_VIEW))
    else:
        res = converge(case, args.levels, args.model)
        keys = None if args.all else [k for k in SHORT_VIEW if k in res["levels"][0]
                                      and any(r[k] is not None for r in res["levels"])]
        print(table(res, keys))
        if not args.all:
            print("(--all: every quantity, with the upper-layer volumes V1(t); "
                  "--summary OUT.json: all of it as JSON)")
    if args.summary:
        write_json(args.summary, res)
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="pdeflow converge", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(ap)
    return cmd_converge(ap.parse_args(argv))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
