"""The dam-break page's plan view of an axisymmetric run: the total depth revolved about
the axis, what a camera above the collapse sees.

Built with the page and hidden until an axisymmetric run is shown, so that its 36 Bokeh
models reach the browser with the page: a figure added to a live page, and changed in
the same tick, sometimes reached the browser after the change that referred to it
(Bokeh's "reference ... isn't known", twice in full browser runs).
"""

from __future__ import annotations

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
    """The plan view's figure (:attr:`pane` on the page), hidden until an axisymmetric
    run is shown."""

    def __init__(self, present: bool = False, radius: float = 1.0):
        self.source = ColumnDataSource({"image": [np.full((2, 2), np.nan)], "x": [-radius],
                                        "y": [-radius], "dw": [2 * radius],
                                        "dh": [2 * radius]})
        # no width or height besides the plot area's: Panel makes a figure's width
        # the least of its column (hidden or not), and the default 600 px pushed the
        # results under the figures. Fixed ranges on a square plot area, not
        # match_aspect's data ranges: those have no extent while the figure is
        # hidden, and Bokeh warned "could not set initial ranges" at each layout
        fp = figure(title="seen from above (total depth)", frame_width=FRAME_PX,
                    frame_height=FRAME_PX, width=None, height=None,
                    x_range=Range1d(-radius, radius), y_range=Range1d(-radius, radius),
                    x_axis_label="x [m]", y_axis_label="y [m]", toolbar_location=None,
                    visible=False)
        self.colours = LinearColorMapper(palette="Cividis256", low=0.0, high=1.0,
                                         nan_color="white")
        fp.image("image", x="x", y="y", dw="dw", dh="dh", source=self.source,
                 color_mapper=self.colours)
        fp.css_classes = ["pdeflow-plan"]  # for the browser tests
        style_figures((fp,), present)
        self.figure = fp
        self.pane = pn.Column(pn.pane.Bokeh(fp), sizing_mode="stretch_width", visible=False)

    @property
    def visible(self) -> bool:
        """Whether the page shows the plan view (the last run was axisymmetric)."""
        return bool(self.figure.visible)

    def show_run(self, axisymmetric: bool, depth: float, radius: float) -> None:
        """A new run: shown if ``axisymmetric``, its colour scale up to ``depth`` [m]
        (the initial total depth), its axes over the domain's ``radius`` [m]."""
        self.figure.visible = self.pane.visible = axisymmetric  # the pane takes no room
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
        """Presentation mode on or off."""
        style_figures((self.figure,), present)
