"""Page 4, hillside: draw a release on a terrain, run both models in 2D, watch them flow.

The lecturer picks a terrain (a case file over a named topography,
:func:`~pdeflow.app.hillside_setup.hillside_cases`; the plane with a flat run-out
first), draws the release polygon on the plan view (Bokeh's polygon tools: press and
hold at the first vertex, click the next ones, press and hold at the last; drag the
polygon to move it), sets its thickness, the models, the friction law and angle and the
grid, and presses run. The run goes to the
server's queue (:mod:`.run_queue`) and computes in a worker
(:class:`~pdeflow.app.live_run.LiveRun`); the page draws its frames as they arrive,
every :data:`FRAME_MS` ms, the models side by side with their fronts, and the long
section along the path; at the end the deposit's outline, the table of ``pdeflow run``'s
numbers for the downloadable case file, and the command line's warnings. A new run
cancels the page's previous one, and so does closing the tab.
"""

from __future__ import annotations

import io
from html import escape
from pathlib import Path
from typing import Any

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource, DataRange1d, Div, Range1d

from ..cases import CaseError, load_case
from ..metrics_2d import front_x
from ..numerics.geometry import centre_values
from .controls import served
from .dam_break import LABELS, WARNING_STYLE, warnings_html
from .hillside_figures import (
    MODEL_COLOURS,
    PLAN_HEIGHT_PX,
    SECTION_HEIGHT_PX,
    TABLE_WIDTH_PX,
    PlanView,
    contour_lines,
    hillshade_rgba,
    section_figure,
)
from .hillside_setup import (
    CELLS_RANGE,
    FRICTION_RANGE,
    HILLSIDE_LAWS,
    HILLSIDE_MODELS,
    THICKNESS_RANGE,
    HillsideSetup,
    hillside_cases,
    release_polygon,
)
from .live_run import LiveRun
from .look import PageLayout, style_figures
from .run_queue import QUEUE, QueueFull

FRAME_MS = 66
"""Interval between two drawn frames [ms]: 15 frames per second while frames arrive."""
SUMMARY_ROWS = (("runout", "run-out [m]", "{:.0f}"), ("stop_time", "stop time [s]", "{:.1f}"),
                ("lateral_spread", "lateral spread [m]", "{:.0f}"),
                ("travel_angle", "travel angle [deg]", "{:.1f}"),
                ("max_speed", "largest speed [m/s]", "{:.1f}"),
                ("affected_area", "affected area [m²]", "{:.3g}"))
"""The table's rows: summary key, label, format."""


class HillsidePage:
    """The hillside page of one session (build it once the kernels are loaded)."""

    def __init__(self, case_dir: Path, present: bool = False):
        self.cases = hillside_cases(case_dir)
        if not self.cases:
            raise CaseError(f"{case_dir}: no case file over a named topography "
                            "([terrain] bed = 'hockey_stick', ...) for the hillside page")
        self.present = present
        self._controls()
        self.release = ColumnDataSource({"xs": [[]], "ys": [[]]})
        # data ranges, from the terrain's image: the plan views keep its aspect
        # (match_aspect widens one range); the long section has its own x range
        self.x_range, self.y_range = (DataRange1d(range_padding=0.0) for _ in range(2))
        self.plans = {m: PlanView(m, LABELS[m], self.release, self.x_range, self.y_range,
                                  draw=(m == HILLSIDE_MODELS[0]))
                      for m in HILLSIDE_MODELS}
        self.section, self.section_depths, self.section_bed = section_figure(Range1d(0, 1))
        self.status = pn.pane.HTML("", css_classes=["pdeflow-status"],
                                   sizing_mode="stretch_width")
        self.warnings = pn.pane.HTML("", css_classes=["pdeflow-warnings"], visible=False,
                                     sizing_mode="stretch_width", styles=WARNING_STYLE)
        self.table = Div(text="", css_classes=["pdeflow-summary"], width=TABLE_WIDTH_PX)
        self.run: LiveRun | None = None
        self._shown = 0  # frames of the current run drawn so far
        self._ticker: Any = None
        self.set_present(present)
        self.load_terrain()
        if served():
            pn.state.on_session_destroyed(lambda _context: self.cancel())

    # --- controls -------------------------------------------------------------------------
    def _controls(self) -> None:
        w = pn.widgets
        self.case_select = w.Select(name="terrain (case file)", options=list(self.cases),
                                    css_classes=["pdeflow-terrain"], sizing_mode="stretch_width")
        self.thickness = w.FloatSlider(name="release thickness ⊥ slope [m]", value=2.0,
                                       start=THICKNESS_RANGE[0], end=5.0, step=0.1,
                                       css_classes=["pdeflow-thickness"],
                                       sizing_mode="stretch_width")
        self.models = w.CheckButtonGroup(name="models", value=list(HILLSIDE_MODELS),
                                         button_type="primary",
                                         options={LABELS[m]: m for m in HILLSIDE_MODELS},
                                         css_classes=["pdeflow-models"])
        self.law = w.Select(name="basal friction law", options=list(HILLSIDE_LAWS),
                            value="coulomb", css_classes=["pdeflow-law"],
                            sizing_mode="stretch_width")
        self.angle = w.FloatSlider(name="friction angle [deg]", value=25.0,
                                   start=FRICTION_RANGE[0], end=45.0, step=0.5,
                                   css_classes=["pdeflow-angle"], sizing_mode="stretch_width")
        self.cells = w.IntSlider(name="cells down the path", value=120,
                                 start=CELLS_RANGE[0], end=CELLS_RANGE[1], step=10,
                                 css_classes=["pdeflow-cells"], sizing_mode="stretch_width")
        # above the figures, beside the side bar's toggle: in view when the controls
        # are folded away (presentation mode)
        self.run_button = w.Button(name="▶ run", button_type="primary", width=140,
                                   height=30, css_classes=["pdeflow-run"])
        self.download = w.FileDownload(callback=self._case_file, filename="hillside.toml",
                                       label="download the case file",
                                       css_classes=["pdeflow-download"],
                                       sizing_mode="stretch_width")
        self.command = pn.pane.HTML("", css_classes=["pdeflow-command"],
                                    sizing_mode="stretch_width")
        self.player = w.Player(start=0, end=1, value=0, interval=FRAME_MS,
                               loop_policy="once", show_loop_controls=False, visible=False,
                               visible_buttons=["first", "previous", "pause", "play",
                                                "next", "last"],
                               css_classes=["pdeflow-player"], sizing_mode="stretch_width")
        self.run_button.on_click(lambda _event: self.start())
        self.case_select.param.watch(lambda _e: self.load_terrain(), "value")
        self.cells.param.watch(lambda _e: self.load_terrain(keep_release=True),
                               "value_throttled")
        self.player.param.watch(lambda e: self._scrub(e.new), "value")

    def setup(self) -> HillsideSetup:
        """The run the controls and the drawn polygon stand for."""
        xs, ys = (self.release.data.get(k, [[]]) for k in ("xs", "ys"))
        vertices = tuple(zip(map(float, xs[-1]), map(float, ys[-1]), strict=True)) \
            if xs else ()
        return HillsideSetup(self.cases[self.case_select.value], vertices,
                             thickness=float(self.thickness.value),
                             models=tuple(m for m in HILLSIDE_MODELS if m in self.models.value),
                             friction_law=self.law.value,
                             friction_deg=float(self.angle.value), cells=int(self.cells.value))

    def _case_file(self) -> io.StringIO:
        setup = self.setup()
        self.download.filename = setup.file_name
        return io.StringIO(setup.toml())

    # --- terrain ---------------------------------------------------------------------------
    def load_terrain(self, keep_release: bool = False) -> None:
        """Draw the chosen terrain at the chosen resolution (and, unless
        ``keep_release``, the case's own release)."""
        self.cancel()
        path = self.cases[self.case_select.value]
        case = load_case(path)
        if not keep_release:
            ring = release_polygon(case)
            self.release.data = {"xs": [[p[0] for p in ring]], "ys": [[p[1] for p in ring]]}
        try:
            grid_case = HillsideSetup(path, release_polygon(case),
                                      cells=int(self.cells.value)).case()
        except (CaseError, ValueError) as err:
            self._say(f"<b>cannot draw this terrain:</b> {escape(str(err))}")
            return
        bed = centre_values(grid_case.terrain_corners())
        self.grid = grid_case
        dx, dy = grid_case.dx, grid_case.dy
        x = (np.arange(bed.shape[0]) + 0.5) * dx
        y = (np.arange(bed.shape[1]) + 0.5) * dy
        shade, lines = hillshade_rgba(bed, dx, dy), contour_lines(bed, x, y)
        length, width = grid_case.length, grid_case.width
        with pn.io.hold():
            self.section.x_range.start, self.section.x_range.end = 0.0, length
            for plan in self.plans.values():
                plan.show_terrain(shade, lines, length, width)
            row = self._section_row(bed.shape[1])
            self.section_bed.data = {"x": x, "z": bed[:, row],
                                     "base": np.full(x.size, float(bed.min()))}
            self.section.extra_y_ranges["bed"].start = float(bed.min())
            self.section.extra_y_ranges["bed"].end = float(bed.max()) + 1.0
            self.section_depths.data = {"x": x, **{m: np.full(x.size, np.nan)
                                                   for m in MODEL_COLOURS}}
            self.table.text = ""
            self.player.visible = False
            # Bokeh 3's PolyDrawTool starts and ends a polygon with a press (held 300
            # ms); a click adds a vertex only while drawing, a double-click nothing
            self._say("<span class='pdeflow-hint'>Draw a release on the plan view (press "
                      "and hold at its first corner, click the next ones, press and hold "
                      "at the last; drag it to move it), then press <b>▶ run</b>.</span>")
        self.command.object = ""

    def _section_row(self, ny: int) -> int:
        """The row of cells along the path through the release's centre."""
        ys = self.release.data.get("ys", [[]])
        y = float(np.mean(ys[-1])) if ys and len(ys[-1]) else 0.5 * self.grid.width
        return int(np.clip(y // self.grid.dy, 0, ny - 1))

    # --- running ---------------------------------------------------------------------------
    def start(self) -> None:
        """Run what the controls say (a one-line reason instead if it cannot run)."""
        self.cancel()
        try:
            run = LiveRun(self.setup())
            QUEUE.submit(run)
        except (CaseError, ValueError, QueueFull) as err:
            self._say(f"<b>cannot run this:</b> {escape(str(err))}")
            return
        self.run, self._shown = run, 0
        setup = run.setup
        self.command.object = (f"<p>The same run on the command line, with the case file "
                               f"below:<br><code>{escape(setup.command())}</code></p>")
        top = 1.5 * setup.thickness
        for m, plan in self.plans.items():
            plan.colours.high = top
            plan.figure.visible = m in run.models
            plan.show_outline({"xs": [], "ys": []})
        self.section.y_range.start, self.section.y_range.end = 0.0, top
        self.table.text = ""
        self.warnings.visible = False
        self.player.visible = False
        if self._ticker is None and served():
            self._ticker = pn.state.add_periodic_callback(self.tick, period=FRAME_MS)
        self.tick()

    def cancel(self) -> None:
        """Cancel the page's run (a new one replaces it, or the tab closed)."""
        if self.run is not None and not self.run.finished:
            QUEUE.cancel(self.run)

    def tick(self) -> None:
        """Draw the next frame of the current run, or say where it stands."""
        run = self.run
        if run is None:
            return
        place = QUEUE.position(run)
        if run.status == "queued":
            self._say(f"waiting for a free core: {place or 1} in the queue"
                      if place else "starting")
            return
        count = run.frame_count()
        if self._shown < count:
            self.draw(self._shown)
            self._shown += 1
        elif run.finished:
            self._finish(run)
        elif self._shown == 0:
            self._say("computing the first frame (the first run on a machine compiles "
                      "the 2D kernels, up to a minute)")

    def draw(self, k: int) -> None:
        """Draw frame ``k`` of the current run: every model's depth and front."""
        run = self.run
        if run is None:
            return
        frames = run.frame(k)
        threshold = run.case.front_threshold
        length, width = run.case.length, run.case.width
        section: dict[str, Any] = {"x": self.section_depths.data["x"]}
        row = self._section_row(run.case.cells_y)
        x = (np.arange(run.case.cells) + 0.5) * run.case.dx  # from the grid's corner
        t = 0.0
        fronts = []
        for m in MODEL_COLOURS:
            frame = frames.get(m)
            if frame is None:
                section[m] = np.full(run.case.cells, np.nan)
                continue
            t = max(t, frame.t)
            front = front_x(x, frame.depth, threshold, run.case.dx)
            self.plans[m].show_depth(frame.depth, threshold, length, width, front)
            section[m] = np.where(frame.depth[:, row] > threshold, frame.depth[:, row],
                                  np.nan)
            fronts.append(f"{LABELS[m]} {front:.0f} m" if front is not None else "")
        if len(section["x"]) == run.case.cells:
            self.section_depths.data = section
        self._say(f"t = {t:.1f} s{'' if run.finished else ' (computing)'}; fronts: "
                  f"<span class='pdeflow-fronts'>{', '.join(fronts)}</span>")

    def _scrub(self, k: int) -> None:
        if self.run is not None and self.run.finished and self.player.visible:
            self.draw(int(k))

    def _finish(self, run: LiveRun) -> None:
        """The run has ended and every frame is drawn: the outlines, the numbers."""
        if self._ticker is not None:
            self._ticker.stop()
            self._ticker = None
        if run.status != "done":
            self._say(f"<b>the run {escape(run.status)}:</b> {escape(run.message)}")
            return
        x = (np.arange(run.case.cells) + 0.5) * run.case.dx
        y = (np.arange(run.case.cells_y) + 0.5) * run.case.dy
        last = run.frame(run.frame_count() - 1)
        for m, frame in last.items():
            self.plans[m].show_outline(contour_lines(frame.depth, x, y,
                                                     [run.case.front_threshold]))
        self.table.text = self._table_html(run)
        self.warnings.object = warnings_html(run.warnings)
        self.warnings.visible = bool(run.warnings)
        self.player.end = max(run.frame_count() - 1, 1)
        self.player.value = run.frame_count() - 1
        self.player.visible = True
        # the stop time, as the table (one end time on the page, issue 38)
        ends = ", ".join(f"{LABELS[m]} at rest at {s['stop_time']:.1f} s (the stop time)"
                         if s.get("stop_time") is not None
                         else f"{LABELS[m]} still moving at t_end"
                         for m, s in run.summaries.items())
        self._say(f"done in {run.wall_time_s:.1f} s of computing: {ends}")

    def _table_html(self, run: LiveRun) -> str:
        head = "".join(f"<th>{LABELS[m]}</th>" for m in run.summaries)
        rows = []
        for key, label, fmt in SUMMARY_ROWS:
            cells = []
            for s in run.summaries.values():
                v = s.get(key)
                cells.append("-" if v is None else fmt.format(v))
            rows.append(f"<tr><td>{label}</td>" + "".join(f"<td>{c}</td>" for c in cells)
                        + "</tr>")
        return (f"<table class='pdeflow-table'><tr><th></th>{head}</tr>{''.join(rows)}"
                f"</table><p style='color:#666'>run-out: the front (last cell deeper "
                f"than {run.case.front_threshold:g} m) past the release's lowest point; "
                f"stop time: when every cell came to rest.</p>")

    # --- page -------------------------------------------------------------------------------
    def _say(self, html: str) -> None:
        self.status.object = html

    def set_present(self, present: bool) -> None:
        """Presentation mode: larger fonts and lines, taller figures."""
        self.present = present
        figures = [p.figure for p in self.plans.values()] + [self.section]
        style_figures(figures, present)
        for p in self.plans.values():
            p.figure.height = PLAN_HEIGHT_PX[present]
        self.section.height = SECTION_HEIGHT_PX[present]

    def panel(self) -> pn.Row:
        sidebar = pn.Column("### hillside", self.case_select, self.models, self.thickness,
                            self.law, self.angle, self.cells, self.download,
                            self.command, sizing_mode="stretch_width")
        plans = pn.Row(*(pn.pane.Bokeh(p.figure, sizing_mode="stretch_width")
                         for p in self.plans.values()), sizing_mode="stretch_width")
        # the section and the table side by side: on a projector's 768 px the table
        # stays above the fold
        below = pn.Row(pn.pane.Bokeh(self.section, sizing_mode="stretch_width"),
                       pn.pane.Bokeh(self.table),
                       sizing_mode="stretch_width")
        figures = pn.Column(self.status, self.warnings, plans, self.player, below,
                            sizing_mode="stretch_width")
        self.layout = PageLayout(sidebar, figures, top=self.run_button)
        if self.present:
            self.layout.show_sidebar(False)
        return self.layout.row
