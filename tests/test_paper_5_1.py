"""The paper's test 5.1: qualitative results with the documented default parameters."""

from pathlib import Path

import pytest

from pdeflow.cases import load_case
from pdeflow.simulate import run_model

CASE = Path(__file__).parents[1] / "cases" / "paper_5_1_dam_break.toml"


@pytest.fixture(scope="module")
def runs():
    case = load_case(CASE, ["case.t_end=4.0"])
    return {m: run_model(case, m) for m in case.models}


def test_both_layers_come_to_rest_upper_after_lower(runs):
    s = runs["two_layer"].summary
    assert s["at_rest"]
    assert s["lower_stop_time"] is not None and s["upper_stop_time"] is not None
    # paper: lower layer at rest at about 0.7 s, upper layer just before 1.5 s
    assert 0.6 < s["lower_stop_time"] < 0.9
    assert 1.2 < s["upper_stop_time"] < 1.5
    # the practical definition (|u| < 1 cm/s where h > 1 mm) agrees within 0.1 s here
    assert abs(s["upper_slow_time"] - s["upper_stop_time"]) < 0.1


def test_two_layer_runout_clearly_shorter(runs):
    r2 = runs["two_layer"].summary["runout"]
    r1 = runs["single_layer"].summary["runout"]
    assert r2 < 0.9 * r1


def test_fextra_bounded_and_near_lower_front(runs):
    s = runs["two_layer"].summary
    assert 0 < s["max_fextra_over_rho1"] < 2.0
    # the toe of the initial wedge is at x = L0 = 1 m
    assert abs(s["max_fextra_x"] - 1.0) < 0.3


def test_mass_passes_from_upper_to_lower(runs):
    s = runs["two_layer"].summary
    assert s["deposited_volume"] > 10 * s["eroded_volume"]
    snaps = runs["two_layer"].snapshots
    v1 = [snaps[t][0][0].sum() for t in sorted(snaps)]
    assert all(a > b for a, b in zip(v1, v1[1:], strict=False))


def test_mass_conserved(runs):
    for res in runs.values():
        assert res.summary["mass_relative_error"] < 1e-12
