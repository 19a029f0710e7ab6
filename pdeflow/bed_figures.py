"""The figure of a run over a bed: side views of the bed's surface and the flowing
layer at several times, and a space-time map of the bed's change, like the side views
of the channel experiments (written by ``pdeflow run`` for the cases that lay a bed).

Depths in m, x in m, times in s.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from . import systems
from .plotting import LAYER_STYLES, display_name, new_figure

SIDE_VIEWS = 6
"""side views drawn, at evenly spaced frames from t = 0 to the end of the flow"""


def view_times(t: np.ndarray, duration: float | None, n: int = SIDE_VIEWS) -> list[int]:
    """Indices of ``n`` frames (times ``t`` [s]) spread from 0 to ``duration`` [s] (the
    flow's, or the run's end without one)."""
    end = t[-1] if duration is None else min(max(duration, t[1] if t.size > 1 else 0.0),
                                             t[-1])
    want = np.linspace(0.0, end, n)
    return sorted({int(np.argmin(np.abs(t - w))) for w in want})


def _side_views(ax: Any, x: np.ndarray, t: np.ndarray, frames: Sequence[np.ndarray],
                model: str, bed0: np.ndarray | None, picks: list[int]) -> None:
    """The layers of the frames ``picks`` stacked upwards with an offset each, the
    original bed surface dashed; each view's base is a y tick labelled with its time
    (the offsets are no depths), and a bar at the right gives the depth scale."""
    system = systems.get(model)
    top = max(float(np.max(np.sum(np.maximum(frames[i][::2], 0), axis=0))) for i in picks)
    offset = 1.15 * top
    for row, i in enumerate(picks):
        base = row * offset
        d = frames[i]
        level = np.full_like(x, base)
        for k in reversed(range(len(system.layers))):
            layer = system.layers[k]
            fill, alpha, line = LAYER_STYLES[layer.style]
            upper = level + np.maximum(d[2 * k], 0.0)
            ax.fill_between(x, level, upper, color=fill or "tan", alpha=alpha, lw=0,
                            label=layer.label if row == 0 else None)
            level = upper
        ax.plot(x, level, color="k", lw=0.6)
        if bed0 is not None:
            ax.plot(x, base + bed0, color="k", ls="--", lw=0.7,
                    label="original bed surface" if row == 0 else None)
    ax.set_yticks([row * offset for row in range(len(picks))],
                  [f"t = {t[i]:.2f} s" for i in picks], fontsize=8)
    ax.set_ylabel("side views (depths to the scale bar)")
    scale = _scale_bar(top)
    x_bar = x[-1] - 0.01 * (x[-1] - x[0])
    ax.plot([x_bar, x_bar], [0.0, scale], color="k", lw=2)
    ax.text(x_bar, 0.5 * scale, f"{scale:g} m ", ha="right", va="center", fontsize=8)
    # above the panel, under the title: never over a profile
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=3, fontsize=7,
              frameon=False)


def _scale_bar(top: float) -> float:
    """The depth [m] of the scale bar: the largest 1, 2 or 5 times a power of ten that is
    at most ``top`` [m] (the deepest view), so that the bar fits in one view."""
    if not top > 0:
        return 1.0
    power = 10.0 ** np.floor(np.log10(top))
    return float(max(m * power for m in (1, 2, 5) if m * power <= top))


def _space_time(ax: Any, fig: Any, x: np.ndarray, t: np.ndarray,
                frames: Sequence[np.ndarray], model: str, bed0: np.ndarray | None,
                series: Any, region: np.ndarray | None) -> None:
    """Bed change h2 - bed0 in the bed ``region`` (an erodible bed; blank outside it, where
    the column's own lower layer is no bed) or total depth (a rigid one) over x and t,
    with the flow front and the erosion front."""
    layer = systems.get(model).bed_layer
    if bed0 is not None and layer is not None:
        inside = np.ones_like(x, dtype=bool) if region is None else region
        z = np.array([np.where(inside, d[2 * layer] - bed0, np.nan) for d in frames])
        # the colours span the bed's thickness: erosion (at most e0 deep) uses the whole
        # red range, deposits deeper than e0 saturate
        lim = float(np.max(bed0)) or (float(np.nanmax(np.abs(z))) if np.isfinite(z).any()
                                      else 0.0) or 1e-9
        im = ax.pcolormesh(x, t, z, cmap="RdBu", vmin=-lim, vmax=lim, shading="nearest")
        label = "bed change h2 - e0 [m] (red: eroded; clipped at ±e0)"
    else:
        z = np.array([np.sum(np.maximum(d[::2], 0), axis=0) for d in frames])
        im = ax.pcolormesh(x, t, z, cmap="Greys", shading="nearest")
        label = "depth [m] (rigid bed)"
    box = ax.get_position()
    cax = fig.add_axes((box.x1 + 0.01, box.y0, 0.015, box.height))
    fig.colorbar(im, cax=cax, label=label)
    ax.plot(series.front, series.t, color="tab:orange", lw=1.2, label="flow front")
    if series.erosion_front is not None:
        ax.plot(series.erosion_front, series.t, color="k", lw=0.8, ls=":",
                label="erosion front")
    ax.set_ylabel("t [s]")
    ax.set_xlabel("x [m]")
    ax.legend(loc="lower right", fontsize=7)


def bed_figure(x: np.ndarray, t: np.ndarray, frames: Sequence[np.ndarray], model: str,
               bed0: np.ndarray | None, series: Any, title: str = "",
               duration: float | None = None, region: np.ndarray | None = None) -> Any:
    """Side views (top) and the space-time map (bottom) of one run's frames (state data
    at the times ``t``), ``series`` its :class:`~pdeflow.erosion.ErosionSeries`,
    over the x range the material reached; the side views span t = 0 .. ``duration``
    [s] (the flow's; default: the whole run)."""
    reach = np.nanmax(series.front) if np.isfinite(series.front).any() else x[-1]
    keep = x <= min(x[-1], reach + 0.15 * (reach - x[0]) + 1e-12)
    fig = new_figure((8, 7.5))
    axes = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1.4, 1]})
    picks = view_times(t, duration)
    sub = [f[:, keep] for f in frames]
    b0 = None if bed0 is None else bed0[keep]
    _side_views(axes[0], x[keep], t, sub, model, b0, picks)
    label = systems.get(model).label
    fig.suptitle(f"{display_name(title)}: {label}" if title else label, fontsize=10)
    for ax in axes:
        ax.grid(alpha=0.3)
    # margins by hand: the colour bar sits beside the lower panel, outside the grid; the
    # legend of the side views between the title and the panel
    fig.subplots_adjust(left=0.12, right=0.86, top=0.92, bottom=0.08, hspace=0.12)
    _space_time(axes[1], fig, x[keep], t, sub, model, b0, series,
                None if region is None else region[keep])
    return fig
