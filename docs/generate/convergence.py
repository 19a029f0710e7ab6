"""Regenerate docs/convergence.md and its figure: grid convergence of the two-layer results.

    python docs/generate/convergence.py [--out docs]     # about 20 minutes on 2 cores

The paper's closure next to the relaxed one (first order and MUSCL), for test 5.1
(dx = 0.05 .. 0.003125 m) and test 5.2 (dx = 0.01 .. 0.00125 m), and the single layer
on the same grids. Uses the package's convergence studies
(:func:`pdeflow.analysis.convergence.converge`, ``converge_sweep``).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

from pdeflow.analysis.convergence import (  # noqa: E402
    SWEEP_VIEW,
    converge,
    converge_sweep,
    table,
)
from pdeflow.cases import load_case  # noqa: E402
from pdeflow.io import write_text  # noqa: E402
from pdeflow.plotting import save  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def volume_figure(results: dict[str, dict[str, Any]], path: Path) -> None:
    """Upper-layer volume at fixed times against dx, one panel per closure."""
    import matplotlib.pyplot as plt

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
             "Generated by `python docs/generate/convergence.py` "
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
    write_text(path, "\n".join(lines) + "\n")
    return path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=str(ROOT / "docs"), help="directory of convergence.md")
    args = ap.parse_args(argv)
    path = report(args.out, case_51=str(ROOT / "cases" / "paper_5_1_dam_break.toml"),
                  case_52=str(ROOT / "cases" / "collapse_sweep.toml"))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
