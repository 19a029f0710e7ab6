"""Command line: ``pdeflow run CASE.toml [--set section.key=value ...] [outputs]``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from . import __version__

RUN_HELP = """Run every model listed in the case file (case.models) to rest or t_end.

Without output options the summary and all figures go to results/<case name>/.
Outputs are written atomically: a failed run leaves no partial file behind."""


def _fmt(v: Any, unit: str = "") -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}{unit}"
    return f"{v}{unit}"


def print_summary(summary: dict[str, Any], out: Any = None) -> None:
    """A short human-readable table of the per-model results."""
    out = out or sys.stdout
    rows = [("stop time", "stop_time", " s"), ("lower stop", "lower_stop_time", " s"),
            ("upper stop", "upper_stop_time", " s"), ("front", "front_position", " m"),
            ("run-out", "runout", " m"), ("max F_extra/rho1", "max_fextra_over_rho1",
                                           " m2/s2"),
            ("mass error", "mass_relative_error", ""), ("steps", "steps", ""),
            ("wall time", "wall_time_s", " s")]
    models = summary["models"]
    print(f"case {summary['case']}", file=out)
    print(f"{'':18}" + "".join(f"{m:>16}" for m in models), file=out)
    for label, key, unit in rows:
        print(f"{label:18}" + "".join(f"{_fmt(models[m].get(key), unit):>16}"
                                      for m in models), file=out)


def cmd_run(args: argparse.Namespace) -> int:
    from .cases import load_case
    from .io import write_json, write_npz
    from .plotting import case_figures, deposit_figure, save
    from .simulate import run_model

    case = load_case(args.case, args.set)
    results = {}
    for model in case.models:
        results[model] = run_model(case, model)
    summary = {
        "case": case.name,
        "case_file": str(args.case),
        "overrides": args.set,
        "pdeflow_version": __version__,
        "parameters": {m: case.make_pde(m).parameters.to_dict() for m in case.models},
        "models": {m: r.summary for m, r in results.items()},
    }
    default_out = not (args.summary or args.final or args.plot or args.outdir)
    outdir = Path(args.outdir) if args.outdir else (
        Path("results") / case.name if default_out else None)
    written = []
    if args.summary or outdir:
        written.append(write_json(args.summary or outdir / "summary.json", summary))
    if args.final:
        first = case.models[0]
        final = Path(args.final)
        for m in case.models:
            path = final if m == first else final.with_name(
                f"{final.stem}.{m}{final.suffix}")
            written.append(write_npz(path, results[m].final_arrays()))
    if args.plot:
        two = results.get("two_layer")
        one = results.get("single_layer")
        fig = deposit_figure((two or one).x, two.state.data if two else None,
                             one.state.data if one else None, case.name)
        written.append(save(fig, args.plot))
    if outdir:
        written.extend(case_figures(results, outdir))
    if not args.quiet:
        print_summary(summary)
        for p in written:
            print(f"wrote {p}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pdeflow",
        description="Depth-averaged single- and two-layer granular flow models on py-pde.")
    parser.add_argument("--version", action="version", version=f"pdeflow {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a case file", description=RUN_HELP,
                         formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("case", help="TOML case file (see cases/ and docs/cases.md)")
    run.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                     help="override a case value, e.g. --set two_layer.c=0.05 (repeatable)")
    run.add_argument("--summary", metavar="OUT.json", help="write the JSON summary here")
    run.add_argument("--final", metavar="OUT.npz",
                     help="write the final state (x, h1, u1, h2, u2 or x, h, u, and t); "
                     "further models go to OUT.<model>.npz")
    run.add_argument("--plot", metavar="OUT.png", help="write the final-deposit figure")
    run.add_argument("--outdir", metavar="DIR",
                     help="write summary.json and all figures (snapshots, deposits) here")
    run.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    run.set_defaults(func=cmd_run)
    return parser


def main(argv: list[str] | None = None) -> int:
    from .cases import CaseError

    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except CaseError as err:
        print(f"pdeflow: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
