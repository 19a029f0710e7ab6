"""The plan view of runs on a 2D grid, redrawn in place (issue 36): the live plots of
:mod:`pdeflow.trackers.live` on a 2D grid (``pdeflow run CASE2D --live``), their movies
and PNG frames (``--movie``, ``--frames``) and the movies of stored 2D runs (``pdeflow
plot RUN.h5 --movie``), as :class:`pdeflow.plotting.RunFigure` is for 1D runs.

One map per run, side by side (x down the slope across the page, y across it up the
page, equal aspect): its total depth [m] (blank where dry) on one colour scale that the
maps share and keep from frame to frame (it only grows, so that a movie does not
flicker), the deposit outline (black: the total depth at ``output.front_threshold``,
the cells a 2D summary's ``deposit_area`` counts) and the simulation time in the title.
The outline, the cells' edges and the zoom to the material are those of the final-state
figure (:mod:`pdeflow.figures_2d`); F_extra/rho1, which the 1D live plot draws, is not
shown (the stored runs keep it).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from . import metrics_2d as m2
from . import systems
from .figures_2d import MARGIN, cell_edges, deposit_outline, plan_box
from .plotting import DRY, RedrawnFigure, Series, new_figure

Box = tuple[tuple[float, float], tuple[float, float]]
"""(x range, y range) a map shows [m]"""

DEPOSIT_THRESHOLD = 1e-3
"""the deposit outline's total depth [m] where none is given: the default of
``output.front_threshold`` (``pdeflow run`` passes the case's)"""
MAPS_WIDTH = 6.0
"""the width of the maps' axes together [inch] (each at least :data:`MIN_MAP`)"""
MIN_MAP = 2.6
"""the narrowest map [inch]"""
GAP = 0.3
"""between a map and the next one's y labels, and before the colour bar [inch]"""
BAR = 0.15
"""the colour bar's width [inch]; its labels take :data:`BAR_LABELS` more"""
BAR_LABELS = 0.85
TOP, TITLE, LABEL = 0.45, 0.3, 0.5
"""above the figure (its title), above each map (its run's name) and below it (x ticks
and label) [inch]"""


def domain_box(series: Sequence[Series]) -> Box:
    """The (x, y) ranges [m] of the runs' domains together (the faces of their cells)."""
    xs = [cell_edges(s.x) for s in series]
    ys = [cell_edges(np.asarray(s.y)) for s in series]
    return ((min(e[0] for e in xs), max(e[-1] for e in xs)),
            (min(e[0] for e in ys), max(e[-1] for e in ys)))


def frames_box(series: Sequence[Series],
               states: Sequence[Sequence[np.ndarray | None]]) -> Box:
    """The (x, y) ranges [m] that hold the material of every frame: per run the box of
    :func:`pdeflow.figures_2d.plan_box` around its deepest total depth over the frames
    (``states``: per frame, per run the state data or None), the runs' boxes together."""
    boxes = []
    for i, s in enumerate(series):
        totals = [m2.total_depth(frame[i]) for frame in states if frame[i] is not None]
        if totals:
            boxes.append(plan_box(s.x, np.asarray(s.y), [np.max(totals, axis=0)]))
    if not boxes:
        return domain_box(series)
    return ((min(b[0][0] for b in boxes), max(b[0][1] for b in boxes)),
            (min(b[1][0] for b in boxes), max(b[1][1] for b in boxes)))


class PlanFigure(RedrawnFigure):
    """The total depth maps of one or more runs on 2D grids at one time, redrawn in
    place (see the module docstring).

    Args:
        series: the runs to draw (each with its cells across, ``Series.y``).
        title: text before "t = ... s" in the title.
        depth_max: the colour scale's top [m] to begin with; default 1.1 x the largest
            total depth of the first frame drawn (it grows with deeper frames).
        pyplot: create the figure through pyplot (needed for a desktop window); else a
            plain figure on an Agg canvas (:func:`pdeflow.plotting.new_figure`).
        threshold: the deposit outline's total depth [m].
        box: the (x, y) ranges the maps show [m] (default: the whole domain;
            :func:`frames_box` zooms to the material of known frames).
    """

    def __init__(self, series: Sequence[Series], *, title: str = "",
                 depth_max: float | None = None, pyplot: bool = False,
                 threshold: float = DEPOSIT_THRESHOLD, box: Box | None = None):
        from matplotlib.colors import Normalize

        if not series or any(s.y is None for s in series):
            raise ValueError("PlanFigure needs at least one series, each on a 2D grid")
        self.series = list(series)
        self.title = title
        self.threshold = float(threshold)
        self.box = box or domain_box(self.series)
        n = len(self.series)
        width = max(MAPS_WIDTH / n, MIN_MAP)
        ratio = (self.box[1][1] - self.box[1][0]) / (self.box[0][1] - self.box[0][0])
        # at equal aspect, within bounds (a long, narrow domain keeps a readable height;
        # equal aspect then shrinks the map inside it)
        height = float(np.clip(width * ratio, 1.2, 6.0))
        column = MARGIN + width + GAP
        size = (n * column + BAR + BAR_LABELS, TOP + TITLE + height + LABEL)
        if pyplot:
            import matplotlib.pyplot as plt

            self.fig = plt.figure(figsize=size)
        else:
            self.fig = new_figure(size)
        # one scale for every map; a top to begin with (a colour bar on a scale
        # without one widens it below 0), set by the first frame unless given
        self._norm = Normalize(0.0, depth_max or 1.0)
        self._scaled = depth_max is not None
        self.axes, self._meshes = [], []
        self._outlines: list[Any] = [None] * n
        for i, s in enumerate(self.series):
            ax = self.fig.add_axes([(i * column + MARGIN) / size[0], LABEL / size[1],
                                    width / size[0], height / size[1]])
            blank = np.full((np.asarray(s.y).size, s.x.size), np.nan)
            self._meshes.append(ax.pcolormesh(cell_edges(s.x), cell_edges(np.asarray(s.y)),
                                              blank, cmap="viridis", norm=self._norm,
                                              shading="flat"))
            ax.set_aspect("equal")
            ax.set_xlim(*self.box[0])
            ax.set_ylim(*self.box[1])
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
            ax.set_title(s.label or systems.get(s.model).label, fontsize=9)
            self.axes.append(ax)
        cax = self.fig.add_axes([n * column / size[0], LABEL / size[1], BAR / size[0],
                                 height / size[1]], label="<colorbar>")
        self.fig.colorbar(self._meshes[0], cax=cax, label="total depth [m]")
        self._title = self.fig.suptitle(title, fontsize=10, y=1 - 0.08 / size[1],
                                        va="top")
        self.t: float | None = None

    def update(self, t: float, states: Sequence[np.ndarray | None],
               fextras: Sequence[np.ndarray | None] | None = None) -> None:
        """Draw the runs at time ``t`` [s]: ``states`` per series its state data (rows
        h1, h1u1, h1v1, h2, h2u2, h2v2 or h, hu, hv, each (nx, ny)) or None to leave
        its map as it is; ``fextras`` is accepted for :class:`RunFigure`'s callers and
        not drawn."""
        if len(states) != len(self.series):
            raise ValueError(f"expected {len(self.series)} states, got {len(states)}")
        totals = [None if d is None else m2.total_depth(np.asarray(d)) for d in states]
        top = max((float(np.max(h)) for h in totals if h is not None), default=0.0)
        if not self._scaled or top > self._norm.vmax:
            self._norm.vmax = 1.1 * max(top, 1e-3)  # redraws every map and the bar
            self._scaled = True
        for i, (s, total) in enumerate(zip(self.series, totals, strict=True)):
            if total is None:
                continue
            self._meshes[i].set_array(np.where(total > DRY, total, np.nan).T)
            if self._outlines[i] is not None:
                self._outlines[i].remove()
            self._outlines[i] = deposit_outline(self.axes[i], s.x, np.asarray(s.y), total,
                                                self.threshold)
        self.t = float(t)
        self.set_title(f"t = {t:.3f} s")


__all__ = ["DEPOSIT_THRESHOLD", "PlanFigure", "domain_box", "frames_box"]
