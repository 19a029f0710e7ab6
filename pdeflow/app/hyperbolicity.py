"""Page 3, hyperbolicity: the four eigenvalues of a local two-layer state, the band of
relative velocities where two of them are complex, and where F_extra acts in the run.

For a state (h1, h2 [m], r = rho1/rho2, du = u1 - u2 [m/s]) the page shows the roots
of the characteristic polynomial (:func:`pdeflow.models.two_layer.hyperbolicity.eigenvalues`)
and the band F_c1 < |du| < F_c2 where the inner pair is complex (the discriminant of
:mod:`pdeflow.models.two_layer.hyperbolicity` is negative), with the closed-form bounds F_L and
F_R. Next to it: the cells and times where the dam-break page's current run needed
F_extra, and the state of any of its cells (to analyse it with one click).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import panel as pn
from bokeh.models import (
    BoxAnnotation,
    ColorBar,
    ColumnDataSource,
    LinearColorMapper,
    Range1d,
    Span,
)
from bokeh.palettes import Reds256
from bokeh.plotting import figure

from ..cases import PAPER_MODEL
from ..models.two_layer import hyperbolicity as hyp
from ..models.two_layer.hyperbolicity import (
    discriminant,
    eigenvalues,
    lower_bound_fl,
    upper_bound_fr,
)
from ..numerics.state import velocity_profile
from ..plotting import DRY
from .controls import Slider
from .dam_break import COLOURS, FRAMES_PER_T_END, DamBreakRun, SharedRun
from .look import (
    FIGURES_MIN_PRESENT_PX,
    PageLayout,
    fit_height,
    legend_outside,
    style_figures,
)

G = 9.81
"""g_z of the sliders' state [m/s^2] (a flat bed); a cell of a run brings its own."""
COLUMN_MIN_PX = 380
"""The least width of each of the page's two columns (the spectrum's figures; the run's
x-t map with its controls) before the second wraps under the first [px]: a projector's
1024 px less the side bar (784 px) holds both, so the map is in the window too."""


@dataclass
class LocalSpectrum:
    """Eigenvalues and band of one state; speeds in m/s."""

    h1: float
    h2: float
    r: float
    du: float
    g: float
    eigenvalues: np.ndarray
    """the four roots with u2 = 0, u1 = du, sorted by real part (complex)"""
    f_l: float
    """closed-form lower bound F_L of the band"""
    f_r: float
    """closed-form upper bound F_R of the band"""
    band: tuple[float, float] | None
    """(F_c1, F_c2), or None if every du is hyperbolic"""

    @property
    def hyperbolic(self) -> bool:
        return bool(discriminant(self.h1, self.h2, self.du, 0.0, self.g, self.r) >= 0.0)


def band_edges(h1: float, h2: float, r: float, g: float = G) -> tuple[float, float] | None:
    """(F_c1, F_c2) [m/s] of :func:`pdeflow.models.two_layer.hyperbolicity.band_edges`, or None."""
    return hyp.band_edges(h1, h2, g, r)


def local_spectrum(h1: float, h2: float, r: float, du: float, g: float = G
                   ) -> LocalSpectrum:
    """Everything the page shows about one state."""
    return LocalSpectrum(h1, h2, r, du, g, eigenvalues(h1, h2, du, 0.0, g, r),
                         lower_bound_fl(h1, h2, g, r), upper_bound_fr(h1, h2, g, r),
                         band_edges(h1, h2, r, g))


def format_eigenvalue(z: complex) -> str:
    """An eigenvalue as the page prints it [m/s]: 4 digits, ± i for a complex one."""
    if abs(z.imag) <= 1e-9 * max(1.0, abs(z.real)):
        return f"{z.real:.4g}"
    return f"{z.real:.4g} {'+' if z.imag > 0 else '-'} {abs(z.imag):.4g}i"


def cell_state(run: DamBreakRun, frame: int, cell: int) -> dict[str, float]:
    """h1, h2 [m], u1, u2, du [m/s], F_extra/rho1 [m^2/s^2], r and g_z of a run's cell."""
    h1, m1, h2, m2 = run.states[PAPER_MODEL][frame][:, cell]
    p = run.case.make_pde(PAPER_MODEL).parameters
    u1 = velocity_profile(h1, m1, p.dry_tolerance)
    u2 = velocity_profile(h2, m2, p.dry_tolerance)
    return {"h1": float(h1), "h2": float(h2), "u1": float(u1), "u2": float(u2),
            "du": float(u1 - u2), "fextra": float(run.fextra[frame][cell]),
            "r": p.density_ratio, "g": p.g * math.cos(math.radians(p.theta_deg))}


class HyperbolicityPage:
    """The hyperbolicity page of one session; follows ``shared.run``."""

    def __init__(self, shared: SharedRun, present: bool = False):
        self.shared = shared
        self.present = present
        self.g = G
        self.sliders = {  # (label, start, end, step, value)
            name: Slider(label=label, start=lo, end=hi, step=step, value=value,
                         css_classes=[f"pdeflow-{name}"], sizing_mode="stretch_width")
            for name, (label, lo, hi, step, value) in {
                "h1": ("upper depth h1 [m]", 0.01, 2.0, 0.01, 0.5),
                "h2": ("lower depth h2 [m]", 0.01, 2.0, 0.01, 1.0),
                "r": ("density ratio r = ρ1/ρ2", 0.05, 0.95, 0.01, 0.67),
                "du": ("relative velocity du = u1 - u2 [m/s]", 0.0, 12.0, 0.01, 3.0),
            }.items()}
        for s in self.sliders.values():
            s.param.watch(lambda e: self.update(), "value_throttled")
        self.text = pn.pane.HTML("", css_classes=["pdeflow-spectrum"],
                                 sizing_mode="stretch_width")
        self.frame = pn.widgets.IntSlider(label="frame of the run", start=0, end=1,
                                          css_classes=["pdeflow-frame"],
                                          sizing_mode="stretch_width")
        self.cell = pn.widgets.IntSlider(label="cell of the run", start=0, end=1,
                                         css_classes=["pdeflow-cell"],
                                         sizing_mode="stretch_width")
        for w in (self.frame, self.cell):
            w.param.watch(lambda e: self.show_cell(), "value")
        self.take = pn.widgets.Button(label="analyse this cell's state", color="primary",
                                      css_classes=["pdeflow-take"])
        self.take.on_click(lambda e: self.take_cell())
        self.cell_text = pn.pane.HTML("", css_classes=["pdeflow-cell-state"],
                                      sizing_mode="stretch_width")
        self.run: DamBreakRun | None = None
        self._figures()
        self._xt_figure()
        self.columns = (
            pn.Column(pn.pane.Bokeh(self.fig_spec), pn.pane.Bokeh(self.fig_im),
                      sizing_mode="stretch_width"),
            pn.Column(pn.pane.HTML("<b>where F_extra acts in the dam-break page's run</b>",
                                   sizing_mode="stretch_width"),
                      pn.pane.Bokeh(self.fig_xt),
                      pn.Row(self.frame, self.cell, sizing_mode="stretch_width"),
                      self.take, self.cell_text, sizing_mode="stretch_width"))
        self.set_present(present)
        self.update()
        shared.param.watch(lambda e: self.show_run(e.new), "run")
        self.show_run(shared.run)

    # --- the spectrum of the sliders' state ----------------------------------------------
    def _figures(self) -> None:
        opts = {"height": 260, "sizing_mode": "stretch_width",
                "tools": "pan,wheel_zoom,box_zoom,reset,save"}
        self.src_curves = ColumnDataSource({k: [] for k in
                                            ("du", "l1", "l2", "l3", "l4", "im")})
        self.src_now = ColumnDataSource({"du": [], "re": []})
        fs = figure(y_axis_label="Re λ [m/s]", **opts)
        for k, colour in (("l1", "black"), ("l2", "#1f77b4"), ("l3", "#1f77b4"),
                          ("l4", "black")):
            fs.line("du", k, source=self.src_curves, color=colour, line_width=2,
                    legend_label="outer eigenvalues" if colour == "black"
                    else "inner pair λ2, λ3")
        fs.scatter("du", "re", source=self.src_now, size=9, color="#d62728",
                   legend_label="this state")
        fi = figure(x_range=fs.x_range, height=200, sizing_mode="stretch_width",
                    x_axis_label="du = u1 - u2 [m/s]", y_axis_label="|Im λ2,3| [m/s]",
                    tools=opts["tools"])
        fi.line("du", "im", source=self.src_curves, color="#d62728", line_width=2)
        self.band_boxes = [BoxAnnotation(fill_color="#d62728", fill_alpha=0.15)
                           for _ in (fs, fi)]
        self.lines = {}
        for f, box in zip((fs, fi), self.band_boxes, strict=True):
            f.add_layout(box)
            for name, colour, dash in (("f_l", "green", "dashed"),
                                       ("f_r", "purple", "dashed"),
                                       ("du", "black", "solid")):
                span = Span(location=0, dimension="height", line_color=colour,
                            line_dash=dash, line_width=1.5)
                f.add_layout(span)
                self.lines.setdefault(name, []).append(span)
        legend_outside(fs, "above")  # never over the curves; the plot keeps the width
        fs.css_classes = ["pdeflow-eigen"]
        fi.css_classes = ["pdeflow-imag"]
        self.fig_spec, self.fig_im = fs, fi

    def update(self) -> None:
        """Recompute and redraw the spectrum of the sliders' state."""
        v = {k: float(s.value) for k, s in self.sliders.items()}
        if min(v["h1"], v["h2"]) <= 0:
            return
        sp = local_spectrum(v["h1"], v["h2"], v["r"], v["du"], self.g)
        du = np.linspace(0.0, max(1.3 * sp.f_r, 1.1 * abs(sp.du)), 400)
        lam = eigenvalues(sp.h1, sp.h2, du, 0.0, sp.g, sp.r)
        with pn.io.hold():
            self.src_curves.data = {"du": du, "l1": lam[:, 0].real, "l2": lam[:, 1].real,
                                    "l3": lam[:, 2].real, "l4": lam[:, 3].real,
                                    "im": np.abs(lam[:, 1].imag)}
            self.src_now.data = {"du": [abs(sp.du)] * 4, "re": sp.eigenvalues.real}
            for box in self.band_boxes:
                box.visible = sp.band is not None
                if sp.band is not None:
                    box.left, box.right = sp.band
            for name, value in (("f_l", sp.f_l), ("f_r", sp.f_r), ("du", abs(sp.du))):
                for span in self.lines[name]:
                    span.location = value
            self.text.object = self._spectrum_html(sp)

    @staticmethod
    def _spectrum_html(sp: LocalSpectrum) -> str:
        lam = "".join(f"<li>λ{k + 1} = {format_eigenvalue(z)} m/s</li>"
                      for k, z in enumerate(sp.eigenvalues))
        if sp.band is None:
            band = "every du is hyperbolic for these depths and r"
        else:
            band = (f"complex for <b>F_c1 = {sp.band[0]:.4g} &lt; |du| &lt; "
                    f"F_c2 = {sp.band[1]:.4g} m/s</b> (red band)")
        verdict = ("<b style='color:green'>hyperbolic</b>: four real eigenvalues"
                   if sp.hyperbolic else
                   "<b style='color:#d62728'>not hyperbolic</b>: λ2, λ3 are complex; "
                   "the scheme would add F_extra to bring |du| down to F_c1")
        return (f"<p>{verdict}</p><ul class='pdeflow-eigenvalues'>{lam}</ul>"
                f"<p>{band}; closed-form bounds F_L = {sp.f_l:.4g} m/s (green), "
                f"F_R = {sp.f_r:.4g} m/s (purple); g_z = {sp.g:.4g} m/s².</p>")

    # --- the current run ------------------------------------------------------------------
    def show_run(self, run: DamBreakRun | None) -> None:
        """Where the run's F_extra acts; select its largest value."""
        self.run = run
        self.fig_xt.visible = run is not None and run.fextra is not None
        if not self.fig_xt.visible:
            self.cell_text.object = ("the dam-break page's current run has no two-layer "
                                     "model: nothing to show here")
            return
        f = run.fextra
        i, j = np.nonzero(f > 0)
        dx = run.case.dx
        dt = run.case.t_end / FRAMES_PER_T_END
        self.mapper.high = max(float(f.max()), 1e-6)
        self.src_xt.data = {"x": run.x[j], "t": run.times[i], "f": f[i, j],
                            "w": np.full(i.size, dx), "h": np.full(i.size, dt)}
        # short: it must fit half a projector's page (the map's column)
        self.fig_xt.title.text = f"F_extra > 0 at {i.size} of {f.size} (x, t)"
        self.fig_xt.x_range.start = run.case.x_start
        self.fig_xt.x_range.end = run.case.x_start + run.case.length
        self.fig_xt.y_range.start, self.fig_xt.y_range.end = 0.0, float(run.times[-1])
        k, c = np.unravel_index(int(np.argmax(f)), f.shape)
        self.frame.end = len(run.times) - 1
        self.cell.end = run.x.size - 1
        self.frame.value, self.cell.value = int(k), int(c)
        self.show_cell()

    def _xt_figure(self) -> None:
        self.src_xt = ColumnDataSource({k: [] for k in ("x", "t", "f", "w", "h")})
        self.mapper = LinearColorMapper(palette=Reds256[::-1], low=0.0, high=1.0)
        fx = figure(height=300, sizing_mode="stretch_width", x_axis_label="x [m]",
                    y_axis_label="t [s]", x_range=Range1d(0, 1), y_range=Range1d(0, 1),
                    tools="pan,wheel_zoom,box_zoom,reset,save")
        fx.rect("x", "t", "w", "h", source=self.src_xt, line_color=None,
                fill_color={"field": "f", "transform": self.mapper})
        # below: beside the map it took 100 px of a half page's width
        fx.add_layout(ColorBar(color_mapper=self.mapper, title="F_extra/ρ1 [m²/s²]",
                               orientation="horizontal", height=10), "below")
        self.cross = (Span(dimension="height", line_color=COLOURS["lower"],
                           line_width=1.5),
                      Span(dimension="width", line_color=COLOURS["lower"], line_width=1.5))
        for s in self.cross:
            fx.add_layout(s)
        fx.css_classes = ["pdeflow-fextra-map"]
        self.fig_xt = fx

    def show_cell(self) -> None:
        """Mark the selected cell and time and print its state."""
        run = self.run
        if run is None or run.fextra is None:
            return
        k = min(int(self.frame.value), len(run.times) - 1)
        c = min(int(self.cell.value), run.x.size - 1)
        s = cell_state(run, k, c)
        self.cross[0].location, self.cross[1].location = float(run.x[c]), float(run.times[k])
        self.cell_text.object = (
            f"<p>cell at x = {run.x[c]:.4g} m, t = {run.times[k]:.4g} s: "
            f"h1 = {s['h1']:.4g} m, h2 = {s['h2']:.4g} m, u1 = {s['u1']:.4g} m/s, "
            f"u2 = {s['u2']:.4g} m/s, du = {s['du']:.4g} m/s, "
            f"<b>F_extra/ρ1 = {s['fextra']:.4g} m²/s²</b> (r = {s['r']:.3g}).</p>"
            f"<p>The largest over every step of the summary's run: "
            f"{run.results[PAPER_MODEL].summary['max_fextra_over_rho1']:.4g} m²/s² (the "
            f"map's frames: the animation's run, which stops at each).</p>"
            + ("" if s["h1"] > DRY and s["h2"] > DRY else
               "<p>a layer is dry here: nothing to analyse</p>"))

    def take_cell(self) -> None:
        """Put the selected cell's state into the sliders (its r and g_z too)."""
        run = self.run
        if run is None or run.fextra is None:
            return
        s = cell_state(run, int(self.frame.value), int(self.cell.value))
        if min(s["h1"], s["h2"]) <= DRY:
            return
        self.g = s["g"]
        with pn.io.hold():
            for name in ("h1", "h2", "r", "du"):
                w = self.sliders[name]
                value = abs(s[name]) if name == "du" else s[name]
                w.end = max(w.end, value)
                w.start = min(w.start, value)
                w.value = value
            self.update()

    def set_present(self, present: bool) -> None:
        """Presentation mode: larger fonts and lines."""
        self.present = present
        style_figures((self.fig_spec, self.fig_im, self.fig_xt), present)
        for f, normal in ((self.fig_spec, 260), (self.fig_im, 200), (self.fig_xt, 300)):
            f.height = fit_height(normal, present)
        least = FIGURES_MIN_PRESENT_PX if present else COLUMN_MIN_PX
        for column in self.columns:  # larger fonts: one column under the other
            column.styles = {"flex": f"1 1 {least}px", "min-width": "0"}

    def panel(self) -> pn.Row:
        left = pn.Column("### a local state", *self.sliders.values(), self.text,
                         sizing_mode="stretch_width")
        right = pn.FlexBox(*self.columns, flex_wrap="wrap", align_items="flex-start",
                           sizing_mode="stretch_width")
        # the side bar holds the spectrum's numbers too: presentation mode keeps it
        self.layout = PageLayout(left, right)
        return self.layout.row
