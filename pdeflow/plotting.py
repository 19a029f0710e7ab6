"""Figures of runs: stacked layers, velocities and F_extra (as the paper's Figs. 3-7).

Static figures of finished runs (:func:`snapshot_figure`, :func:`deposit_figure`,
:func:`case_figures`) and :class:`RunFigure`, a figure of one or more runs that is
redrawn in place: the live plots of :mod:`pdeflow.trackers.live`, movies, and the
figures of stored runs (``pdeflow plot``). Depths in m, velocities in m/s, F_extra/rho1
in m^2/s^2, times in s.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from .io import atomic_path
from .numerics.compile_parallel import can_fork, fork_context
from .numerics.state import DRY_TOLERANCE, velocity_profile

DRY = 1e-9
"""Depths [m] up to which no surface line is drawn."""


def _velocity(h: np.ndarray, m: np.ndarray, dry: float = DRY_TOLERANCE) -> np.ndarray:
    """u = hu/h [m/s], NaN (a gap in a line) where the layer is dry."""
    return velocity_profile(h, m, dry, fill=np.nan)


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
    fixed_margins(fig, top=0.45)
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
    fixed_margins(fig, top=0.55)
    return fig


def fixed_margins(fig: Any, top: float, left: float = 0.9, right: float = 0.2,
                  bottom: float = 0.5, gap: float = 0.3) -> None:
    """Margins and gap between stacked panels [inches], wide enough for axis labels
    and 5-character tick labels (``tight_layout`` took half the drawing time)."""
    w, h = fig.get_size_inches()
    rows = len(fig.axes)
    panel = (h - top - bottom - gap * (rows - 1)) / rows
    fig.subplots_adjust(left=left / w, right=1 - right / w, bottom=bottom / h,
                        top=1 - top / h, hspace=gap / panel)


ASPECT_TICKS = (2, 4, 8, 16, 30)
"""Ticks of aspect-ratio axes (a = 2 .. 30 in the paper's test 5.2)."""


def log_ticks(axis: Any, ticks: Sequence[float]) -> None:
    """Label a logarithmic axis at ``ticks`` only, in plain numbers (matplotlib labels
    minor ticks too on short log ranges, and they overlap)."""
    from matplotlib.ticker import FixedLocator, NullFormatter, ScalarFormatter

    axis.set_major_locator(FixedLocator(list(ticks)))
    axis.set_major_formatter(ScalarFormatter())
    axis.set_minor_formatter(NullFormatter())


def save(fig: Any, path: str | Path) -> Path:
    """Save a figure atomically (complete file or none) and close it."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path


def case_figures(results: dict[str, Any], outdir: str | Path, prefix: str = "",
                 parallel: bool = True) -> list[Path]:
    """Snapshot figures at every stored time and the final-deposit figure (drawn by
    :func:`draw_all`, on two cores with ``parallel``)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    two = results.get("two_layer")
    one = results.get("single_layer")
    any_res = two or one
    x = any_res.x
    times = sorted(set(two.snapshots if two else {}) | set(one.snapshots if one else {}))
    jobs = []
    for t in times:
        s2 = two.snapshots.get(t) if two else None
        s1 = one.snapshots.get(t) if one else None
        jobs.append((snapshot_figure, (x, t, s2[0] if s2 else None, s1[0] if s1 else None,
                                       s2[1] if s2 else None, any_res.case.name),
                     outdir / f"{prefix}snapshot_t{t:g}.png"))
    stop = []
    for res in (two, one):
        if res is not None:
            st = res.summary.get("stop_time")
            stop.append(f"{res.model}: t={st:.2f} s" if st else f"{res.model}: moving")
    jobs.append((deposit_figure, (x, two.state.data if two else None,
                                  one.state.data if one else None, any_res.case.name,
                                  "(" + ", ".join(stop) + ")"),
                 outdir / f"{prefix}final_deposits.png"))
    return draw_all(jobs, parallel)


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
    return [mine[i // 2] if i % 2 == 0 else paths[i // 2] for i in range(len(jobs))]


def _draw(job: tuple[Callable, tuple, Path]) -> Path:
    make, args, path = job
    return save(make(*args), path)


# --- figures that can be redrawn in place: live plots, movies, stored runs ------------------

#: colours of the runs drawn as lines (the first run is drawn filled)
LINE_COLOURS = ("tab:blue", "tab:green", "tab:purple", "tab:olive", "tab:cyan", "tab:gray")


def _set(lines: dict[str, Any], key: str, y: np.ndarray) -> None:
    """Set the data of a line if the figure has it (one-panel figures have no u, F)."""
    if key in lines:
        lines[key].set_ydata(y)


@dataclass
class Series:
    """One run drawn in a :class:`RunFigure`: its cell centres, model and legend label."""

    x: np.ndarray
    """cell centres [m]"""
    model: str
    """'two_layer' (state h1, h1u1, h2, h2u2) or 'single_layer' (state h, hu)"""
    label: str = ""
    """legend label (default: the model name)"""
    dry: float = DRY_TOLERANCE
    """the model's dry tolerance [m]: no velocity is drawn where a layer is thinner"""


class RunFigure:
    """Three stacked panels of one or more runs at one time, redrawn in place.

    Panel 1: the bed (grey, at depth 0; depths are measured normal to the bed), the
    lower layer filled from the bed, the upper layer filled on top of it, the interface
    and the free surface. Panel 2: the velocities of the layers [m/s] (gaps where a
    layer is dry). Panel 3: F_extra/rho1 [m^2/s^2], the momentum exchange added to keep
    the two-layer system hyperbolic. The simulation time is in the title. With
    ``panels=1`` only the depths are drawn (deposits at rest: nothing moves, and
    F_extra is zero).

    The first run is drawn filled, in the colours of the run's own figures (lower layer
    brown, upper layer orange, a single layer tan with a black surface); further runs
    (comparisons) as lines: the first single layer among them black, as in the run's
    figures, the others in :data:`LINE_COLOURS`; free surface solid, interface dashed.
    Legend entries name a run only where two runs of the same model need telling apart
    (by their labels). Axis limits only ever grow, so that a sequence of frames (a live
    plot, a movie) does not jitter.

    Args:
        series: the runs to draw (their grids may differ).
        title: text before "t = ... s" in the title.
        depth_max: upper depth limit [m]; default 1.1 x the largest depth of the first
            frame drawn.
        pyplot: create the figure through pyplot (needed for a desktop window); else a
            plain :class:`matplotlib.figure.Figure` that no GUI or notebook shows by itself.
        figsize: figure size [inch] (default (7, 7.5) for three panels, (7, 3.4) for one).
        panels: 3 (depths, velocities, F_extra) or 1 (depths only).
    """

    def __init__(self, series: Sequence[Series], *, title: str = "",
                 depth_max: float | None = None, pyplot: bool = False,
                 figsize: tuple[float, float] | None = None, panels: int = 3):
        from matplotlib.figure import Figure

        if not series:
            raise ValueError("RunFigure needs at least one series")
        if panels not in (1, 3):
            raise ValueError(f"panels must be 1 or 3, got {panels!r}")
        self.series = list(series)
        self.title = title
        figsize = figsize or ((7.0, 7.5) if panels == 3 else (7.0, 3.4))
        self.fig = (plt.figure(figsize=figsize, layout="constrained") if pyplot
                    else Figure(figsize=figsize, layout="constrained"))
        axes = np.atleast_1d(self.fig.subplots(panels, 1, sharex=True))
        self.ax_h = axes[0]
        self.ax_u = axes[1] if panels == 3 else None
        self.ax_f = axes[2] if panels == 3 else None
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
        # a run is named in the legend only where another run has the same model
        self._named = len({s.model for s in self.series}) < len(self.series)
        free = list(LINE_COLOURS)
        self._black_free = True
        for i, s in enumerate(self.series):
            self._lines.append(self._add_lines(s, filled=i == 0, free=free))
        self.ax_h.set_ylabel("depth normal to bed [m]")
        self.ax_h.set_xlabel("x [m]")
        if self.ax_u is not None and self.ax_f is not None:
            self.ax_h.set_xlabel("")
            self.ax_u.set_ylabel("velocity [m/s]")
            self.ax_f.set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
            self.ax_f.set_xlabel("x [m]")
            if not any(s.model == "two_layer" for s in self.series):
                self.ax_f.text(0.5, 0.5, "single layer: no F_extra", ha="center",
                               va="center", transform=self.ax_f.transAxes, color="0.4")
            self.ax_u.axhline(0.0, color="0.5", lw=0.6)
        for ax in axes:
            ax.grid(alpha=0.3)
        self._title = self.fig.suptitle(title)
        self.t: float | None = None

    def name(self, s: Series) -> str:
        """A run's name: its label, else its model ('two layers', 'single layer')."""
        return s.label or ("two layers" if s.model == "two_layer" else "single layer")

    def _prefix(self, s: Series) -> str:
        return f"{self.name(s)}: " if self._named else ""

    def _add_lines(self, s: Series, *, filled: bool, free: list[str]) -> dict[str, Any]:
        """The (empty) lines of one run; ``free``: line colours not taken yet."""
        name, pre = self.name(s), self._prefix(s)
        nan = np.full(s.x.size, np.nan)
        ln: dict[str, Any] = {}
        if s.model == "two_layer":
            if filled:  # the fills carry the legend; the lines are their edges
                c_up, c_lo, hide = "tab:orange", "tab:brown", "_"
                up, lo = f"{pre}$u_1$ (upper)", f"{pre}$u_2$ (lower)"
            else:
                c_up = c_lo = free.pop(0) if free else "0.5"
                hide = ""
                up, lo = f"{name}: $u_1$ (upper)", f"{name}: $u_2$ (lower)"
            ln["surface"], = self.ax_h.plot(s.x, nan, color=c_up, lw=1.0,
                                            label=f"{hide}{name}: free surface")
            ln["interface"], = self.ax_h.plot(s.x, nan, color=c_lo, lw=1.0,
                                              ls="-" if filled else "--",
                                              label=f"{hide}{name}: interface")
            if self.ax_u is not None and self.ax_f is not None:
                ln["u1"], = self.ax_u.plot(s.x, nan, color=c_up, lw=1.2, label=up)
                ln["u2"], = self.ax_u.plot(s.x, nan, color=c_lo, lw=1.2,
                                           ls="-" if filled else "--", label=lo)
                ln["fextra"], = self.ax_f.plot(s.x, nan, color="tab:red" if filled
                                               else c_up, lw=1.2, label=name)
        else:
            # black, as in the run's figures, for the first single layer only
            color = "k" if self._black_free else (free.pop(0) if free else "0.5")
            self._black_free = False
            label = f"_{name}" if filled else name  # a filled layer: its patch
            ln["surface"], = self.ax_h.plot(s.x, nan, color=color, lw=1.2, label=label)
            if self.ax_u is not None:
                ln["u"], = self.ax_u.plot(s.x, nan, color=color, lw=1.2, label=name)
        return ln

    def _legend(self) -> None:
        from matplotlib.patches import Patch

        first = self.series[0]
        pre = self._prefix(first)
        if first.model == "two_layer":
            patches = [Patch(color="tab:brown", alpha=0.6, label=f"{pre}lower layer $h_2$"),
                       Patch(color="tab:orange", alpha=0.5, label=f"{pre}upper layer $h_1$")]
        else:
            patches = [Patch(color="tan", alpha=0.7, label=self.name(first))]
        lines = [ln for ln in self.ax_h.get_lines()[1:]  # [0] is the bed line
                 if not ln.get_label().startswith("_")]
        self.ax_h.legend(handles=patches + lines, loc="upper right", fontsize=7)
        if self.ax_u is not None and self.ax_f is not None:
            self.ax_u.legend(loc="upper right", fontsize=7)
            if sum(s.model == "two_layer" for s in self.series) > 1:
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
                u1, u2 = _velocity(h1, d[1], s.dry), _velocity(h2, d[3], s.dry)
                _set(ln, "u1", u1)
                _set(ln, "u2", u2)
                us = [u1, u2]
                f = np.zeros_like(h1) if fx is None else np.asarray(fx)
                _set(ln, "fextra", f)
                self._f_max = max(self._f_max, float(np.max(f)) if f.size else 0.0)
                if i == 0:
                    self._fills.append(self.ax_h.fill_between(
                        s.x, 0, h2, color="tab:brown", alpha=0.6, lw=0))
                    self._fills.append(self.ax_h.fill_between(
                        s.x, h2, top, color="tab:orange", alpha=0.5, lw=0))
            else:
                h = d[0]
                ln["surface"].set_ydata(np.where(h > DRY, h, np.nan))
                u = _velocity(h, d[1], s.dry)
                _set(ln, "u", u)
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
        if self.ax_u is not None and self.ax_f is not None:
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
