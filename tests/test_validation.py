"""Fast forms of the verification/validation report, the 5.2 sweep and grid studies."""

from pathlib import Path

import numpy as np
import pytest

from pdeflow.analysis import stoker
from pdeflow.analysis.convergence import converge, richardson
from pdeflow.analysis.sweep import fit_power_law, run_sweep
from pdeflow.analysis.validation import exact_study, smooth_study, two_layer_checks
from pdeflow.cases import load_case

ROOT = Path(__file__).parents[1]


def test_stoker_solution_is_consistent():
    h, u = stoker(np.array([-2.0, 0.0, 2.0]), 1e-9, 1.0, 0.1)
    assert h[0] == 1.0 and h[-1] == 0.1
    # mass conservation of the exact solution on a closed window
    x = np.linspace(-3, 3, 60001)
    h, _ = stoker(x, 0.5, 1.0, 0.1)
    assert np.trapezoid(h, x) == pytest.approx(3 * 1.0 + 3 * 0.1, rel=1e-4)


def _exact_case(name: str, *sets: str):
    return load_case(ROOT / "cases" / name, ["numerics.cfl=0.45", *sets])


def test_orders_on_exact_solutions_fast_form():
    rows = {r["variant"]: r for r in exact_study(_exact_case("ritter_dam_break.toml"),
                                                 [100, 200, 400])}
    assert min(rows["hll/first-order"]["order_L1_h"]) > 0.55
    assert min(rows["hll/muscl/minmod"]["order_L1_h"]) > 0.9
    assert min(rows["hll/muscl/minmod"]["order_L1_h_away"]) > 0.95
    rows = {r["variant"]: r for r in exact_study(_exact_case("stoker_dam_break.toml"),
                                                 [100, 200, 400])}
    assert rows["hll/muscl/minmod"]["L1_h"][-1] < 0.5 * rows["hll/first-order"]["L1_h"][-1]


def test_exact_solutions_come_from_the_case_files():
    from pdeflow.analysis.exact import exact_solution_for

    kinds = {name: exact_solution_for(_exact_case(f"{name}.toml")).name
             for name in ("ritter_dam_break", "mangeney_dam_break_slope",
                          "stoker_dam_break")}
    assert kinds == {"ritter_dam_break": "ritter", "mangeney_dam_break_slope": "mangeney",
                     "stoker_dam_break": "stoker"}
    assert exact_solution_for(load_case(ROOT / "cases" / "paper_5_1_dam_break.toml")) is None
    with pytest.raises(Exception, match="no exact solution"):
        exact_study(load_case(ROOT / "cases" / "paper_5_1_dam_break.toml"), [10])


def test_second_order_on_smooth_problem_fast_form():
    rows = {r["variant"]: r for r in smooth_study([50, 100, 200])}
    assert rows["hll/muscl/minmod"]["order_L1_h"][-1] > 1.7
    assert 0.8 < rows["hll/first-order"]["order_L1_h"][-1] < 1.2


def test_two_layer_steady_state_and_single_layer_limit():
    t = two_layer_checks()
    assert t["rest_none_max_change"] == 0.0
    assert t["rest_paper_final_h1"] == 0.0 and t["rest_paper_mass_error"] < 1e-14
    # the difference to the single-layer solution scales with 1 - r
    assert t["two_vs_one_L1_r0.99"] == pytest.approx(0.1 * t["two_vs_one_L1_r0.9"],
                                                     rel=0.1)
    assert t["two_vs_one_L1_r0.999"] < 1e-5


def test_power_law_fit_recovers_exact_law():
    a = np.array([2, 4, 8, 16.0])
    p, e = fit_power_law(a, 1.7 * a**0.9)
    assert p == pytest.approx(1.7) and e == pytest.approx(0.9)


def test_sweep_coarse_subset_single_layer_law():
    """Coarse form of test 5.2: the single-layer run-out follows the paper's law."""
    case = load_case(ROOT / "cases" / "collapse_sweep.toml",
                     ["grid.dx=0.02", "sweep.aspect_ratios=[2, 6, 18]",
                      "case.models=['single_layer']"])
    res = run_sweep(case)["models"]["single_layer"]
    assert res["all_at_rest"]
    assert abs(res["exponent"] - 1.06) < 0.05
    assert abs(res["prefactor"] / 2.25 - 1) < 0.15


def test_relaxed_closure_upper_volume_converges_paper_closure_does_not():
    """Fast form of the grid study: V1(0.1 s) under dx halving (5.1 geometry)."""
    out = {}
    for closure in ("paper", "relaxed"):
        case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml",
                         ["case.models=['two_layer']", "case.t_end=0.1",
                          f"two_layer.exchange_closure='{closure}'", "grid.dx=0.1",
                          "output.snapshot_times=[]"])
        res = converge(case, 3, volume_times=(0.1,))
        out[closure] = [row["V1(0.1)"] for row in res["levels"]]
    paper, relaxed = out["paper"], out["relaxed"]
    assert paper[-1] < 0.6 * paper[0]  # halves with each halving of dx
    assert abs(relaxed[-1] - relaxed[-2]) < 0.02 * relaxed[-1]


RELAXED_MUSCL = ["two_layer.exchange_closure='relaxed'", "numerics.reconstruction='muscl'",
                 "numerics.limiter='mc'"]


def test_relaxed_closure_with_muscl_meets_the_5_1_grid_targets():
    """The issue's targets on the two finest grids of docs/convergence.md (dx = 0.00625
    and 0.003125 m): run-out and stop times change by less than 2 %. The lower layer's
    exact stop time is left out: it does not settle (docs/convergence.md)."""
    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml",
                     ["case.models=['two_layer']", "output.snapshot_times=[]",
                      "grid.dx=0.0125", *RELAXED_MUSCL])
    res = converge(case, 3, volume_times=())
    fine, finest = res["levels"][-2], res["levels"][-1]
    assert finest["dx"] == pytest.approx(0.003125)
    for key in ("runout", "stop_time", "upper_stop_time", "upper_slow_time",
                "lower_slow_time"):
        assert abs(finest[key] - fine[key]) < 0.02 * finest[key], key


@pytest.mark.slow
def test_relaxed_closure_with_muscl_meets_the_5_2_exponent_target():
    """The 5.2 exponent changes by less than 0.01 between dx = 0.0025 and 0.00125 m."""
    from pdeflow.analysis.convergence import converge_sweep

    case = load_case(ROOT / "cases" / "collapse_sweep.toml",
                     ["grid.dx=0.0025", "case.models=['two_layer']", *RELAXED_MUSCL])
    levels = converge_sweep(case, 2)["levels"]
    assert levels[-1]["dx"] == pytest.approx(0.00125)
    assert abs(levels[-1]["exponent"] - levels[-2]["exponent"]) < 0.01


def test_richardson_on_a_first_order_sequence():
    vals = [1.0 + 0.5 * h for h in (0.4, 0.2, 0.1)]
    r = richardson(vals)
    assert r["order"] == pytest.approx(1.0)
    assert r["extrapolated"] == pytest.approx(1.0)
