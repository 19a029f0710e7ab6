"""``pdeflow plot`` and ``pdeflow export``: stored runs (written by ``pdeflow run
--store``) drawn, compared or exported; their options are added by
:func:`add_plot_and_export`, called from :func:`pdeflow.cli.build_parser`."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from .cli_options import positive

PLOT_HELP = """Plot stored runs (written by `pdeflow run --store`) at one time, or as a movie.

The first run is drawn filled (layers stacked on the bed), further runs as lines on
top, for comparison: e.g. the two-layer and single-layer runs of one case, or two
parameter sets. Each run is shown at its stored time nearest to --time (default: its
last frame, the final state). A short description of each file is printed.
Runs on a 2D grid: the maps and sections of the stored state nearest to --time;
--movie draws the plan view of each run's total depth with the deposit outline over
all stored frames, side by side on one colour scale."""

EXPORT_HELP = """Export a stored run to CSV, NumPy .npz or NetCDF (chosen by the suffix).

CSV: one row per (time, cell), columns t [s], x [m], h1, u1, h2, u2 [m, m/s] and
fextra_over_rho1 [m^2/s^2] (two layers) or h, u (one layer). NPZ: arrays t, x and
each quantity as (time, cell), plus the metadata as JSON. NetCDF needs xarray
(pip install 'pdeflow[export]'); the metadata goes into its attributes.

A run on a 2D grid (a 2D case's --store) exports per layer its depth and velocities
along x and y (h1, u1, v1, h2, u2, v2 or h, u, v) and F_extra/rho1: NetCDF with
dimensions time [s], x and y [m] (cell centres), units and long_name on every variable;
NPZ arrays t, x, y and (time, nx, ny) per quantity; CSV one row per (time, x, y)."""


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


def _stored_axes(args: argparse.Namespace) -> int:
    """The axes of the stored runs' grids (1 or 2), read before any work; a one-line
    error for a mix."""
    from .storage import StorageError, stored_axes

    axes = {stored_axes(p) for p in args.runs}
    if len(axes) > 1:
        raise StorageError("pdeflow plot draws 1D runs or 2D runs, not both: "
                           + ", ".join(args.runs))
    return axes.pop()


def _stored_case(run: Any) -> Any:
    """The case a stored run was run from (its metadata), its files (a DEM, a
    shapefile) read from the case file's folder as the run read them (``case_dir``;
    runs stored before it was recorded: the working directory)."""
    import copy

    from .cases import Case

    folder = Path(run.metadata.get("case_dir", Path.cwd()))
    case = Case(copy.deepcopy(run.metadata["case"]), str(run.path), folder)
    case.validate()
    return case


def _frames(runs: list[Any]) -> list[tuple[float, list[Any], list[Any]]]:
    """The movie's frames (t, states, F_extra/rho1): at the first run's stored times,
    each run at its frame nearest to that time (its last after its end)."""
    frames = []
    for t in runs[0].times:
        idx = [r.index(min(t, r.times[-1])) for r in runs]
        frames.append((float(t), [r.data[i] for r, i in zip(runs, idx, strict=True)],
                       [r.fextra[i] for r, i in zip(runs, idx, strict=True)]))
    return frames


def _movie_2d(args: argparse.Namespace, runs: list[Any]) -> Any:
    """The movie of the stored 2D runs (:func:`pdeflow.trackers.live.replay`: the plan
    view of :mod:`pdeflow.plan_view`); its path."""
    from .plotting import Series, display_name
    from .trackers.live import replay

    case = _stored_case(runs[0])
    series = [Series(r.x, r.model, lab, r.dry_tolerance, y=r.y)
              for r, lab in zip(runs, _plot_labels(runs), strict=True)]
    title = args.title if args.title is not None else display_name(case.name)
    return replay(_frames(runs), series, args.movie, title=title, fps=args.fps,
                  progress=not args.quiet, threshold=case.front_threshold)


def _stored_bed(case: Any) -> Any:
    """The bed [m] at the cell centres of a stored run's case over one, else None."""
    corners = case.terrain_corners()
    if corners is None:
        return None
    from .numerics.geometry import centre_values

    return centre_values(corners)


def _plot_2d(args: argparse.Namespace, runs: list[Any]) -> Any:
    """The 2D figure (:func:`pdeflow.figures_2d.final_figure_2d`) of the stored 2D runs
    at the stored time nearest to ``--time`` (default: the last), saved; its path."""
    from .figures_2d import final_figure_2d
    from .metrics_2d import total_depth
    from .plotting import display_name, save

    first = runs[0]
    case = _stored_case(first)
    idx = [r.index(args.time) for r in runs]
    if not args.quiet:
        _say_nearest_frames(runs, idx, args.time)
    title = args.title if args.title is not None else display_name(case.name)
    last = all(i == len(r.times) - 1 for r, i in zip(runs, idx, strict=True))
    fig = final_figure_2d(first.x, first.y, [(r.model, r.data[i]) for r, i in
                                             zip(runs, idx, strict=True)],
                          [float(r.times[i]) for r, i in zip(runs, idx, strict=True)],
                          case.front_threshold, total_depth(first.data[0]),
                          case.release_centre[1], title,
                          state="last stored state" if last else "stored state",
                          bed=_stored_bed(case))
    return save(fig, args.out or first.path.with_suffix(".png"))


def cmd_plot(args: argparse.Namespace) -> int:
    from .outpaths import FIGURE_SUFFIXES, check_file
    from .plotting import RunFigure, Series, display_name
    from .stored_runs import open_run

    positive("--fps", args.fps)
    if args.time is not None and not math.isfinite(args.time):
        from .cases import CaseError

        raise CaseError(f"--time must be a finite time [s], got {args.time!r}")
    check_file(args.out, "--out", FIGURE_SUFFIXES)
    check_file(args.movie, "--movie")
    if args.movie:
        from .trackers.live import check_movie_path

        check_movie_path(args.movie)
    two_d = _stored_axes(args) == 2
    runs = [open_run(p) for p in args.runs]
    if two_d:
        written = [_movie_2d(args, runs)] if args.movie else []
        if args.out or not args.movie:
            written.append(_plot_2d(args, runs))
        if not args.quiet:
            for r in runs:
                print(r.describe())
            for p in written:
                print(f"wrote {p}")
        return 0
    series = [Series(r.x, r.model, lab, r.dry_tolerance, r.coordinate)
              for r, lab in zip(runs, _plot_labels(runs), strict=True)]
    title = args.title if args.title is not None else display_name(
        runs[0].metadata.get("case_name", runs[0].path.stem))
    written = []
    if args.movie:
        from .trackers.live import replay

        written.append(replay(_frames(runs), series, args.movie, title=title,
                              fps=args.fps, progress=not args.quiet))
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
    from .outpaths import EXPORT_SUFFIXES, check_file
    from .stored_runs import open_run

    check_file(args.out, "OUT", EXPORT_SUFFIXES)
    run = open_run(args.run)
    out = run.export(args.out)
    if not args.quiet:
        print(run.describe())
        print(f"wrote {out}")
    return 0


def add_plot_and_export(sub: Any, formatter: Any) -> None:
    """``pdeflow plot`` and ``pdeflow export``: their options."""
    plot = sub.add_parser("plot", help="plot or compare stored runs (.h5)",
                          description=PLOT_HELP, formatter_class=formatter)
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
    export = sub.add_parser("export", help="export a stored run to CSV, NPZ or NetCDF",
                            description=EXPORT_HELP, formatter_class=formatter)
    export.add_argument("run", metavar="RUN.h5", help="stored run (pdeflow run --store)")
    export.add_argument("out", metavar="OUT.csv",
                        help="output file: .csv, .npz or .nc (NetCDF, needs xarray)")
    export.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    export.set_defaults(func=cmd_export)
