"""A field over a bed drawn on a hillshade with contour lines (issue 37's figures).

:func:`hillshade_figure` draws a field of a 2D run over a bed (a flow depth, or a peak
field from :func:`pdeflow.metrics_2d.peak_fields`) on the bed's hillshade, lit from the
north-west at 45 deg as maps are, with the bed's contour lines; cells where the field
is below ``threshold`` show the terrain only.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .plotting import new_figure, save


def contour_step(relief: float) -> float:
    """A round contour interval [m] giving about 10 to 25 lines over ``relief`` [m]."""
    for step in (1, 2, 5, 10, 20, 25, 50, 100, 200, 250, 500):
        if relief / step <= 25:
            return float(step)
    return 1000.0


def hillshade(bed: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """The hillshade in [0, 1] of ``bed`` (nx, ny) [m] with cells ``dx`` x ``dy`` [m],
    lit from the north-west at 45 deg as maps are: an image (ny, nx), row 0 north."""
    from matplotlib.colors import LightSource

    return LightSource(azdeg=315, altdeg=45).hillshade(np.asarray(bed, float).T[::-1],
                                                       vert_exag=1.0, dx=dx, dy=dy)


def terrain_underlay(ax: Any, bed: np.ndarray, extent: tuple[float, ...]) -> float:
    """Draw on ``ax`` the hillshade of ``bed`` (nx, ny) [m, at the cell centres] and its
    contour lines (every 5th labelled), ``extent`` (x0, x1, y0, y1) [m] of the cells'
    outer faces; returns the contour interval [m]."""
    bed = np.asarray(bed, dtype=float)
    x0, x1, y0, y1 = extent
    dx = (x1 - x0) / bed.shape[0]
    dy = (y1 - y0) / bed.shape[1]
    ax.imshow(hillshade(bed, dx, dy), cmap="gray", extent=extent, vmin=0, vmax=1,
              interpolation="nearest")
    step = contour_step(float(np.ptp(bed)))
    if min(bed.shape) > 1 and step > 0:  # a contour needs a 2 x 2 grid
        xc = x0 + dx * (np.arange(bed.shape[0]) + 0.5)
        yc = y0 + dy * (np.arange(bed.shape[1]) + 0.5)
        levels = np.arange(np.floor(bed.min() / step) * step, bed.max() + step, step)
        lines = ax.contour(xc, yc, bed.T, levels=levels, colors="k", linewidths=0.4,
                           alpha=0.6)
        ax.clabel(lines, lines.levels[::5], fontsize=6, fmt="%g")
    return step


def hillshade_figure(bed: np.ndarray, field: np.ndarray, extent: tuple[float, ...],
                     path: str | Path, label: str, threshold: float = 0.0,
                     title: str = "") -> Path:
    """Draw ``field`` (nx, ny) over the hillshade and contours of ``bed`` (nx, ny) [m]
    at the same cell centres, ``extent`` (x0, x1, y0, y1) [m] of the cells' outer
    faces, the colour bar named ``label``; write it at ``path`` (complete or absent)."""
    x0, x1, y0, y1 = extent
    width = 8.0
    height = min(max(width * (y1 - y0) / (x1 - x0), 3.0), 10.0) + 0.8
    fig = new_figure((width, height))
    ax = fig.add_subplot(1, 1, 1)
    step = terrain_underlay(ax, bed, extent)
    shown = np.ma.masked_less_equal(np.asarray(field, dtype=float).T[::-1], threshold)
    image = ax.imshow(shown, cmap="viridis", extent=extent, alpha=0.85,
                      interpolation="nearest")
    fig.colorbar(image, ax=ax, label=label, shrink=0.8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.set_title(title or f"{label} (contours every {step:g} m)", fontsize=9)
    return save(fig, path)
