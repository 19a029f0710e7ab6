"""The figures of a case's runs: snapshots like the paper's Figs. 3-6 and the final
deposits (Fig. 7), written by ``pdeflow run`` (drawn on two cores where there are, in
a process forked before the run: :mod:`pdeflow.figure_worker`).

Each run is drawn as its system describes its layers (:mod:`pdeflow.systems`,
:data:`pdeflow.plotting.LAYER_STYLES`). The figures are plain matplotlib figures
(:class:`matplotlib.figure.Figure`, drawn by Agg when saved): no pyplot, so nothing a
GUI or a notebook would show by itself, and matplotlib is imported only when one is
drawn. A figure *job* is ``(make, args, path)``: ``make(*args)`` returns the figure to
save at ``path``; the snapshots of a case are drawn by one :class:`SnapshotFigures`,
which redraws one figure in place (they share their axes, ticks and labels).
"""

from __future__ import annotations

import sys
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from . import systems
from .numerics.compile_parallel import can_fork, fork_context
from .numerics.geometry import COORDINATES
from .plotting import (
    LAYER_STYLES,
    _short,
    _symbol,
    _velocity,
    display_name,
    fixed_margins,
    new_figure,
    save,
)

Job = tuple[Callable[..., Any], tuple, Path]
"""a figure job: (make, its arguments, path), see the module docstring"""


def plot_depths(ax, x: np.ndarray, runs: Sequence[tuple[str, np.ndarray]]) -> None:
    """Each run (model name, state data): its layers stacked from the bed, the lowest
    first, filled where their style has a fill; a run with no filled layer as its
    surface line."""
    for model, d in runs:
        system = systems.get(model)
        base: Any = 0
        filled = False
        for k in reversed(range(len(system.layers))):
            layer = system.layers[k]
            fill, alpha, _ = LAYER_STYLES[layer.style]
            top = base + d[2 * k]
            if fill is not None:
                ax.fill_between(x, base, top, color=fill, alpha=alpha, lw=0,
                                label=f"{layer.label} {_symbol(layer.depth)}")
                filled = True
            base = top
        line = LAYER_STYLES[system.layers[0].style][2]
        if filled:
            ax.plot(x, base, color=line, lw=1)
        else:
            ax.plot(x, base, color=line, lw=1.2, label=system.label)
    ax.set_ylabel("depth [m]")


def plot_velocities(ax, x: np.ndarray, runs: Sequence[tuple[str, np.ndarray]]) -> None:
    """Velocities where a layer is present (gaps where it is dry)."""
    for model, d in runs:
        system = systems.get(model)
        for k, layer in enumerate(system.layers):
            u = _velocity(d[2 * k], d[2 * k + 1])
            colour = LAYER_STYLES[layer.style][2]
            if len(system.layers) == 1:
                ax.plot(x, u, color=colour, lw=1.2, label=system.label)
            else:
                ax.plot(x, u, color=colour,
                        label=f"{_symbol(layer.velocity)} ({_short(layer)})")
    ax.set_ylabel("velocity [m/s]")


def snapshot_figure(x: np.ndarray, t: float, runs: Sequence[tuple[str, np.ndarray]],
                    fextra: np.ndarray | None, title: str = "",
                    coordinate: str = "x",
                    xlim: tuple[float, float] | None = None) -> Any:
    """Three stacked panels at time t, like the paper's Figs. 3-6: depths and velocities
    of the runs (model name, state data), F_extra/rho1 [m^2/s^2]; x limited to ``xlim``
    [m] if given (:func:`reach`)."""
    fig = new_figure((7, 7.5))
    axes = fig.subplots(3, 1, sharex=True)
    _snapshot_data(fig, x, t, runs, fextra, title, xlim)
    axes[2].set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
    axes[2].set_xlabel(f"{coordinate} [m]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fixed_margins(fig, top=0.45)
    return fig


def _snapshot_data(fig: Any, x: np.ndarray, t: float,
                   runs: Sequence[tuple[str, np.ndarray]], fextra: np.ndarray | None,
                   title: str, xlim: tuple[float, float] | None = None) -> None:
    """The runs' layers, velocities and F_extra/rho1 [m^2/s^2] at t [s] in the panels of
    a snapshot figure, their legends and the title."""
    axes = fig.axes
    plot_depths(axes[0], x, runs)
    plot_velocities(axes[1], x, runs)
    axes[2].plot(x, fextra if fextra is not None else np.zeros_like(x), color="tab:red")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].legend(loc="upper right", fontsize=8)
    if xlim is not None:
        axes[0].set_xlim(*xlim)  # shared by the panels
    fig.suptitle(f"{title} t = {t:g} s".strip())


class SnapshotFigures:
    """The snapshot figures (:func:`snapshot_figure`) of one case, one figure redrawn in
    place: :meth:`draw` draws the runs at another time into it. The data, legends and
    title are drawn anew and the data limits recomputed, so that each image is the one
    a new figure gives, whatever was drawn before; the axes, their ticks and labels
    stay (making them took most of a figure's time).

    Args:
        x: cell centres [m].
        title: the case's name (before "t = ... s").
        coordinate: the grid's coordinate, 'x' or 'r'.
        xlim: the x range of every figure [m] (:func:`reach`), or None: the domain.
    """

    def __init__(self, x: np.ndarray, title: str = "", coordinate: str = "x",
                 xlim: tuple[float, float] | None = None):
        self.x, self.title, self.coordinate, self.xlim = x, title, coordinate, xlim
        self.fig: Any = None

    def draw(self, t: float, runs: Sequence[tuple[str, np.ndarray]],
             fextra: np.ndarray | None) -> Any:
        """The figure at time t [s] of the runs (model name, state data), F_extra/rho1
        [m^2/s^2]: valid until the next call."""
        if self.fig is None:
            self.fig = snapshot_figure(self.x, t, runs, fextra, self.title,
                                       self.coordinate, self.xlim)
            return self.fig
        for ax in self.fig.axes:
            for artist in [*ax.lines, *ax.collections, *ax.patches, *ax.texts]:
                artist.remove()
            if ax.get_legend() is not None:
                ax.get_legend().remove()
            ax.relim()  # no artist left: the limits of a new axes
        _snapshot_data(self.fig, self.x, t, runs, fextra, self.title, self.xlim)
        return self.fig


DEPOSIT_EDGE = 1e-3
"""the figures show x up to 10 % beyond the last cell deeper than this fraction of the
deepest state drawn (or of the initial state): the material, not a thin tail or an
empty domain (:func:`reach`)"""


def reach(x: np.ndarray, depths: Sequence[np.ndarray]) -> tuple[float, float] | None:
    """The x range [m] of figures of the total ``depths`` [m] per cell (at the uniform
    cell centres ``x``): from the domain's start to 10 % beyond the last cell deeper than
    :data:`DEPOSIT_EDGE` of the deepest, at most the domain's end; None without material."""
    deepest = max((float(np.max(h)) for h in depths), default=0.0)
    if not deepest > 0:
        return None
    wet = np.nonzero(np.max(depths, axis=0) > DEPOSIT_EDGE * deepest)[0]
    dx = float(x[1] - x[0]) if x.size > 1 else 0.0
    start, end = float(x[0]) - dx / 2, float(x[-1]) + dx / 2
    return start, min(end, start + 1.1 * (float(x[wet[-1]]) + dx / 2 - start))


def deposit_figure(x: np.ndarray, runs: Sequence[tuple[str, np.ndarray]],
                   title: str = "", times: str = "", coordinate: str = "x",
                   initial: np.ndarray | None = None) -> Any:
    """Final deposits of the runs (model name, state data): the paper's Fig. 7, with the
    ``initial`` total depth [m] per cell (the released column) outlined if given, and
    zoomed to the deposits (:data:`DEPOSIT_EDGE`)."""
    fig = new_figure((7, 3.2))
    ax = fig.subplots()
    plot_depths(ax, x, runs)
    depths = [d[::2].sum(axis=0) for _, d in runs]
    if initial is not None:
        ax.plot(x, initial, color="0.35", ls="--", lw=1, label="initial state")
        depths.append(initial)
    ax.legend(loc="upper right", fontsize=8)
    xlim = reach(x, depths)
    if xlim is not None:
        ax.set_xlim(*xlim)
    deepest = max(float(np.max(h)) for h in depths)
    ax.set_ylim(0, 1.25 * deepest if deepest > 0 else 1)  # room for the legend
    ax.set_xlabel(f"{coordinate} [m]")
    ax.grid(alpha=0.3)
    ax.set_title(f"{title}: final deposits\n{times}".strip(), fontsize=10)
    fixed_margins(fig, top=0.55)
    return fig


def _initial_depth(res: Any) -> np.ndarray:
    """The total depth [m] per cell of a run's initial state (its case's shape)."""
    profiles = res.case.initial_profiles(res.model, res.state.grid)
    return sum(profiles[layer.depth] for layer in res.pde.system.layers)


def _stops(runs: Sequence[Any]) -> str:
    """'(two layers at rest at t = 1.35 s, single layer at rest at 1.37 s)': each run's
    state at the end, by its model's label."""
    parts = []
    for res in runs:
        st = res.summary.get("stop_time")
        label = res.pde.system.label
        parts.append(f"{label} at rest at t = {st:.2f} s" if st
                     else f"{label} still moving at t = {res.t_final:.2f} s")
    return "(" + ", ".join(parts) + ")"


def case_figures(results: dict[str, Any], outdir: str | Path, prefix: str = "",
                 parallel: bool = True) -> list[Path]:
    """Snapshot figures at every stored time and the final-deposit figure (the jobs of
    :func:`figure_jobs`, drawn by :func:`draw_all`, on two cores with ``parallel``)."""
    return draw_all(figure_jobs(results, outdir, prefix), parallel)


def run_figure_jobs(results: dict[str, Any], outdir: str | Path | None = None,
                    plot: str | Path | None = None) -> list[Job]:
    """The figures of ``pdeflow run``: the final deposits at ``plot`` (``--plot``), then
    those of :func:`figure_jobs` in ``outdir`` (``--outdir``); a 2D case's final-state
    figure (:mod:`pdeflow.figures_2d`) at both instead."""
    if next(iter(results.values())).case.is_2d:
        return _run_figure_jobs_2d(results, outdir, plot)
    jobs: list[Job] = []
    if plot:
        runs = list(results.values())
        jobs.append((deposit_figure, (runs[0].x, [(r.model, r.state.data) for r in runs],
                                      display_name(runs[0].case.name), _stops(runs),
                                      COORDINATES[runs[0].case.geometry],
                                      _initial_depth(runs[0])), Path(plot)))
    if outdir:
        jobs.extend(figure_jobs(results, outdir))
    return jobs


def _run_figure_jobs_2d(results: dict[str, Any], outdir: str | Path | None,
                        plot: str | Path | None) -> list[Job]:
    """:func:`run_figure_jobs` of a 2D case: its final-state figure
    (:func:`pdeflow.figures_2d.final_figure_2d`) at ``plot`` and as
    ``final_deposits.png`` in ``outdir`` (the 1D folder's name for the final state),
    and in ``outdir`` the same figure of each snapshot, ``snapshot_t<t>.png`` (a 2D
    run has no bed figures yet)."""
    from .figures_2d import final_figure_job, snapshot_figure_jobs

    stops = _stops(list(results.values()))
    targets = [Path(plot)] if plot else []
    jobs: list[Job] = []
    if outdir:
        Path(outdir).mkdir(parents=True, exist_ok=True)
        jobs.extend(snapshot_figure_jobs(results, Path(outdir)))
        targets.append(Path(outdir) / "final_deposits.png")
    return [final_figure_job(results, path, stops) for path in targets] + jobs


def figure_jobs(results: dict[str, Any], outdir: str | Path,
                prefix: str = "") -> list[Job]:
    """The jobs of :func:`case_figures` (``outdir`` is created): the snapshots, the
    final deposits and the bed figures."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    runs = list(results.values())
    first = runs[0]
    # every snapshot on the x range the material reached at any of them or at the end
    states = [s[0] for res in runs for s in res.snapshots.values()]
    states += [res.state.data for res in runs]
    snapshots = SnapshotFigures(first.x, display_name(first.case.name),
                                COORDINATES[first.case.geometry],
                                reach(first.x, [d[::2].sum(axis=0) for d in states]))
    jobs: list[Job] = []
    for t in sorted(set().union(*(res.snapshots for res in runs))):
        shown = [res for res in runs if t in res.snapshots]
        fextra = next((res.snapshots[t][1] for res in shown if res.pde.system.has_fextra),
                      None)
        jobs.append((snapshots.draw, (t, [(res.model, res.snapshots[t][0])
                                          for res in shown], fextra),
                     outdir / f"{prefix}snapshot_t{t:g}.png"))
    jobs.append((deposit_figure, (first.x, [(res.model, res.state.data) for res in runs],
                                  display_name(first.case.name), _stops(runs),
                                  snapshots.coordinate, _initial_depth(first)),
                 outdir / f"{prefix}final_deposits.png"))
    jobs.extend(bed_jobs(runs, outdir, prefix))
    return jobs


def bed_jobs(runs: Sequence[Any], outdir: Path, prefix: str = "") -> list[tuple]:
    """The bed figure (:func:`pdeflow.bed_figures.bed_figure`) of every run of a case
    that lays a bed, as :func:`draw_all` jobs: ``bed_<model>.png``."""
    from .bed_figures import bed_figure

    jobs = []
    for res in runs:
        if res.frames is None or res.series is None or res.case.bed_kind(res.model) is None:
            continue
        t, frames = res.frames
        xs = res.x - res.case.x_start
        bed0 = res.case.bed(res.model, xs)
        jobs.append((bed_figure, (res.x, t, frames, res.model, bed0, res.series,
                                  res.case.name, res.summary.get("flow_duration"),
                                  res.case.bed_region(xs)),
                     outdir / f"{prefix}bed_{res.model}.png"))
    return jobs


def draw_all(jobs: Sequence[Job], parallel: bool = True) -> list[Path]:
    """Draw and :func:`save` the figures of ``jobs``; returns their paths. With
    ``parallel``, no GUI figure open (a fork would share its window) and
    :func:`~pdeflow.numerics.compile_parallel.can_fork`, a forked process draws every
    second one meanwhile (matplotlib uses one core)."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    gui = pyplot is not None and pyplot.get_backend().lower() != "agg"
    if not (parallel and len(jobs) > 1 and not gui and can_fork()):
        return [_draw(job) for job in jobs]
    ctx = fork_context()
    mine, theirs = ctx.Pipe()
    helper = ctx.Process(target=_draw_each, args=(jobs[1::2], theirs),
                         name="pdeflow-figures-helper")
    helper.start()
    theirs.close()
    try:
        for job in jobs[::2]:
            _draw(job)
    finally:
        # the helper leaves on its own, whatever happens here (the run's deferred
        # signals, the outputs written whole, hold a SIGTERM back in the fork)
        try:
            failed = mine.recv()
        except EOFError:
            failed = "it ended without a word"
        helper.join()
    if failed is not None or helper.exitcode != 0:
        raise RuntimeError(f"drawing figures in the helper process failed "
                           f"(exit code {helper.exitcode}):\n{failed}")
    return [Path(path) for _, _, path in jobs]


def _draw(job: Job) -> Path:
    """Draw and save the figure of one job; its path."""
    make, args, path = job
    return save(make(*args), path)


def _draw_each(jobs: Sequence[Job], conn: Any) -> None:
    """The helper of :func:`draw_all`: draw ``jobs``, then send None or the
    traceback."""
    try:
        mathtext = sys.modules.get("matplotlib.mathtext")
        if mathtext is not None:
            # matplotlib opens its fonts anew in a fork (their files' read offsets are
            # shared with the parent); mathtext's cached layouts hold the parent's
            mathtext.MathTextParser._parse_cached.cache_clear()
        for job in jobs:
            _draw(job)
        conn.send(None)
    except BaseException:
        conn.send(traceback.format_exc())
