"""Observers do not change the solution (issue 28): the fv-split steps, and with them
every number of the summary, are the same whichever trackers, output times or driver
ran the case; frames at requested times are interpolated between the steps around
them, not made by shortening a step."""

from __future__ import annotations

import importlib.util
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from pdeflow.cases import load_case
from pdeflow.cli import main
from pdeflow.simulate import Run, run_model
from pdeflow.solvers.fv_split import FVSplitSolver
from pdeflow.trackers import FextraStorageTracker, ProgressBar

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
SMALL = ["grid.dx=0.1"]  # 70 cells: both models to rest in well under a second


def numbers(summary: dict) -> dict:
    """The summary without what measures the machine rather than the solution."""
    return {k: v for k, v in summary.items() if k not in ("wall_time_s", "warnings")}


def case(*sets: str):
    return load_case(CASE_51, [*SMALL, *sets])


@pytest.fixture(scope="module")
def plain() -> dict[str, dict]:
    """``pdeflow run`` with nothing but --summary: the reference."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "s.json"
        assert main(["run", str(CASE_51), *sum((["--set", s] for s in SMALL), []),
                     "--summary", str(out), "-q", "--no-progress"]) == 0
        models = json.loads(out.read_text())["models"]
    assert models["two_layer"]["at_rest"] and models["two_layer"]["stop_time"] > 1.0
    return {m: numbers(s) for m, s in models.items()}


def test_cli_observers_do_not_change_the_summary(plain, tmp_path):
    """--progress, --store (every 0.05 s), live frames and a movie (every 0.3 s)."""
    out = tmp_path / "s.json"
    assert main(["run", str(CASE_51), *sum((["--set", s] for s in SMALL), []),
                 "--summary", str(out), "-q", "--progress", "--store",
                 str(tmp_path / "r.h5"), "--store-every", "0.05", "--frames",
                 str(tmp_path / "frames"), "--movie", str(tmp_path / "m.gif"),
                 "--live-every", "0.3"]) == 0
    assert (tmp_path / "m.gif").stat().st_size > 0
    models = json.loads(out.read_text())["models"]
    for model, s in models.items():
        assert numbers(s) == plain[model], model


@pytest.mark.parametrize("model", ["two_layer", "single_layer"])
def test_python_api_snapshots_and_trackers_do_not_change_the_summary(plain, model):
    runs = {
        "no snapshots": (case("output.snapshot_times=[]"), None),
        "odd snapshot times": (case("output.snapshot_times=[0.013, 0.5, 0.50001, 1.2]"),
                               None),
        "progress bar and frames": (case(), [ProgressBar(0.01),
                                            FextraStorageTracker(0.0173)]),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, (c, tracker) in runs.items():
            s = numbers(Run(c, model).execute(tracker).summary)
            assert s == plain[model], name


def test_converge_level_and_sweep_point_are_the_plain_run(plain):
    from pdeflow.analysis.convergence import converge
    from pdeflow.analysis.sweep import run_sweep

    ref = plain["two_layer"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        level = converge(case(), 1)["levels"][0]
        sweep = run_sweep(case(), aspect_ratios=[2.0], models=["two_layer"])
    for key in ("stop_time", "lower_stop_time", "upper_stop_time", "runout",
                "max_fextra_over_rho1", "front_position"):
        if key in level:
            assert level[key] == ref[key], key
    assert level["steps"] == ref["steps"]
    point = sweep["models"]["two_layer"]["runs"][0]
    assert point["stop_time"] == ref["stop_time"]
    assert point["runout"] == ref["runout"] and point["steps"] == ref["steps"]


def test_a_frame_is_the_state_interpolated_between_the_steps_around_its_time():
    """The frame at 0.5 s: the linear interpolation, at exactly 0.5 s, of the states of
    the unshortened run before and after the step across 0.5 s (found by running the
    stepping loop to the first step that reaches 0.5 s)."""
    c = case("output.snapshot_times=[0.5]", "case.t_end=1.0")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = run_model(c, "two_layer")
    frame = res.snapshots[0.5][0]
    run = Run(c, "two_layer")
    state = run.state.copy()
    solver = FVSplitSolver(run.pde, cfl=c.cfl, t_end=None)
    stepper = solver.make_stepper(state)
    t = 0.0
    while True:  # one step per call: t_end = t + dt of an unshortened step
        before, t_before = state.data.copy(), t
        solver.max_steps = 1
        t = stepper(state, t, 1.0)
        if t >= 0.5:
            break
    assert t_before < 0.5 < t
    w = (0.5 - t_before) / (t - t_before)
    np.testing.assert_allclose(frame, (1 - w) * before + w * state.data, rtol=1e-12,
                               atol=1e-15)
    assert np.all(frame[::2] >= 0)
    # the run's mass is in the frame too (both ends of the interpolation conserve it)
    from pdeflow.metrics import mass

    r = run.pde.system.densities(run.pde.parameters)
    m0 = mass(run.state.data, c.dx, r)
    assert abs(mass(frame, c.dx, r) - m0) < 1e-12 * m0


def test_a_study_evaluation_and_the_app_give_the_plain_run(plain, tmp_path):
    """A study point at the case's own parameters, and the app's run with its animation
    frames (a second run with a frame tracker every t_end/FRAMES_PER_T_END)."""
    from pdeflow.app.dam_break import simulate
    from pdeflow.study.evaluate import DesignPoint, evaluate
    from pdeflow.study.spec import load_study

    ref = plain["two_layer"]
    phi_b = load_case(CASE_51).make_pde("two_layer").parameters.phi_b_deg
    study = tmp_path / "s.toml"
    study.write_text(f"""[study]
name = "observers"
case = "{CASE_51}"
set = ["grid.dx=0.1"]
design = "grid"
quantities = ["two_layer.stop_time", "two_layer.max_fextra_over_rho1",
              "two_layer.steps", "two_layer.runout"]

[parameters]
"two_layer.phi_b_deg" = {{ values = [{phi_b!r}] }}
""")
    spec = load_study(study)
    row = evaluate(spec, DesignPoint(0, {"two_layer.phi_b_deg": phi_b}))
    assert row["status"] == "ok", row
    for key in ("stop_time", "max_fextra_over_rho1", "steps", "runout"):
        assert row[f"two_layer.{key}"] == ref[key], key
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        app = simulate(case(), CASE_51, SMALL, frames=True)
    assert len(app.times) > 10  # the animation was recorded (its own runs)
    for model, res in app.results.items():
        assert numbers(res.summary) == plain[model], model


def test_step_outputs_are_states_of_the_unshortened_run():
    """outputs='step': each frame is the state after the first step that reaches the
    requested time, at its true time; the final state is the plain run's, bit for bit."""
    c = case("output.snapshot_times=[]", "case.t_end=1.0")
    run = Run(c, "two_layer")
    ref = run.pde.solve(run.state, t_range=1.0, solver="fv-split", cfl=c.cfl, tracker=None)
    frames = FextraStorageTracker([0.25, 0.5])
    final = run.pde.solve(run.state, t_range=1.0, solver="fv-split", cfl=c.cfl,
                          tracker=[frames], outputs="step")
    np.testing.assert_array_equal(final.data, ref.data)
    times = sorted(frames.snapshots)
    assert len(times) == 2 and 0.25 < times[0] < 0.26 and 0.5 < times[1] < 0.51
    # the frame at 0.5+ is the unshortened run stopped after the same number of steps
    again = Run(c, "two_layer")
    state = again.state.copy()
    solver = FVSplitSolver(again.pde, cfl=c.cfl, max_steps=1)
    stepper = solver.make_stepper(state)
    t = 0.0
    while t < 0.5:
        t = stepper(state, t, 1.0)
    assert round(t, 9) == times[1]
    np.testing.assert_array_equal(frames.snapshots[times[1]][0], state.data)


def test_an_output_time_inside_the_step_that_comes_to_rest(plain):
    """A snapshot asked for within the last step (the one after which everything is at
    rest): it is recorded, and the run still ends at rest at the plain run's time."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = run_model(case("output.snapshot_times=[]"), "two_layer")
        t_rest, dt = ref.t_final, ref.diagnostics.dt
        t_snap = round(t_rest - 0.5 * dt, 9)
        res = run_model(case(f"output.snapshot_times=[{t_snap!r}]"), "two_layer")
    assert res.summary["at_rest"] and res.t_final == t_rest
    assert numbers(res.summary) == plain["two_layer"]
    assert list(res.snapshots) == [t_snap]
    assert np.all(res.snapshots[t_snap][0][::2] >= 0)


CYLINDER_2D = ROOT / "cases" / "cylinder_2d.toml"
SMALL_2D = ["grid.dx=0.2", "grid.width=3.2", "case.t_end=0.6"]  # 20 x 16 cells


def test_cli_observers_do_not_change_a_2d_summary(tmp_path):
    """A 2D case (both models): --progress, --store, the plan view's frames and movie
    (every 0.1 s) give the summary of the run with --summary alone, number for number.
    The bar and the store (every t_end/100) meet every other sample of the peak speed
    (every t_end/200) to within round-off of the time; the peak is still the plain
    run's (:mod:`pdeflow.trackers.peaks`)."""
    sets = sum((["--set", s] for s in SMALL_2D), [])
    plain, watched = tmp_path / "plain.json", tmp_path / "watched.json"
    assert main(["run", str(CYLINDER_2D), *sets, "--summary", str(plain), "-q",
                 "--no-progress"]) == 0
    args = ["--summary", str(watched), "-q", "--progress", "--frames",
            str(tmp_path / "frames"), "--movie", str(tmp_path / "m.gif"), "--live-every",
            "0.1"]
    if importlib.util.find_spec("h5py") is not None:
        args += ["--store", str(tmp_path / "r.h5")]
    assert main(["run", str(CYLINDER_2D), *sets, *args]) == 0
    assert len(list((tmp_path / "frames" / "two_layer").glob("frame_*.png"))) >= 6
    ref = json.loads(plain.read_text())["models"]
    models = json.loads(watched.read_text())["models"]
    assert set(models) == {"two_layer", "single_layer"}
    for model, s in models.items():
        assert numbers(s) == numbers(ref[model]), model


def test_a_storage_that_meets_the_erosion_series_changes_no_number():
    """An erodible bed with its erosion series every t_end/100 [s], and frames stored
    every t_end/100 as --store does: their times meet to within round-off of each other
    (py-pde hands a tracker the state at a time up to 1e-8 s before its own), which
    changed the series' flow duration in its last digit (0.35000000000000003 against
    0.35 s) before every frame and series tracker took the states at its own times
    (:mod:`pdeflow.trackers.own_times`)."""
    c = load_case(ROOT / "cases" / "erodible_bed.toml", ["output.erosion_series='on'"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alone = numbers(Run(c, "two_layer").execute().summary)
        watched = numbers(Run(c, "two_layer").execute(
            [FextraStorageTracker(c.t_end / 100)]).summary)
    assert watched == alone, {k: (alone[k], watched.get(k)) for k in alone
                              if watched.get(k) != alone[k]}



def test_a_tracker_used_again_takes_its_own_times_again():
    """The run's end lets a tracker take the final state whatever its time; initialised
    for another run, it again skips states handed before its own times."""
    from pdeflow.trackers.own_times import AtOwnTimes, OwnTimes

    tracker = AtOwnTimes()
    tracker.interrupt = OwnTimes(0.02)
    for _ in range(2):  # two runs
        tracker.interrupt.initialize(0.0)
        assert tracker.interrupt.next(0.0) == pytest.approx(0.02)
        assert tracker.handed_early(0.015)  # another tracker's time: skipped
        assert tracker.interrupt.next(0.015) == pytest.approx(0.02)  # asked again
        tracker.final_state_next()
        assert not tracker.handed_early(0.015)  # the run's end: taken


def _frames(eq, state, t_end: float, outputs: str) -> tuple[list, list, int]:
    """Times and states of a run asked for its state every 0.1 ms (fv-split with
    ``outputs``), and its steps."""
    solver = FVSplitSolver(eq, t_end=t_end, outputs=outputs)
    steps = solver.make_stepper(state)
    t, times, frames = 0.0, [], []
    while t < t_end - 1e-12:
        t = steps(state, t, min(t + 1e-4, t_end))
        times.append(t)
        frames.append(state.data.copy())
    return times, frames, solver.info["steps"]


@pytest.mark.parametrize("dims", [1, 2])
def test_outputs_within_one_step_lie_on_the_line_between_its_two_states(dims):
    """Frames 20 times closer than the steps (several outputs inside each step): each
    is the linear interpolation between the states before and after the step around
    it, which the same run with outputs "step" gives (the solver's state before the
    step is not copied for each output, nor rewritten between them), and the run ends
    on the untracked run's state, on a 1D and a 2D grid."""
    from pde import CartesianGrid

    import pdeflow

    if dims == 1:
        grid = CartesianGrid([[0, 2.0]], [40])
        h = np.where(grid.axes_coords[0] < 0.6, 0.3, 0.0)
        bc = ("wall", "open")
    else:
        grid = CartesianGrid([[0, 2.0], [0, 1.0]], [40, 20])
        x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
        h = np.where(np.hypot(x - 0.6, y - 0.5) < 0.3, 0.3, 0.0)
        bc = (("wall", "open"), ("open", "wall"))
    eq = pdeflow.SingleLayerGranular(theta_deg=25, phi_b_deg=20, bc=bc)
    t_end = 0.05
    alone = eq.solve(eq.make_state(grid, h=h), t_range=t_end, solver="fv-split",
                     tracker=None)
    state = eq.make_state(grid, h=h)
    times, frames, n_steps = _frames(eq, state, t_end, "interpolate")
    assert n_steps < len(frames) / 5
    np.testing.assert_array_equal(state.data, alone.data)
    t_steps, at_steps, _ = _frames(eq, eq.make_state(grid, h=h), t_end, "step")
    t_steps = [0.0, *t_steps]
    at_steps = [eq.make_state(grid, h=h).data, *at_steps]
    scale = np.abs(h).max()
    for t, frame in zip(times, frames, strict=True):
        b = int(np.searchsorted(t_steps, t))  # the step from t_steps[b - 1] to t_steps[b]
        w = (t - t_steps[b - 1]) / (t_steps[b] - t_steps[b - 1])
        expected = w * at_steps[b] + (1.0 - w) * at_steps[b - 1]
        # (the weights differ from the solver's by round-off in the times)
        np.testing.assert_allclose(frame, expected, rtol=0, atol=1e-12 * scale)
