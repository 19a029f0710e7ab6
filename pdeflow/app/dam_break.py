"""Page 1, dam break: sliders for a case's parameters, both models animated, the summary.

Every change runs each model of the case twice with :func:`pdeflow.simulate.run_model`:
once exactly as ``pdeflow run`` does (the summary table, the same numbers as the command
line printed under it, and the final state: these go to the browser at once), and then
once with a :class:`~pdeflow.trackers.FextraStorageTracker` that records the frames of the
animation. Observers do not change the solver's steps (docs/user_guide.md), so that run
takes the same steps as the first; its frames are the states after the first step at or
past each frame time (fv-split's ``outputs="step"``: states of the scheme, hyperbolic
after the restoration), shown at that frame time; the numbers and the last frame come
from the first run.
Depths in m, velocities in m/s, F_extra/rho1 in m^2/s^2, times in s.
"""

from __future__ import annotations

import io
import time
from dataclasses import dataclass, field
from html import escape
from pathlib import Path
from typing import Any

import numpy as np
import panel as pn
import param
from bokeh.models import ColumnDataSource, Div, LegendItem, Range1d, Span
from bokeh.plotting import figure

from .. import systems
from ..cases import BASELINE_MODEL, PAPER_MODEL, Case, CaseError
from ..checks import run_warnings
from ..numerics.geometry import COORDINATES
from ..numerics.state import velocity_profile
from ..plotting import DRY
from ..simulate import Run, RunResult, run_model
from ..solvers.fv_split import SimulationBlowUp
from ..summary_table import print_summary
from ..trackers import FextraStorageTracker
from .controls import ParameterControls, command_line, list_cases, served
from .look import PageLayout, legend_outside, style_figures
from .plan_view import PlanView

FRAMES_PER_T_END = 250
"""Frame interval of the animation: t_end / this [s] (5.1: 0.02 s, ~70 frames to rest)."""
COLOURS = {"upper": "#ff7f0e", "lower": "#8c564b", "single": "black", "fextra": "#d62728"}
"""As the figures of pdeflow.plotting: upper layer orange, lower brown, single layer black."""
SEND_MS = 40
"""Time given to the server to send a new picture before it records the frames [ms]
(the frames' run would otherwise hold the message back until it is done)."""
LABELS = {m: systems.get(m).label for m in (PAPER_MODEL, BASELINE_MODEL)}
"""The models as the pages name them."""
FEXTRA_TITLE = "F_extra keeps the layers hyperbolic"  # fits 400 px
FRONTS_LABEL = "final fronts (dotted)"  # both models', each in its layer's colour
FIGURES_MIN_PX = 400
"""The narrowest the figures get before the results wrap under them [px]: legends
above the plots, the results stand beside them on 1024 px with the side bar shown."""
FIGURE_HEIGHTS = {"depths": (220, 205), "velocities": (165, 172), "fextra": (195, 220)}
"""Heights of the three figures [px], normal and presentation mode (larger upright y
labels): on a projector's 768 px they fit under the player, in either mode."""
DEPTH_LEGEND_COLUMNS = (2, 4)
"""Entries per row of the depth legend, normal and presentation mode (full width)."""


@dataclass
class DamBreakRun:
    """One run of every model of a case: summary runs and animation frames."""

    case: Case
    case_path: Path
    overrides: list[str]
    results: dict[str, RunResult]
    """per model, the run exactly as ``pdeflow run`` makes it (summary, final state)"""
    times: np.ndarray
    """frame times [s]: multiples of t_end/FRAMES_PER_T_END, and each model's end
    (only the ends until :func:`add_frames` has run)"""
    states: dict[str, np.ndarray] = field(default_factory=dict)
    """per model, the state at every frame time (frames, fields, cells); a model that
    has stopped keeps its final state"""
    fextra: np.ndarray | None = None
    """F_extra/rho1 of the two-layer run at every frame time (frames, cells)"""
    wall_time_s: float = 0.0
    """wall time of the summary's runs of all models [s]"""
    warnings: list[str] = field(default_factory=list)
    """the lines ``pdeflow run`` prints as ``pdeflow: warning: ...`` for the same case
    and overrides (material leaving the domain, still moving at t_end, ...)"""

    @property
    def x(self) -> np.ndarray:
        return next(iter(self.results.values())).x

    @property
    def summary(self) -> dict[str, Any]:
        """The case name and the per-model summaries, as in ``pdeflow run --summary``."""
        return {"case": self.case.name,
                "models": {m: r.summary for m, r in self.results.items()}}

    def table(self) -> str:
        """The table ``pdeflow run`` prints for the same case and overrides."""
        out = io.StringIO()
        print_summary(self.summary, out)
        return out.getvalue()


def _frames(case: Case, model: str) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(t, state, F_extra/rho1) every t_end/FRAMES_PER_T_END s, from a run of its own."""
    c = case.copy()
    c.data.setdefault("output", {})["snapshot_times"] = []
    c.validate()
    snaps = FextraStorageTracker(case.t_end / FRAMES_PER_T_END)
    run = Run(c, model)
    kwargs = run.solver_arguments()
    if kwargs["solver"] == "fv-split":
        # frames that are states of the scheme (the hyperbolicity page shows a cell
        # after its restoration), at the true time of the first step past each time
        kwargs["outputs"] = "step"
    run.pde.solve(run.state, t_range=c.t_end, tracker=[snaps], **kwargs)
    return [(t, d, f) for t, (d, f) in sorted(snaps.snapshots.items())]


def simulate(case: Case, case_path: Path, overrides: list[str],
             frames: bool = True) -> DamBreakRun:
    """Run every model of ``case`` (loaded with ``overrides``) as ``pdeflow run`` does;
    with ``frames`` also record the animation (:func:`add_frames`)."""
    lines: list[str] = []
    wall0 = time.perf_counter()
    with run_warnings(lines.append):  # what the command line would print
        results = {m: run_model(case, m) for m in case.models}
    run = DamBreakRun(case, case_path, list(overrides), results, np.zeros(0),
                      warnings=lines)
    _set_frames(run, {m: [] for m in results})
    run.wall_time_s = time.perf_counter() - wall0
    if frames:
        add_frames(run)
    return run


def add_frames(run: DamBreakRun) -> None:
    """Record the animation of ``run``: the frames of a second run of every model before
    its end, and the final state of the summary's run (so the last frame, the deposit,
    is the one the numbers describe)."""
    _set_frames(run, {m: _frames(run.case, m) for m in run.results})


def _set_frames(run: DamBreakRun,
                frames: dict[str, list[tuple[float, np.ndarray, np.ndarray]]]) -> None:
    """Put per-model frames (t, state, F_extra) before each model's end, and its final
    state, on the common times of ``run``: the multiples k dt_f of the frame interval,
    where each model shows its first state at or past k dt_f (within one of its steps:
    the models' steps differ, and their true times would make two frames of each), and
    the models' ends; a model that has stopped keeps its end."""
    interval = run.case.t_end / FRAMES_PER_T_END
    series = {}
    for m, res in run.results.items():
        items = [(interval * np.floor(t / interval + 1e-9), d, f) for t, d, f in frames[m]
                 if t < res.t_final - 1e-9]
        items.append((res.t_final, res.state.data, res.fextra_over_rho1))
        series[m] = items
    run.times = np.unique(np.round([f[0] for items in series.values() for f in items], 9))
    for m, items in series.items():
        t = np.array([f[0] for f in items])
        idx = np.clip(np.searchsorted(t, run.times + 1e-9, side="right") - 1, 0, None)
        run.states[m] = np.array([items[i][1] for i in idx])
        if m == PAPER_MODEL:
            run.fextra = np.array([items[i][2] for i in idx])


def opening_frame(run: DamBreakRun) -> int:
    """The frame a page opens on: the one where the fastest cell of any model is
    fastest (the collapse in full motion, not the deposit at rest)."""
    speed = np.zeros(len(run.times))
    for states in run.states.values():
        for k in range(0, states.shape[1], 2):
            u = velocity_profile(states[:, k], states[:, k + 1], fill=0.0)
            speed = np.maximum(speed, np.abs(u).max(axis=1))
    return int(np.argmax(speed))


class SharedRun(param.Parameterized):
    """The current dam-break run of a session, for the pages that show it too."""

    run = param.Parameter(default=None, doc="the last DamBreakRun of the dam-break page")


class DamBreakPage:
    """The dam-break page of one session (build it once the kernels are loaded)."""

    def __init__(self, case_dir: Path, shared: SharedRun | None = None,
                 default: str = "paper_5_1_dam_break.toml", present: bool = False):
        cases = list_cases(case_dir, lambda c: bool(c.models))
        self.shared = shared or SharedRun()
        self.controls = ParameterControls(cases, default if default in cases
                                          else next(iter(cases)), self.rerun)
        self.run: DamBreakRun | None = None
        # shown only with a message: empty, its margins took height from the figures
        self.status = pn.pane.HTML("", css_classes=["pdeflow-status"], visible=False,
                                   sizing_mode="stretch_width")
        self.warnings = pn.pane.HTML("", css_classes=["pdeflow-warnings"],
                                     sizing_mode="stretch_width", visible=False,
                                     styles=WARNING_STYLE)
        self.present = present
        self._opened = False  # the first frames open playing, later ones on the deposit
        # a plain Bokeh Div: its text goes out in the same message as the figures' data
        # (a Panel HTML pane sends its first change separately, later)
        self.summary = Div(text="", css_classes=["pdeflow-summary"],
                           sizing_mode="stretch_width")
        self.player = pn.widgets.Player(
            # no label: the time is in the title of the first figure
            start=0, end=1, value=0, interval=60, loop_policy="once",
            show_loop_controls=False, css_classes=["pdeflow-player"],
            visible_buttons=["first", "previous", "pause", "play", "next", "last"],
            sizing_mode="stretch_width")
        self.player.param.watch(lambda e: self.show_frame(e.new), "value")
        self._figures()
        self.set_present(present)
        self.rerun()

    # --- figures --------------------------------------------------------------------------
    def _figures(self) -> None:
        xr = Range1d(0, 1)  # shared by the panels; set to the domain by each run
        opts = {"sizing_mode": "stretch_width",
                "toolbar_location": "right", "tools": "pan,wheel_zoom,box_zoom,reset,save",
                "x_range": xr}
        zero = np.zeros(2)
        self.src_two = ColumnDataSource({k: zero for k in
                                         ("x", "zero", "h2", "top", "u1", "u2", "f")})
        self.src_one = ColumnDataSource({k: zero for k in ("x", "h", "u")})
        # short: upright, the label must fit the figure's height on a projector
        fh = figure(title="", y_axis_label="depth ⊥ bed [m]",
                    y_range=Range1d(0, 1), height=FIGURE_HEIGHTS["depths"][0], **opts)
        fh.varea("x", "zero", "h2", source=self.src_two, color=COLOURS["lower"],
                 alpha=0.6, legend_label="lower layer h2")
        fh.varea("x", "h2", "top", source=self.src_two, color=COLOURS["upper"],
                 alpha=0.5, legend_label="upper layer h1")
        fh.line("x", "h", source=self.src_one, color=COLOURS["single"], line_width=2,
                legend_label="single layer h")
        fu = figure(y_axis_label="velocity [m/s]", y_range=Range1d(0, 1),
                    height=FIGURE_HEIGHTS["velocities"][0], **opts)
        fu.line("x", "u1", source=self.src_two, color=COLOURS["upper"], line_width=2,
                legend_label="u1 (upper)")
        fu.line("x", "u2", source=self.src_two, color=COLOURS["lower"], line_width=2,
                line_dash="dashed", legend_label="u2 (lower)")
        fu.line("x", "u", source=self.src_one, color=COLOURS["single"], line_width=2,
                legend_label="u single layer")
        ff = figure(x_axis_label="x [m]", y_axis_label="F_extra/ρ1 [m²/s²]",
                    title=FEXTRA_TITLE, y_range=Range1d(0, 1),
                    height=FIGURE_HEIGHTS["fextra"][0], **opts)
        # one line, named by the y axis and the title: no legend row over the plot
        ff.line("x", "f", source=self.src_two, color=COLOURS["fextra"], line_width=2)
        self.fronts = {m: Span(location=0, dimension="height", line_dash="dotted",
                               line_width=2, visible=False,
                               line_color=COLOURS["upper" if m == PAPER_MODEL
                                                  else "single"])
                       for m in (PAPER_MODEL, BASELINE_MODEL)}
        # a Span has no legend entry: empty lines in its styles stand for it, one entry
        # for both fronts (coloured as their layers), so that the legend takes 2 rows
        stand_ins = []
        for s in self.fronts.values():
            fh.add_layout(s)
            stand_ins.append(fh.line([np.nan], [np.nan], line_dash="dotted", line_width=2,
                                     line_color=s.line_color))
        fh.legend.items.append(LegendItem(label=FRONTS_LABEL, renderers=stand_ins))
        for f, ncols in ((fh, DEPTH_LEGEND_COLUMNS[0]), (fu, 3)):
            f.legend.click_policy = "hide"
            legend_outside(f, "above", ncols)  # never over the data, nor beside it
        for f, name in ((fh, "depths"), (fu, "velocities"), (ff, "fextra")):
            f.css_classes = [f"pdeflow-{name}"]  # for the browser tests
        self.fig_h, self.fig_u, self.fig_f = fh, fu, ff
        # an axisymmetric run seen from above, hidden while the runs are planar
        self.plan = PlanView(self.present)

    # --- running --------------------------------------------------------------------------
    def rerun(self) -> None:
        """Run the case with the sliders' values and show it (errors as one line)."""
        c = self.controls
        try:
            overrides = c.overrides()
            case = c.load()
            run = simulate(case, c.case_path, overrides, frames=False)
        except (CaseError, SimulationBlowUp, ValueError) as err:
            self._say(f"<b>cannot run this:</b> {escape(str(err))}")
            return
        with pn.io.hold():
            self.pause()
            self._show_run(run)
        # the final state and the numbers go out first; the animation's frames (a second
        # run, a few times slower: it stops at every frame) follow once they are sent
        if served():
            pn.state.curdoc.add_timeout_callback(lambda: self._animate(run), SEND_MS)
        else:
            self._animate(run)

    def pause(self) -> None:
        """Stop the animation (a new run must not go on playing the old one's frames).
        The browser may have started it without the server's value changing: sent
        again either way."""
        self.player.direction = 0
        self.player.param.trigger("direction")

    def _say(self, html: str) -> None:
        """The status line above the figures (an error), or none."""
        self.status.object = html
        self.status.visible = bool(html)

    def set_present(self, present: bool) -> None:
        """Presentation mode: larger fonts and lines, the expert choices hidden."""
        self.present = present
        style_figures((self.fig_h, self.fig_u, self.fig_f), present)
        self.plan.set_present(present)
        for f, name in ((self.fig_h, "depths"), (self.fig_u, "velocities"),
                        (self.fig_f, "fextra")):
            f.height = FIGURE_HEIGHTS[name][present]
        self.fig_h.legend[0].ncols = DEPTH_LEGEND_COLUMNS[present]
        self.controls.set_present(present)

    def _animate(self, run: DamBreakRun) -> None:
        if run is not self.run:
            return  # a newer run replaced it meanwhile
        try:
            add_frames(run)
        except SimulationBlowUp as err:  # the frames' run differs a little
            self._say(f"<b>no animation:</b> {escape(str(err))}")
            return
        with pn.io.hold():
            self._show_frames(run)
        self.shared.run = run

    def _show_run(self, run: DamBreakRun) -> None:
        """A new run: its final state, fronts and summary."""
        self.run = run
        case = run.case
        self.fig_h.x_range.start, self.fig_h.x_range.end = case.x_start, case.x_start + case.length
        axisymmetric = case.geometry == "axisymmetric"
        self.fig_f.xaxis.axis_label = f"{COORDINATES[case.geometry]} [m]"
        for m, span in self.fronts.items():
            front = run.results[m].summary["front_position"] if m in run.results else None
            span.visible = front is not None
            span.location = front or 0.0
        initial = [case.initial_profiles(m) for m in run.results]
        depth = max(float(sum(p[k] for k in p if k.startswith("h")).max()) for p in initial)
        self.fig_h.y_range.start, self.fig_h.y_range.end = -0.02 * depth, 1.1 * depth
        self.plan.show_run(axisymmetric, depth, case.length)
        # the final state; the player and the velocity limits wait for the frames (each
        # change of the player would redraw it in the browser twice per move)
        self.show_frame(len(run.times) - 1)
        self.summary.text = self._summary_html(run)
        self._say("")
        self.warnings.object = warnings_html(run.warnings)
        self.warnings.visible = bool(run.warnings)

    def _show_frames(self, run: DamBreakRun) -> None:
        """The player's range, the last frame, and the velocity and F_extra limits over
        all frames (fixed, so that the animation does not jitter)."""
        last = len(run.times) - 1
        self.player.end = max(last, 1)
        # the page opens on the collapse in motion (and plays it, in a browser); after a
        # change it shows the final state, the deposit the numbers describe
        target = last if self._opened else opening_frame(run)
        if self.player.value == target:
            self.show_frame(target)
        else:
            self.player.value = target  # watched -> show_frame
        if not self._opened and served():
            self.player.value = 0
            self.player.direction = 1  # play
        self._opened = True
        us = [velocity_profile(s[:, k], s[:, k + 1], fill=np.nan) for s in run.states.values()
              for k in range(0, s.shape[1], 2)]
        lo = min(0.0, *(float(np.nanmin(u)) for u in us if np.isfinite(u).any()))
        hi = max(0.1, *(float(np.nanmax(u)) for u in us if np.isfinite(u).any()))
        self.fig_u.y_range.start, self.fig_u.y_range.end = lo - 0.05 * (hi - lo), 1.1 * hi
        fmax = float(run.fextra.max()) if run.fextra is not None else 0.0
        self.fig_f.y_range.start, self.fig_f.y_range.end = -0.05, 1.1 * max(fmax, 0.1)

    def show_frame(self, i: int) -> None:
        """Draw frame ``i`` of the current run (both models at one time)."""
        run = self.run
        if run is None:
            return
        i = int(min(max(i, 0), len(run.times) - 1))
        x = run.x
        nan = np.full(x.size, np.nan)
        two = run.states.get(PAPER_MODEL)
        if two is not None:
            h1, m1, h2, m2 = two[i]
            self.src_two.data = {"x": x, "zero": np.zeros_like(x), "h2": h2,
                                 "top": h1 + h2, "u1": velocity_profile(h1, m1, fill=np.nan),
                                 "u2": velocity_profile(h2, m2, fill=np.nan), "f": run.fextra[i]}
        else:
            self.src_two.data = {"x": x, "zero": nan, "h2": nan, "top": nan, "u1": nan,
                                 "u2": nan, "f": nan}
        one = run.states.get(BASELINE_MODEL)
        if one is not None:
            h, m = one[i]
            self.src_one.data = {"x": x, "h": np.where(h > DRY, h, np.nan),
                                 "u": velocity_profile(h, m, fill=np.nan)}
        else:
            self.src_one.data = {"x": x, "h": nan, "u": nan}
        if self.plan.visible:
            state = next(iter(run.states.values()))[i]  # the first model's
            self.plan.show_frame(run.x, state[::2].sum(axis=0), run.case.length)
        self.fig_h.title.text = (f"{run.case.name}: t = {run.times[i]:.2f} s"
                                 + (" (final state)" if i == len(run.times) - 1 else ""))

    def _summary_html(self, run: DamBreakRun) -> str:
        rows = []
        for m, r in run.results.items():
            s = r.summary
            stop = s.get("stop_time")
            # each time said what it is (issue 38: four end times on one page)
            state = (f"at rest at {stop:.4g} s (the stop time); the run ended at "
                     f"t = {r.t_final:.2f} s" if stop is not None
                     else "still moving at t_end")
            rows.append(f"<li><b>{LABELS[m]}</b>: {state}</li>")
        return (f"<ul>{''.join(rows)}</ul>"
                f"<pre class='pdeflow-table'>{escape(run.table())}</pre>"
                f"<p>The same numbers from the command line:<br>"
                f"<code class='pdeflow-command'>"
                f"{escape(command_line(run.case_path, run.overrides))}</code></p>"
                f"<p style='color:#666'>run-out = front - L0 (front: the last cell "
                f"deeper than the front threshold; '% mass': the distance from the wall "
                f"or the axis that holds that share of the mass). The runs took "
                f"{1000 * run.wall_time_s:.0f} ms; the animation's frames before the end "
                f"come from a second run that stops at every frame time.</p>")

    def panel(self) -> pn.Row:
        plots = pn.Column(self.status, self.warnings,
                          pn.pane.Bokeh(self.fig_h), pn.pane.Bokeh(self.fig_u),
                          pn.pane.Bokeh(self.fig_f), sizing_mode="stretch_width")
        results = pn.Column("### results", self.plan.pane,
                            pn.pane.Bokeh(self.summary), sizing_mode="stretch_width")
        self.layout = PageLayout(self.controls.panel("dam break"), plots, results,
                                 top=self.player, figures_min_px=FIGURES_MIN_PX)
        if self.present:
            self.layout.show_sidebar(False)
        return self.layout.row


WARNING_STYLE = {"background": "#fff3cd", "border": "2px solid #d62728",
                 "border-radius": "4px", "padding": "0 0.6em", "font-size": "115%"}
"""The warnings box: above the figures, where nobody overlooks it."""


def warnings_html(lines: list[str], about: str = "numbers") -> str:
    """Warning lines (``pdeflow: warning: ...``) as a page's box, saying their ``about``."""
    if not lines:
        return ""
    items = "".join(f"<li>{escape(line)}</li>" for line in lines)
    return (f"<p style='margin:0.4em 0'><b>The command line warns about these "
            f"{about}:</b></p><ul style='margin:0.2em 0 0.5em'>{items}</ul>")
