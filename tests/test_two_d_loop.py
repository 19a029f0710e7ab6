"""One face loop over every axis of the grid: a 2D CartesianGrid is a third metric of the
1D scheme's loop (issue 35).

The model is the frictionless shallow water in 2D of :mod:`tests.shallow_water.two_d`
(h, hu, hv), driven through the fv-split stepper as pdeflow's runs drive it. A state
uniform across one direction gives the 1D run's numbers bit for bit (every flux,
reconstruction and splitting, along x and rotated along y): the faces across that
direction carry exactly zero fluctuations (equal states, no normal momentum), so every
cell adds the 1D arithmetic's terms in the 1D order. The 2D time step bounds the sum of
the Courant numbers over both axes (each face's speed counts twice on a grid with
dx = dy), so the 2D run takes CFL 2 c to make the 1D run's steps at c; the factor is a
power of two, so the step is the same to the bit. A radial dam break in a walled box
conserves mass to round-off and is symmetric under x <-> y to round-off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pde import CartesianGrid

from pdeflow.numerics import layout as L
from pdeflow.numerics.geometry import metric_of
from pdeflow.numerics.splitting import STATUS_END, scheme_stepper
from tests.helpers import schemes_2d
from tests.shallow_water import layout as W
from tests.shallow_water import two_d
from tests.shallow_water.model import KERNELS as ONE_D
from tests.shallow_water.model import ShallowWater

N = 40  #: cells along the flow
DX = 0.125  #: cell width along both axes [m] (a power of 2: both grids get it exactly)
ACROSS = 3  #: cells across the flow
CFL = 0.3
SCHEMES = [(flux, order, limiter) for flux in ("hll", "rusanov", "ifcp")
           for order, limiter in ((1, "minmod"), (2, "minmod"), (2, "mc"))]


def _parameters(theta_deg: float) -> np.ndarray:
    P = np.zeros(W.SIZE)
    P[W.G_Z] = 9.81 * math.cos(math.radians(theta_deg))
    P[W.G_X] = 9.81 * math.sin(math.radians(theta_deg))
    P[W.DRY] = 1e-6
    return P


def _run(model, grid, q: np.ndarray, scheme, strang: bool, bc_lo: int, bc_hi: int,
         P: np.ndarray, cfl: float, t_end: float):
    """q advanced to t_end by the compiled fv-split stepper (as tests.helpers.step)."""
    flux, order, limiter = scheme
    metric = metric_of(grid)
    stepper = scheme_stepper(model, L.FLUXES[flux], order, L.LIMITERS[limiter], strang,
                             metric.code)
    diag = np.zeros(L.N_DIAG + q.shape[1])
    t, steps, status = stepper(q, 0.0, t_end, metric.dx, metric.array(), bc_lo, bc_hi, P,
                               cfl, diag, np.empty_like(q), np.empty_like(q),
                               np.empty((3, *q.shape)), 10**6, False)
    assert status == STATUS_END
    return q, steps


def _profile() -> tuple[np.ndarray, np.ndarray]:
    """A column (1 m, moving) beside a smaller heap at rest and dry cells: fronts, a wet
    window with a dry gap, cells at rest."""
    x = (np.arange(N) + 0.5) * DX
    h = np.where(x < 1.5, 1.0, np.where((x > 3.0) & (x < 3.5), 0.3, 0.0))
    hu = np.where(x < 1.5, 0.2 * h, 0.0)
    return h, hu


@pytest.mark.parametrize(("scheme", "strang"), schemes_2d(SCHEMES))
def test_uniform_across_gives_the_1d_numbers(scheme, strang):
    """Uniform in y on an N x 3 grid (wall below, open above in y; on a 5 deg slope along
    x), and rotated, uniform in x on a 3 x N grid with the flow along y (horizontal: the
    model's gravity acts along x only): every cell of every line equals the 1D run's,
    exactly, with the same number of steps."""
    h, hu = _profile()
    bc = (L.BC_WALL, L.BC_OPEN)  # the flow's low and high sides
    across = (L.BC_WALL, L.BC_OPEN)
    for theta, rotated in ((5.0, False), (0.0, True)):
        P = _parameters(theta)
        q1, steps1 = _run(ONE_D, CartesianGrid([[0, N * DX]], N), np.stack([h, hu]),
                          scheme, strang, *bc, P, CFL, 0.4)
        flat = np.zeros_like(h)
        if rotated:
            grid = CartesianGrid([[0, ACROSS * DX], [0, N * DX]], [ACROSS, N])
            lines = (np.tile(h, (ACROSS, 1)), np.zeros((ACROSS, N)), np.tile(hu, (ACROSS, 1)))
            sides = [L.sides((across[k], bc[k])) for k in (0, 1)]
        else:
            grid = CartesianGrid([[0, N * DX], [0, ACROSS * DX]], [N, ACROSS])
            lines = tuple(np.repeat(f[:, None], ACROSS, axis=1) for f in (h, hu, flat))
            sides = [L.sides((bc[k], across[k])) for k in (0, 1)]
        q2, steps2 = _run(two_d.KERNELS, grid, two_d.state(*lines), scheme, strang, *sides,
                          P, 2 * CFL, 0.4)
        assert steps2 == steps1
        fields = q2.reshape(3, *grid.shape)
        for j in range(ACROSS):
            if rotated:
                h2, along, across_m = fields[0, j, :], fields[2, j, :], fields[1, j, :]
            else:
                h2, along, across_m = fields[0, :, j], fields[1, :, j], fields[2, :, j]
            assert np.array_equal(h2, q1[0]), (rotated, j)
            assert np.array_equal(along, q1[1]), (rotated, j)
            assert not np.any(across_m), (rotated, j)


@pytest.mark.parametrize("scheme", [("hll", 1, "minmod"), ("hll", 2, "mc")],
                         ids=["hll/first-order", "hll/muscl/mc"])
def test_radial_dam_break_in_a_box(scheme):
    """A cylinder column (radius 0.5 m, 1 m deep) in the middle of a 2 m x 2 m box with
    walls (and a film of 5 cm around it) spreads to the walls (t = 1 s).

    The mass stays to round-off (a face's mass fluctuations add to the jump of the mass
    flux, zero at a wall): relative 1e-12 for ~300-400 steps of sums over 1600 cells
    (measured below 3e-16). The depth stays non-negative. The state is symmetric under
    x <-> y (h(x, y) = h(y, x), hu(x, y) = hv(y, x)) to round-off: the x- and y-faces
    add their terms to a cell in a different order, so mirror cells differ by rounding
    (a few units of 1e-16 per step), which the flow carries over the steps: 1e-12 m
    [m^2/s] absolute on depths of order 1 m (measured below 3e-15)."""
    n = 40
    grid = CartesianGrid([[0, 2.0], [0, 2.0]], [n, n])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    h = np.where((x - 1.0) ** 2 + (y - 1.0) ** 2 < 0.25, 1.0, 0.05)
    q = two_d.state(h, np.zeros_like(h), np.zeros_like(h))
    mass0 = q[0].sum()
    walls = L.sides((L.BC_WALL, L.BC_WALL))
    q, steps = _run(two_d.KERNELS, grid, q, scheme, False, walls, walls, _parameters(0.0),
                    0.4, 1.0)
    assert steps > 20
    assert abs(q[0].sum() - mass0) <= 1e-12 * mass0
    assert q[0].min() >= 0.0
    f = q.reshape(3, n, n)
    assert np.abs(f[0] - f[0].T).max() <= 1e-12
    assert np.abs(f[1] - f[2].T).max() <= 1e-12
    # the column did spread: the depth at the centre fell, the walls got wet
    assert f[0, n // 2, n // 2] < 0.8 and f[0, 0, n // 2] > 0.05


def test_the_2d_metric_and_what_still_refuses_a_2d_grid():
    """A 2D CartesianGrid's metric: axes as (stride in the flattened cell index, cells,
    width), the cell area dx dy (the mass integral), each side's boundary codes packed
    one bit per axis; a model without 2D kernels (the 1D shallow water of the tests)
    refuses the grid with a one-line error naming the grids it takes."""

    grid = CartesianGrid([[0, 2.0], [0, 0.5]], [8, 4])
    metric = metric_of(grid)
    assert metric.code == L.GEOMETRY_PLANAR_2D
    assert metric.axes == [(4, 8, 0.25), (1, 4, 0.125)]
    assert metric.array()[L.M_AXES, :6].tolist() == [4, 8, 0.25, 1, 4, 0.125]
    # the exact sum of 32 cells of 0.25 * 0.125 m^2 (powers of two: no rounding)
    assert metric.integral(np.ones(32)) == 1.0
    assert L.sides((L.BC_OPEN,)) == L.BC_OPEN
    assert L.sides((L.BC_WALL, L.BC_OPEN)) == 2 and L.sides((L.BC_OPEN, L.BC_WALL)) == 1
    with pytest.raises(ValueError, match="1D CartesianGrid or a PolarSymGrid"):
        ShallowWater().metric(grid)
