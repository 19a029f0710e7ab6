"""Command line: ``pdeflow run | plot | export | ...`` (``pdeflow COMMAND --help``).

Each subcommand is a function ``cmd_<name>(args) -> exit code`` and its options are set
up in :func:`build_parser`; errors in the user's input (case files, stored runs, movie
formats) are printed as one line and exit with code 2.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path
from typing import Any

from . import __version__
from .cli_options import positive, threads_option
from .numerics.threads import DEFAULT_THREADS

RUN_HELP = """Run every model listed in the case file (case.models) to rest or t_end.

Without output options the summary and all figures go to results/<case name>/ (the
case as written) or results/<case name>--<overrides>/ (with --set); a run replaces
its folder as a whole. A 2D case (grid.width) writes its summary there and one
figure, final_deposits.png (plan-view maps of each layer's depth and speed, the
deposit outline, cross-sections; also --plot); its --live, --movie and --frames
draw the plan view of the total depth with the deposit outline.
Every output is complete or absent: a failed or interrupted run writes nothing
(Ctrl-C while the results are written lets them finish).
For cases with several models, per-model outputs (--final, --store, --movie) go to
the given name for the first model and to NAME.<model>.SUFFIX for the others.

examples:
  pdeflow run cases/paper_5_1_dam_break.toml
  pdeflow run cases/paper_5_1_dam_break.toml --set two_layer.c=0.05 --summary s.json
  pdeflow run cases/ritter_dam_break.toml --live            # desktop window
  pdeflow run cases/paper_5_1_dam_break.toml --movie 5_1.mp4 --store 5_1.h5
  pdeflow plot 5_1.h5 5_1.single_layer.h5 --time 0.4 --out t04.png"""

def _run_trackers(args: argparse.Namespace, case: Any, model: str,
                  first: bool) -> list[Any]:
    """The trackers that the run options ask for (progress, live plot, storage); those
    that write files keep them under temporary names until the outputs are written."""
    from .run_outputs import model_path

    trackers: list[Any] = []
    interval = case.t_end / 100
    progress = args.progress
    drawing = args.movie or args.frames
    if progress is None:
        # default: on a terminal, for long runs, and while frames are drawn (a movie
        # takes seconds per model, longer than the run; the bar is on stderr)
        from .checks import run_cost

        progress = not args.quiet and (sys.stdout.isatty() or bool(drawing)
                                       or run_cost(case, model).long)
    if progress:
        from .trackers import ProgressBar

        label = model
        if drawing:
            target = (model_path(args.movie, model, first).name if args.movie
                      else "frames")
            label = f"{model}, drawing {target}"
        trackers.append(ProgressBar(interval, label=label))
    show = args.live and _live_display()  # headless: nothing to show
    if show or args.movie or args.frames:
        from .trackers.live import LayersPlotTracker

        movie = model_path(args.movie, model, first) if args.movie else None
        frames = (Path(args.frames) / model) if args.frames else None
        trackers.append(LayersPlotTracker(
            args.live_every or interval, title=f"{case.name}: {model.replace('_', ' ')}",
            display="auto" if show else "none", movie=movie, frames=frames,
            fps=args.fps, autocommit=False, model=model,
            threshold=case.front_threshold))
    if args.store:
        from .storage import RunStorageTracker, run_metadata

        meta = run_metadata(case, model, overrides=args.set, case_file=str(args.case),
                            store_every=args.store_every or interval)
        trackers.append(RunStorageTracker(model_path(args.store, model, first),
                                          args.store_every or interval, metadata=meta,
                                          autocommit=False))
    return trackers


def _load_run_case(args: argparse.Namespace) -> Any:
    """The case of ``pdeflow run``; a study file is pointed to ``pdeflow study``; what
    the run leaves out of the file is said in notes on stderr (:func:`_case_notes`)."""
    from .cases import CaseError, load_case, read_toml

    data = read_toml(args.case, "case file")
    if "study" in data:
        raise CaseError(f"{args.case} is a study file ([study]): run it with "
                        f"`pdeflow study {args.case}`")
    case = load_case(args.case, args.set)
    if not args.quiet:
        for note in _case_notes(case, "sweep" in data, args.case):
            print(f"pdeflow: note: {note}", file=sys.stderr)
    return case


def _case_notes(case: Any, sweep: bool, path: str) -> list[str]:
    """What ``pdeflow run`` of the case file ``path`` does not do although the file
    asks for it: the sweep of a sweep file (``sweep``: it has a [sweep]), snapshots
    past t_end (a short check, ``--set case.t_end=0.1``)."""
    notes = []
    if sweep:
        notes.append(f"{path} is a sweep file: `pdeflow run` runs its one column "
                     f"(initial.H0 = {case.initial.get('H0', '-')} m), not its "
                     f"sweep.aspect_ratios; `pdeflow sweep {path}` runs the sweep")
    if case.dropped_snapshot_times:
        times = ", ".join(f"{t:g}" for t in case.dropped_snapshot_times)
        notes.append(f"output.snapshot_times {times} s lie past case.t_end = "
                     f"{case.t_end:g} s: those snapshots are not taken")
    return notes


def _live_display() -> bool:
    """Whether a live plot can be shown here (imports matplotlib: only for --live)."""
    from .trackers.live import display_mode

    return display_mode("auto") != "none"


def _live_window(args: argparse.Namespace) -> bool:
    """Whether ``--live`` opens a window (it warns on a headless machine)."""
    if not args.live:
        return False
    from .trackers.live import display_mode

    if display_mode("auto") == "none":
        print("pdeflow: warning: --live needs a display (matplotlib backend "
              "is non-interactive); use --movie or --frames on a headless machine",
              file=sys.stderr)
    return display_mode("auto") == "window"


def _run_models(args: argparse.Namespace, case: Any, outputs: Any) -> dict[str, Any]:
    """Run every model with the trackers the options ask for (those that write files
    go to ``outputs``, a :class:`~pdeflow.run_outputs.RunOutputs`); the results."""
    from .interrupts import SignalCheck
    from .simulate import run_model

    results: dict[str, Any] = {}
    if args.live or args.movie or args.frames:
        # drawing frames takes longer than the run itself: py-pde's warning about it
        # would only be noise here
        logging.getLogger("pde.solvers.controller").setLevel(logging.ERROR)
    for i, model in enumerate(case.models):
        trackers = _run_trackers(args, case, model, first=i == 0)
        outputs.add(trackers)
        # a signal is handled within a second (observers do not change the run)
        results[model] = run_model(case, model, tracker=[*trackers, SignalCheck()],
                                   threads=args.threads)
    return results


def cmd_run(args: argparse.Namespace) -> int:
    from .run_outputs import RunOutputs, check_run_outputs, run_folder
    from .sizecheck import check_size

    case = _load_run_case(args)
    for name in ("live_every", "store_every", "fps"):
        positive(f"--{name.replace('_', '-')}", getattr(args, name))
    default_out = not (args.summary or args.final or args.plot or args.outdir
                       or args.store or args.movie or args.frames)
    outdir = Path(args.outdir) if args.outdir else (
        run_folder(case.name, args.set) if default_out else None)
    check_run_outputs(args, outdir)
    check_size(case, args.force, "use a coarser grid (--set grid.dx=...)")
    live_window = _live_window(args)
    figures = None
    if args.plot or outdir:
        from .figure_worker import RunFigures

        figures = RunFigures(here=bool(args.live or args.movie or args.frames))
    outputs = RunOutputs(args, outdir)
    try:
        return _run_and_write(args, case, outputs, figures, live_window)
    except BaseException:
        outputs.discard()  # nothing of an unfinished run stays, hidden or not
        raise
    finally:
        if figures is not None:
            figures.close()


def _run_and_write(args: argparse.Namespace, case: Any, outputs: Any, figures: Any,
                   live_window: bool) -> int:
    """The body of ``pdeflow run`` after the checks: kernels, runs, outputs (``outputs``,
    a :class:`~pdeflow.run_outputs.RunOutputs`), printing; ``figures``: a
    :class:`~pdeflow.figure_worker.RunFigures` (None: no figures)."""
    from .interrupts import received
    from .numerics.warmup import COLD, prepare, status
    from .simulate import case_steppers
    from .summary_table import print_summary

    steppers = case_steppers(case)
    meanwhile = None
    if figures is not None and status(steppers) == COLD:
        meanwhile = figures.start  # it fills the wait for the kernels a helper compiles
    elif figures is not None:
        figures.start()  # matplotlib's import overlaps the kernels' loading and the runs
    prepare(steppers, log=None if args.quiet else sys.stderr, meanwhile=meanwhile)
    results = _run_models(args, case, outputs)
    summary = {
        "case": case.name,
        "case_file": str(args.case),
        "overrides": args.set,
        "pdeflow_version": __version__,
        "parameters": {m: case.make_pde(m).parameters.to_dict() for m in case.models},
        "models": {m: r.summary for m, r in results.items()},
    }
    written = outputs.write(case, summary, results, figures)
    if received():  # held back while the results were written: the command ends here
        raise KeyboardInterrupt("after the results were written")
    if not args.quiet:
        print_summary(summary)
        for p in written:
            print(f"wrote {p}")
    if live_window:
        import matplotlib.pyplot as plt

        if not args.quiet:
            print("close the plot window(s) to finish")
        plt.show()
    return 0


RAW = argparse.RawDescriptionHelpFormatter


def _add_run(sub: Any) -> None:
    """``pdeflow run``: its options."""
    run = sub.add_parser("run", help="run a case file", description=RUN_HELP,
                         formatter_class=RAW)
    run.add_argument("case", help="TOML case file (see cases/ and docs/cases.md)")
    run.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                     help="override a case value, e.g. --set two_layer.c=0.05 (repeatable)")
    out = run.add_argument_group("result files")
    out.add_argument("--summary", metavar="OUT.json", help="write the JSON summary here")
    out.add_argument("--final", metavar="OUT.npz",
                     help="write the final state (x, h1, u1, h2, u2 or x, h, u, and t; "
                     "a 2D case also y and v1, v2 or v, arrays (nx, ny)); "
                     "further models go to OUT.<model>.npz")
    out.add_argument("--plot", metavar="OUT.png",
                     help="write the final-deposit figure (2D: plan-view maps and "
                     "cross-sections of the final state)")
    out.add_argument("--outdir", metavar="DIR",
                     help="write summary.json and all figures (snapshots, deposits) here; "
                     "the folder is replaced as a whole (refused if it holds other files)")
    out.add_argument("--store", metavar="OUT.h5",
                     help="store the run in HDF5 (py-pde FileStorage: state and "
                     "F_extra/rho1 every --store-every s, and the final state; case, "
                     "parameters, variant, version and summary as metadata); further "
                     "models go to OUT.<model>.h5. Needs h5py")
    out.add_argument("--store-every", type=float, metavar="DT",
                     help="simulation time between stored frames [s] (default t_end/100)")
    watch = run.add_argument_group("watching the run")
    watch.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                       help="show a progress bar on stderr (default: when stdout is a "
                       "terminal, when the run is estimated to be long, or with --movie "
                       "or --frames)")
    watch.add_argument("--live", action="store_true",
                       help="draw the layers, velocities and F_extra/rho1 in a window "
                       "while the run goes (a 2D case: the plan view of the total depth "
                       "with the deposit outline; needs a display; close it to finish)")
    watch.add_argument("--movie", metavar="OUT.mp4",
                       help="write the live plot as a movie, headless: .mp4 (also "
                       ".m4v, .mov, .mkv, .avi; H.264, needs ffmpeg, e.g. pip install "
                       "imageio-ffmpeg) or .gif; further models go to OUT.<model>.mp4")
    watch.add_argument("--frames", metavar="DIR",
                       help="write the live plot as PNG frames DIR/<model>/frame_*.png (each "
                     "DIR/<model> replaced as a whole)")
    watch.add_argument("--live-every", type=float, metavar="DT",
                       help="simulation time between live frames [s] (default t_end/100)")
    watch.add_argument("--fps", type=float, default=10.0,
                       help="frames per second of --movie (default 10)")
    run.add_argument("--threads", type=threads_option, default=DEFAULT_THREADS,
                     metavar="N", help="threads of a 2D run (1 to the cores; the same "
                     "numbers for any N; default 1: runs in parallel processes do not "
                     "crowd the cores; a 1D run uses one)")
    run.add_argument("--force", action="store_true",
                     help="run even if the run is estimated to take more than a day or "
                     "half the machine's memory (refused otherwise)")
    run.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    run.set_defaults(func=cmd_run)


MODULE_COMMANDS = (
    ("sweep", "pdeflow.analysis.sweep", "cmd_sweep",
     "aspect-ratio sweep and run-out law (paper 5.2)"),
    ("converge", "pdeflow.analysis.convergence", "cmd_converge",
     "grid-convergence study of a case"),
    ("compare", "pdeflow.analysis.workprecision", "cmd_compare",
     "work-precision study: error against wall time of solver variants (to compare "
     "runs, use plot)"),
    ("study", "pdeflow.study.command", "cmd_study",
     "parameter study, sensitivity or calibration on Dask"),
    ("app", "pdeflow.app.server", "cmd_app", "teaching app in the browser (needs panel)"))
"""(command, module, function, help) of the commands whose module owns its options
(``add_arguments``) and body"""


def _add_module_commands(sub: Any, command: str | None = None) -> None:
    """The commands of :data:`MODULE_COMMANDS`; with ``command`` only that one's module
    is imported and given its options (the others are listed, for ``--help``)."""
    import importlib

    for name, module_name, func, help_ in MODULE_COMMANDS:
        if command is not None and name != command:
            sub.add_parser(name, help=help_)
            continue
        module = importlib.import_module(module_name)  # panel: only when the app runs
        cmd = sub.add_parser(name, help=help_, formatter_class=RAW,
                             description=getattr(module, "HELP", module.__doc__))
        module.add_arguments(cmd)
        cmd.set_defaults(func=getattr(module, func))


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``pdeflow`` parser: one subcommand per command; with ``command`` (the one
    about to run) the modules of the others are not imported."""
    parser = argparse.ArgumentParser(
        prog="pdeflow",
        description="Depth-averaged single- and two-layer granular flow models on py-pde.",
        epilog="docs/user_guide.md explains the commands, docs/cases.md the case files.")
    parser.add_argument("--version", action="version", version=f"pdeflow {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _add_run(sub)
    from .cli_stored import add_plot_and_export

    add_plot_and_export(sub, RAW)
    _add_module_commands(sub, command)
    return parser


def main(argv: list[str] | None = None) -> int:
    """``pdeflow COMMAND ...``: the exit code; warnings about a run or its results
    (:class:`pdeflow.checks.RunWarning`) are printed as one line each, once."""
    from .checks import run_warnings

    with run_warnings(lambda line: print(line, file=sys.stderr, flush=True)):
        return _main(argv)


def _interrupted(err: BaseException, session: Any) -> int:
    """Ctrl-C or SIGTERM: one line saying what was kept; exit code 130. Temporary files
    are gone (atomic writes, discarded trackers); either nothing was written or every
    output is complete (:mod:`pdeflow.interrupts`)."""
    from .interrupts import RunInterrupted

    if session.written:
        n = len(session.written)
        print(f"pdeflow: interrupted after the results were written ({n} output"
              f"{'s' if n > 1 else ''}, all complete)", file=sys.stderr)
        return 130
    t = getattr(err, "t", None)
    when = f"at t = {t:.6g} s" if isinstance(err, RunInterrupted) and t is not None \
        else "before the results were complete"
    print(f"pdeflow: interrupted {when}; nothing written", file=sys.stderr)
    return 130


def _main(argv: list[str] | None = None) -> int:
    from .cases import CaseError
    from .interrupts import Session, signals_interrupt
    from .solvers.fv_split import SimulationBlowUp

    argv = sys.argv[1:] if argv is None else list(argv)
    command = next((a for a in argv if not a.startswith("-")), None)
    args = build_parser(command).parse_args(argv)
    session = Session()
    try:
        with signals_interrupt(session):
            try:
                code = args.func(args)
            except Exception as err:
                if session.signals:  # a failure a signal caused (e.g. a worker it ended)
                    raise KeyboardInterrupt(str(err)) from None
                raise
            if session.signals:  # a Ctrl-C whose KeyboardInterrupt was swallowed
                raise KeyboardInterrupt("a signal came")
            return code
    except KeyboardInterrupt as err:
        return _interrupted(err, session)
    except CaseError as err:
        print(f"pdeflow: error: {err}", file=sys.stderr)
        return 2
    except SimulationBlowUp as err:
        # the message says where, when and with which scheme; the traceback adds nothing
        print(f"pdeflow: simulation failed: {err}", file=sys.stderr)
        return 3
    except ValueError as err:
        from .io import OutputError

        # only movies raise a MovieError, only stored runs a StorageError: neither
        # module is imported for nothing
        known = [sys.modules[name].__dict__[error] for name, error in (
            ("pdeflow.trackers.live", "MovieError"), ("pdeflow.storage", "StorageError"))
            if name in sys.modules]
        if not isinstance(err, (OutputError, *known)):
            raise
        print(f"pdeflow: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
