r"""Work-precision harness: error against wall time for every numerical variant.

Every variant is run on a sequence of grids of one case and compared, at a fixed time,
with an exact solution or with a fine-grid reference; the result is a table (JSON and
Markdown) and a log-log work-precision diagram (error against wall time, PNG).

Usage::

    pdeflow compare CASE [CASE ...] [--set SECTION.KEY=VALUE ...]
        [--variants hll/first-order rusanov/muscl/minmod ifcp/muscl/mc+strang mol-rk]
        [--grids 0.05 0.025 0.0125 | 100 200 400] [--reference auto|exact|fine|fine:VARIANT]
        [--t 0.4] [--repeats 3] [--cfl 0.45] [--mol-cap 20] [--out-dir results/workprecision]
        [--hyperbolicity]

``CASE`` is a TOML case file (``cases/*.toml``); the dam breaks with exact solutions are
``cases/ritter_dam_break.toml``, ``mangeney_dam_break_slope.toml`` and
``stoker_dam_break.toml`` (:func:`~pdeflow.analysis.exact.exact_solution_for`). The
study is a :class:`~pdeflow.study.core.Study` over variants x grids: :func:`compare`.

Variants
--------
Names as in :mod:`pdeflow.variant`: ``FLUX/RECONSTRUCTION[/LIMITER][+SPLITTING]``, e.g.
``hll/first-order``, ``rusanov/muscl/minmod``, ``ifcp/muscl/mc+strang`` (the ``fv-split``
solver), or ``mol-rk``: py-pde's ``runge-kutta`` solver (classical RK4 with a fixed step)
on the method-of-lines rate of the hll/first-order discretisation, with
dt = CFL dx / s_est and the a-priori speed bound
s_est = 2 max(|u| + sqrt(g_z H)) + g_x t over the initial state (exact for Ritter's
solution, whose front moves at 2 sqrt(g h0)). Its compiled run is stopped after
``mol_cap`` seconds of wall time (status ``capped``); a run that blows up (a non-finite
state, a depth above 1.5 times the initial maximum depth or a velocity above 5 s_est;
the post-step hook clips negative depths silently) is ``failed``.

Errors and timing
-----------------
* error: L1 norms at the time ``t`` of the depth, sum_k sum_i |h_k,i - h_k,ref,i| dx
  [m^2], and of the momentum, sum_k sum_i |(hu)_k,i - (hu)_k,ref,i| dx [m^3/s] (k runs
  over the layers). Exact solutions are averaged over each cell (8-point midpoint rule);
  a fine-grid reference is restricted to the coarse grid by cell averaging (exact
  integration of the piecewise-constant fine solution over each coarse cell). A 2D
  case: over the area (dx dy; m^3 and m^4/s, hu and hv), against a fine 2D reference
  averaged along y and x; no mol-rk (docs/two_d.md).
* reference: ``exact`` for single-layer dam breaks onto a dry bed (Ritter with
  phi_B -> 0, Mangeney on a slope); otherwise ``fine``: the same variant and model on a
  grid with dx_ref = min(dx)/4 (``reference_dx``). ``fine:VARIANT`` uses one common
  reference variant for all. mol-rk is compared with the hll/first-order fv-split
  reference (the same spatial discretisation; a fine RK4 run would cost minutes).
* wall time: the median over ``repeats`` runs of the compiled stepper (more, up to 25,
  while the timed runs add up to less than 0.25 s: short runs are noisy), after one
  warm-up run that compiles (numba) and is not counted. The compile time of mol-rk (py-pde
  builds and compiles a new stepper and rate for every grid) is reported separately as
  ``compile_s``; for fv-split it is the warm-up run's excess over the median.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import statistics
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..cases import Case, CaseError, load_case
from ..metrics_2d import ROWS_PER_LAYER
from ..study.core import Study
from ..variant import MAX_CFL, Variant
from .exact import exact_solution_for
from .points import Point, case_on_grid, resolve_case, with_sets
from .timing import run_variant, timed
from .workprecision_outputs import CompareResult, markdown_table, write_outputs

DEFAULT_VARIANTS: tuple[str, ...] = (
    "hll/first-order", "rusanov/first-order", "ifcp/first-order",
    "hll/muscl/minmod", "rusanov/muscl/minmod", "ifcp/muscl/mc",
    "hll/first-order+strang", "hll/muscl/mc+strang", "mol-rk",
)
"""Variants run when none are named: every flux at first order, MUSCL with both
limiters, Strang splitting, and the method of lines with RK4."""


# --- cases and references --------------------------------------------------------------

def restrict(values: np.ndarray, fine_edges: np.ndarray,
             coarse_edges: np.ndarray) -> np.ndarray:
    """Average the piecewise-constant fine-grid ``values`` (last axis: cells) over the
    coarse cells: exact integration, nested or not, for grids on the same interval."""
    values = np.asarray(values, dtype=float)
    widths = np.diff(fine_edges)
    cum = np.concatenate([np.zeros((*values.shape[:-1], 1)),
                          np.cumsum(values * widths, axis=-1)], axis=-1)
    flat = cum.reshape(-1, cum.shape[-1])
    at = np.stack([np.interp(coarse_edges, fine_edges, row) for row in flat])
    out = np.diff(at, axis=-1) / np.diff(coarse_edges)
    return out.reshape(*values.shape[:-1], coarse_edges.size - 1)


def cell_edges(case: Case) -> Any:
    """Cell faces [m] of the case's grid; a 2D grid's along x and along y (a pair)."""
    x = case.x_start + case.length * np.linspace(0.0, 1.0, case.cells + 1)
    if not case.is_2d:
        return x
    return x, case.y_start + case.width * np.linspace(0.0, 1.0, case.cells_y + 1)


def restrict_grid(values: np.ndarray, fine_edges: Any, coarse_edges: Any) -> np.ndarray:
    """:func:`restrict` on the grid of :func:`cell_edges`: a 2D grid's values (last
    two axes: x, y) along y, then along x (the average over a coarse cell either way)."""
    if not isinstance(fine_edges, tuple):
        return restrict(values, fine_edges, coarse_edges)
    (fx, fy), (cx, cy) = fine_edges, coarse_edges
    along_y = restrict(values, fy, cy)
    return np.swapaxes(restrict(np.swapaxes(along_y, -1, -2), fx, cx), -1, -2)


# --- the harness -----------------------------------------------------------------------

def _errors(data: np.ndarray, ref: np.ndarray, cell: float,
            rows: int = 2) -> tuple[float, float]:
    """L1 errors of the depths and of the momenta (every row of a layer after its
    depth: hu, and hv on a 2D grid) over cells of size ``cell`` [m, or m^2 in 2D]."""
    depth = float(np.abs(data[::rows] - ref[::rows]).sum() * cell)
    mom = sum(float(np.abs(data[k::rows] - ref[k::rows]).sum()) for k in range(1, rows))
    return depth, mom * cell


def compare(case_path: str | Path | Case, variants: Sequence[str] | None = None,
            grids: Sequence[float | int] | None = None, reference: str = "auto",
            out_dir: str | Path | None = "results/workprecision", *,
            t: float | None = None, repeats: int = 3, models: Sequence[str] | None = None,
            cfl: float | None = None, reference_dx: float | None = None,
            mol_cap: float = 20.0, label: str | None = None,
            log: Any = None) -> CompareResult:
    """Run every variant on every grid of a case and measure error against wall time.

    Args:
        case_path: a TOML case file or a :class:`~pdeflow.cases.Case`.
        variants: variant names (:meth:`pdeflow.variant.Variant.parse`); default
            :data:`DEFAULT_VARIANTS`.
        grids: the grid sequence, each an int (number of cells) or a float (dx [m]);
            default: the case's dx, dx/2, dx/4.
        reference: ``"auto"`` (exact where :func:`exact_solution_for` knows one, else
            fine), ``"exact"``, ``"fine"`` (same variant on a grid with
            ``reference_dx``) or ``"fine:VARIANT"`` (one common reference variant).
        out_dir: directory for ``<case>_workprecision.{json,md,png}``; None writes
            nothing.
        t: time [s] at which errors are measured (default: the case's t_end).
        repeats: timed runs per point; the median wall time is reported.
        models: models to run (default: the case's ``case.models``).
        cfl: Courant number for every variant (default: the case's).
        reference_dx: grid spacing [m] of fine references (default min(dx)/4).
        mol_cap: wall-time cap [s] of one compiled mol-rk run.
        log: a stream for progress lines (e.g. ``sys.stderr``), or None.

    Returns:
        A :class:`CompareResult`; each row has ``case, model, variant, solver,
        splitting, cells, dx [m], t [s], err_h [m^2], err_hu [m^3/s], rel_err_h,
        wall_s`` (median [s]), ``walls`` (all repeats), ``compile_s, steps,
        cell_updates, status, note, reference`` and ``order_h`` (observed L1 order
        against the previous grid of the same variant).
    """
    base = resolve_case(case_path)
    if reference not in ("auto", "exact", "fine") and not reference.startswith("fine:"):
        raise ValueError(f"reference must be auto, exact, fine or fine:VARIANT, got "
                         f"{reference!r}")
    grids = list(grids or [base.dx, base.dx / 2, base.dx / 4])
    _check_options(base, grids, repeats, cfl)
    ref_dx = reference_dx or min(_dx_of(base, gr) for gr in grids) / 4
    if base.is_2d:  # a fine 2D reference grows as 1/dx^2: estimated before any run
        from ..sizecheck import check_size

        check_size(case_on_grid(base, ref_dx, Variant()), False,
                   f"the fine reference (dx = {ref_dx:.3g} m) is too fine: use coarser "
                   "--grids or a larger --reference-dx")
    harness = _Harness(base, float(t if t is not None else base.t_end), reference,
                       ref_dx, repeats, cfl, mol_cap, log)
    parsed = [Variant.parse(v) for v in variants or default_variants(base)]
    rows = [row for model in models or base.models
            for row in harness.model_rows(model, parsed, grids)]
    result = CompareResult(label or base.name, harness.t, rows)
    if out_dir is not None:
        write_outputs(result, Path(out_dir))
    return result


def default_variants(case: Case) -> tuple[str, ...]:
    """:data:`DEFAULT_VARIANTS`; on a 2D grid without mol-rk: py-pde compiles its
    stepper around the 2D rate for every grid, tens of seconds each (ask for it with
    ``variants``)."""
    if case.is_2d:
        return tuple(v for v in DEFAULT_VARIANTS if not Variant.parse(v).is_mol)
    return DEFAULT_VARIANTS


def _check_options(case: Case, grids: list[float | int], repeats: int,
                   cfl: float | None) -> None:
    """One-line ValueError naming the option before any run: a grid is a number of
    cells >= 1 or a dx in (0, length] [m]; repeats >= 1; cfl in (0, 1]."""
    for gr in grids:
        cells = isinstance(gr, (int, np.integer)) and not isinstance(gr, bool)
        if (cells and gr < 1) or (not cells and not 0 < gr <= case.length):
            raise ValueError(f"grids (--grids): each is a number of cells >= 1 or a dx "
                             f"in (0, {case.length:g}] m, got {gr!r}")
    if repeats < 1:
        raise ValueError(f"repeats (--repeats) must be an integer >= 1, got {repeats!r}")
    if cfl is not None and not 0 < cfl <= 1:
        raise ValueError(f"cfl (--cfl) must lie in (0, 1], got {cfl!r}")


def _dx_of(case: Case, grid: float | int) -> float:
    """The spacing [m] of a grid given as a number of cells (int) or as dx [m]."""
    if isinstance(grid, (int, np.integer)) and not isinstance(grid, bool):
        return case.length / int(grid)
    return float(grid)


@dataclass
class _Harness:
    """One :func:`compare`: its case, evaluation time [s], reference and timing options,
    and the fine references computed so far (one per model and reference variant)."""

    base: Case
    t: float
    reference: str
    ref_dx: float
    repeats: int
    cfl: float | None
    mol_cap: float
    log: Any
    fine: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, str]] = field(
        default_factory=dict)
    capped: set[str] = field(default_factory=set)
    """variants whose CFL cap has been announced (once each, not once per grid)"""

    def say(self, msg: str) -> None:
        if self.log is not None:
            print(msg, file=self.log, flush=True)

    def model_rows(self, model: str, variants: list[Variant],
                   grids: list[float | int]) -> list[dict[str, Any]]:
        """The rows of one model: a Study over variants x grids, timed, each compared
        with the exact solution or a fine reference; orders along each variant's grids."""
        exact = exact_solution_for(self.base, model)
        if self.reference == "exact" and exact is None:
            raise ValueError(f"no exact solution for {model} on {self.base.name}")
        use_exact = exact if self.reference in ("auto", "exact") else None
        points = [Point(case_on_grid(self.base, gr, v, self.cfl_of(v)), model, v)
                  for v in variants for gr in grids]
        runs = Study(points, self.timed).execute()
        rows: list[dict[str, Any]] = []
        for point, out in zip(points, runs, strict=True):
            ref, ref_name = self.reference_on(point, use_exact)
            prev = rows[-1] if rows and rows[-1]["variant"] == point.variant.name else None
            rows.append(self.row(point, out["run"], ref, ref_name, prev))
        return rows

    def cfl_of(self, v: Variant) -> float | None:
        """The Courant number of variant ``v``: ``cfl`` if given, else the case's, or the
        variant's own limit (:data:`pdeflow.variant.MAX_CFL`) where the case's is above
        it (a case at CFL 0.9 compares MUSCL at 0.5); None: the case's."""
        if self.cfl is not None or v.is_mol:
            return self.cfl
        limit = MAX_CFL[v.reconstruction]
        if self.base.cfl <= limit:
            return None
        if v.name not in self.capped:
            self.capped.add(v.name)
            self.say(f"  {v.name} at CFL {limit:g}: the case's {self.base.cfl:g} is above "
                     f"the limit of {v.reconstruction}")
        return limit

    def timed(self, point: Point) -> dict[str, Any]:
        """Measure: the timing of one point, announced on the log."""
        self.say(f"{self.base.name} {point.model} {point.variant} "
                 f"cells={_cells(point.case)}")
        return timed(point, self.t, self.repeats, self.mol_cap)

    def reference_on(self, point: Point, exact: Any) -> tuple[np.ndarray, str]:
        """The reference state on the point's cells, and its name."""
        edges = cell_edges(point.case)
        if exact is not None:
            h, hu = exact.cell_averages(edges, self.t)
            return np.stack([h, hu]), f"exact {exact.name.capitalize()}"
        fdata, fedges, ref_name = self.fine_reference(point.model, point.variant)
        return restrict_grid(fdata, fedges, edges), ref_name

    def fine_reference(self, model: str, v: Variant) -> tuple[np.ndarray, np.ndarray, str]:
        """A fine-grid run (state, cell faces, name), computed once per model and
        reference variant: the common one, else the point's (hll/first-order for the
        method of lines)."""
        common = self.reference[5:] if self.reference.startswith("fine:") else None
        rv = Variant.parse(common) if common else (v if not v.is_mol else Variant())
        key = (model, rv.name)
        if key not in self.fine:
            fc = case_on_grid(self.base, self.ref_dx, rv, self.cfl_of(rv))
            self.say(f"  reference {model} {rv.name} dx={self.ref_dx:g} ({_cells(fc)} cells)")
            run = run_variant(fc, model, rv, self.t, repeats=0)
            if run.status != "ok":
                raise RuntimeError(f"fine reference {rv.name} failed: {run.note}")
            self.fine[key] = (run.data, cell_edges(fc),
                              f"fine {rv.name} dx={self.ref_dx:g} m")
        return self.fine[key]

    def row(self, point: Point, run: Any, ref: np.ndarray, ref_name: str,
            prev: dict[str, Any] | None) -> dict[str, Any]:
        """The row of one point: errors against ``ref``, timing, and the observed order
        against ``prev`` (the previous grid of the same variant, or None)."""
        c, v = point.case, point.variant
        assert v is not None
        dx = c.length / c.cells
        rows = ROWS_PER_LAYER if c.is_2d else 2
        cell = dx * c.width / c.cells_y if c.is_2d else dx  # [m] or [m^2]
        eh, ehu = (_errors(run.data, ref, cell, rows) if run.status == "ok"
                   else (math.nan,) * 2)
        norm = float(np.abs(ref[::rows]).sum() * cell)
        row = {
            "case": self.base.name, "model": point.model, "variant": v.name,
            "solver": v.solver, "splitting": None if v.is_mol else v.splitting,
            "cells": c.cells, **({"cells_y": c.cells_y} if c.is_2d else {}),
            "dx": dx, "t": self.t,
            "err_h": eh, "err_hu": ehu,
            "rel_err_h": eh / norm if norm > 0 else math.nan,
            "wall_s": statistics.median(run.wall_s), "walls": run.wall_s,
            "compile_s": run.compile_s, "steps": run.steps,
            "cell_updates": run.steps * c.total_cells, "status": run.status,
            "note": run.note, "reference": ref_name, "order_h": None,
        }
        if v.is_mol:
            row["dt"] = run.info.get("dt")
        if (prev is not None and prev["status"] == "ok" and run.status == "ok"
                and eh > 0 and prev["err_h"] > 0):
            row["order_h"] = math.log(prev["err_h"] / eh) / math.log(prev["dx"] / dx)
        depth, momentum = ("m^3", "m^4/s") if c.is_2d else ("m^2", "m^3/s")
        self.say(f"    err_h={eh:.3e} {depth} err_hu={ehu:.3e} {momentum} "
                 f"wall={row['wall_s'] * 1e3:.2f} ms {run.status} {run.note}")
        return row


def _cells(case: Case) -> str:
    """The cells of a case's grid: '200', a 2D grid's '40x20'."""
    return f"{case.cells}x{case.cells_y}" if case.is_2d else str(case.cells)


# --- command line ----------------------------------------------------------------------

def _grid_value(text: str) -> float | int:
    """'200' -> 200 cells; '0.05' or '5e-2' -> dx = 0.05 m."""
    if re.fullmatch(r"\d+", text):
        return int(text)
    return float(text)


HELP = ("Work-precision study: runs every numerical variant (flux, reconstruction, "
        "splitting, or a py-pde solver) on a sequence of grids and measures its error "
        "against an exact solution or a fine-grid reference, and its wall time; writes "
        "the error-against-wall-time diagram (PNG) and table (JSON, Markdown). To compare "
        "stored runs with each other, use `pdeflow plot RUN.h5 RUN.h5`.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``pdeflow compare``."""
    p.add_argument("cases", nargs="+", help="case TOML files (the dam breaks with exact "
                   "solutions: cases/ritter_dam_break.toml, mangeney_dam_break_slope.toml, "
                   "stoker_dam_break.toml)")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override a case value, for every case (repeatable)")
    p.add_argument("--variants", nargs="+", default=None,
                   help="variant names, e.g. hll/first-order rusanov/muscl/minmod "
                        "ifcp/muscl/mc+strang mol-rk (default: a set of 9)")
    p.add_argument("--grids", nargs="+", type=_grid_value, default=None,
                   help="grids: integers are cell counts, decimals are dx [m] "
                        "(default: the case's dx, dx/2, dx/4)")
    p.add_argument("--reference", default="auto",
                   help="auto | exact | fine | fine:VARIANT (default auto)")
    p.add_argument("--t", type=float, default=None, help="evaluation time [s] "
                   "(default: the case's t_end)")
    p.add_argument("--repeats", type=int, default=3, help="timed repeats (median)")
    p.add_argument("--models", nargs="+", default=None, help="models (default: case's)")
    p.add_argument("--cfl", type=float, default=None, help="Courant number for all")
    p.add_argument("--reference-dx", type=float, default=None,
                   help="dx [m] of fine references (default min(dx)/4)")
    p.add_argument("--mol-cap", type=float, default=20.0,
                   help="wall-time cap [s] of one mol-rk run (default 20)")
    p.add_argument("--out-dir", default="results/workprecision",
                   help="output directory (default results/workprecision)")
    p.add_argument("--hyperbolicity", action="store_true",
                   help="also compare the hyperbolicity modes exact/bound/none "
                        "(two-layer cases)")
    p.add_argument("--laws", nargs="+", default=None, metavar="LAW",
                   help="basal friction laws to compare on the same grids (coulomb, "
                        "pouliquen, mu_i, voellmy): each model's friction_law in turn; "
                        "default: the case's")
    p.add_argument("--quiet", action="store_true", help="no progress lines")


def _cases_and_laws(args: argparse.Namespace) -> list[tuple[str, Case, str | None]]:
    """(path, case, label) of every case file, once per ``--laws`` entry if given (the
    case with every model's ``friction_law`` set to it, labelled ``<case>_<law>``: the
    laws then run on the same grids, variants and reference time)."""
    out: list[tuple[str, Case, str | None]] = []
    for path in args.cases:
        case = load_case(path, args.set)
        if not getattr(args, "laws", None):
            out.append((path, case, None))
            continue
        models = args.models or case.models
        for law in args.laws:
            sets = [f"{m}.friction_law={law}" for m in models]
            out.append((path, with_sets(case, sets), f"{case.name}_{law}"))
    return out


def cmd_compare(args: argparse.Namespace) -> int:
    """``pdeflow compare``: the exit status (2 for bad input, named in one line)."""
    from .hyperbolicity_modes import hyperbolicity_study

    log = None if args.quiet else sys.stderr
    try:
        for path, case, label in _cases_and_laws(args):
            res = compare(case, args.variants, args.grids, args.reference, args.out_dir,
                          t=args.t, repeats=args.repeats, models=args.models,
                          cfl=args.cfl, reference_dx=args.reference_dx,
                          mol_cap=args.mol_cap, label=label, log=log)
            print(f"## {res.case} (t = {res.t:g} s)\n")
            print(markdown_table(res))
            print(f"written: {', '.join(res.files.values())}\n")
            if args.hyperbolicity:
                rows = hyperbolicity_study(case, log=log, repeats=args.repeats)
                path = Path(args.out_dir) / f"{res.case}_hyperbolicity.json"
                path.write_text(json.dumps(rows, indent=1))
                print(f"hyperbolicity modes written to {path}")
    except (CaseError, ValueError, RuntimeError) as err:
        print(f"pdeflow compare: error: {err}", file=sys.stderr)
        return 2
    return 0
