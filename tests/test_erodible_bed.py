"""Erodible beds: the shape ``column_on_bed`` lays a layer at rest in the model's
erodible layer (two layers: the lower one), and a bed at rest stays exactly at rest."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.cases import load_case
from pdeflow.simulate import run_model

ROOT = Path(__file__).parents[1]
CASE = ROOT / "cases" / "erodible_bed.toml"


@pytest.mark.parametrize("closure", ["paper", "relaxed"])
@pytest.mark.parametrize("theta", [0.0, 20.0, 38.0])
def test_uniform_bed_below_its_friction_angle_stays_at_rest_for_100_s(theta, closure):
    """A uniform lower layer at rest on a slope below its basal friction angle (41 deg),
    no upper layer: an exact steady state, kept to the last bit over 100 s (the solver
    is not allowed to stop early at rest)."""
    grid = CartesianGrid([[0, 4]], 400)
    eq = pdeflow.TwoLayerGranular({"theta_deg": theta, "exchange_closure": closure},
                                  bc=("wall", "open"))
    state = eq.make_state(grid, h1=np.zeros(400), h2=np.full(400, 0.02))
    out = eq.solve(state, t_range=100, solver="fv-split", cfl=0.3, stop_at_rest=False,
                   tracker=None)
    assert np.max(np.abs(out.data - state.data)) == 0.0


def test_bed_under_a_depositing_film_does_not_move_and_only_gains():
    """A thin upper film sliding onto the bed is deposited into it; the bed never moves
    and no cell of it loses material."""
    grid = CartesianGrid([[0, 4]], 400)
    x = grid.axes_coords[0]
    eq = pdeflow.TwoLayerGranular({"theta_deg": 20.0}, bc=("wall", "open"))
    film = np.where(x < 1, 1e-3, 0.0)
    state = eq.make_state(grid, h1=film, u1=np.where(x < 1, 0.05, 0.0),
                          h2=np.full(400, 0.02))
    out = eq.solve(state, t_range=100, solver="fv-split", cfl=0.3, stop_at_rest=False,
                   tracker=None)
    assert np.all(out.data[3] == 0.0)  # the bed's momentum
    assert np.all(out.data[2] >= state.data[2])
    assert out.data[0].max() == 0.0  # the film is deposited
    r = eq.parameters.density_ratio
    np.testing.assert_allclose(np.sum(out.data[2] - state.data[2]), r * film.sum(),
                               rtol=1e-12)


def test_column_on_bed_lays_the_bed_in_the_lower_layer_and_not_under_the_column():
    case = load_case(CASE, ["initial.bed_thickness=0.004", "initial.bed_length=0.5"])
    x = case.make_grid().axes_coords[0]
    two = case.initial_profiles("two_layer")
    plain = load_case(CASE, ["initial.shape='column'"]).initial_profiles("two_layer")
    bed = np.where((x >= 0.2) & (x < 0.7), 0.004, 0.0)
    np.testing.assert_array_equal(two["h2"], plain["h2"] + bed)
    np.testing.assert_array_equal(two["h1"], plain["h1"])
    single = case.initial_profiles("single_layer")  # the rigid bed: the column only
    np.testing.assert_array_equal(single["h"], np.where(x < 0.2, 0.14, 0.0))
    assert case.bed_kind("two_layer") == "erodible"
    assert case.bed_kind("single_layer") == "rigid"
    assert load_case(CASE, ["initial.shape='column'"]).bed_kind("two_layer") is None


def test_front_is_that_of_the_material_on_the_bed():
    """The bed reaches the open end of the domain from the start: neither the front nor
    the domain-end check count it as material that got there."""
    case = load_case(CASE, ["output.snapshot_times=[]"])
    s = run_model(case, "two_layer").summary
    assert s["bed"] == "erodible"
    assert s["front_position"] < case.length - 0.5
    assert not s["runout_lower_bound"] and not s["warnings"]
    assert run_model(case, "single_layer").summary["bed"] == "rigid"


@pytest.mark.parametrize("override, message", [
    ("initial.bed_thickness=-0.01", "initial.bed_thickness"),
    ("initial.bed_length=0", "initial.bed_length"),
])
def test_bad_bed_keys_are_one_line_errors(override, message):
    with pytest.raises(ValueError, match=message) as err:
        load_case(CASE, [override])
    assert "\n" not in str(err.value)


def test_radial_bed_beyond_the_deposit_is_left_exactly_as_laid():
    """On py-pde's polar grid the bed is a ring of radius > L0; past the deposit's front
    it has not moved by a bit."""
    case = load_case(CASE, ["grid.geometry='axisymmetric'", "output.snapshot_times=[]",
                            "two_layer.theta_deg=0",  # radial flow: no slope
                            "case.models=['two_layer']"])
    eq, state = case.make_state("two_layer")
    res = run_model(case, "two_layer")
    assert res.summary["at_rest"] and res.summary["geometry"] == "axisymmetric"
    beyond = res.x > res.summary["front_position"] + 0.05
    assert beyond.sum() > 100
    np.testing.assert_array_equal(res.state.data[:, beyond], state.data[:, beyond])
    assert np.all(state.data[2, beyond] == 0.005)
