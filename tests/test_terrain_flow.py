"""The single layer over a bed z_b(x, y) (issue 37; docs/terrain.md, "The flow over a
bed"): well balanced (a lake at rest on a rough bed), exactly at rest (a pile whose
slopes are below the friction angle, a release that stopped), the bed's slope felt by a
layer thinner than the relief of a cell, mass and positivity, a flat bed giving the
plane's numbers, the energy line's bound on the parabola, and the one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.numerics.geometry import bed_corners, corner_coordinates
from pdeflow.terrain.topographies import parabola

WALLS = (("wall", "wall"), ("wall", "wall"))


def cell_beds(grid: CartesianGrid, corners: np.ndarray) -> np.ndarray:
    """The cells' beds [m]: the means of their four corners."""
    c = corners
    return 0.25 * (c[:-1, :-1] + c[1:, :-1] + c[:-1, 1:] + c[1:, 1:])


def at_rest(pde: pdeflow.SingleLayerGranular, grid: CartesianGrid, h: np.ndarray):
    return pde.make_state(grid, h=h, u=np.zeros_like(h), v=np.zeros_like(h))


def rough_lake(seed: int = 1):
    """A lake at rest, level 2 m, over a random bed of 0 to 1 m on 50 x 40 cells."""
    grid = CartesianGrid([[0, 100], [0, 80]], [50, 40])
    corners = np.random.default_rng(seed).uniform(0.0, 1.0, (51, 41))
    return grid, corners, 2.0 - cell_beds(grid, corners)


def test_a_lake_at_rest_on_a_rough_bed_stays_at_rest():
    """Well balanced: on a random bed the method-of-lines rate of a lake at rest is
    round-off (< 1e-12), and fv-split keeps it to < 1e-12 for 100 s (friction of 1e-6
    deg: the model has no frictionless setting; the rate above is the check that holds
    without it)."""
    grid, corners, h = rough_lake()
    pde = pdeflow.SingleLayerGranular(phi_b_deg=1e-6, bc=WALLS, bed=corners)
    state = at_rest(pde, grid, h)
    rate = pde.make_evolution_rate(state, "numba")(state.data, 0.0)
    assert np.abs(rate).max() < 1e-12
    end = pde.solve(state, 100.0, solver="fv-split", tracker=None, stop_at_rest=False)
    assert np.abs(end.data - state.data).max() < 1e-12


def test_a_lake_on_a_bed_without_its_level_moves():
    """Negative control: the same lake with its surface tilted by 1 cm over the domain
    is not at rest (the rate sees the tilt)."""
    grid, corners, h = rough_lake()
    x = grid.axes_coords[0][:, None]
    h = h + 0.01 * x / 100.0
    pde = pdeflow.SingleLayerGranular(phi_b_deg=1e-6, bc=WALLS, bed=corners)
    state = at_rest(pde, grid, h)
    rate = pde.make_evolution_rate(state, "numba")(state.data, 0.0)
    assert np.abs(rate[1]).max() > 1e-4


def inclined_bumpy(grid: CartesianGrid, slope_deg: float) -> np.ndarray:
    tan_t = math.tan(math.radians(slope_deg))
    return bed_corners(grid, lambda x, y: -tan_t * x
                       + 0.2 * np.sin(x / 9.0) * np.sin(y / 11.0))


def test_a_pile_below_the_friction_angle_stays_exactly_at_rest_100_s():
    """A cone (flanks 0.1) on a bumpy plane inclined at 15 deg, friction 35 deg: every
    slope of its surface is below the friction angle, so nothing moves for 100 s: the
    state is unchanged to the bit."""
    grid = CartesianGrid([[0, 200], [0, 100]], [100, 50])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    cone = np.maximum(4.0 - 0.1 * np.hypot(xx - 100, yy - 50), 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=35, bc=(("open", "open"), ("open", "open")),
                                      bed=inclined_bumpy(grid, 15.0))
    state = at_rest(pde, grid, cone)
    end = pde.solve(state, 100.0, solver="fv-split", tracker=None, stop_at_rest=False)
    np.testing.assert_array_equal(end.data, state.data)


@pytest.mark.parametrize("depth", [0.1, 1.0, 10.0])
def test_a_layer_thinner_than_the_relief_feels_the_slope(depth):
    """A uniform layer on a plane at 34 deg, 5 m cells (the bed rises 3.4 m across a
    cell, 34 times the thinnest layer): inside the layer the advective rate is g h
    tan(34 deg) whatever the depth, and after 1 s the velocity is g (tan 34 - tan 20)
    t (friction 20 deg), to 1e-12 relative. (The hydrostatic reconstruction of Audusse
    et al. gives a thin layer a fraction of this slope.)"""
    tan_t = math.tan(math.radians(34.0))
    grid = CartesianGrid([[0, 500], [0, 50]], [100, 10])
    corners = bed_corners(grid, lambda x, y: -tan_t * x + 0.0 * y)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=20, bc=(("open", "open"), ("open", "open")),
                                      bed=corners)
    h = np.full(grid.shape, depth)
    state = at_rest(pde, grid, h)
    rate = pde.make_evolution_rate(state, "numba")(state.data, 0.0)
    assert rate[1, 50, 5] / depth == pytest.approx(9.81 * tan_t, rel=1e-12)
    end = pde.solve(state, 1.0, solver="fv-split", tracker=None, stop_at_rest=False)
    u = end.data[1, 50, 5] / end.data[0, 50, 5]
    assert u == pytest.approx(9.81 * (tan_t - math.tan(math.radians(20.0))), rel=1e-12)


def test_a_release_conserves_mass_stays_positive_and_stops_for_good():
    """A 6 m column released on the bumpy plane at 30 deg, friction 32 deg (its own
    pressure spreads it), walls around: mass to 1e-12, depths >= 0, it comes to rest,
    and 50 s more change nothing (zero momentum for ever)."""
    grid = CartesianGrid([[0, 200], [0, 100]], [80, 40])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    column = np.where(np.hypot(xx - 50, yy - 50) < 15, 6.0, 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=32, bc=WALLS,
                                      bed=inclined_bumpy(grid, 30.0))
    state = at_rest(pde, grid, column)
    end = pde.solve(state, 200.0, solver="fv-split", tracker=None)
    assert end.data[0].sum() == pytest.approx(column.sum(), rel=1e-12)
    assert end.data[0].min() >= 0.0
    assert np.count_nonzero(end.data[0] > 1e-3) > np.count_nonzero(column)  # it spread
    assert np.all(end.data[1:] == 0.0)
    later = pde.solve(end, 50.0, solver="fv-split", tracker=None, stop_at_rest=False)
    np.testing.assert_array_equal(later.data, end.data)


def test_a_flat_bed_gives_the_plane_s_numbers():
    """Over a horizontal bed (any constant level) the face values are the cell averages
    up to round-off (h (hu / h)), so a dam break spreading in 2D gives the numbers of
    the run without a bed to 1e-12."""
    grid = CartesianGrid([[0, 60], [0, 40]], [30, 20])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    h = np.where(np.hypot(xx - 20, yy - 20) < 8, 3.0, 0.0)
    plain = pdeflow.SingleLayerGranular(phi_b_deg=20, bc=WALLS)
    flat = pdeflow.SingleLayerGranular(phi_b_deg=20, bc=WALLS,
                                       bed=np.full((31, 21), 123.0))
    a = plain.solve(at_rest(plain, grid, h), 3.0, solver="fv-split", tracker=None)
    b = flat.solve(at_rest(flat, grid, h), 3.0, solver="fv-split", tracker=None)
    assert np.abs(a.data).max() > 1.0  # it flowed
    np.testing.assert_allclose(b.data, a.data, rtol=0, atol=1e-12 * np.abs(a.data).max())


def test_the_energy_line_bounds_the_travel_angle_on_the_parabola():
    """AvaFrame's energy-line idea on its parabolic path (fall height 1000 m, mean slope
    34 deg; a strip of 4 cells across, walls): friction dissipates at least mu g times
    the mass centre's horizontal travel, so the mass centre's travel angle is at least
    the friction angle (25 deg). Measured in docs/terrain.md: 25.05-25.14 deg, the
    excess falling with the grid (with each cell's surface flat, 27.4-28.7 deg: the
    test below)."""
    dx = 10.0
    grid = CartesianGrid([[0, 2600], [-2 * dx, 2 * dx]], [260, 4])
    xs, ys = corner_coordinates(grid)
    corners = parabola(*np.meshgrid(xs, ys, indexing="ij"))
    x = grid.axes_coords[0][:, None] * np.ones(grid.shape)
    h = np.where((x > 100) & (x < 300), 1.0, 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=25, bed=corners,
                                      bc=(("wall", "open"), ("wall", "wall")))
    end = pde.solve(at_rest(pde, grid, h), 400.0, solver="fv-split", tracker=None)
    zc = cell_beds(grid, corners)
    h1 = end.data[0]
    assert np.all(end.data[1:] == 0.0)  # at rest
    drop = (h * zc).sum() / h.sum() - (h1 * zc).sum() / h1.sum()
    travel = (h1 * x).sum() / h1.sum() - (h * x).sum() / h.sum()
    angle = math.degrees(math.atan(drop / travel))
    assert 25.0 <= angle < 25.3


@pytest.mark.parametrize("slope_deg, dx", [(10.0, 5.0), (10.0, 20.0), (34.0, 5.0),
                                           (34.0, 20.0)])
def test_the_mass_centre_moves_with_the_momentum(slope_deg, dx):
    """d/dt sum h x = sum h u up to the release's two end cells: a release 1.2 m deep
    over 200 m moving at 10 m/s down a plane, the layer thicker than half the bed's
    rise across a cell (10 deg, 5 m) or thinner (10 deg, 20 m and 34 deg). Measured:
    1.009-1.05 times sum h u, 1 + (dx / 200 m) / 4 at 34 deg, the ends' share. With
    each cell's surface flat (no surface slope from the neighbours) it was 1.37 and 2
    times: the mass ran ahead of its momentum."""
    grid = CartesianGrid([[0, 600], [-2 * dx, 2 * dx]], [round(600 / dx), 4])
    tan_t = math.tan(math.radians(slope_deg))
    corners = bed_corners(grid, lambda x, y: -tan_t * x + 0.0 * y)
    x = grid.axes_coords[0][:, None] * np.ones(grid.shape)
    h = np.where((x > 100) & (x < 300), 1.2, 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=5, bed=corners,
                                      bc=(("wall", "open"), ("wall", "wall")))
    state = pde.make_state(grid, h=h, u=10.0 + 0 * h, v=0 * h)
    rate = pde.make_evolution_rate(state, "numba")(state.data, 0.0)
    ratio = (rate[0] * x).sum() / state.data[1].sum()
    assert 1.0 - 1e-12 <= ratio <= 1.0 + 0.3 * dx / 100.0


def test_a_bed_is_refused_with_one_line_where_it_cannot_run():
    """Before any work: a bed on a 1D grid, with a slope angle or azimuth, with MUSCL,
    under the two-layer model, of the wrong shape, not finite, or with cfl > 0.5."""
    grid = CartesianGrid([[0, 10], [0, 10]], [5, 5])
    bed = np.zeros((6, 6))
    h = np.ones((5, 5))
    with pytest.raises(ValueError, match=r"^bed needs a 2D CartesianGrid, got a planar"):
        pdeflow.SingleLayerGranular(bed=bed).make_state(CartesianGrid([[0, 1]], 4),
                                                        h=np.ones(4))
    with pytest.raises(ValueError, match=r"^theta_deg must be 0 over a bed .* got 20$"):
        pdeflow.SingleLayerGranular(theta_deg=20, bed=bed)
    with pytest.raises(ValueError, match=r"^slope_azimuth_deg must be 0 over a bed"):
        pdeflow.SingleLayerGranular(slope_azimuth_deg=10, bed=bed)
    with pytest.raises(ValueError, match=r"^reconstruction must be 'first-order' over a"):
        pdeflow.SingleLayerGranular(scheme="hll/muscl", bed=bed)
    with pytest.raises(ValueError, match=r"^bed: the two layers? model does not flow"):
        pdeflow.TwoLayerGranular(bed=bed)
    with pytest.raises(ValueError, match=r"^bed must give the elevation at the grid's "
                                         r"6 x 6 cell corners, got shape \(5, 5\)$"):
        pdeflow.SingleLayerGranular(bed=np.zeros((5, 5)), bc=WALLS).make_state(grid, h=h)
    bad = bed.copy()
    bad[2, 3] = np.nan
    with pytest.raises(ValueError, match=r"^bed must be finite at every corner, got nan "
                                         r"at x = 4 m, y = 6 m and 0 more$"):
        pdeflow.SingleLayerGranular(bed=bad, bc=WALLS).make_state(grid, h=h)
    pde = pdeflow.SingleLayerGranular(bed=bed, bc=WALLS)
    with pytest.raises(ValueError, match=r"^cfl \(over a bed\) must lie in \(0, 0.5\]"):
        pde.solve(at_rest(pde, grid, h), 1.0, solver="fv-split", tracker=None, cfl=0.8)


def test_the_numbers_docs_terrain_quotes_come_from_its_script():
    """docs/terrain.md's energy-line row at dx = 20 m and its fully wet lake's rate are
    what ``python benchmarks/terrain_checks.py --dx 20`` prints (to its digits)."""
    import re
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).parents[1]
    out = subprocess.run([sys.executable, str(root / "benchmarks" / "terrain_checks.py"),
                          "--dx", "20"], capture_output=True, text=True, check=True,
                         cwd=root).stdout
    doc = (root / "docs" / "terrain.md").read_text(encoding="utf-8")
    angle = re.search(r"^\s+20\s+([\d.]+)", out, re.M).group(1)
    assert f"| 20 | {angle} |" in doc
    rate = float(re.search(r"100% wet\): max \|rate\| = (\S+)", out).group(1))
    assert rate < 1e-12
    shore = re.search(r"shore .* max \|rate\| = (\S+)", out).group(1)
    assert f"is {shore} m^2/s^2" in doc


def test_peak_fields_over_a_bed_are_sampled_rasters_that_change_nothing(tmp_path):
    """A release on the bumpy plane with a PeakTracker of the peak fields: the run's
    numbers are those without it (bit for bit); the peak depth is at least the initial
    and the final depth everywhere, the peak pressure is 200 kg/m^3 times the peak
    speed squared [kPa], the flow reached beyond the release; the rasters read back give
    the fields, north up, each cell's centre at the grid's."""
    from pdeflow.metrics_2d import peak_fields
    from pdeflow.terrain import peak_rasters, read_raster
    from pdeflow.trackers.peaks import PeakTracker

    grid = CartesianGrid([[1000, 1200], [500, 600]], [40, 20])
    xx, yy = np.meshgrid(*grid.axes_coords, indexing="ij")
    column = np.where(np.hypot(xx - 1050, yy - 550) < 15, 6.0, 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=28, bc=WALLS,
                                      bed=inclined_bumpy(grid, 30.0))
    state = at_rest(pde, grid, column)
    peaks = PeakTracker(0.5, lambda data: peak_fields(data, 1e-6, 200.0))
    watched = pde.solve(state, 20.0, solver="fv-split", tracker=[peaks])
    alone = pde.solve(state, 20.0, solver="fv-split", tracker=None)
    np.testing.assert_array_equal(watched.data, alone.data)
    depth, speed, pressure = peaks.peak
    assert np.all(depth >= column) and np.all(depth >= alone.data[0])
    np.testing.assert_allclose(pressure, 200.0 * speed ** 2 / 1000.0, rtol=1e-15)
    assert np.count_nonzero(speed > 0.1) > np.count_nonzero(column)
    paths = peak_rasters(peaks.peak, 1000.0, 500.0, 5.0, tmp_path)
    assert [p.name for p in paths] == ["peak_depth.asc", "peak_speed.asc",
                                       "peak_pressure.asc"]
    back = read_raster(paths[0])
    assert (back.x_corner, back.y_corner, back.cellsize) == (1000.0, 500.0, 5.0)
    np.testing.assert_array_equal(back.values[::-1].T, depth)
