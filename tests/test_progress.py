"""Progress while kernels compile and runs go (issue 14, part C): the first run says that
it compiles, the estimate of the remaining time leaves the compilation out, the bar
of a plain ``eq.solve`` (the README's snippet) ends at rest, and ``pdeflow run`` shows it
on a terminal or when asked."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from pde import CartesianGrid
from pde.trackers.base import TrackerBase

import pdeflow
from pdeflow.cases import load_case
from pdeflow.cli import build_parser
from pdeflow.numerics import warmup
from pdeflow.solvers import fv_split
from pdeflow.trackers import ProgressBar

ROOT = Path(__file__).parents[1]
RITTER = ROOT / "cases" / "ritter_dam_break.toml"


def _readme_state():
    grid = CartesianGrid([[0, 7]], 140)
    x = grid.axes_coords[0]
    eq = pdeflow.TwoLayerGranular(bc=("wall", "open"))
    h2 = np.clip((1 - x) * np.tan(np.radians(60)), 0, 2.0)
    return eq, eq.make_state(grid, h1=np.where(x < 1, 2 - h2, 0), h2=h2)


def test_readme_snippet_progress_bar_ends_at_rest(capsys):
    """``eq.solve`` with its default trackers: pdeflow's bar, filled when the run stops
    at rest at 1.36 s of t_range = 5 s (py-pde's own bar stayed at 27 %)."""
    eq, state = _readme_state()
    eq.solve(state, t_range=5, solver="fv-split", cfl=0.3)
    last = capsys.readouterr().err.replace("\r", "\n").strip().splitlines()[-1]
    assert last.lstrip().startswith("100%") and "at rest at t = 1.3" in last, last


def test_named_progress_tracker_is_replaced():
    from pdeflow.models.base import _named_progress

    trackers = _named_progress("auto", (1.0, 3.0))
    assert isinstance(trackers[0], ProgressBar) and trackers[1] == "consistency"
    assert trackers[0].interrupt.dt == pytest.approx(0.02)
    assert _named_progress(None, 5) is None
    assert _named_progress(["consistency"], 5) == ["consistency"]


def test_progress_bar_says_it_compiles_and_restarts_its_clock(monkeypatch, capsys):
    """While the kernels are compiled the bar says so; its clock starts after the
    first interval, so the remaining time comes from the run alone."""
    monkeypatch.setattr(warmup, "status", lambda work=None: warmup.COLD)
    eq, state = _readme_state()
    bar = ProgressBar(0.5, label="two_layer")
    seen = []

    class Spy(TrackerBase):
        def handle(self, field, t):
            seen.append((t, bar.progress_bar.desc, bar.progress_bar.start_t,
                         bar.progress_bar.initial))

    eq.solve(state, t_range=5, solver="fv-split", tracker=[bar, Spy(0.5)])
    # (tqdm appends ": " to a description)
    assert seen[0][1].startswith("two_layer: compiling kernels (once per machine)")
    assert seen[1][0] == pytest.approx(0.5) and seen[1][1].rstrip(": ") == "two_layer"
    start0, start1 = seen[0][2], seen[1][2]
    assert start1 > start0 and seen[1][3] == pytest.approx(0.5)  # clock restarted at 0.5 s
    assert all(s[2] == start1 for s in seen[1:])  # only once
    assert "at rest" in capsys.readouterr().err


def test_each_update_draws_the_bar_once_with_its_label(monkeypatch):
    """py-pde's own update draws the bar with an empty label; the bar here draws every
    update once, with the model's label (no flicker)."""
    monkeypatch.setattr(warmup, "status", lambda work=None: warmup.READY)
    eq, state = _readme_state()
    bar = ProgressBar(0.5, label="two_layer")
    drawn: list[str] = []

    class Spy(TrackerBase):
        def initialize(self, field, info=None):
            tqdm_bar = bar.progress_bar
            refresh = tqdm_bar.refresh

            def counted(*args, **kwargs):
                drawn.append(tqdm_bar.desc)
                return refresh(*args, **kwargs)

            monkeypatch.setattr(tqdm_bar, "refresh", counted)
            return super().initialize(field, info)

        def handle(self, field, t):
            pass

    eq.solve(state, t_range=2, solver="fv-split", tracker=[bar, Spy(0.5)])
    updates = [d for d in drawn if d]
    assert updates and all(d.rstrip(": ") == "two_layer" for d in drawn[:-1])
    assert len(drawn) <= 2 * len(updates)  # at most the close's own draw besides


def test_prepare_says_when_it_compiles(monkeypatch):
    """``pdeflow run`` compiles (or loads) the kernels before its runs and, when it has
    to compile them, says so with the time it took."""
    log = io.StringIO()
    eq, state = _readme_state()
    stepper = fv_split.split_stepper(eq, eq.metric(state.grid))
    monkeypatch.setattr(warmup, "status", lambda work=None: warmup.COLD)
    seconds = warmup.prepare(stepper, log=log)
    assert seconds > 0
    text = log.getvalue()
    assert text.startswith("pdeflow: compiling numba kernels (once per machine) ...")
    assert f"done in {seconds:.1f} s" in text
    monkeypatch.setattr(warmup, "status", lambda work=None: warmup.CACHED)
    log = io.StringIO()
    warmup.prepare(stepper, log=log)
    assert log.getvalue() == ""  # loading from the disk cache is quick: nothing to say


def test_kernels_are_loaded_before_the_wall_time_starts():
    from pdeflow.simulate import run_model

    run_model(load_case(RITTER, ["grid.cells=20", "output.snapshot_times=[]"]),
              "single_layer")
    assert warmup.status() == warmup.READY


def test_progress_bar_only_on_a_terminal_or_asked(monkeypatch):
    from pdeflow.cli import _run_trackers
    from pdeflow.trackers import ProgressBar as ProgressTracker

    case = load_case(RITTER)
    parser = build_parser()

    def kinds(argv):
        args = parser.parse_args(["run", str(RITTER), *argv])
        return [type(t) for t in _run_trackers(args, case, "single_layer", True)]

    monkeypatch.setattr("sys.stdout.isatty", lambda: False)
    assert ProgressTracker not in kinds([])
    assert ProgressTracker in kinds(["--progress"])
    monkeypatch.setattr("sys.stdout.isatty", lambda: True)
    assert ProgressTracker in kinds([])
    assert ProgressTracker not in kinds(["--no-progress"])
    assert ProgressTracker not in kinds(["-q"])


def test_movie_shows_progress_drawn_once_per_update(tmp_path, capsys, monkeypatch):
    """``--movie`` draws a frame per interval, seconds in all: the bar is shown without
    a terminal too, labelled with the movie, every draw with that label (py-pde's own
    draw with an empty label came first), and it ends at 100 %; the movie and the
    numbers are those of a run without the bar."""
    pytest.importorskip("PIL")
    from pdeflow.cli import main

    monkeypatch.setattr("sys.stdout.isatty", lambda: False)
    movie = tmp_path / "ritter.gif"
    common = ["run", str(RITTER), "--set", "grid.cells=40", "--live-every", "0.05"]
    assert main([*common, "--movie", str(movie), "--summary",
                 str(tmp_path / "with.json")]) == 0
    err = capsys.readouterr().err
    draws = [d.strip() for d in err.replace("\n", "\r").split("\r") if d.strip()]
    bar = [d for d in draws if "|" in d]
    assert bar and all(d.startswith("single_layer, drawing ritter.gif") for d in bar), draws
    assert "100%" in bar[-1]
    # each state of the bar drawn once (py-pde's first call at t = 0 repeated the first)
    assert len(bar) == len(set(bar)), [d for d in bar if bar.count(d) > 1]
    assert movie.is_file()
    assert main([*common, "--no-progress", "--summary", str(tmp_path / "without.json")]) == 0
    import json

    def numbers(name):
        s = json.loads((tmp_path / name).read_text())["models"]["single_layer"]
        return {k: v for k, v in s.items() if k != "wall_time_s"}

    assert numbers("with.json") == numbers("without.json")


def test_replayed_movie_counts_its_frames(tmp_path, capsys):
    pytest.importorskip("PIL")
    pytest.importorskip("h5py")
    from pdeflow.cli import main

    store = tmp_path / "r.h5"
    assert main(["run", str(RITTER), "--set", "grid.cells=40", "--store", str(store),
                 "--store-every", "0.1", "--quiet"]) == 0
    capsys.readouterr()
    assert main(["plot", str(store), "--movie", str(tmp_path / "r.gif")]) == 0
    err = capsys.readouterr().err.replace("\n", "\r").split("\r")
    bar = [d.strip() for d in err if "|" in d]
    assert bar and bar[-1].startswith("drawing r.gif: 100%"), bar


def test_sweep_and_convergence_show_a_bar_over_their_runs(capsys):
    """A sweep counts its runs, a convergence study its grid levels, on stderr; the
    numbers are those of a run without the bar."""
    from pdeflow.analysis.convergence import converge
    from pdeflow.analysis.sweep import run_sweep

    case = load_case(ROOT / "cases" / "collapse_sweep.toml",
                     ["sweep.aspect_ratios=[2, 4]", "grid.dx=0.05",
                      "case.models=['single_layer']"])
    quiet = run_sweep(case)
    capsys.readouterr()
    shown = run_sweep(case, progress=True)
    err = capsys.readouterr().err
    assert "sweep" in err and "2/2" in err
    assert [r["r"] for r in shown["models"]["single_layer"]["runs"]] == \
        [r["r"] for r in quiet["models"]["single_layer"]["runs"]]
    converge(load_case(RITTER, ["grid.dx=0.05"]), 2, "single_layer", progress=True)
    assert "grid levels" in capsys.readouterr().err


def test_commands_draw_the_bar_only_on_a_terminal(tmp_path, capsys):
    """``pdeflow sweep`` into a pipe (a test, a script) prints no bar."""
    from pdeflow.cli import main

    main(["sweep", str(ROOT / "cases" / "collapse_sweep.toml"), "--set",
          "sweep.aspect_ratios=[2]", "--set", "grid.dx=0.05"])
    assert "sweep:" not in capsys.readouterr().err
