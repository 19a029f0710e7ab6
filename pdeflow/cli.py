"""Command line: ``pdeflow run | plot | export`` (``pdeflow COMMAND --help`` for each).

Each subcommand is a function ``cmd_<name>(args) -> exit code`` and its options are set
up in :func:`build_parser`; errors in the user's input (case files, stored runs, movie
formats) are printed as one line and exit with code 2.
"""

from __future__ import annotations

import argparse
import logging
import sys
import warnings
from pathlib import Path
from typing import Any

from . import __version__

RUN_HELP = """Run every model listed in the case file (case.models) to rest or t_end.

Without output options the summary and all figures go to results/<case name>/.
Outputs are written atomically: a failed run leaves no partial file behind.
For cases with several models, per-model outputs (--final, --store, --movie) go to
the given name for the first model and to NAME.<model>.SUFFIX for the others.

examples:
  pdeflow run cases/paper_5_1_dam_break.toml
  pdeflow run cases/paper_5_1_dam_break.toml --set two_layer.c=0.05 --summary s.json
  pdeflow run cases/ritter_dam_break.toml --live            # desktop window
  pdeflow run cases/paper_5_1_dam_break.toml --movie 5_1.mp4 --store 5_1.h5
  pdeflow plot 5_1.h5 5_1.single_layer.h5 --time 0.4 --out t04.png"""

PLOT_HELP = """Plot stored runs (written by `pdeflow run --store`) at one time, or as a movie.

The first run is drawn filled (layers stacked on the bed), further runs as lines on
top, for comparison: e.g. the two-layer and single-layer runs of one case, or two
parameter sets. Each run is shown at its stored time nearest to --time (default: its
last frame, the final state). A short description of each file is printed."""

EXPORT_HELP = """Export a stored run to CSV, NumPy .npz or NetCDF (chosen by the suffix).

CSV: one row per (time, cell), columns t [s], x [m], h1, u1, h2, u2 [m, m/s] and
fextra_over_rho1 [m^2/s^2] (two layers) or h, u (one layer). NPZ: arrays t, x and
each quantity as (time, cell), plus the metadata as JSON. NetCDF needs xarray
(pip install 'pdeflow[export]'); the metadata goes into its attributes."""


def _model_path(path: str | Path, model: str, first: bool) -> Path:
    """Per-model output name: PATH for the first model, NAME.<model>.SUFFIX after it."""
    path = Path(path)
    return path if first else path.with_name(f"{path.stem}.{model}{path.suffix}")


def _positive(name: str, value: float | None) -> None:
    from .cases import CaseError

    if value is not None and not value > 0:
        raise CaseError(f"{name} must be > 0, got {value!r}")


def _run_trackers(args: argparse.Namespace, case: Any, model: str,
                  first: bool) -> list[Any]:
    """The trackers that the run options ask for (progress, live plot, storage)."""
    trackers: list[Any] = []
    interval = case.t_end / 100
    progress = args.progress
    if progress is None:  # default: on a terminal, and for long runs (the bar is stderr)
        from .checks import run_cost

        progress = not args.quiet and (sys.stdout.isatty() or run_cost(case, model).long)
    if progress:
        from .trackers import ProgressBar

        trackers.append(ProgressBar(interval, label=model))
    from .trackers.live import display_mode

    show = args.live and display_mode("auto") != "none"  # headless: nothing to show
    if show or args.movie or args.frames:
        from .trackers.live import LayersPlotTracker

        movie = _model_path(args.movie, model, first) if args.movie else None
        frames = (Path(args.frames) / model) if args.frames else None
        trackers.append(LayersPlotTracker(
            args.live_every or interval, title=f"{case.name}: {model.replace('_', ' ')}",
            display="auto" if show else "none", movie=movie, frames=frames,
            fps=args.fps))
    if args.store:
        from .storage import RunStorageTracker, run_metadata

        meta = run_metadata(case, model, overrides=args.set, case_file=str(args.case),
                            store_every=args.store_every or interval)
        trackers.append(RunStorageTracker(_model_path(args.store, model, first),
                                          args.store_every or interval, metadata=meta,
                                          autocommit=False))
    return trackers


def _import_plotting() -> None:
    from . import plotting  # noqa: F401


def cmd_run(args: argparse.Namespace) -> int:
    from .cases import load_case
    from .io import check_output, write_json, write_npz
    from .numerics.warmup import prepare
    from .simulate import case_steppers, print_summary, run_model

    case = load_case(args.case, args.set)
    for name in ("live_every", "store_every", "fps"):
        _positive(f"--{name.replace('_', '-')}", getattr(args, name))
    for name in ("summary", "final", "plot", "outdir", "store", "movie", "frames"):
        check_output(getattr(args, name), f"--{name}")
    if args.movie:
        from .trackers.live import check_movie_path

        check_movie_path(args.movie)
    if args.store:
        from .storage import require_h5py

        require_h5py()
    live_window = False
    if args.live:
        from .trackers.live import display_mode

        live_window = display_mode("auto") == "window"
        if display_mode("auto") == "none":
            print("pdeflow: warning: --live needs a display (matplotlib backend "
                  "is non-interactive); use --movie or --frames on a headless machine",
                  file=sys.stderr)
    default_out = not (args.summary or args.final or args.plot or args.outdir
                       or args.store or args.movie or args.frames)
    outdir = Path(args.outdir) if args.outdir else (
        Path("results") / case.name if default_out else None)
    # matplotlib's import (~0.5 s) fills the wait for the kernels a helper compiles
    prepare(case_steppers(case), log=None if args.quiet else sys.stderr,
            meanwhile=_import_plotting if args.plot or outdir else None)
    results = {}
    stores: dict[str, Any] = {}
    all_trackers: list[Any] = []
    if args.live or args.movie or args.frames:
        # drawing frames takes longer than the run itself: py-pde's warning about it
        # would only be noise here
        logging.getLogger("pde.solvers.controller").setLevel(logging.ERROR)
    try:
        for i, model in enumerate(case.models):
            trackers = _run_trackers(args, case, model, first=i == 0)
            all_trackers.extend(trackers)
            for t in trackers:
                if hasattr(t, "commit"):
                    stores[model] = t
            results[model] = run_model(case, model, tracker=trackers or None)
    except BaseException:
        for t in all_trackers:  # no partial movie or storage file stays behind
            if hasattr(t, "discard"):
                t.discard()
        raise
    summary = {
        "case": case.name,
        "case_file": str(args.case),
        "overrides": args.set,
        "pdeflow_version": __version__,
        "parameters": {m: case.make_pde(m).parameters.to_dict() for m in case.models},
        "models": {m: r.summary for m, r in results.items()},
    }
    written = []
    for model, tracker in stores.items():
        written.append(tracker.commit({"summary": summary["models"][model]}))
    for t in all_trackers:
        if getattr(t, "movie", None) is not None:
            written.append(t.movie.path)
        if getattr(t, "frames_dir", None) is not None and t.frame_paths:
            written.append(t.frames_dir / f"frame_*.png ({len(t.frame_paths)} frames)")
    if args.summary or outdir:
        written.append(write_json(args.summary or outdir / "summary.json", summary))
    if args.final:
        for i, m in enumerate(case.models):
            written.append(write_npz(_model_path(args.final, m, i == 0),
                                     results[m].final_arrays()))
    if args.plot or outdir:
        from .case_figures import case_figures, deposit_figure
        from .plotting import save
    if args.plot:
        runs = list(results.values())
        fig = deposit_figure(runs[0].x, [(r.model, r.state.data) for r in runs], case.name)
        written.append(save(fig, args.plot))
    if outdir:
        written.extend(case_figures(results, outdir))
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


def _plot_labels(runs: list[Any]) -> list[str]:
    """Legend names of stored runs: none where their models differ (the model names
    them), else the file names (their paths where the names repeat)."""
    if len({r.model for r in runs}) == len(runs):
        return [""] * len(runs)
    if len({r.path.stem for r in runs}) == len(runs):
        return [r.path.stem for r in runs]
    return [str(r.path) for r in runs]


def _say_nearest_frames(runs: list[Any], idx: list[int], t: float | None) -> None:
    """Tell which stored frame is shown where a run has none at the asked time."""
    if t is None:
        return
    for r, i in zip(runs, idx, strict=True):
        shown = float(r.times[i])
        if abs(shown - t) > 1e-9 * max(1.0, abs(t)):
            last = " (its last frame)" if i == len(r.times) - 1 else ""
            print(f"pdeflow: note: {r.path.name} has no frame at t = {t:g} s; showing "
                  f"the nearest, t = {shown:.4g} s{last}", file=sys.stderr)


def cmd_plot(args: argparse.Namespace) -> int:
    from .io import check_output
    from .plotting import RunFigure, Series
    from .storage import open_run

    _positive("--fps", args.fps)
    check_output(args.out, "--out")
    check_output(args.movie, "--movie")
    if args.movie:
        from .trackers.live import check_movie_path

        check_movie_path(args.movie)
    runs = [open_run(p) for p in args.runs]
    series = [Series(r.x, r.model, lab, r.dry_tolerance, r.coordinate)
              for r, lab in zip(runs, _plot_labels(runs), strict=True)]
    title = args.title if args.title is not None else runs[0].metadata.get(
        "case_name", runs[0].path.stem)
    written = []
    if args.movie:
        from .trackers.live import replay

        frames = []
        for t in runs[0].times:
            idx = [r.index(min(t, r.times[-1])) for r in runs]
            frames.append((float(t), [r.data[i] for r, i in zip(runs, idx, strict=True)],
                           [r.fextra[i] for r, i in zip(runs, idx, strict=True)]))
        written.append(replay(frames, series, args.movie, title=title, fps=args.fps))
    if args.out or not args.movie:
        idx = [r.index(args.time) for r in runs]
        times = [float(r.times[i]) for r, i in zip(runs, idx, strict=True)]
        if not args.quiet:
            _say_nearest_frames(runs, idx, args.time)
        # deposits at rest: velocities and F_extra are zero, so only the depths are drawn
        deposits = args.time is None and all(r.metadata.get("at_rest") for r in runs)
        if len({round(t, 9) for t in times}) > 1 and not deposits:
            for s, t in zip(series, times, strict=True):  # show each run's own time
                s.label = f"{s.label or s.model.replace('_', ' ')}, t = {t:.3g} s"
        fig = RunFigure(series, title=title, panels=1 if deposits else 3)
        fig.update(times[0], [r.data[i] for r, i in zip(runs, idx, strict=True)],
                   [r.fextra[i] for r, i in zip(runs, idx, strict=True)])
        if deposits:
            fig.set_title("final deposits (at rest: " + ", ".join(
                f"{fig.name(s)} t = {t:.3g} s" for s, t in zip(series, times, strict=True))
                + ")")
        elif len({round(t, 9) for t in times}) > 1:
            fig.set_title("(times in the legend)" if args.time is None
                          else f"(nearest stored times to t = {args.time:g} s)")
        out = args.out or runs[0].path.with_suffix(".png")
        written.append(fig.save(out))
        fig.close()
    if not args.quiet:
        for r in runs:
            print(r.describe())
        for p in written:
            print(f"wrote {p}")
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from .io import check_output
    from .storage import open_run

    check_output(args.out, "OUT")
    run = open_run(args.run)
    out = run.export(args.out)
    if not args.quiet:
        print(run.describe())
        print(f"wrote {out}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    raw = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(
        prog="pdeflow",
        description="Depth-averaged single- and two-layer granular flow models on py-pde.",
        epilog="docs/user_guide.md explains the commands, docs/cases.md the case files.")
    parser.add_argument("--version", action="version", version=f"pdeflow {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    # --- run ------------------------------------------------------------------------------
    run = sub.add_parser("run", help="run a case file", description=RUN_HELP,
                         formatter_class=raw)
    run.add_argument("case", help="TOML case file (see cases/ and docs/cases.md)")
    run.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                     help="override a case value, e.g. --set two_layer.c=0.05 (repeatable)")
    out = run.add_argument_group("result files")
    out.add_argument("--summary", metavar="OUT.json", help="write the JSON summary here")
    out.add_argument("--final", metavar="OUT.npz",
                     help="write the final state (x, h1, u1, h2, u2 or x, h, u, and t); "
                     "further models go to OUT.<model>.npz")
    out.add_argument("--plot", metavar="OUT.png", help="write the final-deposit figure")
    out.add_argument("--outdir", metavar="DIR",
                     help="write summary.json and all figures (snapshots, deposits) here")
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
                       "terminal, or when the run is estimated to be long)")
    watch.add_argument("--live", action="store_true",
                       help="draw the layers, velocities and F_extra/rho1 in a window "
                       "while the run goes (needs a display; close it to finish)")
    watch.add_argument("--movie", metavar="OUT.mp4",
                       help="write the live plot as a movie, headless: .mp4 (also "
                       ".m4v, .mov, .mkv, .avi; H.264, needs ffmpeg, e.g. pip install "
                       "imageio-ffmpeg) or .gif; further models go to OUT.<model>.mp4")
    watch.add_argument("--frames", metavar="DIR",
                       help="write the live plot as PNG frames DIR/<model>/frame_*.png")
    watch.add_argument("--live-every", type=float, metavar="DT",
                       help="simulation time between live frames [s] (default t_end/100)")
    watch.add_argument("--fps", type=float, default=10.0,
                       help="frames per second of --movie (default 10)")
    run.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    run.set_defaults(func=cmd_run)

    # --- plot -----------------------------------------------------------------------------
    plot = sub.add_parser("plot", help="plot or compare stored runs (.h5)",
                          description=PLOT_HELP, formatter_class=raw)
    plot.add_argument("runs", nargs="+", metavar="RUN.h5",
                      help="stored runs (pdeflow run --store); the first is drawn filled")
    plot.add_argument("--time", type=float, metavar="T",
                      help="time to show [s] (nearest stored frame; default: the end)")
    plot.add_argument("--out", metavar="FIG.png",
                      help="write the figure here (default: the first RUN with .png)")
    plot.add_argument("--movie", metavar="OUT.mp4",
                      help="write a movie over all stored frames (.mp4, .m4v, .mov, "
                      ".mkv, .avi: needs ffmpeg; or .gif)")
    plot.add_argument("--fps", type=float, default=10.0,
                      help="frames per second of --movie (default 10)")
    plot.add_argument("--title", help="figure title (default: the case name)")
    plot.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    plot.set_defaults(func=cmd_plot)

    # --- export ---------------------------------------------------------------------------
    export = sub.add_parser("export", help="export a stored run to CSV, NPZ or NetCDF",
                            description=EXPORT_HELP, formatter_class=raw)
    export.add_argument("run", metavar="RUN.h5", help="stored run (pdeflow run --store)")
    export.add_argument("out", metavar="OUT.csv",
                        help="output file: .csv, .npz or .nc (NetCDF, needs xarray)")
    export.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    export.set_defaults(func=cmd_export)

    # --- the commands whose module owns its options (add_arguments) and body ----------
    from .analysis import convergence, sweep, workprecision
    from .app import server  # panel is imported only when the app runs
    from .study import command as study

    for name, module, func, help_ in (
            ("sweep", sweep, sweep.cmd_sweep,
             "aspect-ratio sweep and run-out law (paper 5.2)"),
            ("converge", convergence, convergence.cmd_converge,
             "grid-convergence study of a case"),
            ("compare", workprecision, workprecision.cmd_compare,
             "work-precision study: error against wall time of solver variants (to "
             "compare runs, use plot)"),
            ("study", study, study.cmd_study,
             "parameter study, sensitivity or calibration on Dask"),
            ("app", server, server.cmd_app, "teaching app in the browser (needs panel)")):
        cmd = sub.add_parser(name, help=help_, formatter_class=raw,
                             description=getattr(module, "HELP", module.__doc__))
        module.add_arguments(cmd)
        cmd.set_defaults(func=func)
    return parser


def main(argv: list[str] | None = None) -> int:
    """``pdeflow COMMAND ...``: the exit code; warnings about a run or its results
    (:class:`pdeflow.checks.RunWarning`) are printed as one line each, once."""
    from .checks import RunWarning

    original = warnings.showwarning
    shown: set[str] = set()

    def show(message: Any, category: type, *args: Any, **kwargs: Any) -> None:
        if not issubclass(category, RunWarning):
            original(message, category, *args, **kwargs)
        elif str(message) not in shown:  # e.g. the solver's, once for all models
            shown.add(str(message))
            print(f"pdeflow: warning: {message}", file=sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.simplefilter("always", RunWarning)
        warnings.showwarning = show
        return _main(argv)


def _main(argv: list[str] | None = None) -> int:
    from .cases import CaseError
    from .solvers.fv_split import SimulationBlowUp
    from .storage import StorageError

    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (CaseError, StorageError) as err:
        print(f"pdeflow: error: {err}", file=sys.stderr)
        return 2
    except SimulationBlowUp as err:
        # the message says where, when and with which scheme; the traceback adds nothing
        print(f"pdeflow: simulation failed: {err}", file=sys.stderr)
        return 3
    except ValueError as err:
        from .io import OutputError
        from .trackers.live import MovieError

        if not isinstance(err, (MovieError, OutputError)):
            raise
        print(f"pdeflow: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
