"""Failures that lose nothing (issue 5).

* Bad input - parameters, grids, states, case files, initial-profile files - is rejected
  before the run, by an error that names the offending item and its allowed range (and,
  for case files, the file).
* A run that blows up anyway stops at once with a diagnostic (time, step, cell, the state
  there, the variant) and keeps the last good state.
* Output files are complete or absent.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from pde import CartesianGrid, Controller, FieldCollection, PolarSymGrid, ScalarField

import pdeflow
from pdeflow import FVSplitSolver, SimulationBlowUp
from pdeflow.cases import CaseError, load_case
from pdeflow.io import atomic_path, write_json, write_npz
from pdeflow.numerics import layout as L
from pdeflow.solvers.fv_split import diagnose_blowup

from .helpers import grid, two_layer_column

ROOT = Path(__file__).parents[1]
CASE = ROOT / "cases" / "paper_5_1_dam_break.toml"

# --- parameters -------------------------------------------------------------------------

TWO = pdeflow.TwoLayerParameters
ONE = pdeflow.SingleLayerParameters
NAN = math.nan


@pytest.mark.parametrize("cls, name, value, allowed", [
    (TWO, "density_ratio", 0.0, "(0, 1)"),
    (TWO, "density_ratio", 1.0, "(0, 1)"),
    (TWO, "density_ratio", 1.5, "(0, 1)"),
    (TWO, "density_ratio", -0.2, "(0, 1)"),
    (TWO, "density_ratio", NAN, "(0, 1)"),
    (TWO, "k", -0.1, "[0, 1)"),
    (TWO, "k", 1.0, "[0, 1)"),
    (TWO, "k", NAN, "[0, 1)"),
    (TWO, "phi_int_deg", 0.0, "(0, 90) deg"),
    (TWO, "phi_int_deg", 90.0, "(0, 90) deg"),
    (TWO, "phi_int_deg", -10.0, "(0, 90) deg"),
    (TWO, "phi_b_deg", 120.0, "(0, 90) deg"),
    (TWO, "phi_b_deg", NAN, "(0, 90) deg"),
    (TWO, "theta_deg", 90.0, "(-90, 90) deg"),
    (TWO, "slope_azimuth_deg", 180.5, "[-180, 180] deg"),
    (ONE, "slope_azimuth_deg", NAN, "[-180, 180] deg"),
    (TWO, "g", 0.0, "(0, inf] m/s^2"),
    (TWO, "c", -0.01, "[0, inf]"),
    (TWO, "c", math.inf, "[0, inf]"),
    (TWO, "w", 0.0, "(0, inf] m/s"),
    (TWO, "dry_tolerance", 0.0, "(0, 1] m"),
    (TWO, "film_depth", -1e-3, "[0, 1] m"),
    (TWO, "du_reg", -1.0, "[0, inf] m/s"),
    (TWO, "mol_eps", 0.0, "(0, inf] m/s"),
    (ONE, "phi_b_deg", 0.0, "(0, 90) deg"),
    (ONE, "phi_b_deg", 90.0, "(0, 90) deg"),
    (ONE, "theta_deg", -90.0, "(-90, 90) deg"),
    (ONE, "dry_tolerance", 2.0, "(0, 1] m"),
])
def test_parameter_out_of_range_names_parameter_and_range(cls, name, value, allowed):
    with pytest.raises(ValueError) as err:
        cls(**{name: value})
    msg = str(err.value)
    assert msg.startswith(f"{name} must lie in {allowed}"), msg
    assert "got" in msg


@pytest.mark.parametrize("name, value", [
    ("k", "0.5"), ("density_ratio", True), ("g", None), ("c", [0.1]), ("phi_b_deg", "41")])
def test_parameter_of_wrong_type_is_rejected_by_name(name, value):
    with pytest.raises(ValueError, match=f"^{name} must be a number, got"):
        pdeflow.TwoLayerGranular(**{name: value})


def test_unknown_parameter_and_mode_are_rejected_by_name():
    with pytest.raises(ValueError, match=r"unknown two-layer parameter\(s\) \['phi_bed'\]"):
        pdeflow.TwoLayerGranular(phi_bed=30)
    with pytest.raises(ValueError, match=r"unknown single-layer parameter\(s\) \['k'\]"):
        pdeflow.SingleLayerGranular(k=0.5)
    with pytest.raises(ValueError, match="hyperbolicity must be one of .*'exact'"):
        pdeflow.TwoLayerGranular(hyperbolicity="maybe")
    with pytest.raises(ValueError, match="bc must be a pair of 'wall' or 'open'"):
        pdeflow.TwoLayerGranular(bc=("wall", "periodic"))


@pytest.mark.parametrize("cfl", [0.0, -0.3, 1.0001, 2.0, NAN, math.inf])
def test_cfl_outside_0_1_is_rejected_before_the_run(cfl):
    eq, st = two_layer_column(n=20)
    with pytest.raises(ValueError, match=r"^cfl must lie in \(0, 1\]"):
        eq.solve(st, t_range=0.1, solver="fv-split", cfl=cfl, tracker=None)
    with pytest.raises(ValueError, match="cfl must be a number"):
        FVSplitSolver(eq, cfl="0.3")


def test_muscl_above_cfl_one_half_is_rejected():
    """SSP-RK2 with limited slopes is positive only up to CFL 1/2 (a single-layer run at
    CFL 0.75 reached h = -2e-5 m in step 4, docs/stability.md)."""
    eq = pdeflow.SingleLayerGranular(reconstruction="muscl")
    with pytest.raises(ValueError, match=r"^cfl \(with reconstruction='muscl'\) must lie "
                                         r"in \(0, 0.5\], got 0.75"):
        FVSplitSolver(eq, cfl=0.75)
    assert FVSplitSolver(eq, cfl=0.5).cfl == 0.5
    assert FVSplitSolver(pdeflow.SingleLayerGranular(), cfl=0.75).cfl == 0.75


# --- grids and states -------------------------------------------------------------------

@pytest.mark.parametrize("bad_grid, words", [
    (CartesianGrid([[0, 1]] * 3, [4, 4, 4]), "1D or 2D CartesianGrid"),
    (CartesianGrid([[0, 1], [0, 1]], [4, 4], periodic=[False, True]), "must not be periodic"),
    (PolarSymGrid((0.5, 1.0), 8), "must start at the axis"),
    (CartesianGrid([[0, 1]], 8, periodic=True), "must not be periodic"),
])
def test_grid_the_models_do_not_run_on_is_rejected(bad_grid, words):
    eq = pdeflow.TwoLayerGranular()
    with pytest.raises(ValueError, match=words):
        eq.make_state(bad_grid, h2=np.ones(bad_grid.shape))
    fields = FieldCollection([ScalarField(bad_grid, 1.0) for _ in range(4)])
    for solver, kw in (("fv-split", {}), ("euler", {"dt": 1e-3})):
        with pytest.raises(ValueError, match=words):
            eq.solve(fields, t_range=0.01, solver=solver, tracker=None, **kw)


@pytest.mark.parametrize("profiles, words", [
    ({"h1": np.full(10, -0.1)}, r"h1 must be >= 0 m, got min -0.1"),
    ({"h2": np.r_[np.ones(9), np.nan]}, "h2 must be finite"),
    ({"u1": np.r_[np.ones(9), np.inf]}, "u1 must be finite"),
    ({"h1": np.ones(11)}, r"h1 must have shape \(10,\), got \(11,\)"),
    ({"h2": np.ones((10, 2))}, r"h2 must have shape \(10,\), got \(10, 2\)"),
    ({"h": np.ones(10)}, r"unknown profile\(s\) \['h'\] for TwoLayerGranular; allowed"),
])
def test_bad_initial_profiles_are_rejected_by_name(profiles, words):
    with pytest.raises(ValueError, match=words):
        pdeflow.TwoLayerGranular().make_state(grid(10), **profiles)


@pytest.mark.parametrize("solver, kw", [("fv-split", {}), ("euler", {"dt": 1e-4}),
                                        ("runge-kutta", {"dt": 1e-4})])
@pytest.mark.parametrize("field, value, words", [
    (2, -1e-3, r"h2 must be >= 0 m, got -0.001 in cell 7 \(x=0.75 m\)"),
    (3, np.nan, r"h2u2 must be finite \(no NaN or inf\), got nan in cell 7"),
    (0, np.inf, "h1 must be finite"),
])
def test_bad_state_is_rejected_before_the_run_by_every_solver(solver, kw, field, value,
                                                              words):
    eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"))
    st = eq.make_state(grid(10), h1=np.full(10, 0.1), h2=np.full(10, 0.2))
    st.data[field, 7] = value
    with pytest.raises(ValueError, match=words):
        eq.solve(st, t_range=1e-3, solver=solver, tracker=None, backend="numpy", **kw)


def test_state_of_the_other_model_is_rejected():
    one = pdeflow.SingleLayerGranular()
    st = one.make_state(grid(10), h=np.ones(10))
    with pytest.raises(ValueError, match=r"state must have 4 fields \('h1', 'h1u1'"):
        pdeflow.TwoLayerGranular().solve(st, t_range=0.1, solver="fv-split", tracker=None)


# --- case files -------------------------------------------------------------------------

GOOD = '[grid]\nlength = 2.0\ncells = 20\n[initial]\nshape = "file"\npath = "init.npz"\n'


def write_case(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "case.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize("text, words", [
    ('[case]\nt_end = 1\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n[grid]\nlength = 2\n'
     'dx = 0.1\nresolution = 3\n', ["unknown key grid.resolution", "allowed"]),
    ('[physics]\ng = 9.81\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["unknown section [physics]"]),
    ('[grid]\nlength = "7"\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.length must be float or int", "'7'"]),
    ('[grid]\nlength = true\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.length must be float or int", "True"]),
    ('[grid]\ncells = 2.5\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.cells must be int"]),
    ('[grid]\nlength = 2\ncells = 0\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.cells must be an integer >= 1, got 0"]),
    ('[grid]\nlength = 2\ndx = 0\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.dx must lie in (0, 2.0] m"]),
    ('[grid]\nlength = -2\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.length must lie in (0, inf] m"]),
    ('[grid]\nlength = 2\ndx = 0.3\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.dx = 0.3 m does not divide grid.length = 2 m"]),
    ('[grid]\nx_start = nan\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["grid.x_start must be a finite number, got nan"]),
    ('[initial]\nshape = "dam_break"\nx_dam = inf\nh_left = 1\n',
     ["initial.x_dam must be a finite number, got inf"]),
    ('[numerics]\ncfl = 1.2\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["numerics.cfl must lie in (0, 1]"]),
    ('[numerics]\nsolver = "euler"\ndt = 0\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["numerics.dt must lie in (0, inf] s"]),
    ('[numerics]\nsolver = "rk4"\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["numerics.solver must be one of", "'fv-split'", "'runge-kutta'", "'rk4'"]),
    ('[two_layer]\nk = "0.5"\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["[two_layer] k must be a number, got '0.5'"]),
    ('[two_layer]\ndensity_ratio = 1.0\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["[two_layer] density_ratio must lie in (0, 1)"]),
    ('[single_layer]\nphi_b_deg = 95\n[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n',
     ["[single_layer] phi_b_deg must lie in (0, 90) deg"]),
    ('[output]\nsnapshot_times = [0.1, "late"]\n[initial]\nshape = "column"\nL0 = 1\n'
     'H0 = 1\n', ["output.snapshot_times must be a list of numbers [s], got 'late'"]),
    ('[case]\nt_end = 1\n[output]\nsnapshot_times = [-0.5]\n[initial]\nshape = "column"\n'
     'L0 = 1\nH0 = 1\n', ["output.snapshot_times must lie in [0, inf] s"]),
    ('[initial]\nshape = "column"\nL0 = 1\n', ["initial.H0 is required"]),
    ('[grid]\nlength = 2\n', ["[initial] with a 'shape' is required"]),
    ('[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n[[grid]]\n', ["[grid] must be a table"]),
    ('[initial]\nshape = "column"\nL0 = = 1\nH0 = 1\n', ["not valid TOML"]),
])
def test_bad_case_file_names_key_and_file(tmp_path, text, words):
    p = write_case(tmp_path, text)
    with pytest.raises(CaseError) as err:
        load_case(p)
    msg = str(err.value)
    assert msg.startswith(str(p)), msg
    for w in words:
        assert w in msg, msg


def profile_arrays(n: int = 20, **changes: np.ndarray) -> dict[str, np.ndarray]:
    arrays = {"h1": np.full(n, 0.1), "u1": np.zeros(n), "h2": np.full(n, 0.2),
              "u2": np.zeros(n)}
    arrays.update(changes)
    return arrays


@pytest.mark.parametrize("arrays, words", [
    (profile_arrays(h2=np.full(21, 0.2)), ["array h2 has shape (21,)", "(20,) cells"]),
    (profile_arrays(u1=np.zeros(19)), ["array u1 has shape (19,)"]),
    (profile_arrays(h1=np.full((20, 1), 0.1)), ["array h1 has shape (20, 1)"]),
    ({"h1": np.zeros(20), "h2": np.zeros(20)}, ["lacks arrays ['u1', 'u2']"]),
    (profile_arrays(h1=np.r_[np.full(19, 0.1), np.nan]), ["initial state: h1 must be finite"]),
    (profile_arrays(h2=np.r_[np.full(19, 0.1), -0.5]), ["initial state: h2 must be >= 0 m"]),
    (profile_arrays(u2=np.r_[np.zeros(19), np.inf]), ["initial state: u2 must be finite"]),
])
def test_bad_initial_profile_file_is_rejected_before_the_run(tmp_path, arrays, words):
    np.savez(tmp_path / "init.npz", **arrays)
    case = load_case(write_case(tmp_path, GOOD))
    with pytest.raises(CaseError) as err:
        case.make_state("two_layer")
    msg = str(err.value)
    assert msg.startswith(str(tmp_path / "case.toml")), msg
    for w in words:
        assert w in msg, msg


def test_unreadable_initial_profile_file_is_a_case_error(tmp_path):
    (tmp_path / "init.npz").write_bytes(b"this is not an npz file")
    case = load_case(write_case(tmp_path, GOOD))
    with pytest.raises(CaseError, match="cannot read initial profile"):
        case.make_state("two_layer")
    (tmp_path / "init.npz").unlink()
    with pytest.raises(CaseError, match="initial.path: file init.npz not found"):
        load_case(write_case(tmp_path, GOOD))


# --- blow-ups -----------------------------------------------------------------------------

def beyond_cfl_limit(eq, cfl: float, **kw) -> FVSplitSolver:
    """An fv-split solver at a Courant number above 1.

    The solver rejects cfl > 1 (tested above); setting the attribute after validation
    is the only way to run the scheme beyond its stability limit, which is a genuine
    way to make the numerics fail (negative depths after a few steps)."""
    solver = FVSplitSolver(eq, cfl=0.5, **kw)
    solver.cfl = cfl
    return solver


def test_steps_beyond_the_cfl_limit_are_retried_not_blown_up():
    """Beyond the CFL limit a full step makes depths negative (checked independently
    with the numpy HLL update); the stepper rejects such a step, retries it with half
    the time step (as often as needed) and counts it, instead of blowing up."""
    eq, st = two_layer_column(n=70)
    solver = beyond_cfl_limit(eq, 1.5, max_steps=1)
    state = st.copy()
    stepper = solver.make_stepper(state)
    t = 0.0
    for _ in range(200):
        before = state.data.copy()
        t_before = t
        t = stepper(state, t, 2.0)
        if solver.diagnostics[L.D_RETRIES] > 0:
            break
    assert solver.diagnostics[L.D_RETRIES] > 0, "no step of CFL 1.5 was rejected"
    P = eq.parameter_array()
    rate, smax = eq.kernels.numpy_advection(before, 0.1, eq.bc_codes, P)
    full = 1.5 * 0.1 / smax
    new = before + full * rate
    assert np.any(new[::2] < -1e-12 * (1 + np.abs(before[::2])))  # a full step fails
    taken = t - t_before
    assert taken <= 0.5 * full * (1 + 1e-12)  # the kept step is at most half of it
    assert np.all(np.isfinite(state.data)) and np.all(state.data[::2] >= 0)
    # the whole run ends without a blow-up, depths non-negative
    final = Controller(beyond_cfl_limit(eq, 1.5), t_range=2.0, tracker=None).run(st.copy())
    assert np.all(final.data[::2] >= 0)


@pytest.mark.filterwarnings("ignore:overflow encountered", "ignore:invalid value")
@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_absurd_state_blows_up_in_the_first_step_and_keeps_the_initial_state(backend):
    eq, st = two_layer_column(n=40, length=4.0)
    assert st.data[2, 5] > 0.5
    st.data[3, 5] = 1e200 * st.data[2, 5]  # u2 = 1e200 m/s: finite, but u^2 overflows
    with pytest.raises(SimulationBlowUp) as info:
        eq.solve(st, t_range=1.0, solver="fv-split", backend=backend, tracker=None)
    err = info.value
    assert err.step == 1 and err.t == 0.0
    assert err.cell in (4, 5, 6)
    assert "non-finite values" in str(err)
    assert not all(np.isfinite(list(err.report["failed"].values())))
    np.testing.assert_array_equal(err.state, st.data)
    np.testing.assert_array_equal(eq.diagnostics["last_state"].data, st.data)


def test_diagnosis_of_a_state_spoilt_by_a_source_stage():
    eq, st = two_layer_column(n=20)
    q = st.data.copy()
    q[1, 4] = np.nan

    def replay(*args):  # pragma: no cover - must not be needed
        raise AssertionError("a bad kept state is reported without replaying")

    report = diagnose_blowup(eq, q, 0.5, 1.0, replay)
    assert report["stage"] == 0 and report["cell"] == 4
    assert "source stage" in report["cause"]


def test_failed_run_from_the_command_line_writes_no_file(tmp_path):
    from pdeflow.cli import main

    n = 40
    u2 = np.zeros(n)
    u2[5] = 1e200
    np.savez(tmp_path / "init.npz", h1=np.full(n, 0.1), u1=np.zeros(n),
             h2=np.full(n, 0.2), u2=u2)
    p = write_case(tmp_path, GOOD.replace("cells = 20", f"cells = {n}"))
    out = tmp_path / "out"
    args = ["run", str(p), "-q", "--summary", str(out / "s.json"), "--final",
            str(out / "f.npz"), "--plot", str(out / "p.png")]
    try:
        rc = main(args)
    except SimulationBlowUp:
        rc = None
    assert rc != 0
    left = sorted(q.name for q in out.rglob("*")) if out.exists() else []
    assert left == []


@pytest.mark.filterwarnings("ignore::pdeflow.checks.RunWarning")
def test_method_of_lines_run_that_blows_up_is_an_error_not_a_result(tmp_path):
    """py-pde's solvers have no step control: a run whose state turns non-finite used
    to go on to t_end and hand back NaN as its result. It now fails like fv-split
    does, and the command line writes nothing."""
    from pdeflow.cli import main
    from pdeflow.simulate import run_model

    sets = ["numerics.solver='runge-kutta'", "numerics.dt=0.001", "case.t_end=0.5",
            "case.models=['two_layer']", "output.snapshot_times=[]"]
    with pytest.raises(SimulationBlowUp, match="mol-rk .*dt=0.001 s.* blew up.*"
                       "numerics.dt"):
        run_model(load_case(CASE, sets), "two_layer")
    # the same run with a small enough step is a result
    ok = run_model(load_case(CASE, [*sets, "numerics.dt=1e-4"]), "two_layer")
    assert np.all(np.isfinite(ok.state.data)) and ok.summary["t_final"] == 0.5
    rc = main(["run", str(CASE), "-q", *sum((["--set", s] for s in sets), []),
               "--summary", str(tmp_path / "s.json")])
    assert rc == 3 and list(tmp_path.iterdir()) == []


# --- output files: complete or absent ------------------------------------------------------

def test_atomic_write_interrupted_leaves_no_file_and_keeps_the_old_one(tmp_path):
    target = tmp_path / "summary.json"
    with pytest.raises(KeyboardInterrupt), atomic_path(target) as tmp:
        tmp.write_text('{"half": ')
        raise KeyboardInterrupt
    assert not target.exists() and list(tmp_path.iterdir()) == []
    write_json(target, {"complete": True})
    with pytest.raises(TypeError):
        write_json(target, {"complete": object()})  # fails half-way through
    assert target.read_text() == '{\n  "complete": true\n}\n'
    assert [q.name for q in tmp_path.iterdir()] == ["summary.json"]


def test_npz_that_cannot_be_written_leaves_no_file(tmp_path):
    target = tmp_path / "final.npz"
    bad = np.array([lambda: 0], dtype=object)  # pickling a lambda fails mid-write
    with pytest.raises(Exception):  # noqa: B017 - pickle raises several types
        write_npz(target, {"h": np.ones(3), "bad": bad})
    assert list(tmp_path.iterdir()) == []


def test_interrupted_run_writes_no_file(tmp_path, monkeypatch):
    from pdeflow.cli import main
    from pdeflow.trackers import FextraStorageTracker

    calls = []
    handle = FextraStorageTracker.handle

    def interrupt(self, field, t):
        calls.append(t)
        if len(calls) == 2:
            raise KeyboardInterrupt  # Ctrl-C during the run
        return handle(self, field, t)

    monkeypatch.setattr(FextraStorageTracker, "handle", interrupt)
    out = tmp_path / "s.json"
    try:
        rc = main(["run", str(CASE), "-q", "--set", "grid.dx=0.1", "--summary", str(out)])
    except KeyboardInterrupt:
        rc = None
    assert len(calls) >= 2
    assert rc != 0 and not out.exists()
