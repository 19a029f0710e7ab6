"""How the pages look: font sizes and line widths (normal or for a projector), and the
page layout that works from 1024x768 to wide screens.

A page is a side bar of parameters (collapsible: a button above the figures hides it)
and a main area in which the figures take the width they need and the results sit
beside them on a wide screen or wrap under them on a narrow one (a CSS flex box, so the
browser decides, and nothing waits for the server).

Presentation mode (a toggle in the header, ``?present=1`` in the URL, or ``pdeflow app
--present``): larger fonts and lines, figure toolbars only on hover, and the controls a
class does not need (scheme, friction law, the command line) hidden.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import panel as pn
from bokeh.models import FixedTicker, GlyphRenderer, NumeralTickFormatter, Span

SIDEBAR_PX = 240
"""Width of a page's side bar of parameters [px] (23 % of a projector's 1024 px)."""
SIDEBAR_TOP_PX = 110
"""Height above the side bar [px] (the header and the tabs): the side bar is at most the
rest of the window high and scrolls on its own, so that the figures stay in view while
one scrolls to the last sliders."""
RESULTS_PX = 380
"""Width of a page's results column [px] (beside the figures, or under them)."""
FIGURES_MIN_PX = 580
"""The narrowest the figures get before the results wrap under them [px], by default:
on a projector's 1024 px the results stand beside the figures once the side bar is
hidden (a page whose legends stand above its plots gives a smaller width)."""
FIGURES_MIN_PRESENT_PX = 700
"""The same in presentation mode [px]: larger fonts need wider figures, and the results
go under them."""


@dataclass(frozen=True)
class Look:
    """Font sizes [pt] and the factor on line widths of one mode."""

    title_pt: int
    axis_pt: int
    ticks_pt: int
    legend_pt: int
    line_scale: float


NORMAL = Look(title_pt=13, axis_pt=12, ticks_pt=11, legend_pt=11, line_scale=1.0)
PRESENT = Look(title_pt=20, axis_pt=17, ticks_pt=15, legend_pt=15, line_scale=2.0)


def look(present: bool) -> Look:
    return PRESENT if present else NORMAL


def fit_height(normal_px: int, present: bool) -> int:
    """A figure's height [px] for the mode: larger fonts need more room for the y
    axis' label (upright) and the tick labels."""
    return round(normal_px * PRESENT.axis_pt / NORMAL.axis_pt) if present else normal_px


def _scale_line(model: Any, scale: float) -> None:
    """Set ``model.line_width`` to its width as built times ``scale`` (the width as
    built is kept in its tags, so that switching back and forth does not drift)."""
    if not hasattr(model, "line_width"):
        return
    if not model.tags:
        model.tags = [float(model.line_width)]
    model.line_width = model.tags[0] * scale


def style_figure(fig: Any, present: bool) -> None:
    """Fonts, line widths and toolbar of one Bokeh figure for the mode."""
    lk = look(present)
    fig.title.text_font_size = f"{lk.title_pt}pt"
    for axis in (*fig.xaxis, *fig.yaxis):
        axis.axis_label_text_font_size = f"{lk.axis_pt}pt"
        axis.major_label_text_font_size = f"{lk.ticks_pt}pt"
    for legend in fig.legend:
        legend.label_text_font_size = f"{lk.legend_pt}pt"
        legend.glyph_width = round(20 * lk.line_scale)
    for r in fig.renderers:
        if isinstance(r, GlyphRenderer):
            _scale_line(r.glyph, lk.line_scale)
    for a in fig.center:
        if isinstance(a, Span):
            _scale_line(a, lk.line_scale)
    fig.toolbar.autohide = present


def style_figures(figures: Iterable[Any], present: bool) -> None:
    for f in figures:
        style_figure(f, present)


LOG_MANTISSAS = (1, 2, 3, 5)
"""The labelled ticks of a log axis in each decade: 1, 2, 3, 5, 10, 20, ..."""


def log_ticks(low: float, high: float, mantissas: Sequence[int] = LOG_MANTISSAS
              ) -> list[float]:
    """The ticks ``m * 10**k`` (m in ``mantissas``) in [low, high] (> 0), ascending.

    Bokeh's log ticker labels only the decades, and over less than about two decades
    falls back to linear steps: on the run-out law's a axis (1 to 35) it labelled 5, 10,
    15, ... and nothing below 5."""
    ticks = []
    for k in range(math.floor(math.log10(low)), math.ceil(math.log10(high)) + 1):
        for m in mantissas:
            tick = float(m * 10.0**k) if k >= 0 else m / 10.0**-k  # 0.5, not 0.5000001
            if low * (1 - 1e-9) <= tick <= high * (1 + 1e-9):
                ticks.append(tick)
    return ticks


def label_log_axis(axis: Any, low: float, high: float) -> None:
    """Ticks of :func:`log_ticks` on the Bokeh log ``axis`` shown over [low, high] (and a
    decade beyond, for panning), labelled as plain numbers (0.5, 1, 20; not 10^0), with
    a minor tick at every 1..9 x 10^k."""
    low, high = low / 10, high * 10
    axis.ticker = FixedTicker(ticks=log_ticks(low, high),
                              minor_ticks=log_ticks(low, high, range(1, 10)))
    axis.formatter = NumeralTickFormatter(format="0[.][0000]")


def legend_outside(fig: Any, place: str = "right", ncols: int | None = None) -> None:
    """Move the figure's legend out of the plot area (``place``: 'right', 'below',
    'above'), where it cannot cover the data; above or below, its entries stand in rows
    of ``ncols`` (default: all in one row), so that the plot keeps the figure's width (a
    legend at the right took 200 px of it)."""
    for legend in list(fig.legend):
        if legend in fig.center:
            fig.center.remove(legend)
            fig.add_layout(legend, place)
        if place in ("above", "below"):
            legend.orientation = "horizontal"
            legend.ncols = ncols or len(legend.items)
            legend.margin, legend.padding, legend.spacing = 0, 2, 12
            legend.border_line_alpha = 0


class PageLayout:
    """Side bar | figures + results (results under the figures when space is short).

    Args:
        sidebar: the page's parameters.
        figures: the figures and what belongs to them (player, warnings).
        results: the numbers; beside the figures if both fit, else under them.
        top: beside the side bar's button, above the figures and results (the
            animation's player: one row for both, the figures start higher).
        figures_min_px: the narrowest the figures get before the results wrap under
            them [px] (outside presentation mode).
        results_px: the results' width [px].
    """

    def __init__(self, sidebar: pn.viewable.Viewable, figures: pn.viewable.Viewable,
                 results: pn.viewable.Viewable | None = None,
                 top: pn.viewable.Viewable | None = None,
                 figures_min_px: int = FIGURES_MIN_PX, results_px: int = RESULTS_PX):
        self.figures_min_px = figures_min_px
        self.sidebar = pn.Column(sidebar, width=SIDEBAR_PX, css_classes=["pdeflow-sidebar"],
                                 styles={"max-height": f"calc(100vh - {SIDEBAR_TOP_PX}px)",
                                         "overflow-y": "auto", "overflow-x": "hidden"})
        self.toggle = pn.widgets.Toggle(name="◀ hide the parameters", value=True,
                                        css_classes=["pdeflow-sidebar-toggle"],
                                        width=200, height=30)
        self.toggle.param.watch(lambda e: self.show_sidebar(e.new), "value")
        self.figures = figures
        self.set_present(False)
        parts = [figures]
        if results is not None:
            results.styles = {"flex": f"0 1 {results_px}px"}
            parts.append(results)
        self.main = pn.FlexBox(*parts, flex_wrap="wrap", align_items="flex-start",
                               sizing_mode="stretch_width")
        head = (self.toggle if top is None
                else pn.Row(self.toggle, top, sizing_mode="stretch_width"))
        self.row = pn.Row(self.sidebar, pn.Column(head, self.main,
                                                  sizing_mode="stretch_width"),
                          sizing_mode="stretch_width")

    def set_present(self, present: bool) -> None:
        """The figures' narrowest width for the mode."""
        least = FIGURES_MIN_PRESENT_PX if present else self.figures_min_px
        self.figures.styles = {"flex": f"1 1 {least}px", "min-width": "0"}

    def show_sidebar(self, shown: bool) -> None:
        self.sidebar.visible = shown
        self.toggle.name = "◀ hide the parameters" if shown else "▶ show the parameters"
        if self.toggle.value != shown:
            self.toggle.value = shown
