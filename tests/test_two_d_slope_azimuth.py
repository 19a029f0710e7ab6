"""A plane inclined at an angle to the grid (``slope_azimuth_deg``, issue 36's
verification 4): gravity along the plane g sin(theta) (cos a, sin a), the friction's
normal g cos(theta). The parameter is 2D only; the two layers on the plane inclined along
y give the 1D run's numbers; a two-layer cone on the plane inclined along 30 deg stays at
rest (the single layer's: tests/test_two_d_single_layer.py); a uniform layer above the
friction angle accelerates along the steepest descent. Mangeney's dam break at an angle:
tests/test_two_d_dam_angles.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.case_schema import CaseError
from pdeflow.cases import load_case
from pdeflow.checks import slope_warning
from pdeflow.models.two_layer import layout as T
from pdeflow.models.two_layer.kernels import kernels, kernels_2d
from pdeflow.numerics import layout as L
from tests.test_two_d_two_layer import (
    ACROSS,
    CFL,
    DX,
    N,
    column,
    cone_stays_at_rest,
    grid_2d,
    lines,
    parameters,
    run,
)

CASES = Path(__file__).parents[1] / "cases"


def test_a_slope_azimuth_is_2d_only_and_in_range():
    """On a 1D grid (planar or axisymmetric) and in a 1D case file a nonzero azimuth is
    a one-line error before any work; outside [-180, 180] deg one naming the range; in a
    2D case it reaches the kernels' parameter vector, and models inclined along
    different directions are warned about as models on different slopes are."""
    eq = pdeflow.SingleLayerGranular(theta_deg=20.0, slope_azimuth_deg=30.0)
    with pytest.raises(ValueError, match=r"^slope_azimuth_deg must be 0 on a 1D grid .*"
                                         r"got 30$"):
        eq.make_state(CartesianGrid([[0, 1]], 10), h=np.ones(10))
    with pytest.raises(ValueError, match=r"^slope_azimuth_deg must lie in \[-180, 180\] "
                                         r"deg, got 270"):
        pdeflow.TwoLayerGranular(slope_azimuth_deg=270)
    with pytest.raises(CaseError, match=r"two_layer.slope_azimuth_deg = -45 belongs to a "
                                        r"2D grid"):
        load_case(CASES / "paper_5_1_dam_break.toml",
                  ["two_layer.slope_azimuth_deg=-45"])
    case = load_case(CASES / "column_on_slope_2d.toml",
                     ["single_layer.slope_azimuth_deg=90", "two_layer.slope_azimuth_deg=90"])
    for model in case.models:
        P = case.make_pde(model).parameter_array()
        assert P[L.G_X] == 0.0 and P[L.G_Y] > 0.0, (model, P[:3])
    assert slope_warning(case) is None
    one = load_case(CASES / "column_on_slope_2d.toml", ["two_layer.slope_azimuth_deg=90"])
    assert "two_layer.slope_azimuth_deg = 90, single_layer.slope_azimuth_deg = 0 deg" \
        in slope_warning(one)


@pytest.mark.parametrize("scheme, strang", [(("hll", 1, "minmod"), False),
                                            (("rusanov", 2, "minmod"), True)],
                         ids=["hll/first-order", "rusanov/muscl/minmod+strang"])
def test_two_layers_on_the_plane_inclined_along_y_give_the_1d_run(scheme, strang):
    """5.1's column on a 20 deg slope (closure and restoration acting), 1 s: the 1D run
    along x, and the 2D run uniform in x on the plane inclined along y (azimuth 90 deg:
    gravity exactly (0, g sin theta)) with the flow along y, every line equal to the 1D
    run bit for bit, with the same steps (exact: gravity across the flow is exactly 0,
    so every cell's velocities lie along y and the kernels do the 1D arithmetic;
    tests/test_two_d_two_layer.py's rotated run, horizontal, for the rest)."""
    h1, h2 = column()
    zero = np.zeros_like(h1)
    kw = {"theta_deg": 20.0, "exchange_closure": "relaxed" if strang else "paper"}
    q1, steps1, diag1 = run(kernels(), CartesianGrid([[0, N * DX]], N),
                            np.stack([h1, zero, h2, zero]), scheme, strang, L.BC_WALL,
                            L.BC_OPEN, parameters(**kw), CFL, 1.0)
    assert diag1[T.D_HYP_EVENTS] > 0 and diag1[T.D_DEPOSITED] > 0
    P = parameters(slope_azimuth_deg=90.0, **kw)
    sides = [L.sides((L.BC_WALL, L.BC_WALL)), L.sides((L.BC_OPEN, L.BC_OPEN))]
    q2, steps2, _ = run(kernels_2d(directions="flow"), grid_2d(True),
                        lines([h1, zero, h2, zero], True), scheme, strang, *sides, P,
                        2 * CFL, 1.0)
    assert steps2 == steps1
    f = q2.reshape(6, ACROSS, N)
    for j in range(ACROSS):
        for k1, k2 in ((0, 0), (2, 1), (3, 2), (5, 3)):
            assert np.array_equal(f[k1, j], q1[k2]), (j, k1)
        assert not np.any(f[[1, 4], j])
    assert q1[3].max() > 0.1  # the lower layer slid down the slope [m^2/s]


@pytest.mark.parametrize("scheme", [("hll", 1, "minmod"), ("hll", 2, "mc")],
                         ids=["hll/first-order", "hll/muscl/mc"])
def test_a_two_layer_cone_on_a_plane_inclined_at_30_degrees_stays_at_rest(scheme):
    """A cone of slope 0.1 (1 m deep at the apex, 40 % upper layer) in a walled 2.5 m
    box on a plane at theta = 10 deg inclined along 30 deg from x: the upper layer's
    drive, at most g_z 0.1 sqrt 2 + g sin(theta) = 0.32 g_z, is held by the interface
    friction k tan(phi_int) g_z = 0.375 g_z, the lower layer's by tan(phi_B) = 0.87. With
    exchange 'none' every value is unchanged after 10 s, exactly (the set-valued friction
    holds the explicit update u + dt g (cos a, sin a) sin(theta) back to exactly 0); with
    the paper's closure every momentum is exactly zero and the mass r h1 + h2 stays to
    round-off (relative 1e-12: sums over 400 cells)."""
    P = parameters(theta_deg=10.0, slope_azimuth_deg=30.0)
    assert P[L.G_X] > 0.0 and P[L.G_Y] > 0.0
    cone_stays_at_rest(scheme, 0.1, theta_deg=10.0, slope_azimuth_deg=30.0)


def _uniform_layer(model: str) -> tuple[np.ndarray, float]:
    """The state after 0.5 s of a uniform layer (0.2 m; two layers: 0.1 m each) on 8 x 8
    cells, open on every side, on a plane at 35 deg inclined along 30 deg from x,
    basal friction 20 deg (two layers: 25 deg, no exchange, which from rest would
    deposit the upper layer whole), fv-split first order; and its number of steps."""
    grid = CartesianGrid([[0, 1], [0, 1]], [8, 8])
    kw = {"theta_deg": 35.0, "slope_azimuth_deg": 30.0, "bc": ("open", "open")}
    if model == "single_layer":
        eq = pdeflow.SingleLayerGranular(phi_b_deg=20.0, **kw)
        state = eq.make_state(grid, h=np.full((8, 8), 0.2))
    else:
        eq = pdeflow.TwoLayerGranular(phi_b_deg=25.0, exchange_closure="none", **kw)
        state = eq.make_state(grid, h1=np.full((8, 8), 0.1), h2=np.full((8, 8), 0.1))
    out, info = eq.solve(state, 0.5, solver="fv-split", tracker=None, ret_info=True)
    return out.data, info["solver"]["steps"]


@pytest.mark.parametrize("model", ["single_layer", "two_layer"])
def test_a_uniform_layer_above_the_friction_angle_accelerates_along_the_slope(model):
    """Every layer of every cell moves along n = (cos 30 deg, sin 30 deg): its velocity
    across n is below 1e-14 of its speed (the two components gain dt g sin(theta)
    (cos a, sin a) and are scaled by the same friction factor each step: a few ulps of
    the direction, measured 2e-16). The single layer's speed is the exact
    (g sin(theta) - g cos(theta) tan(phi_b)) t = 1.35 m/s (relative 1e-12: a sum of 50
    steps' increments, measured 2e-16); the two layers' upper layer slides over the
    lower one (1.28 and 0.71 m/s), both down the slope."""
    q, steps = _uniform_layer(model)
    a = math.radians(30.0)
    speeds = []
    for k in range(0, q.shape[0], 3):  # each layer's rows h, hu, hv
        h, hu, hv = q[k], q[k + 1], q[k + 2]
        along = hu * math.cos(a) + hv * math.sin(a)
        across = -hu * math.sin(a) + hv * math.cos(a)
        assert np.all(along > 0.0), (model, k)
        assert np.abs(across).max() <= 1e-14 * along.min(), (model, k, across)
        assert np.all(h == h.flat[0])  # uniform: the faces carry zero fluctuations
        speeds.append(along.min() / h.min())
    if model == "single_layer":
        th = math.radians(35.0)
        m = 9.81 * (math.sin(th) - math.cos(th) * math.tan(math.radians(20.0)))
        speed = np.hypot(q[1], q[2]) / q[0]
        assert speed == pytest.approx(np.full_like(speed, m * 0.5), rel=1e-12)
    else:
        assert speeds[0] > speeds[1] > 0.0
    assert steps > 10
