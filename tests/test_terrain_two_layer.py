"""The two layers over a bed z_b(x, y) (issue 37; docs/terrain.md): a lake of two
layers and the upper layer alone at rest on a rough bed (well balanced), a two-layer
cone on a bumpy inclined bed exactly at rest, the upper layer over the bare bed feeling
the slope, a horizontal bed giving the plane's numbers, and an erodible lower layer at
rest over terrain that a release overruns."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.numerics.geometry import bed_at_corners
from tests.test_terrain_flow import cell_beds, inclined_bumpy

WALLS = (("wall", "wall"), ("wall", "wall"))


def two_layer_state(pde, grid, h1, h2):
    zero = np.zeros_like(h1)
    return pde.make_state(grid, h1=h1, u1=zero, v1=zero, h2=h2, u2=zero, v2=zero)


def rate_of(pde, state) -> np.ndarray:
    return pde.make_evolution_rate(state, "numba")(state.data, 0.0)


@pytest.mark.parametrize("upper_only", [False, True])
def test_a_two_layer_lake_at_rest_on_a_rough_bed(upper_only):
    """Flat interface (level 1.5 m) under a uniform upper layer 0.5 m thick, or the
    upper layer alone up to 2 m, on a random bed of 0-1 m: the method-of-lines rate is
    round-off (< 1e-12; no exchange, so that only the scheme is seen)."""
    grid = CartesianGrid([[0, 100], [0, 80]], [50, 40])
    corners = np.random.default_rng(2).uniform(0.0, 1.0, (51, 41))
    z = cell_beds(grid, corners)
    h2 = np.zeros_like(z) if upper_only else 1.5 - z
    h1 = 2.0 - z if upper_only else np.full_like(z, 0.5)
    pde = pdeflow.TwoLayerGranular(exchange_closure="none", bc=WALLS, bed=corners)
    assert np.abs(rate_of(pde, two_layer_state(pde, grid, h1, h2))).max() < 1e-12


def test_a_two_layer_cone_on_a_bumpy_slope_stays_exactly_at_rest():
    """A two-layer cone (flanks 0.1, 40 % of it upper layer, as
    tests/test_two_d_two_layer.py's) on the bumpy plane at 10 deg (the paper's
    frictions): without exchange nothing moves for 50 s, to the bit; with the paper's
    closure every momentum stays zero and the mass r h1 + h2 is kept to 1e-12."""
    grid = CartesianGrid([[0, 200], [0, 100]], [60, 30])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    total = np.maximum(4.0 - 0.1 * np.hypot(xx - 100, yy - 50), 0.0)
    h1, h2 = 0.4 * total, 0.6 * total
    for closure in ("none", "paper"):
        pde = pdeflow.TwoLayerGranular(exchange_closure=closure, bc=WALLS,
                                       bed=inclined_bumpy(grid, 10.0))
        state = two_layer_state(pde, grid, h1, h2)
        end = pde.solve(state, 50.0, solver="fv-split", tracker=None, stop_at_rest=False)
        if closure == "none":
            np.testing.assert_array_equal(end.data, state.data)
        else:
            assert not np.any(end.data[[1, 2, 4, 5]])
            r = pde.parameters.density_ratio
            mass0 = (r * h1 + h2).sum()
            assert (r * end.data[0] + end.data[3]).sum() == pytest.approx(mass0, rel=1e-12)


def test_the_upper_layer_alone_feels_the_bed_s_slope():
    """A uniform upper layer 0.1 m deep, no lower layer, on a plane at 34 deg with 5 m
    cells (the bed rises 3.4 m across a cell): inside it the advective rate of its
    momentum is g h1 tan(34 deg), to 1e-12 relative."""
    tan_t = math.tan(math.radians(34.0))
    grid = CartesianGrid([[0, 500], [0, 50]], [100, 10])
    pde = pdeflow.TwoLayerGranular(exchange_closure="none", bed=bed_at_corners(
        grid, lambda x, y: -tan_t * x + 0.0 * y), bc=(("open", "open"), ("open", "open")))
    h1 = np.full(grid.shape, 0.1)
    state = two_layer_state(pde, grid, h1, np.zeros_like(h1))
    from pdeflow.numerics.advection import rate_kernel
    from pdeflow.numerics.compiled import ready

    metric = pde.metric(grid)
    kernels = pde.kernels_of(metric)
    advect = ready(rate_kernel(kernels, *pde.scheme.codes, metric.code))
    out = np.empty((6, grid.num_cells))
    g, r, dry = kernels.constants(pde.parameter_array())
    bcl, bcr = pde.boundary_codes(2)
    advect(state.data.reshape(6, -1).copy(), out, np.empty((2, 6, grid.num_cells)),
           metric.dx, metric.array(), bcl, bcr, g, r, dry)
    inside = out[1].reshape(grid.shape)[50, 5]
    assert inside / 0.1 == pytest.approx(9.81 * tan_t, rel=1e-12)


def test_a_horizontal_bed_gives_the_plane_s_two_layer_numbers():
    """5.1's column as a disc collapsing in 2D over a bed at a constant level: the
    numbers of the run without a bed to 1e-12 (face momenta h (hu / h) differ in the
    last digit)."""
    grid = CartesianGrid([[0, 6], [0, 6]], [30, 30])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    inside = np.hypot(xx - 3, yy - 3) < 1.0
    h2 = np.where(inside, np.clip((3.5 - xx) * math.tan(math.radians(60)), 0, 2), 0.0)
    h1 = np.where(inside, 2.0 - h2, 0.0)
    plain = pdeflow.TwoLayerGranular(bc=WALLS)
    flat = pdeflow.TwoLayerGranular(bc=WALLS, bed=np.full((31, 31), -7.0))
    a = plain.solve(two_layer_state(plain, grid, h1, h2), 0.3, solver="fv-split",
                    tracker=None)
    b = flat.solve(two_layer_state(flat, grid, h1, h2), 0.3, solver="fv-split",
                   tracker=None)
    assert np.abs(a.data[[1, 2, 4, 5]]).max() > 0.1  # it flowed
    np.testing.assert_allclose(b.data, a.data, rtol=0, atol=1e-12 * np.abs(a.data).max())


def test_an_erodible_lower_layer_over_terrain_is_overrun():
    """A lower layer 0.3 m deep over the bumpy plane at 20 deg (below its friction angle,
    41 deg: an erodible bed at rest), the upper layer released on it upslope, without
    exchange (with the paper's closure the release is deposited into the bed within
    2 s, as on a plane): the mass r h1 + h2 is kept to 1e-12, depths stay >= 0, the
    flow reaches downslope, and the bed far across the slope, out of the flow's reach,
    is exactly as it was."""
    grid = CartesianGrid([[0, 300], [0, 200]], [60, 40])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    h2 = np.full(grid.shape, 0.3)
    h1 = np.where(np.hypot(xx - 50, yy - 50) < 20, 3.0, 0.0)
    pde = pdeflow.TwoLayerGranular(exchange_closure="none", bed=inclined_bumpy(grid, 20.0),
                                   bc=(("open", "open"), ("wall", "wall")))
    state = two_layer_state(pde, grid, h1, h2)
    end = pde.solve(state, 20.0, solver="fv-split", tracker=None)
    r = pde.parameters.density_ratio
    d = end.data
    assert (r * d[0] + d[3]).sum() == pytest.approx((r * h1 + h2).sum(), rel=1e-12)
    assert d[0].min() >= 0.0 and d[3].min() >= 0.0
    assert np.any(d[0][xx > 120] > 1e-3)  # the upper layer travelled down the slope
    far = yy > 150
    np.testing.assert_array_equal(d[:, far], state.data[:, far])
