"""Page 2, run-out law: r(a) of both models as the user sweeps a, against the paper's fits
and the published planar-collapse laws, with the fit of the set updating live.

A point is :func:`pdeflow.analysis.sweep.run_sweep` of the selected sweep case at one aspect ratio
a = H0/L0 (r = (R - L0)/L0, R the threshold front; r_mass the same with the front that
holds 99 % of the mass), exactly what ``pdeflow sweep`` computes; the fits are
:func:`pdeflow.analysis.sweep.fit_power_law` over the points at rest, of each measure.
The set starts as the case's ``sweep.aspect_ratios``; moving the a slider adds a point;
changing a parameter recomputes every point of the set (they appear one by one).
"""

from __future__ import annotations

import asyncio
from html import escape
from pathlib import Path
from typing import Any

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource, Legend, Range1d, Span
from bokeh.plotting import figure

from .. import systems
from ..analysis.sweep import (
    PUBLISHED_EXPONENTS,
    PUBLISHED_LAWS,
    fit_power_law,
    published_law,
    run_sweep,
)
from ..cases import BASELINE_MODEL, PAPER_MODEL, CaseError
from ..checks import run_warnings
from ..solvers.fv_split import SimulationBlowUp
from .controls import KNOBS, ParameterControls, Slider, is_column, list_cases, served
from .dam_break import COLOURS, LABELS, WARNING_STYLE, warnings_html
from .look import PageLayout, label_log_axis, style_figure

MODEL_STYLE = {PAPER_MODEL: (COLOURS["upper"], "square", LABELS[PAPER_MODEL]),
               BASELINE_MODEL: (COLOURS["single"], "circle", LABELS[BASELINE_MODEL])}
PAPER_FITS = {m: systems.get(m).paper_runout_law for m in MODEL_STYLE}
"""the paper's fits of test 5.2, (prefactor, exponent) per model"""
A_RANGE = (1.0, 35.0)
"""a axis of the figure"""
R_RANGE = (0.5, 150.0)
"""r axis of the figure"""
FIGURE_HEIGHT_PX = 580
"""Height of the figure with its legend [px], in either mode: on a projector's 768 px
it ends in the window, under the header, the tabs and the a slider."""
LEGEND_COLUMNS = {False: 1, True: 2}
"""Columns of the legend under the plot, outside and in presentation mode: one column
fits the figure's least width beside the results (two were 580 px wide, and stood out
of a 454 px figure); in presentation mode the figure is at least 700 px wide."""


FIGURES_MIN_PX = 440
"""The figure's least width [px] beside the results: a projector's 1024 px less the side
bar (784 px) holds both, so the results stand beside the figure, in the window."""
RESULTS_PX = 330
"""The results' width [px] (the fits' lines wrap; 1024x768 with the side bar: in the
window's height)."""


def format_r(r: float | None) -> str:
    """A normalised run-out as the page prints it (3 digits; '-' for none)."""
    return "-" if r is None else f"{r:.3g}"


class RunoutPage:
    """The run-out law page of one session."""

    def __init__(self, case_dir: Path, default: str = "collapse_sweep.toml",
                 start: bool = True, present: bool = False):
        cases = list_cases(case_dir, lambda c: is_column(c) and "sweep" in c.data)
        if not cases:
            raise CaseError(f"{case_dir}: no sweep case (a column case with [sweep])")
        self.controls = ParameterControls(
            cases, default if default in cases else next(iter(cases)), self.recompute,
            [k for k in KNOBS if not k.column_only and k.in_sweep])
        self.a = Slider(label="aspect ratio a = H0/L0", start=1.0, end=30.0, step=0.5,
                        value=5.0, css_classes=["pdeflow-a"], sizing_mode="stretch_width",
                        min_width=160)
        self.a.param.watch(lambda e: self.add_point(float(e.new)), "value_throttled")
        self.reset = pn.widgets.Button(label="the case's a values", align="end",
                                       css_classes=["pdeflow-reset"])
        self.reset.on_click(lambda e: self.recompute(self._case_ratios()))
        self.clear = pn.widgets.Button(label="clear the set", align="end",
                                       css_classes=["pdeflow-clear"])
        self.clear.on_click(lambda e: self.recompute([]))
        self.status = pn.pane.HTML("", css_classes=["pdeflow-status"],
                                   sizing_mode="stretch_width")
        self.current = pn.pane.HTML("", css_classes=["pdeflow-current"],
                                    sizing_mode="stretch_width")
        self.fits = pn.pane.HTML("", css_classes=["pdeflow-fits"],
                                 sizing_mode="stretch_width")
        self.warnings = pn.pane.HTML("", css_classes=["pdeflow-warnings"],
                                     sizing_mode="stretch_width", visible=False,
                                     styles=WARNING_STYLE)
        self.points: dict[str, dict[float, dict[str, Any]]] = {}
        self.point_warnings: dict[float, list[str]] = {}
        """per a of the set, the command line's warning lines of its runs"""
        self._todo: list[float] = []
        self._generation = 0
        self._figure()
        self.present = present
        self.set_present(present)
        self.started = False
        if start:
            self.start()

    def start(self) -> None:
        """Compute the case's set (once; a page that is not shown need not)."""
        if not self.started:
            self.started = True
            self.recompute(self._case_ratios() + [float(self.a.value)])

    def _case_ratios(self) -> list[float]:
        return [float(a) for a in self.controls.case.data["sweep"]["aspect_ratios"]]

    # --- points ---------------------------------------------------------------------------
    def recompute(self, ratios: list[float] | None = None) -> None:
        """Compute the set (default: its current a values) again for the sliders."""
        if ratios is None:  # the set as it is (with the points still to come)
            ratios = sorted({a for pts in self.points.values() for a in pts}
                            | set(self._todo) | {float(self.a.value)})
        self._generation += 1
        self.points = {}
        self.point_warnings = {}
        self._todo = sorted(set(ratios))
        self._draw()
        if served():
            pn.state.execute(self._fill_async)
        else:
            while self._todo and self._compute(self._todo.pop(0)):
                pass
            self._draw()

    async def _fill_async(self) -> None:
        generation = self._generation
        while self._todo and generation == self._generation:
            if not self._compute(self._todo.pop(0)):
                break
            self._draw()
            await asyncio.sleep(0.01)  # lets the server send this point

    def add_point(self, a: float) -> None:
        """Compute the point at ``a`` (if new) and show it as the current one."""
        if not any(a in pts for pts in self.points.values()):
            self._compute(a)
        self._draw()

    def _compute(self, a: float) -> bool:
        """Both models at ``a``; False (with the error shown) if the case cannot run."""
        lines: list[str] = []
        try:
            case = self.controls.load()
            with run_warnings(lines.append):  # what the command line would print
                out = run_sweep(case, [a])
        except (CaseError, SimulationBlowUp, ValueError) as err:
            self.status.object = f"<b>cannot run this:</b> {escape(str(err))}"
            self._todo = []
            return False
        for model, res in out["models"].items():
            self.points.setdefault(model, {})[a] = res["runs"][0]
        self.point_warnings[a] = lines
        self.status.object = ""
        return True

    def fit(self, model: str, key: str = "r") -> tuple[float, float] | None:
        """(prefactor, exponent) of the set's points at rest, or None (< 2 points), of
        the threshold run-out (``key`` 'r') or the mass-quantile one ('r_mass')."""
        good = [(a, row[key]) for a, row in sorted(self.points.get(model, {}).items())
                if row[key] and row["at_rest"]]
        if len(good) < 2:
            return None
        return fit_power_law(*zip(*good, strict=True))

    # --- figure ---------------------------------------------------------------------------
    def _figure(self) -> None:
        f = figure(x_axis_type="log", y_axis_type="log", height=FIGURE_HEIGHT_PX,
                   sizing_mode="stretch_width", x_range=Range1d(*A_RANGE),
                   y_range=Range1d(*R_RANGE), x_axis_label="aspect ratio a = H0/L0",
                   y_axis_label="run-out r = (R - L0)/L0",  # upright: fits 545 px
                   tools="pan,wheel_zoom,box_zoom,reset,save")
        label_log_axis(f.xaxis[0], *A_RANGE)  # 1, 2, 3, 5, 10, 20, 30
        label_log_axis(f.yaxis[0], *R_RANGE)
        aa = np.geomspace(*A_RANGE, 200)
        items = []
        self.src_points, self.src_fits = {}, {}
        for model, (colour, marker, label) in MODEL_STYLE.items():
            self.src_points[model] = ColumnDataSource({"a": [], "r": []})
            self.src_fits[model] = ColumnDataSource({"a": [], "r": []})
            g = f.scatter("a", "r", source=self.src_points[model], marker=marker,
                          size=9, color=colour)
            fl = f.line("a", "r", source=self.src_fits[model], color=colour, line_width=2)
            p, e = PAPER_FITS[model]
            pl = f.line(aa, p * aa**e, color=colour, line_dash="dotted", line_width=2)
            # points and their fit: one entry (one row less in a one-column legend)
            items += [(f"{label}: points, fit of the set", [g, fl]),
                      (f"paper, {label}: {p} a^{e}", [pl])]
        for name, colour in zip(PUBLISHED_LAWS, ("#7f7f7f", "#17becf"), strict=True):
            law = f.line(aa, published_law(name, aa), color=colour, line_dash="dashed",
                         line_width=2)
            items.append((f"{name} (experiments)", [law]))
        p2, e2 = PAPER_FITS[PAPER_MODEL]
        for (name, (e, _)), colour in zip(PUBLISHED_EXPONENTS.items(),
                                          ("#bcbd22", "#9467bd", "#2ca02c"), strict=True):
            # an exponent alone has no prefactor: drawn through the paper's two-layer
            # fit at a = 2, as in docs/two_layer_law.md
            law = f.line(aa, p2 * 2**e2 * (aa / 2) ** e, color=colour,
                         line_dash="dotdash", line_width=1.5)
            items.append((f"{name}: slope {e}", [law]))
        self.a_line = Span(location=5.0, dimension="height", line_color="#d62728",
                           line_dash="dashed", line_width=1.5)
        f.add_layout(self.a_line)
        # a Span has no legend entry: an empty line in its style stands for it
        a_item = f.line([np.nan], [np.nan], line_color="#d62728", line_dash="dashed",
                        line_width=1.5)
        items.append(("a of the slider (the current point)", [a_item]))
        # under the plot, in two columns: it never covers the points, and the plot
        # keeps the page's width
        legend = Legend(items=items, click_policy="hide")  # ncols: set_present
        f.add_layout(legend, "below")
        f.css_classes = ["pdeflow-runout"]
        self.fig = f

    def _draw(self) -> None:
        aa = np.geomspace(*A_RANGE, 50)
        a_now = float(self.a.value)
        with pn.io.hold():
            for model in MODEL_STYLE:
                pts = sorted((a, row["r"]) for a, row in self.points.get(model, {}).items()
                             if row["r"])
                self.src_points[model].data = {"a": [p[0] for p in pts],
                                               "r": [p[1] for p in pts]}
                fit = self.fit(model)
                self.src_fits[model].data = ({"a": aa, "r": fit[0] * aa ** fit[1]}
                                             if fit else {"a": [], "r": []})
            self.a_line.location = a_now
            self.current.object = self._current_html(a_now)
            self.fits.object = self._fits_html()
            self.warnings.object = warnings_html(self.warning_lines(), "points")
            self.warnings.visible = any(self.point_warnings.values())

    def _current_html(self, a: float) -> str:
        parts = []
        for model, (_, _, label) in MODEL_STYLE.items():
            row = self.points.get(model, {}).get(a)
            if row is None:
                continue
            p, e = PAPER_FITS[model]
            rest = "" if row["at_rest"] else " (still moving at t_end)"
            parts.append(f"<li>{label}: <b class='pdeflow-r-{model}'>r = "
                         f"{format_r(row['r'])}</b>{rest}; paper's fit {p * a**e:.3g}; "
                         f"r_mass = {format_r(row['r_mass'])}</li>")
        if not parts:
            return f"<p>a = {a:g}: computing ...</p>" if self._todo else ""
        return f"<p><b>a = {a:g}</b></p><ul>{''.join(parts)}</ul>"

    def _fits_html(self) -> str:
        rows = []
        for model, (_, _, label) in MODEL_STYLE.items():
            fit = self.fit(model)
            n = len(self.points.get(model, {}))
            p, e = PAPER_FITS[model]
            got = f"r = {fit[0]:.3g} a^{fit[1]:.3f}" if fit else "needs two points at rest"
            fit_m = self.fit(model, "r_mass")
            mass = f"; r_mass = {fit_m[0]:.3g} a^{fit_m[1]:.3f}" if fit_m else ""
            rows.append(f"<li>{label}: <b>{got}</b> ({n} points; paper {p} a^{e}){mass}"
                        f"</li>")
        todo = f"<p>computing {len(self._todo)} more ...</p>" if self._todo else ""
        return (f"<p>fit of the set:</p><ul>{''.join(rows)}</ul>{todo}"
                f"<p style='color:#666'>r = (R - L0)/L0 with R the front (the last cell "
                f"deeper than the case's front threshold), a front as the paper's figures "
                f"show it; "
                f"r_mass with R the distance from the wall that holds "
                f"{100 * self.controls.case.runout_mass_fraction:.4g}% of the mass "
                f"(it changes less with the grid).</p>")

    def warning_lines(self) -> list[str]:
        """The command line's warnings about the set's runs, each prefixed by its a."""
        return [f"a = {a:g}: {line}" for a, lines in sorted(self.point_warnings.items())
                for line in lines]

    def set_present(self, present: bool) -> None:
        """Presentation mode: larger fonts and lines, the expert choices hidden."""
        self.present = present
        style_figure(self.fig, present)
        self.fig.height = FIGURE_HEIGHT_PX  # the legend's larger rows take from the plot
        self.fig.legend[0].ncols = LEGEND_COLUMNS[present]
        self.controls.set_present(present)

    def panel(self) -> pn.Row:
        main = pn.Column(self.status, self.warnings,
                         pn.Row(self.a, self.reset, self.clear, sizing_mode="stretch_width"),
                         pn.pane.Bokeh(self.fig), sizing_mode="stretch_width")
        results = pn.Column("### results", self.current, self.fits,
                            sizing_mode="stretch_width")
        self.layout = PageLayout(self.controls.panel("run-out law"), main, results,
                                 figures_min_px=FIGURES_MIN_PX, results_px=RESULTS_PX)
        if self.present:
            self.layout.show_sidebar(False)
        return self.layout.row
