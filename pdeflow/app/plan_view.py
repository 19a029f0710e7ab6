"""The dam-break page's plan view of an axisymmetric run: the total depth revolved about
the axis, what a camera above the collapse sees.

Built when the page first shows an axisymmetric run: a page that only ever shows planar
cases (the paper's dam break, the one a start opens with) never sends the figure and
its 36 Bokeh models to the browser.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource, LinearColorMapper, Range1d
from bokeh.plotting import figure

from ..plotting import DRY
from .look import style_figures

PLAN_PIXELS = 121
"""Pixels across the plan view (the revolved total depth)."""
FRAME_PX = 230
"""Width and height of the plan view's plot area [px] (square: a circle is round)."""


def plan_view(r: np.ndarray, depth: np.ndarray, radius: float,
              pixels: int = PLAN_PIXELS) -> np.ndarray:
    """The total depth ``depth`` [m] at the cell centres ``r`` [m] revolved about the
    axis, on ``pixels`` x ``pixels`` points of [-radius, radius]^2 (NaN outside the
    domain and where dry): what a camera above the collapse sees."""
    axis = np.linspace(-radius, radius, pixels)
    rr = np.hypot(*np.meshgrid(axis, axis))
    image = np.interp(rr, r, depth, right=np.nan)
    return np.where(image > DRY, image, np.nan)


class PlanView:
    """The plan view's place on the page (:attr:`pane`, empty until the figure exists)
    and, once an axisymmetric run was shown, its figure."""

    def __init__(self, present: bool = False):
        self.pane = pn.Column(sizing_mode="stretch_width")
        self.figure: Any = None
        self.source: ColumnDataSource | None = None
        self.colours: LinearColorMapper | None = None
        self.present = present

    @property
    def visible(self) -> bool:
        """Whether the page shows the plan view (the last run was axisymmetric)."""
        return self.figure is not None and bool(self.figure.visible)

    def show_run(self, axisymmetric: bool, depth: float, radius: float) -> None:
        """A new run: shown if ``axisymmetric`` (the figure built the first time), its
        colour scale up to ``depth`` [m] (the initial total depth), its axes over the
        domain's ``radius`` [m]."""
        if axisymmetric and self.figure is None:
            self._build(radius)
        if self.figure is not None:
            self.figure.visible = axisymmetric
            self.colours.high = depth
            if axisymmetric:
                for axis in (self.figure.x_range, self.figure.y_range):
                    axis.start, axis.end = -radius, radius  # sent if they change

    def show_frame(self, r: np.ndarray, depth: np.ndarray, radius: float) -> None:
        """The total depth ``depth`` [m] at the radii ``r`` [m] of a domain of
        ``radius`` [m], revolved (while :attr:`visible`)."""
        self.source.data = {"image": [plan_view(r, depth, radius)], "x": [-radius],
                            "y": [-radius], "dw": [2 * radius], "dh": [2 * radius]}

    def set_present(self, present: bool) -> None:
        """Presentation mode on or off (for the figure now or when it is built)."""
        self.present = present
        if self.figure is not None:
            style_figures((self.figure,), present)

    def _build(self, radius: float) -> None:
        self.source = ColumnDataSource({"image": [np.full((2, 2), np.nan)], "x": [-1.0],
                                        "y": [-1.0], "dw": [2.0], "dh": [2.0]})
        # fixed ranges on a square plot area, not match_aspect's data ranges: those
        # have no extent while the figure is hidden (a planar run after an
        # axisymmetric one), and Bokeh warned "could not set initial ranges" at each
        # of its layouts
        fp = figure(title="seen from above (total depth)", frame_width=FRAME_PX,
                    frame_height=FRAME_PX, x_range=Range1d(-radius, radius),
                    y_range=Range1d(-radius, radius),
                    x_axis_label="x [m]", y_axis_label="y [m]", toolbar_location=None)
        self.colours = LinearColorMapper(palette="Cividis256", low=0.0, high=1.0,
                                         nan_color="white")
        fp.image("image", x="x", y="y", dw="dw", dh="dh", source=self.source,
                 color_mapper=self.colours)
        fp.css_classes = ["pdeflow-plan"]  # for the browser tests
        style_figures((fp,), self.present)
        self.figure = fp
        self.pane.objects = [pn.pane.Bokeh(fp)]
