"""On a 2D grid the fv-split loop visits a box of cells: the bounding box of the live
cells widened by the reach of a step along both axes (pdeflow.numerics.boxes), so that
dry margins beside a flow cost nothing per step, in y as in x (issue 36).

Skipping must change no bit: a collapse in a domain with wide dry margins, both models,
first order and MUSCL, gives the numbers of the same loop that visits every cell in every
step (its Python code with an unbounded reach, the switch tests/test_resting_cells.py
uses), bit for bit: the same arithmetic on the same cells in the same order, on one
machine, is the design property compared. The column starts against the wall at x = 0
(the box touches the domain's edge from the first step) and stops before it reaches the
far sides, so resting cells outside the box feed the time step
(pdeflow.numerics.resting).
"""

from __future__ import annotations

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.numerics import advect_step, splitting
from pdeflow.solvers import fv_split

NX, NY, DX = 40, 72, 0.05  #: cells along x (down the slope) and y, their width [m]


def _python_loop(monkeypatch, reach: int | None, calls: list | None = None) -> None:
    """Make fv-split run the loop's Python code (its kernels compiled), with ``reach``
    (None: the loop's own; huge: every cell every step) and, if ``calls`` is given, an
    update that records the boxes it writes."""
    if reach is not None:
        monkeypatch.setattr(splitting, "reach_of", lambda order: reach)

    compiled = advect_step.update_kernel(3)  # both models' 2D state: 3 rows a layer

    def update(q, base, rate, dt, weight, lo, hi):
        if calls is not None:
            calls.append((lo, hi))
        return compiled(q, base, rate, dt, weight, lo, hi)

    monkeypatch.setattr(fv_split, "scheme_stepper",
                        lambda *scheme: splitting.python_stepping(*scheme, update))


def _collapse(two_layer: bool, scheme: str):
    """A column (radius 0.3 m, 0.3 m deep) against the wall at x = 0, centred in y, on a
    plane at 15 deg (single layer: basal friction angle 35 deg): it spreads and stops."""
    grid = CartesianGrid([[0, NX * DX], [0, NY * DX]], [NX, NY])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    column = np.where(np.hypot(x, y - NY * DX / 2) < 0.3, 0.3, 0.0)
    bc = (("wall", "open"), ("wall", "wall"))
    if two_layer:
        eq = pdeflow.TwoLayerGranular(theta_deg=15.0, scheme=scheme, bc=bc)
        return eq, eq.make_state(grid, h1=0.4 * column, h2=0.6 * column)
    eq = pdeflow.SingleLayerGranular(theta_deg=15.0, phi_b_deg=35.0, scheme=scheme, bc=bc)
    return eq, eq.make_state(grid, h=column)


def _run(eq, state, t_end: float = 1.0):
    out, info = eq.solve(state, t_end, solver="fv-split", tracker=None, ret_info=True,
                         stop_at_rest=False)
    return out.data, info["solver"]["steps"]


@pytest.mark.parametrize("scheme", ["hll/first-order", "hll/muscl/mc"])
@pytest.mark.parametrize("two_layer", [False, True], ids=["single_layer", "two_layer"])
def test_skipping_the_dry_margins_changes_no_bit(monkeypatch, two_layer, scheme):
    eq, state = _collapse(two_layer, scheme)
    q, steps = _run(eq, state)
    depth = q[0] + q[3] if two_layer else q[0]
    wet_y = np.flatnonzero(depth.max(axis=0) > 0)
    # the flow stayed clear of the sides in y and of the far end in x: margins it skips
    assert wet_y[0] > 8 and wet_y[-1] < NY - 9 and np.all(depth[-8:] == 0)
    with monkeypatch.context() as m:
        _python_loop(m, reach=10**9)
        q_full, steps_full = _run(eq, state)
    assert steps == steps_full
    np.testing.assert_array_equal(q, q_full)


def test_the_boxes_stay_beside_the_flow(monkeypatch):
    """No update reaches further than a step's reach (and the cell its faces write to)
    beyond the cells the flow has wetted, along either axis: the rows of a box are
    updated one by one, none over a whole row of the grid."""
    eq, state = _collapse(False, "hll/first-order")
    calls: list = []
    _python_loop(monkeypatch, None, calls)
    q, _ = _run(eq, state, 0.5)
    wet = (q[0] > 0) | (state.data[0] > 0)
    xs = np.flatnonzero(wet.any(axis=1))
    ys = np.flatnonzero(wet.any(axis=0))
    margin = splitting.reach_of(1) + 1
    assert len(calls) > 100
    for lo, hi in calls:
        if lo > hi:
            continue
        x0, y0 = divmod(lo, NY)
        x1, y1 = divmod(hi, NY)
        assert x0 >= xs[0] - margin and x1 <= xs[-1] + margin
        assert y0 >= ys[0] - margin and y1 <= ys[-1] + margin


@pytest.mark.parametrize("two_layer", [False, True], ids=["single_layer", "two_layer"])
def test_skipping_changes_no_bit_over_a_bed(monkeypatch, two_layer):
    """The same collapse over a bumpy bed inclined at 15 deg (issue 37's flow over
    terrain, whose face values read the neighbours' surfaces, and whose faces between
    resting cells take the cells' wave speeds, as the loop's bound for the faces it
    skips): the loop's boxes give the numbers of the loop that visits every cell, bit
    for bit."""
    grid = CartesianGrid([[0, NX * DX], [0, NY * DX]], [NX, NY])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    column = np.where(np.hypot(x, y - NY * DX / 2) < 0.3, 0.3, 0.0)
    X, Y = np.meshgrid(np.linspace(0, NX * DX, NX + 1), np.linspace(0, NY * DX, NY + 1),  # noqa: N806
                       indexing="ij")
    bed = -np.tan(np.radians(15.0)) * X + 0.01 * np.sin(X / 0.13) * np.cos(Y / 0.17)
    bc = (("wall", "open"), ("wall", "wall"))
    if two_layer:
        eq = pdeflow.TwoLayerGranular(bed=bed, bc=bc)
        state = eq.make_state(grid, h1=0.4 * column, h2=0.6 * column)
    else:
        eq = pdeflow.SingleLayerGranular(phi_b_deg=35.0, bed=bed, bc=bc)
        state = eq.make_state(grid, h=column)
    q, steps = _run(eq, state)
    depth = q[0] + q[3] if two_layer else q[0]
    assert np.all(depth[-8:] == 0) and np.all(depth[:, :8] == 0)  # margins it skips
    with monkeypatch.context() as m:
        _python_loop(m, reach=10**9)
        q_full, steps_full = _run(eq, state)
    assert steps == steps_full
    np.testing.assert_array_equal(q, q_full)


def test_a_2d_state_changed_between_calls_is_visited_again():
    """On a 2D grid the loop steps a flattened copy of py-pde's state, and that copy is
    also what tells whether anyone changed the state between two calls: a mound put far
    from the flow in between is swept afresh (it slumps as for a new solver; here the
    first call's end is interpolated, and the step past it is dropped for the changed
    state), and without a change the second call goes on as one call would."""
    eq, state = _collapse(False, "hll/first-order")
    far = (slice(30, 34), slice(2, 6))  # x 1.5-1.7 m, y 0.1-0.3 m: beyond the flow

    def two_calls(change: bool):
        s = state.copy()
        stepper = pdeflow.FVSplitSolver(eq, cfl=0.4, stop_at_rest=False,
                                        t_end=0.3).make_stepper(s)
        stepper(s, 0.0, 0.1)
        if change:
            s.data[0][far] += 0.2
        again = s.copy()
        stepper(s, 0.1, 0.3)
        fresh = pdeflow.FVSplitSolver(eq, cfl=0.4, stop_at_rest=False)
        fresh.make_stepper(again)(again, 0.1, 0.3)
        return s, again

    s, again = two_calls(True)
    assert 0.01 < s.data[0][far].max() < 0.2 - 1e-3  # it is there, and it slumped
    np.testing.assert_array_equal(s.data, again.data)
    one = state.copy()
    pdeflow.FVSplitSolver(eq, cfl=0.4, stop_at_rest=False,
                          t_end=0.3).make_stepper(one)(one, 0.0, 0.3)
    s, _ = two_calls(False)  # (the first call's end interpolated, the second resumes)
    np.testing.assert_array_equal(s.data, one.data)
