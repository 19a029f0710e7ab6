"""The figures of a case's runs: snapshots like the paper's Figs. 3-6 and the final
deposits (Fig. 7), written by ``pdeflow run`` (drawn on two cores where there are).

Each run is drawn as its system describes its layers (:mod:`pdeflow.systems`,
:data:`pdeflow.plotting.LAYER_STYLES`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from . import systems
from .numerics.compile_parallel import can_fork, fork_context
from .numerics.geometry import COORDINATES
from .plotting import LAYER_STYLES, _short, _symbol, _velocity, fixed_margins, save


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
                    coordinate: str = "x") -> Any:
    """Three stacked panels at time t, like the paper's Figs. 3-6: depths and velocities
    of the runs (model name, state data), F_extra/rho1 [m^2/s^2]."""
    fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    plot_depths(axes[0], x, runs)
    plot_velocities(axes[1], x, runs)
    axes[2].plot(x, fextra if fextra is not None else np.zeros_like(x), color="tab:red")
    axes[2].set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].legend(loc="upper right", fontsize=8)
    axes[2].set_xlabel(f"{coordinate} [m]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"{title} t = {t:g} s".strip())
    fixed_margins(fig, top=0.45)
    return fig


def deposit_figure(x: np.ndarray, runs: Sequence[tuple[str, np.ndarray]],
                   title: str = "", times: str = "", coordinate: str = "x") -> Any:
    """Final deposits of the runs (model name, state data): the paper's Fig. 7."""
    fig, ax = plt.subplots(figsize=(7, 3.2))
    plot_depths(ax, x, runs)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel(f"{coordinate} [m]")
    ax.grid(alpha=0.3)
    ax.set_title(f"{title}: final deposits\n{times}".strip(), fontsize=10)
    fixed_margins(fig, top=0.55)
    return fig


def case_figures(results: dict[str, Any], outdir: str | Path, prefix: str = "",
                 parallel: bool = True) -> list[Path]:
    """Snapshot figures at every stored time and the final-deposit figure (drawn by
    :func:`draw_all`, on two cores with ``parallel``)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    runs = list(results.values())
    first = runs[0]
    coordinate = COORDINATES[first.case.geometry]
    times = sorted(set().union(*(res.snapshots for res in runs)))
    jobs = []
    for t in times:
        shown = [res for res in runs if t in res.snapshots]
        fextra = next((res.snapshots[t][1] for res in shown if res.pde.system.has_fextra),
                      None)
        jobs.append((snapshot_figure, (first.x, t, [(res.model, res.snapshots[t][0])
                                                   for res in shown],
                                       fextra, first.case.name, coordinate),
                     outdir / f"{prefix}snapshot_t{t:g}.png"))
    stop = []
    for res in runs:
        st = res.summary.get("stop_time")
        stop.append(f"{res.model}: t={st:.2f} s" if st else f"{res.model}: moving")
    jobs.append((deposit_figure, (first.x, [(res.model, res.state.data) for res in runs],
                                  first.case.name, "(" + ", ".join(stop) + ")",
                                  coordinate),
                 outdir / f"{prefix}final_deposits.png"))
    jobs.extend(bed_jobs(runs, outdir, prefix))
    return draw_all(jobs, parallel)


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


def draw_all(jobs: Sequence[tuple[Callable, tuple, Path]],
             parallel: bool = True) -> list[Path]:
    """Draw and :func:`save` the figures ``jobs`` (figure function, its arguments,
    path); returns the paths. With ``parallel``, Agg (no window a fork would share)
    and :func:`~pdeflow.numerics.compile_parallel.can_fork`, a forked process draws
    every second figure meanwhile (matplotlib uses one core)."""
    agg = plt.get_backend().lower() == "agg"
    if not (parallel and len(jobs) > 1 and agg and can_fork()):
        return [_draw(job) for job in jobs]
    with fork_context().Pool(1) as pool:
        theirs = pool.map_async(_draw, jobs[1::2])
        mine = [_draw(job) for job in jobs[::2]]
        paths = theirs.get()
        # the worker leaves on its own: the pool's terminate() at the end of the block
        # stops it with SIGTERM, which the run's deferred signals (the outputs are
        # written whole) hold back in the fork, and the join hung, the worker waiting
        pool.close()
        pool.join()
    return [mine[i // 2] if i % 2 == 0 else paths[i // 2] for i in range(len(jobs))]


def _draw(job: tuple[Callable, tuple, Path]) -> Path:
    make, args, path = job
    return save(make(*args), path)


