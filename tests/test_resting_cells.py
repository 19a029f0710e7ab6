"""The fv-split loop skips cells at rest with a stencil at rest (pdeflow.numerics.resting)
and gives, bit for bit, the numbers of a loop that visits every wet cell in every step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pdeflow.cases import load_case
from pdeflow.numerics import advect_step, splitting
from pdeflow.simulate import run_model
from pdeflow.solvers import fv_split

ROOT = Path(__file__).parents[1]
BED = ROOT / "cases" / "erodible_bed.toml"


def _python_loop(monkeypatch, reach: int | None, calls: list | None = None) -> None:
    """Make fv-split run the loop's Python code (its kernels compiled), with ``reach``
    (None: the loop's own; huge: every wet cell every step) and, if ``calls`` is given,
    an update that records the cells it writes."""
    if reach is not None:
        monkeypatch.setattr(splitting, "reach_of", lambda order: reach)

    def update(q, base, rate, dt, weight, lo, hi):
        if calls is not None:
            calls.append((lo, hi))
        return advect_step.update(q, base, rate, dt, weight, lo, hi)

    monkeypatch.setattr(fv_split, "scheme_stepper",
                        lambda *scheme: splitting.python_stepping(*scheme, update))


def _numbers(case, model):
    """The final state and the summary's numbers (which include the diagnostics)."""
    res = run_model(case, model)
    summary = {k: v for k, v in res.summary.items() if k != "wall_time_s"}
    return res.state.data.copy(), summary


CASES = [
    (BED, ["grid.dx=0.01"]),
    (BED, ["grid.dx=0.01", "numerics.reconstruction='muscl'", "numerics.cfl=0.4"]),
    (BED, ["grid.dx=0.01", "numerics.splitting='strang'", "two_layer.theta_deg=25",
           "initial.bed_thickness=0.01"]),
    (BED, ["grid.dx=0.01", "numerics.flux='ifcp'", "two_layer.exchange_closure='relaxed'"]),
    (ROOT / "cases" / "paper_5_2_single_collapse.toml", ["grid.dx=0.05"]),
    (ROOT / "cases" / "axisymmetric_collapse.toml", ["grid.dx=0.02"]),
]


@pytest.mark.parametrize("path, overrides", CASES,
                         ids=[f"{p.stem}-{i}" for i, (p, _) in enumerate(CASES)])
def test_skipping_resting_cells_changes_no_bit(monkeypatch, path, overrides):
    case = load_case(path, [*overrides, "output.snapshot_times=[]", "case.t_end=2.0"])
    skipping = {m: _numbers(case, m) for m in case.models}
    with monkeypatch.context() as m:
        _python_loop(m, reach=10**9)
        full = {model: _numbers(case, model) for model in case.models}
    for model in case.models:
        np.testing.assert_array_equal(skipping[model][0], full[model][0])
        assert skipping[model][1] == full[model][1]


def test_a_bed_at_rest_ahead_of_the_flow_is_not_visited(monkeypatch):
    """After the first step, no update reaches further than the reach of a step beyond
    the furthest cell the flow has touched."""
    case = load_case(BED, ["grid.dx=0.01", "grid.length=4", "output.snapshot_times=[]",
                           "case.models=['two_layer']"])
    calls: list = []
    _python_loop(monkeypatch, None, calls)
    res = run_model(case, "two_layer")
    front = res.summary["front_position"]
    assert res.summary["at_rest"] and front < 1.0
    furthest = max(hi for lo, hi in calls[1:])
    reach = splitting.reach_of(1)
    assert furthest * case.dx <= front + (reach + 2) * case.dx
    assert calls[0] == (0, case.cells - 1)  # the first step visits every cell


def test_a_longer_bed_leaves_the_run_as_it_is():
    """The two-layer collapse stops 0.4 m down the bed: a bed of 6 m gives the run of
    one of 1 m, step for step (the single layer runs on the rigid bed: nothing to see)."""
    keys = ["output.snapshot_times=[]", "case.models=['two_layer']"]
    short = load_case(BED, ["grid.length=1", *keys])
    long = load_case(BED, ["grid.length=6", *keys])
    a, b = run_model(short, "two_layer"), run_model(long, "two_layer")
    assert a.summary["at_rest"] and a.summary["steps"] == b.summary["steps"]
    np.testing.assert_array_equal(a.state.data, b.state.data[:, :short.cells])


def test_a_state_changed_between_calls_is_visited_again():
    """The loop goes on from the live cells of the state it left; a state changed in
    between (here a mound put on the bed far ahead of the flow) is swept afresh, so the
    mound slumps as it does for a new solver."""
    from pdeflow import FVSplitSolver

    case = load_case(BED, ["grid.dx=0.01", "output.snapshot_times=[]"])
    eq, state = case.make_state("two_layer")
    far = slice(150, 160)  # 1.5-1.6 m, far beyond where the flow stops

    def mound(s):
        s.data[2, far] += 0.05

    solver = FVSplitSolver(eq, cfl=0.3, stop_at_rest=False)
    stepper = solver.make_stepper(state)
    stepper(state, 0.0, 0.1)
    mound(state)
    again = state.copy()
    stepper(state, 0.1, 0.3)
    fresh = FVSplitSolver(eq, cfl=0.3, stop_at_rest=False)
    fresh.make_stepper(again)(again, 0.1, 0.3)
    assert np.abs(state.data[2, far] - 0.055).max() > 1e-3  # it slumped
    np.testing.assert_array_equal(state.data[:, 120:], again.data[:, 120:])
