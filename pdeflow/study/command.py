"""``pdeflow study STUDY.toml --out DIR [--workers N | --scheduler ADDRESS] [--progress]``

Runs a parameter study described by a study file (see docs/studies.md and
``pdeflow.study.spec``) on Dask: a local cluster of N worker processes (default: one
per core) or an existing cluster (``--scheduler tcp://HOST:PORT``). Every finished
evaluation is appended to DIR/results.csv; rerunning the same command resumes, computing
only what is missing. DIR/report.md (with figures) is written at the end.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from .spec import StudyError, load_study


def add_arguments(ap: Any) -> None:
    """The study command's options."""
    ap.add_argument("study", help="study file (TOML; see cases/study_*.toml)")
    ap.add_argument("--out", required=True, metavar="DIR",
                    help="study directory: results.csv, report.md, figures (resumed if "
                    "it holds this study already)")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N",
                       help="local worker processes (default: one per core)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on an existing Dask cluster, e.g. tcp://10.0.0.1:8786")
    ap.add_argument("--progress", action="store_true",
                    help="show evaluations done, failed and the time left")
    ap.add_argument("-q", "--quiet", action="store_true", help="print nothing")


def cmd_study(args: argparse.Namespace) -> int:
    """Run or resume the study, then write its report."""
    def log(msg: str) -> None:
        if not args.quiet:
            print(msg)

    def fail(msg: str) -> int:
        print(f"pdeflow study: error: {msg}", file=sys.stderr)
        return 2

    if args.workers is not None and args.workers < 1:
        return fail(f"--workers must be at least 1, got {args.workers}")
    try:
        import distributed  # noqa: F401
        import pandas  # noqa: F401
    except ImportError as err:
        return fail(f"studies need the 'studies' extra ({err.name} is missing): "
                    "pip install 'pdeflow[studies]'")
    from .execute import run_study
    from .report import write_report

    try:
        spec = load_study(args.study)
        table = run_study(spec, args.out, workers=args.workers, scheduler=args.scheduler,
                          progress=args.progress, log=log)
    except StudyError as err:
        return fail(str(err))
    except KeyboardInterrupt:
        print(f"\npdeflow study: interrupted; finished evaluations are kept in "
              f"{args.out}/results.csv: rerun the same command to resume", file=sys.stderr)
        return 130
    command = f"pdeflow study {args.study} --out {args.out}"
    log(f"report: {write_report(table, command)}")
    return 0

