"""A 2D run that blows up names the failed cell, as a 1D run does (issue 36): the step is
replayed in Python around the compiled kernels with a recording state update (the box
of the 2D loop updated row by row), and the report gives the cell's (i, j), its centre
(x, y), the failed and the kept values, and the extent of the bad cells.

The blow-ups are made by a finite but absurd momentum (u = 1e200 m/s: u^2 overflows),
as in tests/test_failures.py for 1D.
"""

from __future__ import annotations

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow import SimulationBlowUp
from pdeflow.solvers.blowup import diagnose_blowup

NX, NY, DX = 20, 12, 0.1  #: cells along x and y, their width [m]
BAD = (7, 4)  #: the cell given the absurd momentum


def _state(two_layer: bool, scheme: str):
    """A layer 0.5 m deep (two layers: 0.2 m over 0.3 m) on a horizontal walled plane,
    at rest but for one cell moving along x at 1e200 m/s."""
    grid = CartesianGrid([[0, NX * DX], [0, NY * DX]], [NX, NY])
    bc = (("wall", "wall"), ("wall", "wall"))
    if two_layer:
        eq = pdeflow.TwoLayerGranular(scheme=scheme, bc=bc)
        state = eq.make_state(grid, h1=np.full(grid.shape, 0.2), h2=np.full(grid.shape, 0.3))
        state.data[4][BAD] = 1e200 * state.data[3][BAD]  # the lower layer's h2 u2
    else:
        eq = pdeflow.SingleLayerGranular(phi_b_deg=30.0, scheme=scheme, bc=bc)
        state = eq.make_state(grid, h=np.full(grid.shape, 0.5))
        state.data[1][BAD] = 1e200 * state.data[0][BAD]
    return eq, state


@pytest.mark.filterwarnings("ignore:overflow encountered", "ignore:invalid value")
@pytest.mark.parametrize(("two_layer", "scheme"), [(False, "hll/first-order"),
                                                   (True, "hll/muscl/mc+strang")])
def test_a_2d_blow_up_names_the_cell_and_keeps_the_state(two_layer, scheme):
    eq, state = _state(two_layer, scheme)
    with pytest.raises(SimulationBlowUp) as info:
        eq.solve(state, t_range=1.0, solver="fv-split", tracker=None)
    err = info.value
    assert err.step == 1 and err.t == 0.0
    assert "non-finite values" in str(err)
    i, j = err.report["cell_index"]
    # the overflow is in the cell or its neighbours along x (the momentum is along x)
    assert abs(i - BAD[0]) <= 1 and j == BAD[1]
    assert err.cell == i * NY + j  # the kernels' cells, flattened row by row
    x, y = state.grid.axes_coords
    assert err.x == pytest.approx(x[i], rel=1e-12) and err.report["y"] == pytest.approx(
        y[j], rel=1e-12)
    assert f"cell ({i}, {j})" in str(err) and "y=" in str(err)
    assert not all(np.isfinite(list(err.report["failed"].values())))
    names = ("h1", "h1u1", "h1v1", "h2", "h2u2", "h2v2") if two_layer else ("h", "hu", "hv")
    assert tuple(err.report["failed"]) == names
    assert set(err.report["cell_state"]) == ({"h1", "u1", "v1", "h2", "u2", "v2"}
                                             if two_layer else {"h", "u", "v"})
    assert all(np.unravel_index(c, (NX, NY))[1] == BAD[1] for c in err.report["bad_cells"])
    # nothing of the failed step kept: the state is the initial one
    np.testing.assert_array_equal(err.state, state.data)
    np.testing.assert_array_equal(eq.diagnostics["last_state"].data, state.data)


def test_the_last_attempt_of_a_row_by_row_step_is_reported():
    """A replay that updates a box row by row twice (a first attempt, then a retry of
    the step) reports the retry's failure, with its stage and its worst cell."""
    eq = pdeflow.SingleLayerGranular()
    q = np.full((3, 12), 0.5)  # 3 rows of 4 cells, at rest
    q[1:] = 0.0
    rate = np.zeros_like(q)

    def replay(q, t, t_end, update):
        start = q.copy()
        for attempt, dt in enumerate((1.0, 0.5)):
            q[...] = start  # a retry starts from the state before the step
            rate[0] = 0.0
            rate[0, 5 + attempt] = -2.0  # the first attempt fails cell 5, the retry 6
            for row in range(3):  # the predictor stage, row by row
                update(q, q, rate, dt, 0.0, 4 * row, 4 * row + 3)
            for row in range(3):  # the corrector stage
                update(q, q, rate, dt, 0.5, 4 * row, 4 * row + 3)

    report = diagnose_blowup(eq, q, 0.0, 1.0, replay)
    assert report["cause"] == "a negative depth"
    assert report["cell"] == 6 and report["bad_cells"] == [6]
    assert report["stage"] == 1 and report["dt"] == 0.5
    assert report["failed"]["h"] == pytest.approx(-0.5, abs=1e-15)
