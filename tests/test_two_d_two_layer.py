"""The two-layer model's 2D kernels (:func:`pdeflow.models.two_layer.kernels.kernels_2d`)
run by the scheme's 2D face loop directly, as tests/test_two_d_loop.py runs the 2D
shallow water: uniform across a direction they give the 1D run's numbers; a cone below
the friction angles stays at rest; mass, positivity and the x <-> y symmetry; and after
each source stage every wet cell is hyperbolic in every direction.
"""

from __future__ import annotations

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.models.two_layer import layout as T
from pdeflow.models.two_layer import two_d
from pdeflow.models.two_layer.kernels import kernels, kernels_2d
from pdeflow.numerics import layout as L
from pdeflow.numerics.geometry import metric_of
from pdeflow.numerics.splitting import STATUS_END, scheme_stepper

N = 56  #: cells along the flow: the 5.1 domain (7 m) at dx = 0.125 m
DX = 0.125  #: cell width along both axes [m] (a power of 2: both grids get it exactly)
ACROSS = 3  #: cells across the flow
CFL = 0.3
SCHEMES = [(flux, order, limiter) for flux in ("hll", "rusanov", "ifcp")
           for order, limiter in ((1, "minmod"), (2, "minmod"), (2, "mc"))]


def run(model, grid, q: np.ndarray, scheme, strang: bool, bc_lo: int, bc_hi: int,
        P: np.ndarray, cfl: float, t_end: float):
    """(q, steps, diag): q advanced to t_end by the compiled fv-split stepper (as
    tests/test_two_d_loop.py)."""
    flux, order, limiter = scheme
    metric = metric_of(grid)
    stepper = scheme_stepper(model, L.FLUXES[flux], order, L.LIMITERS[limiter], strang,
                             metric.code)
    diag = np.zeros(L.N_DIAG + q.shape[1])
    t, steps, status = stepper(q, 0.0, t_end, metric.dx, metric.array(), bc_lo, bc_hi, P,
                               cfl, diag, np.empty_like(q), np.empty_like(q),
                               np.empty((3, *q.shape)), 10**6, False)
    assert status == STATUS_END
    return q, steps, diag


def parameters(**params) -> np.ndarray:
    """The two-layer parameter vector (the paper's defaults and ``params``)."""
    return pdeflow.TwoLayerGranular(**params).parameter_array()


def column() -> tuple[np.ndarray, np.ndarray]:
    """(h1, h2) [m] of 5.1's column (L0 = 1 m, H0 = 2 m, the Rankine wedge at 60 deg)
    on the N cells of width DX."""
    x = (np.arange(N) + 0.5) * DX
    h2 = np.where(x < 1, np.minimum(2.0, (1 - x) * np.tan(np.radians(60))), 0.0)
    return np.where(x < 1, 2.0 - h2, 0.0), h2


def lines(profiles: list[np.ndarray], rotated: bool) -> np.ndarray:
    """The 2D state whose every line across the flow holds the 1D ``profiles`` (h1,
    h1u1, h2, h2u2): along x on an N x ACROSS grid, or along y on ACROSS x N."""
    h1, m1, h2, m2 = profiles
    zero = np.zeros_like(h1)
    along = [h1, m1, zero, h2, m2, zero] if not rotated else [h1, zero, m1, h2, zero, m2]
    if rotated:
        return two_d.state(*(np.tile(f, (ACROSS, 1)) for f in along))
    return two_d.state(*(np.repeat(f[:, None], ACROSS, axis=1) for f in along))


def grid_2d(rotated: bool) -> CartesianGrid:
    if rotated:
        return CartesianGrid([[0, ACROSS * DX], [0, N * DX]], [ACROSS, N])
    return CartesianGrid([[0, N * DX], [0, ACROSS * DX]], [N, ACROSS])


@pytest.mark.parametrize("strang", [False, True], ids=["lie", "strang"])
@pytest.mark.parametrize("scheme", SCHEMES, ids=["/".join(map(str, s)) for s in SCHEMES])
def test_uniform_across_gives_the_1d_numbers(scheme, strang):
    """5.1 coarsened to dx = 0.125 m (wall at the column's back, open ahead; t = 1 s),
    with the paper's exchange closure (Lie; Strang: the relaxed one, since the paper's,
    singular at du = 0, deposits the whole upper layer in the first half step from rest)
    and the restoration of hyperbolicity, both of which act in the 1D run: on an N x 3
    grid uniform in y (wall below, open above in y), and rotated on a 3 x N grid uniform
    in x with the flow along y, every line equals the 1D run exactly, with the same
    steps, exchanged volumes and F_extra. The 2D kernels restore hyperbolicity as the 1D
    rule does ('flow'): a cell above the band, which 'all' restores, would differ. The
    2D time step bounds the sum of the Courant numbers over both axes, so the 2D run
    takes CFL 2 c (a power of 2: the same step to the bit, tests/test_two_d_loop.py)."""
    h1, h2 = column()
    zero = np.zeros_like(h1)
    P = parameters(exchange_closure="relaxed" if strang else "paper")
    q1, steps1, diag1 = run(kernels(), CartesianGrid([[0, N * DX]], N),
                            np.stack([h1, zero, h2, zero]), scheme, strang, L.BC_WALL,
                            L.BC_OPEN, P, CFL, 1.0)
    assert diag1[T.D_HYP_EVENTS] > 0
    assert diag1[T.D_DEPOSITED] > 0 and diag1[T.D_ERODED] > 0
    model = kernels_2d(directions="flow")
    for rotated in (False, True):
        across = (L.BC_WALL, L.BC_OPEN)
        bc = (L.BC_WALL, L.BC_OPEN)
        sides = ([L.sides((across[k], bc[k])) for k in (0, 1)] if rotated
                 else [L.sides((bc[k], across[k])) for k in (0, 1)])
        grid = grid_2d(rotated)
        q2, steps2, diag2 = run(model, grid, lines([h1, zero, h2, zero], rotated),
                                scheme, strang, *sides, P, 2 * CFL, 1.0)
        assert steps2 == steps1
        assert diag2[T.D_HYP_EVENTS] == ACROSS * diag1[T.D_HYP_EVENTS]
        assert diag2[T.D_FEXTRA_MAX] == diag1[T.D_FEXTRA_MAX]
        assert diag2[T.D_DEPOSITED] == pytest.approx(ACROSS * diag1[T.D_DEPOSITED],
                                                     rel=1e-12)  # sums in another order
        f = q2.reshape(6, *grid.shape)
        normal, tangential = (2, 1) if rotated else (1, 2)
        for j in range(ACROSS):
            line = f[:, j, :] if rotated else f[:, :, j]
            for k1, k2 in ((0, 0), (normal, 1), (3, 2), (3 + normal, 3)):
                assert np.array_equal(line[k1], q1[k2]), (rotated, j, k1)
            assert not np.any(line[tangential]) and not np.any(line[3 + tangential])
