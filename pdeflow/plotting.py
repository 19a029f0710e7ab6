"""Figures of runs: stacked layers, velocities and F_extra (as the paper's Figs. 3-7).

How each layer is drawn (:data:`LAYER_STYLES`), shared helpers, and :class:`RunFigure`,
a figure of one or more runs that is redrawn in place: the live plots of
:mod:`pdeflow.trackers.live`, movies, and the figures of stored runs (``pdeflow plot``);
the static figures of a case's runs are in :mod:`pdeflow.case_figures`. Depths in m,
velocities in m/s, F_extra/rho1
in m^2/s^2, times in s.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from . import systems
from .io import atomic_path
from .numerics.state import DRY_TOLERANCE, velocity_profile

DRY = 1e-9
"""Depths [m] up to which no surface line is drawn."""


def _velocity(h: np.ndarray, m: np.ndarray, dry: float = DRY_TOLERANCE) -> np.ndarray:
    """u = hu/h [m/s], NaN (a gap in a line) where the layer is dry."""
    return velocity_profile(h, m, dry, fill=np.nan)


#: how a layer is drawn, by its :attr:`~pdeflow.systems.Layer.style`: fill colour and
#: opacity (fill None: the paper's figures draw the layer as its surface line), and the
#: colour of its lines
LAYER_STYLES: dict[str, tuple[str | None, float, str]] = {
    "upper": ("tab:orange", 0.5, "tab:orange"),
    "lower": ("tab:brown", 0.6, "tab:brown"),
    "single": (None, 0.7, "k"),
}
#: the fill of a line-drawn layer where a :class:`RunFigure` fills its first run
LINE_LAYER_FILL = "tan"


def _symbol(name: str) -> str:
    """'h1' -> '$h_1$' (mathtext), 'h' -> '$h$'."""
    return f"${name[0]}_{name[1:]}$" if len(name) > 1 else f"${name}$"


def _short(layer: Any) -> str:
    return layer.label.replace(" layer", "")


def display_name(name: str) -> str:
    """A case's name as a figure's title shows it, not as its file is named:
    'paper_5_1_dam_break' -> 'paper 5.1 dam break'."""
    return re.sub(r"(?<=\d)_(?=\d)", ".", name).replace("_", " ")


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


def new_figure(figsize: tuple[float, float]) -> Any:
    """A plain :class:`matplotlib.figure.Figure` of ``figsize`` [inch] on an Agg canvas:
    not pyplot's (no figure manager, nothing a GUI shows). Its canvas keeps its
    renderer, and with it the renderer's text and mathtext caches, from one save to
    the next (saving a figure without a canvas of its own makes a new one each time)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig


def save(fig: Any, path: str | Path) -> Path:
    """Save a figure atomically (complete file or none) and close it if pyplot made it
    (a plain :class:`matplotlib.figure.Figure` holds nothing to release: it can be
    redrawn and saved again)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format=path.suffix.lstrip(".") or "png")
    if getattr(fig.canvas, "manager", None) is not None:
        import matplotlib.pyplot as plt  # here, not at the top: the app takes DRY only

        plt.close(fig)
    return path


# --- figures that can be redrawn in place: live plots, movies, stored runs ------------------

#: colours of the runs drawn as lines (the first run is drawn filled)
LINE_COLOURS = ("tab:blue", "tab:green", "tab:purple", "tab:olive", "tab:cyan", "tab:gray")


def _set(lines: dict[str, Any], key: str, y: np.ndarray) -> None:
    """Set the data of a line if the figure has it (one-panel figures have no u, F)."""
    if key in lines:
        lines[key].set_ydata(y)


@dataclass
class Series:
    """One run drawn in a :class:`RunFigure` (on a 2D grid: in a
    :class:`pdeflow.plan_view.PlanFigure`): its cell centres, model and legend label."""

    x: np.ndarray
    """cell centres [m]"""
    model: str
    """the registered name of its model (:mod:`pdeflow.systems`)"""
    label: str = ""
    """legend label (default: the model name)"""
    dry: float = DRY_TOLERANCE
    """the model's dry tolerance [m]: no velocity is drawn where a layer is thinner"""
    coordinate: str = "x"
    """name of the grid's coordinate: 'x' (planar) or 'r' (axisymmetric) [m]"""
    y: np.ndarray | None = None
    """cell centres across the slope [m] of a run on a 2D grid (None: a 1D grid)"""


class RedrawnFigure:
    """What a figure redrawn in place offers its users (a live plot, a movie, frames):
    its ``fig`` (a matplotlib figure) and title ``_title`` (the suptitle: ``title``,
    then the time), set by the figure (:class:`RunFigure`, the 2D runs'
    :class:`pdeflow.plan_view.PlanFigure`), which draws a frame with
    ``update(t, states, fextras)``."""

    fig: Any
    title: str
    _title: Any

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
        """Jupyter shows the figure as its PNG (independent of the matplotlib backend)."""
        return self.png()

    def save(self, path: str | Path, dpi: int = 110) -> Path:
        """Write the figure atomically (the figure stays open for further frames)."""
        path = Path(path)
        with atomic_path(path) as tmp:
            self.fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".") or "png")
        return path

    def close(self) -> None:
        """Release the figure (and its window, if it was made through pyplot)."""
        import matplotlib.pyplot as plt

        plt.close(self.fig)


class RunFigure(RedrawnFigure):
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
        if pyplot:
            import matplotlib.pyplot as plt
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
        xlabel = f"{self.series[0].coordinate} [m]"
        self.ax_h.set_xlabel(xlabel)
        if self.ax_u is not None and self.ax_f is not None:
            self.ax_h.set_xlabel("")
            self.ax_u.set_ylabel("velocity [m/s]")
            self.ax_f.set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
            self.ax_f.set_xlabel(xlabel)
            if not any(systems.get(s.model).has_fextra for s in self.series):
                self.ax_f.text(0.5, 0.5, f"{systems.get(self.series[0].model).label}: "
                               "no F_extra", ha="center", va="center",
                               transform=self.ax_f.transAxes, color="0.4")
            self.ax_u.axhline(0.0, color="0.5", lw=0.6)
        for ax in axes:
            ax.grid(alpha=0.3)
        self._title = self.fig.suptitle(title)
        self.t: float | None = None

    def name(self, s: Series) -> str:
        """A run's name: its label, else its model's ('two layers', 'single layer')."""
        return s.label or systems.get(s.model).label

    def _prefix(self, s: Series) -> str:
        return f"{self.name(s)}: " if self._named else ""

    def _add_lines(self, s: Series, *, filled: bool, free: list[str]) -> dict[str, Any]:
        """The (empty) lines of one run; ``free``: line colours not taken yet. A run
        drawn filled gets its layers' own colours (its fills carry the legend, the lines
        are their edges); a comparison one colour, the first one-layer run black."""
        system = systems.get(s.model)
        name, pre = self.name(s), self._prefix(s)
        nan = np.full(s.x.size, np.nan)
        one = len(system.layers) == 1
        if filled:
            colours = [LAYER_STYLES[layer.style][2] for layer in system.layers]
            if one:
                self._black_free = False
        elif one and self._black_free:
            colours = ["k"]
            self._black_free = False
        else:
            colours = [free.pop(0) if free else "0.5"] * len(system.layers)
        hide = "_" if filled else ""
        ln: dict[str, Any] = {}
        ln["surface"], = self.ax_h.plot(s.x, nan, color=colours[0], lw=1.2 if one else 1.0,
                                        label=f"{hide}{name}" if one else
                                        f"{hide}{name}: free surface")
        for k in range(1, len(system.layers)):
            ln[f"interface{k}"], = self.ax_h.plot(s.x, nan, color=colours[k], lw=1.0,
                                                  ls="-" if filled else "--",
                                                  label=f"{hide}{name}: interface")
        if self.ax_u is None or self.ax_f is None:
            return ln
        for k, layer in enumerate(system.layers):
            label = name if one else (
                f"{pre if filled else name + ': '}{_symbol(layer.velocity)} "
                f"({_short(layer)})")
            ln[f"u{k}"], = self.ax_u.plot(s.x, nan, color=colours[k], lw=1.2,
                                          ls="-" if filled or k == 0 else "--", label=label)
        if system.has_fextra:
            ln["fextra"], = self.ax_f.plot(s.x, nan, color="tab:red" if filled
                                           else colours[0], lw=1.2, label=name)
        return ln

    def _legend(self) -> None:
        from matplotlib.patches import Patch

        first = self.series[0]
        system = systems.get(first.model)
        pre = self._prefix(first)
        if len(system.layers) == 1:
            patches = [Patch(color=LAYER_STYLES[system.layers[0].style][0]
                             or LINE_LAYER_FILL, alpha=LAYER_STYLES[system.layers[0].style][1],
                             label=self.name(first))]
        else:
            patches = [Patch(color=LAYER_STYLES[layer.style][0],
                             alpha=LAYER_STYLES[layer.style][1],
                             label=f"{pre}{layer.label} {_symbol(layer.depth)}")
                       for layer in reversed(system.layers)]
        lines = [ln for ln in self.ax_h.get_lines()[1:]  # [0] is the bed line
                 if not ln.get_label().startswith("_")]
        self.ax_h.legend(handles=patches + lines, loc="upper right", fontsize=7)
        if self.ax_u is not None and self.ax_f is not None:
            self.ax_u.legend(loc="upper right", fontsize=7)
            if sum(systems.get(s.model).has_fextra for s in self.series) > 1:
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
            us = self._draw_run(i, s, d, fx, ln)
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

    def _draw_run(self, i: int, s: Series, d: np.ndarray, fx: np.ndarray | None,
                  ln: dict[str, Any]) -> list[np.ndarray]:
        """Set the lines of run ``i`` (and fill its layers if it is the first); returns
        its velocities."""
        system = systems.get(s.model)
        n = len(system.layers)
        tops = [d[2 * (n - 1)]]  # surfaces of the layers stacked from the bed
        for k in range(n - 2, -1, -1):
            tops.append(tops[-1] + d[2 * k])
        ln["surface"].set_ydata(np.where(tops[-1] > DRY, tops[-1], np.nan))
        for k in range(1, n):
            h = tops[n - 1 - k]
            ln[f"interface{k}"].set_ydata(np.where(h > DRY, h, np.nan))
        us = [_velocity(d[2 * k], d[2 * k + 1], s.dry) for k in range(n)]
        for k, u in enumerate(us):
            _set(ln, f"u{k}", u)
        if system.has_fextra:
            f = np.zeros_like(d[0]) if fx is None else np.asarray(fx)
            _set(ln, "fextra", f)
            self._f_max = max(self._f_max, float(np.max(f)) if f.size else 0.0)
        if i == 0:
            base: Any = 0
            for k in range(n - 1, -1, -1):
                fill, alpha, _ = LAYER_STYLES[system.layers[k].style]
                top = tops[n - 1 - k]
                self._fills.append(self.ax_h.fill_between(
                    s.x, base, top, color=fill or LINE_LAYER_FILL, alpha=alpha, lw=0))
                base = top
        return us

