"""The final-state figure of a 2D run (issue 36), written by ``pdeflow run`` as the
1D runs' final-deposit figure is (:mod:`pdeflow.case_figures`): ``--plot OUT.png`` and
``final_deposits.png`` in the run's folder.

One row of plan-view maps per model (x down the slope across the page, y across the
slope up the page, equal aspect): each layer's depth [m] with a few contour lines and
the deposit outline (total depth = ``output.front_threshold``, the summary's
``deposit_area`` threshold), and each layer's speed |u| [m/s] (blank where the layer is
dry). A last row holds two cross-sections of the total depth [m], every model on the
same axes with the released state dashed: along x through the release's centre
(y = y0) and along y through the deepest cell of the final states.

A 2D state has three rows per layer (depth, discharge along x, discharge along y),
each of shape (nx, ny) (:mod:`pdeflow.metrics_2d`). The figures are plain matplotlib
figures on an Agg canvas (:func:`pdeflow.plotting.new_figure`); their arguments are
arrays and strings, so that a job can be sent to the figure worker.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from . import metrics_2d as m2
from . import systems
from .numerics.geometry import centre_values
from .plotting import DRY, LAYER_STYLES, _symbol, _velocity, display_name, new_figure
from .terrain_figures import terrain_underlay

Run2D = tuple[str, np.ndarray]
"""a run drawn: (its model's registered name, its final state data (rows, nx, ny))"""

MAP_SIZE = 3.4
"""the width of one plan-view map's column, with its labels and colour bar [inch]"""
MAP_WIDTH = 2.05
"""the width of a map's axes [inch]"""
MARGIN = 0.65
"""left of each map and cross-section: its y tick labels and label [inch]"""
TITLE, LABEL, TOP = 0.5, 0.5, 0.55
"""above each map (its two-line title), below it (x ticks and label) and above the
figure (its two-line title) [inch]"""
SECTION = 2.2
"""the height of the cross-sections' axes [inch]"""
CONTOURS = (0.25, 0.5, 0.75)
"""the depth maps' contour lines, as fractions of the map's deepest cell"""
EDGE = 1e-3
"""the maps show the box of cells deeper than this fraction of the deepest state drawn
(final or released), widened by 10 % on each side (as the 1D figures' x range,
:data:`pdeflow.case_figures.DEPOSIT_EDGE`)"""


def cell_edges(c: np.ndarray) -> np.ndarray:
    """The faces [m] of uniform cells with centres ``c`` [m] (n + 1 values)."""
    d = float(c[1] - c[0]) if c.size > 1 else 1.0
    return np.concatenate([c - d / 2, [c[-1] + d / 2]])


def plan_box(x: np.ndarray, y: np.ndarray, depths: Sequence[np.ndarray]
             ) -> tuple[tuple[float, float], tuple[float, float]]:
    """The (x, y) ranges [m] the maps show: the box of the cells deeper than
    :data:`EDGE` of the deepest of ``depths`` (total depths [m], (nx, ny)), 10 % wider
    on each side, within the domain; the domain if nothing is that deep."""
    xe, ye = cell_edges(x), cell_edges(y)
    deepest = max((float(np.max(h)) for h in depths), default=0.0)
    if not deepest > 0:
        return (xe[0], xe[-1]), (ye[0], ye[-1])
    wet = np.max(depths, axis=0) > EDGE * deepest
    ranges = []
    for edges, axis in ((xe, 1), (ye, 0)):
        idx = np.nonzero(np.any(wet, axis=axis))[0]
        lo, hi = edges[idx[0]], edges[idx[-1] + 1]
        pad = 0.1 * (hi - lo)
        ranges.append((max(edges[0], lo - pad), min(edges[-1], hi + pad)))
    return ranges[0], ranges[1]


def layer_speed(data: np.ndarray, k: int) -> np.ndarray:
    """|u_k| = |(h u, h v)| / h [m/s] of layer ``k`` of a 2D state, NaN (blank on a
    map) where it is dry."""
    h, hu, hv = data[3 * k], data[3 * k + 1], data[3 * k + 2]
    return _velocity(h, np.hypot(hu, hv))


def depth_map(ax: Any, cax: Any, fig: Any, x: np.ndarray, y: np.ndarray, h: np.ndarray,
              total: np.ndarray, threshold: float, alpha: float = 1.0,
              floor: float = DRY) -> Any:
    """A layer's depth ``h`` [m] (nx, ny) on ``ax``: colours (blank where not deeper
    than ``floor`` [m], by default dry; their scale in ``cax``; opacity ``alpha``), the
    :data:`CONTOURS` (white) and the deposit
    outline, the contour of the total depth ``total`` [m] at ``threshold`` [m] (black,
    labelled 'deposit'). Returns the outline's ContourSet (None if no cell is deeper
    than the threshold, or the grid is one cell wide)."""
    shown = np.where(h > floor, h, np.nan)
    top = float(np.max(h)) if np.max(h) > 0 else 1.0
    mesh = ax.pcolormesh(cell_edges(x), cell_edges(y), shown.T, cmap="viridis",
                         vmin=0.0, vmax=top, shading="flat", alpha=alpha)
    fig.colorbar(mesh, cax=cax)
    if np.max(h) > DRY and x.size > 1 and y.size > 1:  # contours need a 2 x 2 grid
        ax.contour(x, y, h.T, levels=[f * top for f in CONTOURS], colors="w",
                   linewidths=0.7)
    if not np.max(h) > DRY:  # a layer that is gone (the upper one after its exchange)
        ax.text(0.5, 0.5, "dry", transform=ax.transAxes, ha="center", va="center",
                color="0.4")
    return deposit_outline(ax, x, y, total, threshold)


def deposit_outline(ax: Any, x: np.ndarray, y: np.ndarray, total: np.ndarray,
                    threshold: float) -> Any:
    """The deposit outline on ``ax``: the contour of the total depth ``total`` [m]
    (nx, ny) at ``threshold`` [m] (black, labelled 'deposit'; the cells a 2D summary's
    ``deposit_area`` counts). Returns its ContourSet, None if no cell is deeper than
    the threshold or the grid is one cell wide (a contour needs a 2 x 2 grid)."""
    if not (np.any(total > threshold) and x.size > 1 and y.size > 1):
        return None
    outline = ax.contour(x, y, total.T, levels=[threshold], colors="k", linewidths=1.2)
    outline.set_label("deposit")
    return outline


def speed_map(ax: Any, cax: Any, fig: Any, x: np.ndarray, y: np.ndarray,
              speed: np.ndarray, alpha: float = 1.0) -> None:
    """A layer's speed ``speed`` [m/s] (nx, ny; NaN where dry) on ``ax``, its colour
    scale in ``cax`` (opacity ``alpha``); a layer at rest shows 0 wherever it is wet
    (the scale then runs to 1 m/s, and the map says 'at rest')."""
    wet = bool(np.any(np.isfinite(speed)))
    top = float(np.nanmax(speed)) if wet else 0.0
    mesh = ax.pcolormesh(cell_edges(x), cell_edges(y), speed.T, cmap="magma",
                         vmin=0.0, vmax=top if top > 0 else 1.0, shading="flat",
                         alpha=alpha)
    fig.colorbar(mesh, cax=cax)
    if top == 0:  # an all-black or empty map: say why
        ax.text(0.5, 0.5, "at rest" if wet else "dry", transform=ax.transAxes,
                ha="center", va="center", color="0.6")


def model_row(fig: Any, axes: Sequence[Any], x: np.ndarray, y: np.ndarray,
              run: Run2D, t: float, threshold: float,
              box: tuple[tuple[float, float], tuple[float, float]],
              bed: np.ndarray | None = None) -> list[Any]:
    """The maps of one run (model name, state data) at time ``t`` [s] on ``axes``
    ((map, colour bar) pairs, two per layer: depth, speed); the deposit outlines drawn
    (see :func:`depth_map`); over a ``bed`` (nx, ny) [m, at the cell centres] each map
    on its hillshade and contour lines, the fields slightly transparent."""
    model, data = run
    system = systems.get(model)
    total = m2.total_depth(data)
    outlines = []
    # over a bed the terrain shows where the flow is thinner than the deposit outline
    alpha, floor = (1.0, DRY) if bed is None else (0.85, threshold)
    for k, layer in enumerate(system.layers):
        (ax_h, cax_h), (ax_u, cax_u) = axes[2 * k], axes[2 * k + 1]
        if bed is not None:
            xe, ye = cell_edges(x), cell_edges(y)
            for ax in (ax_h, ax_u):
                terrain_underlay(ax, bed, (xe[0], xe[-1], ye[0], ye[-1]))
        outlines.append(depth_map(ax_h, cax_h, fig, x, y, data[3 * k], total,
                                  threshold, alpha, floor))
        speed = np.where(data[3 * k] > floor, layer_speed(data, k), np.nan)
        speed_map(ax_u, cax_u, fig, x, y, speed, alpha)
        head = f"{system.label}, t = {t:.3g} s"
        ax_h.set_title(f"{head}\n{_layer_name(layer)} depth {_symbol(layer.depth)} [m]",
                       fontsize=9)
        ax_u.set_title(f"{head}\n{_layer_name(layer)} speed "
                       f"$|{_symbol(layer.velocity)[1:-1]}|$ [m/s]", fontsize=9)
        for ax in (ax_h, ax_u):
            ax.set_aspect("equal")
            ax.set_xlim(*box[0])
            ax.set_ylim(*box[1])
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
    return outlines


def _layer_name(layer: Any) -> str:
    """'upper layer' -> 'upper', 'single layer' -> 'single layer' (a one-layer model
    has no other)."""
    return layer.label if layer.style == "single" else layer.label.replace(" layer", "")


def cross_sections(ax_x: Any, ax_y: Any, x: np.ndarray, y: np.ndarray,
                   runs: Sequence[Run2D], initial: np.ndarray, y0: float,
                   box: tuple[tuple[float, float], tuple[float, float]]) -> None:
    """The total depth [m] of each run along x at the row of cells nearest ``y0`` [m]
    (the lower of two as near; ``ax_x``) and along y at the column through the deepest
    cell of the runs (``ax_y``); the released total depth ``initial`` [m] (nx, ny)
    dashed; x and y limited to the maps' ``box`` [m] (:func:`plan_box`)."""
    totals = [m2.total_depth(d) for _, d in runs]
    j = int(np.argmin(np.abs(y - y0)))
    i = int(np.unravel_index(np.argmax(np.max(totals, axis=0)), totals[0].shape)[0])
    dots = {"marker": "o", "ms": 3} if y.size == 1 else {}  # one cell across
    for (model, _), total in zip(runs, totals, strict=True):
        system = systems.get(model)
        colour = LAYER_STYLES[system.layers[-1].style][2]  # the lowest layer's line
        ax_x.plot(x, total[:, j], color=colour, lw=1.2, label=system.label)
        ax_y.plot(y, total[i, :], color=colour, lw=1.2, label=system.label, **dots)
    ax_x.plot(x, initial[:, j], color="0.35", ls="--", lw=1, label="initial state")
    ax_y.plot(y, initial[i, :], color="0.35", ls="--", lw=1, label="initial state",
              **dots)
    ax_x.set_title(f"along x at y = {y[j]:.3g} m (release centre)", fontsize=9)
    ax_y.set_title(f"along y at x = {x[i]:.3g} m (deepest cell)", fontsize=9)
    ax_x.set_xlabel("x [m]")
    ax_y.set_xlabel("y [m]")
    ax_x.set_xlim(*box[0])
    ax_y.set_xlim(*box[1])
    for ax in (ax_x, ax_y):
        ax.set_ylabel("total depth [m]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)


def final_figure_2d(x: np.ndarray, y: np.ndarray, runs: Sequence[Run2D],
                    times: Sequence[float], threshold: float, initial: np.ndarray,
                    y0: float, title: str = "", stops: str = "",
                    state: str = "final state", also: Sequence[np.ndarray] = (),
                    bed: np.ndarray | None = None) -> Any:
    """The final state of a 2D case's runs (model name, state data) at ``times`` [s]:
    per run a row of maps (:func:`model_row`), then the cross-sections
    (:func:`cross_sections`); ``x``, ``y`` the cell centres [m], ``threshold`` the
    deposit outline's depth [m], ``initial`` the released total depth [m], ``y0`` the
    release centre's y [m]; the title: the case's ``title``, ``state`` (what is drawn)
    and ``stops``; the maps cover the material of the runs, the release and ``also``
    (other total depths [m]: a case's snapshots share one extent); over a ``bed`` (nx,
    ny) [m at the cell centres] on its hillshade and contour lines."""
    maps = [2 * len(systems.get(model).layers) for model, _ in runs]
    ncols = max(maps)
    box = plan_box(x, y, [*(m2.total_depth(d) for _, d in runs), initial, *also])
    ratio = (box[1][1] - box[1][0]) / (box[0][1] - box[0][0])
    # a map's height for its width at equal aspect, within bounds (a long, narrow
    # domain keeps a readable height; equal aspect then shrinks the map inside it)
    height = float(np.clip(MAP_WIDTH * ratio, 0.8, 4.0))
    rows = [TITLE + height + LABEL] * len(runs) + [0.35 + SECTION + LABEL]
    size = (MAP_SIZE * ncols, TOP + sum(rows))
    fig = new_figure(size)
    top = size[1] - TOP
    for run, t, n, row in zip(runs, times, maps, rows[:-1], strict=True):
        bottom = top - row + LABEL
        axes = [_map_axes(fig, size, c * MAP_SIZE, bottom, height) for c in range(n)]
        model_row(fig, axes, x, y, run, t, threshold, box, bed)
        top -= row
    half = ncols * MAP_SIZE / 2
    ax_x, ax_y = (fig.add_axes([(left + MARGIN) / size[0], LABEL / size[1],
                                (half - MARGIN - 0.3) / size[0], SECTION / size[1]])
                  for left in (0.0, half))
    cross_sections(ax_x, ax_y, x, y, runs, initial, y0, box)
    fig.suptitle(f"{title}: {state}\n{stops}".strip(), fontsize=10,
                 y=1 - 0.08 / size[1], va="top")
    return fig


def _map_axes(fig: Any, size: tuple[float, float], left: float, bottom: float,
              height: float) -> tuple[Any, Any]:
    """A map's axes and its colour bar's, placed in inches (``left``, ``bottom`` of the
    map's column and axes, ``height`` of the axes) in a figure of ``size`` [inch]:
    fixed places, no layout engine (constrained layout took half the drawing time)."""
    w, h = size
    ax = fig.add_axes([(left + MARGIN) / w, bottom / h, MAP_WIDTH / w, height / h])
    cax = fig.add_axes([(left + MARGIN + MAP_WIDTH + 0.1) / w, bottom / h, 0.12 / w,
                        height / h], label="<colorbar>")
    return ax, cax


def _initial_total(res: Any) -> np.ndarray:
    """The released total depth [m] (nx, ny) of a 2D run's case."""
    profiles = res.case.initial_profiles(res.model, res.state.grid)
    return sum(profiles[layer.depth] for layer in res.pde.system.layers)


def final_figure_job(results: dict[str, Any], path: str | Path, stops: str) -> tuple:
    """The job (make, args, path) of :func:`final_figure_2d` for the 2D runs of one
    case (``results``: model -> :class:`~pdeflow.simulate.RunResult`), saved at
    ``path``; ``stops`` the title's second line (when each run came to rest)."""
    runs = list(results.values())
    first = runs[0]
    case = first.case
    x, y = first.state.grid.axes_coords
    y0 = case.release_centre[1]
    args = (x, y, [(r.model, r.state.data) for r in runs], [r.t_final for r in runs],
            case.front_threshold, _initial_total(first), y0, display_name(case.name),
            stops, "final state", (), _bed(first))
    return (final_figure_2d, args, Path(path))


def _bed(res: Any) -> np.ndarray | None:
    """The bed [m] at the cell centres (nx, ny) of a 2D run over one, else None."""
    return None if res.metric.bed is None else centre_values(res.metric.bed)


def snapshot_figure_jobs(results: dict[str, Any], outdir: Path) -> list[tuple]:
    """The jobs of :func:`final_figure_2d` for each snapshot time of a 2D case's runs
    (``output.snapshot_times``), the runs that have a snapshot then, saved as
    ``snapshot_t<t>.png`` in ``outdir``."""
    runs = list(results.values())
    first = runs[0]
    case = first.case
    x, y = first.state.grid.axes_coords
    initial = _initial_total(first)
    times = sorted(set().union(*(r.snapshots for r in runs)))
    # every snapshot on the extent the material reached at any of them or at the end
    reached = [m2.total_depth(s[0]) for r in runs for s in r.snapshots.values()]
    reached += [m2.total_depth(r.state.data) for r in runs]
    jobs = []
    for t in times:
        shown = [(r.model, r.snapshots[t][0]) for r in runs if t in r.snapshots]
        args = (x, y, shown, [t] * len(shown), case.front_threshold, initial,
                case.release_centre[1], display_name(case.name), "", f"t = {t:g} s",
                reached, _bed(first))
        jobs.append((final_figure_2d, args, outdir / f"snapshot_t{t:g}.png"))
    return jobs
