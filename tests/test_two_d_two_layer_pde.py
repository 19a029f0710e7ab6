"""The two-layer model on a 2D CartesianGrid through its py-pde shell
(:class:`pdeflow.TwoLayerGranular`): the 2D kernels of tests/test_two_d_two_layer.py
reached by ``make_state`` and ``solve`` as a user reaches them, with the parameter
``hyperbolicity_directions`` choosing the 2D restoration.
"""

from __future__ import annotations

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.models.two_layer import layout as T

N = 56  #: cells along the flow: test 5.1's 7 m at dx = 0.125 m
DX = 0.125  #: cell width along both axes [m] (a power of 2: both grids get it exactly)
ACROSS = 3  #: cells across the flow
CFL = 0.2  #: the 1D run's; the 2D run takes 2 CFL (tests/test_two_d_loop.py), <= 0.5 with MUSCL


def _column() -> tuple[np.ndarray, np.ndarray]:
    """(h1, h2) [m]: 5.1's column (L0 = 1 m, H0 = 2 m, the wedge at 60 deg)."""
    x = (np.arange(N) + 0.5) * DX
    h2 = np.where(x < 1, np.minimum(2.0, (1 - x) * np.tan(np.radians(60))), 0.0)
    return np.where(x < 1, 2.0 - h2, 0.0), h2


@pytest.mark.parametrize("scheme", ["hll/first-order+lie", "ifcp/muscl/mc+strang"])
def test_uniform_across_through_solve_gives_the_1d_run(scheme):
    """5.1 coarsened (wall behind the column, open ahead, t = 1 s) on an N x 3 grid
    uniform in y, solved by ``TwoLayerGranular.solve`` with fv-split and
    ``hyperbolicity_directions='flow'`` (the 1D rule): every line is the 1D run's
    numbers bit for bit (exact: the faces across carry zero fluctuations), with the same
    steps and exchanged volumes (to 1e-12: summed in another order), and no cross-slope
    momentum. Strang takes the relaxed closure (the paper's deposits the whole upper
    layer from rest, tests/test_two_d_two_layer.py)."""
    h1, h2 = _column()
    kw = {"scheme": scheme, "hyperbolicity_directions": "flow",
          "exchange_closure": "relaxed" if "strang" in scheme else "paper"}
    one = pdeflow.TwoLayerGranular(bc=("wall", "open"), **kw)
    st1, info1 = one.solve(one.make_state(CartesianGrid([[0, N * DX]], N), h1=h1, h2=h2),
                           1.0, solver="fv-split", cfl=CFL, tracker=None, ret_info=True)
    two = pdeflow.TwoLayerGranular(bc=(("wall", "open"), ("wall", "open")), **kw)
    grid = CartesianGrid([[0, N * DX], [0, ACROSS * DX]], [N, ACROSS])
    across = {"h1": np.repeat(h1[:, None], ACROSS, 1), "h2": np.repeat(h2[:, None], ACROSS, 1)}
    st2, info2 = two.solve(two.make_state(grid, **across), 1.0, solver="fv-split",
                           cfl=2 * CFL, tracker=None, ret_info=True)
    assert [f.label for f in st2] == ["h1", "h1u1", "h1v1", "h2", "h2u2", "h2v2"]
    assert info2["solver"]["steps"] == info1["solver"]["steps"]
    d1, d2 = info1["solver"]["post_step_data"], info2["solver"]["post_step_data"]
    assert d1[T.D_HYP_EVENTS] > 0 and d1[T.D_DEPOSITED] > 0
    assert d2[T.D_HYP_EVENTS] == ACROSS * d1[T.D_HYP_EVENTS]
    assert d2[T.D_DEPOSITED] == pytest.approx(ACROSS * d1[T.D_DEPOSITED], rel=1e-12)
    q1, q2 = st1.data, st2.data
    for j in range(ACROSS):
        for k2, k1 in ((0, 0), (1, 1), (3, 2), (4, 3)):
            assert np.array_equal(q2[k2, :, j], q1[k1]), (scheme, j, k2)
        assert not np.any(q2[2, :, j]) and not np.any(q2[5, :, j])


def test_a_square_collapse_conserves_mass_and_keeps_the_x_y_mirror():
    """A square two-layer column in a walled horizontal box (24 x 24 cells), default
    2D restoration ('all'), 0.5 s of collapse: the mass rho1 h1 + rho2 h2 (in units of
    rho2: r h1 + h2, the exchange moves M/rho1 and -M/rho2) is conserved to 1e-12
    relative, depths stay >= 0, the column spread, and the solution is symmetric under
    x <-> y (the state is; to 1e-9 m: the 2D restoration's Newton iterates round
    differently in mirrored cells)."""
    n = 24
    grid = CartesianGrid([[0, n * DX], [0, n * DX]], [n, n])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    inside = (np.abs(x - n * DX / 2) < 0.5) & (np.abs(y - n * DX / 2) < 0.5)
    eq = pdeflow.TwoLayerGranular(theta_deg=0.0, bc=("wall", "wall"))
    state = eq.make_state(grid, h1=np.where(inside, 0.8, 0.0), h2=np.where(inside, 1.2, 0.0))
    r = eq.parameters.density_ratio
    mass0 = (r * state.data[0] + state.data[3]).sum()
    out = eq.solve(state, 0.5, solver="fv-split", tracker=None)
    q = out.data
    assert abs((r * q[0] + q[3]).sum() - mass0) <= 1e-12 * mass0
    assert q[0].min() >= 0 and q[3].min() >= 0
    assert np.count_nonzero(q[0] + q[3] > 1e-3) > np.count_nonzero(inside)
    for k_x, k_y in ((0, 0), (3, 3), (1, 2), (4, 5)):
        assert np.allclose(q[k_x], q[k_y].T, rtol=0, atol=1e-9), k_x


def test_bad_2d_input_gets_a_one_line_error():
    """The restoration's directions and a 2D state's profiles are refused before any
    work, in one line naming the parameter."""
    with pytest.raises(ValueError, match="hyperbolicity_directions must be one of"):
        pdeflow.TwoLayerGranular(hyperbolicity_directions="some")
    eq = pdeflow.TwoLayerGranular()
    grid = CartesianGrid([[0, 1], [0, 1]], [4, 4])
    with pytest.raises(ValueError, match=r"h1 must have shape \(4, 4\)"):
        eq.make_state(grid, h1=np.ones(4))
    with pytest.raises(ValueError, match="unknown profile"):
        eq.make_state(grid, h=np.ones((4, 4)))
