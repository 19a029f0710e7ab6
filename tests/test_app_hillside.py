"""The hillside page's machinery without a browser (issue 39): the case file it offers
for download, its checked setup, the run that streams frames while it computes, the
queue of a class's runs and the tracker that stops a run from outside.

The numbers a run shows are the command line's: the downloaded file, run with the
Python API, gives the page's summaries. Those comparisons are exact: both sides are the
same computation in one process (the same case, the same compiled kernels on one numba
thread, the same steps; the page's tracker only reads the state), so any difference
would be an observer changing the run, not round-off between processors."""

from __future__ import annotations

import math
import re
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from pdeflow import metrics_2d
from pdeflow.app import live_run
from pdeflow.app.case_file import case_toml, toml_value
from pdeflow.app.hillside_setup import (
    MAX_CELLS,
    HillsideSetup,
    hillside_cases,
    is_hillside_case,
    release_polygon,
)
from pdeflow.app.live_run import THREADS, Frame, LiveRun, total_depth
from pdeflow.app.run_queue import QueueFull, RunQueue
from pdeflow.cases import CaseError, load_case
from pdeflow.checks import WARNING_PREFIX
from pdeflow.models.friction_laws import LAWS
from pdeflow.simulate import Run, run_model
from pdeflow.trackers.stream import RunStopped, StreamTracker

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

pytestmark = pytest.mark.filterwarnings("ignore::pdeflow.checks.RunWarning")

CASES = Path(__file__).parents[1] / "cases"
PLANE = CASES / "hillside_plane.toml"
DRAWN = ((120.0, 420.0), (250.0, 380.0), (300.0, 500.0), (250.0, 620.0), (120.0, 580.0))
"""a release as drawn on the page (a pentagon on the plane, across the path's axis)"""
SETUP = HillsideSetup(PLANE, DRAWN, thickness=2.0, cells=40)
"""the default case on a coarse grid (40 x 20 cells: a run takes a fraction of a second)"""
NUMBERS = ("stop_time", "runout", "lateral_spread", "steps", "max_depth", "deposit_area")
WAIT_S = 300.0
"""timeout of a wait for a run [s]: a guard against a hung test, not a measurement"""


def numbers(summary: dict) -> dict:
    return {k: summary[k] for k in NUMBERS}


def one_line(err: pytest.ExceptionInfo) -> str:
    message = str(err.value)
    assert message and "\n" not in message, message
    return message


@pytest.fixture(scope="module")
def page_run() -> LiveRun:
    run = LiveRun(SETUP)
    run.execute()
    assert run.status == "done", run.message
    return run


@pytest.fixture(scope="module")
def downloaded(tmp_path_factory) -> Path:
    """The page's download of SETUP, saved under its own name."""
    path = tmp_path_factory.mktemp("download") / SETUP.file_name
    path.write_text(SETUP.toml(), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def api_results(downloaded) -> dict:
    """The downloaded file run with the Python API, as ``pdeflow run`` would."""
    case = load_case(downloaded)
    return {m: run_model(case, m, threads=THREADS) for m in case.models}


# --- the case file ----------------------------------------------------------------------
def test_case_toml_reads_back_as_the_same_data():
    data = {"case": {"name": 'say "hi"\\ and\tgo\nback', "models": ["a", "b"], "t_end": 1e-06,
                     "on": True, "off": False, "n": -3, "big": 1e16, "neg": -0.0},
            "grid": {"length": 2000.0, "empty": [],
                     "vertices": [[0.5, 1.0], [2.0, 3.25], [1e-06, 4.0]]},
            "terrain": {"bed": "hockey_stick", "x0": 1.5,
                        "topography": {"z0": 2000.0, "deep": {"k": "é", "del": "a\x7fb"}}},
            "only_tables": {"sub": {"v": 1}}}
    text = case_toml(data, 'a comment\nwith "quotes"\n\nand a blank line')
    assert tomllib.loads(text) == data
    assert text.startswith("# a comment\n")
    default = load_case(PLANE).data
    assert tomllib.loads(case_toml(default)) == default
    # numpy's numbers as Python's (numpy's float64 is a float whose repr is not TOML)
    assert toml_value(np.float64(0.1)) == "0.1" and toml_value(np.int64(7)) == "7"
    assert toml_value(np.float32(0.5)) == "0.5" and toml_value(np.bool_(True)) == "true"
    setup = SETUP.with_(friction_law="pouliquen", friction_deg=np.float64(30.0))
    assert tomllib.loads(setup.toml()) == setup.case().data  # a slider's numpy angle


@pytest.mark.parametrize("value", [{"a": 1}, None, [1, None]])
def test_toml_value_refuses_what_a_case_file_cannot_hold(value):
    with pytest.raises(ValueError, match="a case file cannot hold") as err:
        toml_value(value)
    one_line(err)


def test_the_downloaded_file_is_the_pages_case(downloaded):
    loaded = load_case(downloaded)
    assert loaded.data == SETUP.case().data
    text = downloaded.read_text(encoding="utf-8")
    assert SETUP.file_name == "hillside_plane.toml"
    assert SETUP.command() == f"pdeflow run {SETUP.file_name}" and SETUP.command() in text
    assert loaded.initial["vertices"] == [list(v) for v in DRAWN]
    assert loaded.data["grid"]["cells"] == 40 and loaded.data["grid"]["cells_y"] == 20
    assert "dx" not in loaded.data["grid"] and "release" not in loaded.data["terrain"]


def test_the_page_shows_the_numbers_of_the_downloaded_file(page_run, api_results):
    # exact: one computation twice in one process (module docstring)
    assert set(page_run.summaries) == set(api_results) == {"single_layer", "two_layer"}
    for m, res in api_results.items():
        assert numbers(page_run.summaries[m]) == numbers(res.summary), m
        for message in res.summary["warnings"]:  # the page shows the summary's warnings
            assert f"{WARNING_PREFIX}{message}" in page_run.warnings


# --- bad input: one line naming the parameter, before any work ---------------------------
@pytest.mark.parametrize("change, name", [
    ({"thickness": 0.05}, "thickness"), ({"thickness": 20.0}, "thickness"),
    ({"friction_deg": 2.0}, "friction_deg"), ({"friction_deg": 60.0}, "friction_deg"),
    ({"cells": 10}, "cells"), ({"cells": 500}, "cells"), ({"cells": 2.5}, "cells"),
    ({"models": ()}, "models"), ({"models": ("nope",)}, "models"),
    ({"friction_law": "nope"}, "friction_law"),
    ({"vertices": ((100.0, 400.0), (200.0, 400.0))}, "vertices"),
    ({"vertices": ((100.0, 400.0), (2500.0, 400.0), (200.0, 600.0))}, "initial.vertices"),
    ({"extra": {"case.t_end": 1000.0}}, "case.t_end"),
])
def test_bad_input_is_a_one_line_error_naming_the_parameter(change, name, monkeypatch):
    def no_work(*args, **kwargs):
        raise AssertionError("a run was set up for bad input")

    monkeypatch.setattr(live_run, "Run", no_work)
    setup = SETUP.with_(**change)
    kind = CaseError if name == "initial.vertices" else ValueError  # the case's own check
    with pytest.raises(kind) as err:
        LiveRun(setup)
    assert name in one_line(err)


def _tall_case(tmp_path: Path, width: float = 3000.0) -> Path:
    path = tmp_path / "hillside_tall.toml"
    path.write_text(PLANE.read_text().replace("width = 1000.0", f"width = {width!r}"))
    return path


@pytest.mark.parametrize("width", [3000.0, 2216.0])  # 2216 m: 190 x 211 cells exceed it
def test_too_many_cells_are_refused_with_a_count_that_fits(width, tmp_path):
    tall = SETUP.with_(case_path=_tall_case(tmp_path, width), cells=200)  # 200 x 300, 222
    with pytest.raises(ValueError) as err:
        tall.case()
    message = one_line(err)
    assert message.startswith("cells:") and str(MAX_CELLS) in message
    most = int(re.search(r"at most (\d+) cells", message).group(1))
    grid = tall.with_(cells=most).case().data["grid"]
    assert grid["cells"] * grid["cells_y"] <= MAX_CELLS
    with pytest.raises(ValueError, match="cells"):
        tall.with_(cells=most + 1).case()


# --- friction ---------------------------------------------------------------------------
def _own_deltas(tmp_path: Path) -> Path:
    path = tmp_path / "hillside_deltas.toml"
    path.write_text(PLANE.read_text().replace(
        "[single_layer]\nphi_b_deg = 25.0",
        "[single_layer]\nphi_b_deg = 25.0\ndelta1_deg = 20.0\ndelta2_deg = 32.5"))
    return path


@pytest.mark.parametrize("law", sorted(LAWS))
def test_each_friction_law_sets_its_keys(law, tmp_path):
    default_gap = 32.76 - 20.9  # FrictionLawParameters' delta2_deg - delta1_deg
    setup = SETUP.with_(case_path=_own_deltas(tmp_path), friction_law=law,
                        friction_deg=30.0)
    case = setup.case()
    for m in setup.models:
        params = case.data[m]
        assert params["friction_law"] == law
        if law == "coulomb":
            assert params["phi_b_deg"] == 30.0 and "delta1_deg" not in case.data["two_layer"]
        elif law == "voellmy":  # mu = tan(angle); the case's phi_b is left alone
            assert params["voellmy_mu"] == pytest.approx(math.tan(math.radians(30.0)),
                                                         rel=1e-12)
            assert params["phi_b_deg"] == 25.0
        else:  # delta2 keeps its distance above delta1: the case's, else the default's
            gap = 12.5 if m == "single_layer" else default_gap
            assert params["delta1_deg"] == 30.0
            assert params["delta2_deg"] == pytest.approx(30.0 + gap, rel=1e-12)
        parameters = case.make_pde(m).parameters  # the model reads what was written
        assert parameters.friction_law == law


# --- the page's cases and releases ------------------------------------------------------
def test_the_page_offers_the_2d_terrain_cases_default_first(tmp_path):
    offered = hillside_cases(CASES)
    names = list(offered)
    assert names[0] == "hillside_plane.toml"
    assert "terrain_hockey_stick.toml" in names
    for name, path in offered.items():
        case = load_case(path)
        assert path.name == name and case.is_2d and is_hillside_case(case), name
    for name in ("paper_5_1_dam_break.toml", "ritter_dam_break.toml",  # 1D
                 "cylinder_2d.toml", "study_smoke.toml"):  # 2D on a flat bed; a study
        assert (CASES / name).exists() and name not in offered, name
    # a file that is not a case is passed over, and the order is the names' but the default
    (tmp_path / "a_broken.toml").write_text("[case\n")
    (tmp_path / "a_1d.toml").write_text((CASES / "ritter_dam_break.toml").read_text())
    for name in ("terrain_bowl.toml", "hillside_plane.toml"):
        (tmp_path / name).write_text((CASES / name).read_text())
    assert list(hillside_cases(tmp_path)) == ["hillside_plane.toml", "terrain_bowl.toml"]


def test_release_polygon_of_a_box_and_of_a_cylinder():
    assert release_polygon(load_case(PLANE)) == (
        (140.0, 400.0), (260.0, 400.0), (260.0, 600.0), (140.0, 600.0))
    bowl = load_case(CASES / "terrain_bowl.toml")  # a cylinder of radius 60 m at (150, 500)
    points = np.array(release_polygon(bowl))
    assert points.shape == (16, 2)
    # on the circle up to the round-off of cos and sin
    np.testing.assert_allclose(np.hypot(points[:, 0] - 150.0, points[:, 1] - 500.0), 60.0,
                               rtol=1e-12)
    np.testing.assert_allclose(points[0], (210.0, 500.0), rtol=1e-12)
    angles = np.unwrap(np.arctan2(points[:, 1] - 500.0, points[:, 0] - 150.0))
    np.testing.assert_allclose(np.diff(angles), 2 * np.pi / 16, rtol=1e-9)
    # a page's release is a valid release of the case it was drawn on
    HillsideSetup(CASES / "terrain_bowl.toml", tuple(map(tuple, points)), cells=40).case()


# --- the run that streams frames --------------------------------------------------------
def test_frames_arrive_for_both_models_and_end_on_the_final_state(page_run, api_results):
    case = page_run.case
    shape = (case.data["grid"]["cells"], case.data["grid"]["cells_y"])
    for m, res in api_results.items():
        frames = page_run.frames[m]
        times = np.array([f.t for f in frames])
        assert len(frames) > 10 and times[0] == 0.0 and np.all(np.diff(times) > 0), m
        assert all(f.depth.dtype == np.float32 and f.depth.shape == shape for f in frames)
        # the run's end: the summary's final time, the final state's depth (exact: the
        # same function of the same state, see the module docstring)
        assert times[-1] == pytest.approx(res.t_final, rel=1e-12)
        assert np.array_equal(frames[-1].depth, total_depth(res.state.data))
        assert np.array_equal(frames[0].depth, total_depth(case.make_state(m)[1].data))
        # and the depth the summary measures (float64, negative round-off as 0): float32's
        np.testing.assert_allclose(frames[-1].depth, metrics_2d.total_depth(res.state.data),
                                   rtol=1e-6, atol=1e-9)
        assert frames[-1].depth.max() == pytest.approx(res.summary["max_depth"], rel=1e-6)
    longest = max(len(f) for f in page_run.frames.values())
    assert page_run.finished and page_run.frame_count() == longest
    last = page_run.frame(longest + 5)  # past a model's end: its last frame
    assert {m: f.t for m, f in last.items()} == {m: f[-1].t for m, f in page_run.frames.items()}
    assert all(f.t == 0.0 for f in page_run.frame(0).values())


def test_frame_count_waits_for_the_models_still_running():
    run = LiveRun(SETUP)
    assert run.frame_count() == 0 and run.frame(0) == {}
    depth = np.zeros((40, 20), np.float32)
    run.frames["single_layer"].extend(Frame(float(t), depth) for t in range(5))
    run.frames["two_layer"].extend(Frame(float(t), depth) for t in range(3))
    assert run.frame_count() == 3  # both running: as far as the slower
    run.summaries["two_layer"] = {}  # the slower has ended: it keeps its last frame
    assert run.frame_count() == 5
    assert {m: f.t for m, f in run.frame(4).items()} == {"single_layer": 4.0,
                                                         "two_layer": 2.0}


def test_a_run_cancelled_before_it_starts_computes_nothing():
    run = LiveRun(SETUP)
    run.cancel()
    run.execute()
    assert (run.status, run.message) == ("stopped", "cancelled")
    assert run.summaries == {} and not any(run.frames.values()) and run.finished


def test_a_run_past_its_wall_limit_stops_with_the_limit():
    run = LiveRun(SETUP, wall_limit_s=1e-6)
    run.execute()
    assert run.status == "stopped" and run.summaries == {}
    assert "1e-06 s" in run.message and "\n" not in run.message


def test_a_failing_run_is_reported_not_raised(monkeypatch):
    class Broken:
        def __init__(self, *args, **kwargs):
            raise RuntimeError("kernel exploded")

    monkeypatch.setattr(live_run, "Run", Broken)
    run = LiveRun(SETUP)
    run.execute()  # does not raise
    assert run.status == "failed" and run.finished
    assert run.message == "RuntimeError: kernel exploded" and run.summaries == {}


# --- the queue --------------------------------------------------------------------------
class GatedRun(LiveRun):
    """A run that, once on a slot, waits for ``gate`` before it computes."""

    def __init__(self, setup: HillsideSetup, gate: threading.Event):
        super().__init__(setup)
        self.gate = gate
        self.on_slot = threading.Event()

    def execute(self) -> None:
        self.on_slot.set()
        self.gate.wait(WAIT_S)
        super().execute()


def test_queue_positions_cancel_and_order():
    queue, gate = RunQueue(slots=1, max_waiting=5), threading.Event()
    first = GatedRun(SETUP, gate)
    second, third = LiveRun(SETUP), LiveRun(SETUP.with_(thickness=1.0))
    try:
        queue.submit(first)
        assert first.on_slot.wait(WAIT_S)
        queue.submit(second)
        queue.submit(third)
        assert [queue.position(r) for r in (first, second, third)] == [0, 1, 2]
        assert queue.waiting == 2
        queue.cancel(second)
        assert queue.position(third) == 1 and queue.waiting == 1
        assert queue.position(second) == 0 and second.status == "queued"
    finally:
        gate.set()
    assert all(r.wait(WAIT_S) for r in (first, second, third))
    assert (second.status, second.message) == ("stopped", "cancelled")
    assert second.summaries == {} and not any(second.frames.values())
    assert first.status == third.status == "done"


def test_a_full_queue_refuses_a_run_in_one_line():
    queue, gate = RunQueue(slots=1, max_waiting=1), threading.Event()
    first, second = GatedRun(SETUP, gate), LiveRun(SETUP)
    try:
        queue.submit(first)
        assert first.on_slot.wait(WAIT_S)  # computing: no longer waiting
        queue.submit(second)
        with pytest.raises(QueueFull) as err:
            queue.submit(LiveRun(SETUP))
        assert "1 runs are waiting" in one_line(err)
    finally:
        gate.set()
    assert first.wait(WAIT_S) and second.wait(WAIT_S)
    assert first.status == second.status == "done"


def test_runs_side_by_side_keep_their_own_results():
    queue = RunQueue(slots=2)
    thin, thick = LiveRun(SETUP.with_(thickness=1.0)), LiveRun(SETUP.with_(thickness=3.0))
    for run in (thin, thick):
        queue.submit(run)
    assert thin.wait(WAIT_S) and thick.wait(WAIT_S)
    for run in (thin, thick):
        assert run.status == "done", run.message
        for m in run.models:  # exact: the same computation (module docstring)
            alone = run_model(run.case, m, threads=THREADS).summary
            assert numbers(run.summaries[m]) == numbers(alone), (run.setup.thickness, m)
    for m in thin.models:
        assert thin.summaries[m]["max_depth"] < thick.summaries[m]["max_depth"]
        assert thin.frames[m][0].depth.max() < thick.frames[m][0].depth.max()


# --- the tracker ------------------------------------------------------------------------
def test_stream_tracker_stops_a_run_from_outside():
    case = SETUP.case()
    emitted: list[tuple[float, float]] = []
    tracker = StreamTracker(case.t_end / 100, lambda data: float(data[0].sum()),
                            lambda t, value: emitted.append((t, value)),
                            lambda: "enough" if len(emitted) >= 3 else None)
    run = Run(case, "single_layer", threads=THREADS)
    with pytest.raises(RunStopped, match="^enough$"):
        run.execute(tracker=tracker)
    assert len(emitted) == 3
    times = [t for t, _ in emitted]
    assert times[0] == 0.0 and times[1] < times[2]
    assert emitted[0][1] == float(run.state.data[0].sum())  # the initial state (unchanged)
