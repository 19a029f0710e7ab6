"""Same-machine regression check: every 1D number of a set of runs, bit for bit.

    python benchmarks/identity.py --save DIR       # record the runs of this checkout
    python benchmarks/identity.py --compare DIR    # exit 1 and list what differs

For each run it records the summary (without wall times), the final state, the
snapshots and the fv-split diagnostics array, and compares them exactly
(``np.array_equal``; floats of the summaries with ``==``). This is not a test: exact
equality only holds on one machine with one numba/LLVM, which is what a refactoring
that must leave every number unchanged is checked against. The runs: the paper's 5.1
dam break (both models) with every flux, first order and MUSCL with each limiter, Lie
and Strang; the planar and radial collapse sweeps (coarsened); the four basal laws; the
erodible bed; 16 runs beyond the CFL limit that retry steps; IFCP steps redone with HLL
(Lie, Strang); a method-of-lines run (py-pde's Runge-Kutta on the rate).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
MODELS = ("two_layer", "single_layer")
SKIP_KEYS = {"wall_time_s"}

Record = dict[str, Any]
"""one run: 'summary' (JSON-able) and named arrays"""


def _case(path: Path, sets: list[str]):
    from pdeflow.cases import load_case

    return load_case(path, ["output.snapshot_times=[0.1, 0.4]"] + sets
                     if path == CASE_51 else sets)


def _record(case, model: str, variant: str | None = None) -> Record:
    """A case's run through the public API (:class:`pdeflow.simulate.Run`)."""
    from pdeflow.simulate import Run

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = Run(case, model, variant).execute()
    summary = {k: v for k, v in res.summary.items() if k not in SKIP_KEYS}
    arrays = {"state": res.state.data}
    for t, (data, fextra) in sorted(res.snapshots.items()):
        arrays[f"snap_{t:g}"] = data
        arrays[f"snap_fextra_{t:g}"] = fextra
    if res.diagnostics is not None:
        arrays["fextra"] = res.fextra_over_rho1
    return {"summary": summary, **arrays}


def _controller_record(eq, state, t_end: float, cfl: float, **kw: Any) -> Record:
    """A run of the fv-split solver at a Courant number set after its validation (above
    1: the only way to make steps fail and be retried, as tests/test_failures.py does)."""
    from pde import Controller

    from pdeflow.solvers.fv_split import FVSplitSolver

    solver = FVSplitSolver(eq, cfl=0.5, **kw)
    solver.cfl = cfl
    final = Controller(solver, t_range=t_end, tracker=None).run(state.copy())
    return {"summary": {}, "state": final.data, "diagnostics": np.array(solver.diagnostics)}


def runs_51() -> Iterator[tuple[str, Callable[[], Record]]]:
    """5.1 with every flux x reconstruction/limiter x splitting, both models."""
    from pdeflow.variant import FLUXES, LIMITERS

    schemes = ["first-order"] + [f"muscl/{lim}" for lim in LIMITERS]
    case = _case(CASE_51, [])
    for flux in FLUXES:
        for rec in schemes:
            for split in ("lie", "strang"):
                variant = f"{flux}/{rec}" + ("+strang" if split == "strang" else "")
                for model in MODELS:
                    yield f"5.1/{variant}/{model}", (
                        lambda v=variant, m=model: _record(case, m, v))


def runs_sweeps() -> Iterator[tuple[str, Callable[[], Record]]]:
    """The planar and radial collapse sweeps, coarsened (dx doubled or more)."""
    for name, dx, ratios in (("collapse_sweep", 0.02, (2, 8, 30)),
                             ("axisymmetric_collapse_sweep", 0.01, (0.5, 2, 10))):
        for a in ratios:
            case = _case(ROOT / "cases" / f"{name}.toml",
                         [f"grid.dx={dx}", f"initial.H0={a * 0.1}"])
            for model in MODELS:
                yield f"{name}/a={a}/{model}", (lambda c=case, m=model: _record(c, m))


def runs_laws_bed_mol() -> Iterator[tuple[str, Callable[[], Record]]]:
    """The four basal laws on 5.1, the erodible bed, a method-of-lines run."""
    for law in ("coulomb", "pouliquen", "mu_i", "voellmy"):
        case = _case(CASE_51, [f"{m}.friction_law='{law}'" for m in MODELS])
        for model in MODELS:
            yield f"law/{law}/{model}", (lambda c=case, m=model: _record(c, m))
    bed = _case(ROOT / "cases" / "erodible_bed.toml", [])
    for model in MODELS:
        yield f"erodible_bed/{model}", (lambda m=model: _record(bed, m))
    mol = _case(CASE_51, ["grid.dx=0.1", "case.t_end=0.1", "numerics.dt=1e-4",
                          "output.snapshot_times=[]"])
    for model in MODELS:
        yield f"mol-rk/{model}", (lambda m=model: _record(mol, m, "mol-rk"))


def runs_retries() -> Iterator[tuple[str, Callable[[], Record]]]:
    """16 runs beyond the CFL limit (steps retried with dt/2), 2 IFCP runs whose
    steps are redone with HLL (the state of tests/test_stress.py)."""
    from pde import CartesianGrid

    import pdeflow

    for model in MODELS:
        for rec in ("first-order", "muscl"):
            case = _case(CASE_51, ["case.t_end=1.0", f"numerics.reconstruction='{rec}'"])
            for cfl in (1.5, 1.9):
                for split in ("lie", "strang"):
                    def run(c=case, m=model, cfl=cfl, split=split) -> Record:
                        eq, state = c.make_state(m)
                        return _controller_record(eq, state, 1.0, cfl, splitting=split)
                    yield f"retry/{model}/{rec}/cfl={cfl}/{split}", run
    for split in ("lie", "strang"):
        def redo(split=split) -> Record:
            eq = pdeflow.SingleLayerGranular(bc=("wall", "wall"), flux="ifcp",
                                             phi_b_deg=10.0)
            state = eq.make_state(CartesianGrid([[0.0, 1.0]], 3),
                                  h=np.array([0.51182162, 0.9504637, 0.14415961]),
                                  u=np.array([-5.36953235, 5.81118104, 3.64572396]))
            return _controller_record(eq, state, 0.5, 0.5, splitting=split,
                                      stop_at_rest=False)
        yield f"ifcp-redo/{split}", redo


def all_runs() -> Iterator[tuple[str, Callable[[], Record]]]:
    yield from runs_51()
    yield from runs_sweeps()
    yield from runs_laws_bed_mol()
    yield from runs_retries()


def _file(directory: Path, name: str) -> Path:
    return directory / (name.replace("/", "__") + ".npz")


def save(directory: Path, record: Record, name: str) -> None:
    arrays = {k: np.asarray(v) for k, v in record.items() if k != "summary"}
    arrays["summary_json"] = np.array(json.dumps(record["summary"], sort_keys=True,
                                                 default=str))
    np.savez(_file(directory, name), **arrays)


def _same(a: Any, b: Any) -> bool:
    """Exact equality of value and type (an int printed as 3.0 is a change), NaN equal
    to NaN (a run's NaN summary numbers are its numbers)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b


def differences(directory: Path, record: Record, name: str) -> list[str]:
    path = _file(directory, name)
    if not path.exists():
        return [f"{name}: no reference"]
    ref = np.load(path)
    out = []
    summary = json.loads(json.dumps(record["summary"], sort_keys=True, default=str))
    ref_summary = json.loads(str(ref["summary_json"]))
    for key in sorted(set(summary) | set(ref_summary)):
        if not _same(summary.get(key), ref_summary.get(key)):
            out.append(f"{name}: summary {key}: {ref_summary.get(key)!r} -> "
                       f"{summary.get(key)!r}")
    keys = {k for k in record if k != "summary"}
    for key in sorted(keys | (set(ref.files) - {"summary_json"})):
        if key not in keys or key not in ref.files:
            out.append(f"{name}: array {key} only in one of the two")
        elif not np.array_equal(np.asarray(record[key]), ref[key], equal_nan=True):
            diff = np.nanmax(np.abs(np.asarray(record[key]) - ref[key])) \
                if np.shape(record[key]) == ref[key].shape else "shape"
            out.append(f"{name}: array {key} differs (max |diff| {diff})")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--save", type=Path, metavar="DIR")
    mode.add_argument("--compare", type=Path, metavar="DIR")
    ap.add_argument("--only", default="", help="run only the runs whose name has this")
    args = ap.parse_args(argv)
    if args.save:
        args.save.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    count = 0
    for name, make in all_runs():
        if args.only not in name:
            continue
        record = make()
        count += 1
        if args.save:
            save(args.save, record, name)
        else:
            problems += differences(args.compare, record, name)
    if args.compare:
        for line in problems:
            print(line)
        print(f"{count} runs compared with {args.compare}: "
              f"{'identical' if not problems else f'{len(problems)} differences'}")
        return 1 if problems else 0
    print(f"{count} runs saved to {args.save}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
