"""The hillside page's figures: plan views of the flow over the terrain's hillshade and
contour lines, one per model, with the release polygon (drawn and dragged with Bokeh's
tools on the first), the front and the deposit's outline; and the long section of the
depth along the path.

Coordinates are the case file's: x [m] down the path and y [m] across, both from the
grid's corner (where the release polygon's vertices are given). Depths in m.
"""

from __future__ import annotations

import math

import numpy as np
from bokeh.models import (
    ColumnDataSource,
    DataRange1d,
    LinearAxis,
    LinearColorMapper,
    PolyDrawTool,
    PolyEditTool,
    Range1d,
    Span,
)
from bokeh.palettes import Viridis256
from bokeh.plotting import figure

from ..terrain_figures import contour_step, hillshade

DEPTH_PALETTE = tuple(reversed(Viridis256))
"""Depth colours: light and thin, dark and deep."""
DEPTH_ALPHA = 0.85
"""Opacity of the depth over the hillshade: the relief stays readable under the flow."""
TRANSPARENT = "rgba(0, 0, 0, 0)"
"""Dry cells (NaN depth): the terrain shows through."""
MODEL_COLOURS = {"single_layer": "black", "two_layer": "#ff7f0e"}
"""As the dam-break page: the single layer black, the two layers orange (the upper)."""
PLAN_HEIGHT_PX = (260, 300)
"""Height of a plan view's plot area [px], normal and presentation mode."""
SECTION_HEIGHT_PX = (170, 200)
"""Height of the long section [px], normal and presentation mode."""
TABLE_WIDTH_PX = 300
"""Width of the results table beside the long section [px]: two models' columns and
their labels, so that the section keeps the rest (at 1024 px with the side bar shown,
its plot area above the page's 300 px least)."""


def hillshade_rgba(bed: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """The hillshade of ``bed`` (nx, ny) [m], lit from the north-west at 45 deg as maps
    are, as Bokeh's RGBA image (ny, nx) of uint32, row 0 at the lowest y."""
    shade = hillshade(bed, dx, dy)[::-1]  # Bokeh's row 0 is the lowest y
    grey = (150 + 100 * np.clip(shade, 0.0, 1.0)).astype(np.uint32)  # never black
    return (255 << 24) | (grey << 16) | (grey << 8) | grey


def contour_lines(bed: np.ndarray, x: np.ndarray, y: np.ndarray,
                  levels: np.ndarray | None = None) -> dict[str, list[np.ndarray]]:
    """The contour lines of ``bed`` (nx, ny) [m] at the centres ``x`` (nx), ``y`` (ny)
    [m], at round ``levels`` [m] (default: :func:`pdeflow.terrain_figures.contour_step`
    apart), as a multi_line source's ``xs`` and ``ys``."""
    from contourpy import contour_generator

    if levels is None:
        low, high = float(np.min(bed)), float(np.max(bed))
        step = contour_step(max(high - low, 1e-9))
        levels = np.arange(math.ceil(low / step) * step, high, step)
    gen = contour_generator(x, y, np.asarray(bed, dtype=float).T)
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    for level in levels:
        for line in gen.lines(float(level)):
            xs.append(line[:, 0])
            ys.append(line[:, 1])
    return {"xs": xs, "ys": ys}


def depth_image(depth: np.ndarray, threshold: float) -> np.ndarray:
    """``depth`` (nx, ny) [m] as Bokeh's image (ny, nx): NaN (the terrain shows) where
    it is not above ``threshold`` [m]."""
    d = np.asarray(depth, dtype=np.float32)
    return np.where(d > threshold, d, np.nan).T


class PlanView:
    """One model's plan view: hillshade, contours, depth, release, front and deposit
    outline. ``release`` is the polygon's source, shared by all plan views; ``draw``
    gives this one the tools to draw and drag it."""

    def __init__(self, model: str, label: str, release: ColumnDataSource,
                 x_range: DataRange1d, y_range: DataRange1d, draw: bool = False):
        self.model = model
        self.terrain = ColumnDataSource({"image": [np.zeros((2, 2), np.uint32)],
                                         "x": [0.0], "y": [0.0], "dw": [1.0], "dh": [1.0]})
        self.contours = ColumnDataSource({"xs": [], "ys": []})
        self.flow = ColumnDataSource({"image": [np.full((2, 2), np.nan)], "x": [0.0],
                                      "y": [0.0], "dw": [1.0], "dh": [1.0]})
        self.outline = ColumnDataSource({"xs": [], "ys": []})
        self.colours = LinearColorMapper(palette=DEPTH_PALETTE, low=0.0, high=1.0,
                                         nan_color=TRANSPARENT)
        tools = "pan,wheel_zoom,reset,save"
        fig = figure(title=label, x_range=x_range, y_range=y_range, tools=tools,
                     height=PLAN_HEIGHT_PX[0], sizing_mode="stretch_width",
                     x_axis_label="x down the path [m]", y_axis_label="y [m]",
                     toolbar_location="above" if draw else None, match_aspect=True)
        fig.image_rgba("image", x="x", y="y", dw="dw", dh="dh", source=self.terrain)
        fig.multi_line("xs", "ys", source=self.contours, line_color="#4a3f30",
                       line_alpha=0.5, line_width=1)
        fig.image("image", x="x", y="y", dw="dw", dh="dh", source=self.flow,
                  color_mapper=self.colours, global_alpha=DEPTH_ALPHA)
        fig.multi_line("xs", "ys", source=self.outline, line_color="#d62728",
                       line_width=2, line_dash="dashed")
        patches = fig.patches("xs", "ys", source=release, fill_alpha=0.15,
                              fill_color="#d62728", line_color="#d62728", line_width=2)
        self.front = Span(location=0.0, dimension="height", line_color="#d62728",
                          line_width=2, visible=False)
        fig.add_layout(self.front)
        if draw:
            vertices = fig.scatter([], [], size=9, color="#d62728")
            draw_tool = PolyDrawTool(renderers=[patches], num_objects=1)
            edit_tool = PolyEditTool(renderers=[patches], vertex_renderer=vertices)
            fig.add_tools(draw_tool, edit_tool)
            fig.toolbar.active_drag = draw_tool  # drawing is what the page is for
        fig.grid.visible = False
        fig.css_classes = [f"pdeflow-plan-{model}"]  # for the browser tests
        self.figure = fig

    def show_terrain(self, hillshade: np.ndarray, contours: dict[str, list[np.ndarray]],
                     length: float, width: float) -> None:
        """A new terrain or grid: the hillshade over [0, length] x [0, width] [m]."""
        self.terrain.data = {"image": [hillshade], "x": [0.0], "y": [0.0],
                             "dw": [length], "dh": [width]}
        self.contours.data = contours
        self.flow.data = {"image": [np.full((2, 2), np.nan)], "x": [0.0], "y": [0.0],
                          "dw": [length], "dh": [width]}
        self.outline.data = {"xs": [], "ys": []}
        self.front.visible = False

    def show_depth(self, depth: np.ndarray, threshold: float, length: float,
                   width: float, front: float | None) -> None:
        """The depth (nx, ny) [m] over the terrain, and the front's x [m] (None: no
        cell above ``threshold``)."""
        self.flow.data = {"image": [depth_image(depth, threshold)], "x": [0.0],
                          "y": [0.0], "dw": [length], "dh": [width]}
        self.front.visible = front is not None
        self.front.location = front or 0.0

    def show_outline(self, lines: dict[str, list[np.ndarray]]) -> None:
        """The deposit's outline (contour lines at the front threshold)."""
        self.outline.data = lines


def section_figure(x_range: Range1d) -> tuple[figure, ColumnDataSource, ColumnDataSource]:
    """The long section: each model's depth [m] along x on the path's row, over the
    bed's elevation (grey, on its own axis at the right). Returns the figure, the depths'
    source (x, one column per model) and the bed's (x, z)."""
    depths = ColumnDataSource({"x": [], **{m: [] for m in MODEL_COLOURS}})
    bed = ColumnDataSource({"x": [], "z": [], "base": []})
    fig = figure(title="long section along the path", x_range=x_range,
                 y_range=Range1d(0, 1), height=SECTION_HEIGHT_PX[0],
                 sizing_mode="stretch_width", x_axis_label="x down the path [m]",
                 y_axis_label="depth [m]", tools="pan,wheel_zoom,reset,save",
                 toolbar_location=None)
    fig.extra_y_ranges = {"bed": Range1d(0, 1)}
    fig.add_layout(LinearAxis(y_range_name="bed", axis_label="bed [m]"), "right")
    fig.varea("x", "base", "z", source=bed, y_range_name="bed", color="#bbbbbb",
              alpha=0.6)
    for model, colour in MODEL_COLOURS.items():
        fig.line("x", model, source=depths, color=colour, line_width=2,
                 legend_label="single layer" if model == "single_layer" else "two layers")
    fig.legend.location = "top_right"
    fig.css_classes = ["pdeflow-section"]
    return fig, depths, bed
