"""Figures of runs: stacked layers, velocities and F_extra (as the paper's Figs. 3-7).

Static figures of finished runs (:func:`snapshot_figure`, :func:`deposit_figure`,
:func:`case_figures`) and :class:`RunFigure`, a figure of one or more runs that is
redrawn in place: the live plots of :mod:`pdeflow.trackers.live`, movies, and the
figures of stored runs (``pdeflow plot``). Depths in m, velocities in m/s, F_extra/rho1
in m^2/s^2, times in s.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from .io import atomic_path

DRY = 1e-9


def _velocity(h: np.ndarray, m: np.ndarray) -> np.ndarray:
    return np.where(h > DRY, m / np.where(h > DRY, h, 1.0), np.nan)


def plot_depths(ax, x: np.ndarray, two: np.ndarray | None,
                single: np.ndarray | None) -> None:
    """Lower layer filled from the bed, upper layer stacked on it, single layer as a line."""
    if two is not None:
        h1, h2 = two[0], two[2]
        ax.fill_between(x, 0, h2, color="tab:brown", alpha=0.6, lw=0,
                        label="lower layer $h_2$")
        ax.fill_between(x, h2, h1 + h2, color="tab:orange", alpha=0.5, lw=0,
                        label="upper layer $h_1$")
        ax.plot(x, h1 + h2, color="tab:orange", lw=1)
    if single is not None:
        ax.plot(x, single[0], color="k", lw=1.2, label="single layer")
    ax.set_ylabel("depth [m]")


def plot_velocities(ax, x: np.ndarray, two: np.ndarray | None,
                    single: np.ndarray | None) -> None:
    """Velocities where a layer is present (gaps where it is dry)."""
    if two is not None:
        ax.plot(x, _velocity(two[0], two[1]), color="tab:orange", label="$u_1$ (upper)")
        ax.plot(x, _velocity(two[2], two[3]), color="tab:brown", label="$u_2$ (lower)")
    if single is not None:
        ax.plot(x, _velocity(single[0], single[1]), color="k", lw=1.2,
                label="single layer")
    ax.set_ylabel("velocity [m/s]")


def snapshot_figure(x: np.ndarray, t: float, two: np.ndarray | None,
                    single: np.ndarray | None, fextra: np.ndarray | None,
                    title: str = "") -> Any:
    """Three stacked panels at time t, like the paper's Figs. 3-6."""
    fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    plot_depths(axes[0], x, two, single)
    plot_velocities(axes[1], x, two, single)
    axes[2].plot(x, fextra if fextra is not None else np.zeros_like(x), color="tab:red")
    axes[2].set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].legend(loc="upper right", fontsize=8)
    axes[2].set_xlabel("x [m]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"{title} t = {t:g} s".strip())
    fig.tight_layout()
    return fig


def deposit_figure(x: np.ndarray, two: np.ndarray | None, single: np.ndarray | None,
                   title: str = "", times: str = "") -> Any:
    """Final deposits of both models (paper's Fig. 7)."""
    fig, ax = plt.subplots(figsize=(7, 3.2))
    plot_depths(ax, x, two, single)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("x [m]")
    ax.grid(alpha=0.3)
    ax.set_title(f"{title}: final deposits\n{times}".strip(), fontsize=10)
    fig.tight_layout()
    return fig


def save(fig: Any, path: str | Path) -> Path:
    """Save a figure atomically (complete file or none) and close it."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path


def case_figures(results: dict[str, Any], outdir: str | Path,
                 prefix: str = "") -> list[Path]:
    """Snapshot figures at every stored time and the final-deposit figure."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    two = results.get("two_layer")
    one = results.get("single_layer")
    any_res = two or one
    x = any_res.x
    times = sorted(set(two.snapshots if two else {}) | set(one.snapshots if one else {}))
    paths = []
    for t in times:
        s2 = two.snapshots.get(t) if two else None
        s1 = one.snapshots.get(t) if one else None
        fig = snapshot_figure(x, t, s2[0] if s2 else None, s1[0] if s1 else None,
                              s2[1] if s2 else None, any_res.case.name)
        paths.append(save(fig, outdir / f"{prefix}snapshot_t{t:g}.png"))
    stop = []
    for res in (two, one):
        if res is not None:
            st = res.summary.get("stop_time")
            stop.append(f"{res.model}: t={st:.2f} s" if st else f"{res.model}: moving")
    fig = deposit_figure(x, two.state.data if two else None,
                         one.state.data if one else None, any_res.case.name,
                         "(" + ", ".join(stop) + ")")
    paths.append(save(fig, outdir / f"{prefix}final_deposits.png"))
    return paths


# --- figures that can be redrawn in place: live plots, movies, stored runs ------------------

#: colours of the runs drawn as lines (the first run is drawn filled)
LINE_COLOURS = ("tab:blue", "tab:green", "tab:purple", "tab:olive", "tab:cyan", "tab:gray")


@dataclass
class Series:
    """One run drawn in a :class:`RunFigure`: its cell centres, model and legend label."""

    x: np.ndarray
    """cell centres [m]"""
    model: str
    """'two_layer' (state h1, h1u1, h2, h2u2) or 'single_layer' (state h, hu)"""
    label: str = ""
    """legend label (default: the model name)"""


class RunFigure:
    """Three stacked panels of one or more runs at one time, redrawn in place.

    Panel 1: the bed (grey, at depth 0; depths are measured normal to the bed), the
    lower layer filled from the bed, the upper layer filled on top of it, the interface
    and the free surface. Panel 2: the velocities of the layers [m/s] (gaps where a
    layer is dry). Panel 3: F_extra/rho1 [m^2/s^2], the momentum exchange added to keep
    the two-layer system hyperbolic. The simulation time is in the title.

    The first run is drawn filled; further runs (comparisons) as lines: free surface
    solid, interface dashed. Axis limits only ever grow, so that a sequence of frames
    (a live plot, a movie) does not jitter.

    Args:
        series: the runs to draw (their grids may differ).
        title: text before "t = ... s" in the title.
        depth_max: upper depth limit [m]; default 1.1 x the largest depth of the first
            frame drawn.
        pyplot: create the figure through pyplot (needed for a desktop window); else a
            plain :class:`matplotlib.figure.Figure` that no GUI or notebook shows by itself.
        figsize: figure size [inch].
    """

    def __init__(self, series: Sequence[Series], *, title: str = "",
                 depth_max: float | None = None, pyplot: bool = False,
                 figsize: tuple[float, float] = (7.0, 7.5)):
        from matplotlib.figure import Figure

        if not series:
            raise ValueError("RunFigure needs at least one series")
        self.series = list(series)
        self.title = title
        self.fig = (plt.figure(figsize=figsize, layout="constrained") if pyplot
                    else Figure(figsize=figsize, layout="constrained"))
        self.ax_h, self.ax_u, self.ax_f = self.fig.subplots(3, 1, sharex=True)
        self._fills: list[Any] = []
        self._depth_max = depth_max
        self._u_lim = [0.0, 0.0]
        self._f_max = 0.0
        self._lines: list[dict[str, Any]] = []
        xs = [s.x for s in self.series]
        dxs = [float(x[1] - x[0]) if x.size > 1 else 1.0 for x in xs]
        lo = min(float(x[0]) - d / 2 for x, d in zip(xs, dxs, strict=True))
        hi = max(float(x[-1]) + d / 2 for x, d in zip(xs, dxs, strict=True))
        self.ax_h.set_xlim(lo, hi)
        self.ax_h.axhline(0.0, color="0.3", lw=1.0)
        self._bed = None
        n_lines = 0
        for i, s in enumerate(self.series):
            label = s.label or s.model.replace("_", " ")
            two = s.model == "two_layer"
            filled = i == 0
            col = None if filled else LINE_COLOURS[n_lines % len(LINE_COLOURS)]
            n_lines += 0 if filled else 1
            c_up = "tab:orange" if filled and two else col or "k"
            c_lo = "tab:brown" if filled and two else col or "k"
            ln: dict[str, Any] = {}
            nan = np.full(s.x.size, np.nan)
            if two:
                ln["surface"], = self.ax_h.plot(s.x, nan, color="k" if filled else col,
                                                lw=1.0, label=f"{label}: free surface")
                ln["interface"], = self.ax_h.plot(s.x, nan, color=c_lo, lw=1.0,
                                                  ls="-" if filled else "--",
                                                  label=f"{label}: interface")
                ln["u1"], = self.ax_u.plot(s.x, nan, color=c_up, lw=1.2,
                                           label=f"{label}: $u_1$ (upper)")
                ln["u2"], = self.ax_u.plot(s.x, nan, color=c_lo, lw=1.2, ls="--",
                                           label=f"{label}: $u_2$ (lower)")
                ln["fextra"], = self.ax_f.plot(s.x, nan, color="tab:red" if filled
                                               else col, lw=1.2, label=label)
            else:
                ln["surface"], = self.ax_h.plot(s.x, nan, color="k" if filled else col,
                                                lw=1.2, label=f"{label}: surface")
                ln["u"], = self.ax_u.plot(s.x, nan, color="k" if filled else col,
                                          lw=1.2, label=f"{label}: $u$")
            self._lines.append(ln)
        self.ax_h.set_ylabel("depth normal to bed [m]")
        self.ax_u.set_ylabel("velocity [m/s]")
        self.ax_f.set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
        self.ax_f.set_xlabel("x [m]")
        if not any(s.model == "two_layer" for s in self.series):
            self.ax_f.text(0.5, 0.5, "single layer: no F_extra", ha="center",
                           va="center", transform=self.ax_f.transAxes, color="0.4")
        for ax in (self.ax_h, self.ax_u, self.ax_f):
            ax.grid(alpha=0.3)
        self.ax_u.axhline(0.0, color="0.5", lw=0.6)
        self._title = self.fig.suptitle(title)
        self.t: float | None = None

    def _legend(self) -> None:
        from matplotlib.patches import Patch

        first = self.series[0]
        label = first.label or first.model.replace("_", " ")
        if first.model == "two_layer":
            patches = [Patch(color="tab:orange", alpha=0.5, label=f"{label}: upper layer $h_1$"),
                       Patch(color="tab:brown", alpha=0.6, label=f"{label}: lower layer $h_2$")]
        else:
            patches = [Patch(color="tan", alpha=0.7, label=f"{label}: layer $h$")]
        handles = patches + list(self.ax_h.get_lines()[1:])  # [0] is the bed line
        self.ax_h.legend(handles=handles, loc="upper right", fontsize=7)
        self.ax_u.legend(loc="upper right", fontsize=7)
        if len(self.series) > 1 and any(s.model == "two_layer" for s in self.series):
            self.ax_f.legend(loc="upper right", fontsize=7)

    def update(self, t: float, states: Sequence[np.ndarray | None],
               fextras: Sequence[np.ndarray | None] | None = None) -> None:
        """Draw the runs at time t [s].

        Args:
            t: simulation time [s] shown in the title.
            states: per series, the state data (rows h1, h1u1, h2, h2u2 or h, hu) or
                None to leave that series blank.
            fextras: per series, F_extra/rho1 per cell [m^2/s^2] (None: zeros).
        """
        if len(states) != len(self.series):
            raise ValueError(f"expected {len(self.series)} states, got {len(states)}")
        fextras = list(fextras) if fextras is not None else [None] * len(states)
        for poly in self._fills:
            poly.remove()
        self._fills = []
        first = self._bed is None
        if self._depth_max is None:
            tops = [float(np.max(d[::2].sum(axis=0))) for d in states if d is not None]
            self._depth_max = 1.1 * max(tops + [1e-3])
        dm = self._depth_max
        if first:
            self._legend()
            self._bed = self.ax_h.axhspan(-0.05 * dm, 0.0, color="0.8", lw=0)
            self.ax_h.set_ylim(-0.05 * dm, dm)
        for i, (s, d, fx, ln) in enumerate(zip(self.series, states, fextras, self._lines,
                                               strict=True)):
            if d is None:
                continue
            if s.model == "two_layer":
                h1, h2 = d[0], d[2]
                top = h1 + h2
                ln["surface"].set_ydata(np.where(top > DRY, top, np.nan))
                ln["interface"].set_ydata(np.where(h2 > DRY, h2, np.nan))
                u1, u2 = _velocity(h1, d[1]), _velocity(h2, d[3])
                ln["u1"].set_ydata(u1)
                ln["u2"].set_ydata(u2)
                us = [u1, u2]
                f = np.zeros_like(h1) if fx is None else np.asarray(fx)
                ln["fextra"].set_ydata(f)
                self._f_max = max(self._f_max, float(np.max(f)) if f.size else 0.0)
                if i == 0:
                    self._fills.append(self.ax_h.fill_between(
                        s.x, 0, h2, color="tab:brown", alpha=0.6, lw=0))
                    self._fills.append(self.ax_h.fill_between(
                        s.x, h2, top, color="tab:orange", alpha=0.5, lw=0))
            else:
                h = d[0]
                ln["surface"].set_ydata(np.where(h > DRY, h, np.nan))
                u = _velocity(h, d[1])
                ln["u"].set_ydata(u)
                us = [u]
                if i == 0:
                    self._fills.append(self.ax_h.fill_between(
                        s.x, 0, h, color="tan", alpha=0.7, lw=0))
            for u in us:
                if np.any(np.isfinite(u)):
                    self._u_lim[0] = min(self._u_lim[0], float(np.nanmin(u)))
                    self._u_lim[1] = max(self._u_lim[1], float(np.nanmax(u)))
        span = max(self._u_lim[1] - self._u_lim[0], 0.1)  # at least 0.1 m/s shown
        mid = 0.5 * (self._u_lim[0] + self._u_lim[1])
        lo, hi = min(self._u_lim[0], mid - span / 2), max(self._u_lim[1], mid + span / 2)
        self.ax_u.set_ylim(lo - 0.08 * span, hi + 0.08 * span)
        f_top = max(self._f_max, 0.1)
        self.ax_f.set_ylim(-0.05 * f_top, 1.1 * f_top)
        self.t = float(t)
        self.set_title(f"t = {t:.3f} s")
        if first:
            # lay the panels out once: a layout engine on every frame would cost more
            # than drawing the frame
            engine = self.fig.get_layout_engine()
            if engine is not None:
                engine.execute(self.fig)
                self.fig.set_layout_engine("none")

    def set_title(self, text: str) -> None:
        """Title: the figure's ``title`` followed by ``text`` (normally the time)."""
        self._title.set_text(f"{self.title}  {text}".strip())

    def png(self, dpi: int = 100) -> bytes:
        """The figure as PNG bytes."""
        import io

        buf = io.BytesIO()
        self.fig.savefig(buf, format="png", dpi=dpi)
        return buf.getvalue()

    def _repr_png_(self) -> bytes:
        """Jupyter shows a RunFigure as its PNG (independent of the matplotlib backend)."""
        return self.png()

    def save(self, path: str | Path, dpi: int = 110) -> Path:
        """Write the figure atomically (the figure stays open for further frames)."""
        path = Path(path)
        with atomic_path(path) as tmp:
            self.fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".") or "png")
        return path

    def close(self) -> None:
        """Release the figure (and its window, if it was made through pyplot)."""
        plt.close(self.fig)
