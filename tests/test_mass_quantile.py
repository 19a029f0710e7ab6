"""The mass-quantile run-out (pdeflow.metrics.mass_quantile_position) on profiles whose
answer is computed by hand, its parameter's range check, and the summaries that carry it.

Tolerances: where the answer falls on a cell face or the profile is constant within the
crossing cell, the quantile is exact up to round-off of a cumulative sum of a few hundred
terms of order 1, so 1e-12 (relative) is far above the round-off (~1e-14) and far below
any error of the formula (a cell, 1e-2 here). Elsewhere the bound is stated at the test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pde import CartesianGrid, PolarSymGrid

from pdeflow.cases import CaseError, load_case
from pdeflow.metrics import RUNOUT_MASS_FRACTION, mass_quantile_position, weighted_depth
from pdeflow.numerics.geometry import metric_of

EXACT = 1e-12


def planar(length: float, n: int, x0: float = 0.0):
    return metric_of(CartesianGrid([[x0, x0 + length]], n))


def radial(length: float, n: int):
    return metric_of(PolarSymGrid(length, n))


def centres(metric) -> np.ndarray:
    return 0.5 * (metric.faces[1:] + metric.faces[:-1])


def test_uniform_layer_holds_the_fraction_at_that_fraction_of_its_length():
    # h = 1 on [0, 0.6] of a [0, 1] grid of 50 cells (0.6 is a face): the mass up to s is
    # s, the total 0.6, so 99 % lies within s = 0.99 * 0.6 = 0.594 (inside a cell, where
    # the depth is constant: exact)
    m = planar(1.0, 50)
    h = np.where(centres(m) < 0.6, 1.0, 0.0)
    s = mass_quantile_position(m.faces, m.volumes, h, 0.99)
    assert s == pytest.approx(0.594, rel=EXACT)
    # from the domain's start: the same layer on a grid starting at x = 2 m
    m2 = planar(1.0, 50, x0=2.0)
    assert mass_quantile_position(m2.faces, m2.volumes, h, 0.99) == pytest.approx(
        2.594, rel=EXACT)


def test_linear_wedge_on_a_face():
    # h = 1 - x on [0, 1]: mass up to s is s - s^2/2, total 1/2; the fraction q lies
    # within s = 1 - sqrt(1 - q): 0.9 for q = 0.99, 0.5 for q = 0.75 (faces of a grid of
    # 20 cells). Cell averages of a linear profile integrate it exactly over each cell,
    # so the cumulative mass at the faces is exact and so is s on a face.
    m = planar(1.0, 20)
    h = 1.0 - centres(m)
    assert mass_quantile_position(m.faces, m.volumes, h, 0.99) == pytest.approx(
        0.9, rel=EXACT)
    assert mass_quantile_position(m.faces, m.volumes, h, 0.75) == pytest.approx(
        0.5, rel=EXACT)


def test_a_thin_tail_moves_the_threshold_front_not_the_quantile():
    # a block h = 1 on [0, 1] and a tail of 1e-3 m from 1 to 1.005 (5e-6 of the mass):
    # the 99 % position stays at 0.99 exactly (the tail's mass lies beyond it), while a
    # threshold front below 1e-3 m would jump to the tail's end
    m = planar(2.0, 400)
    x = centres(m)
    h = np.where(x < 1.0, 1.0, np.where(x < 1.005, 1e-3, 0.0))
    total = float(np.sum(h * m.volumes))
    s = mass_quantile_position(m.faces, m.volumes, h, 0.99)
    assert s == pytest.approx(0.99 * total, rel=EXACT)
    assert abs(s - 0.99) < 1e-4  # the tail's mass shifts the target by 0.99 * 5e-6 m


def test_uniform_disc_holds_the_fraction_within_sqrt_fraction_of_its_radius():
    # h = 1 for r < R = 0.8 on a radial grid of 40 cells on [0, 1] (R is a face): mass up
    # to s is pi s^2, so the fraction q lies within R sqrt(q) (inside a cell of constant
    # depth, where the mass grows with r^2: exact)
    m = radial(1.0, 40)
    h = np.where(centres(m) < 0.8, 1.0, 0.0)
    for q in (0.99, 0.5):
        assert mass_quantile_position(m.faces, m.volumes, h, q, radial=True) == \
            pytest.approx(0.8 * math.sqrt(q), rel=EXACT)


def test_cone_on_a_radial_grid():
    # h = 1 - r on [0, 1]: mass up to s is 2 pi (s^2/2 - s^3/3), total pi/3; the 99 % radius
    # solves 3 s^2 - 2 s^3 = 0.99. Cell averages over annuli integrate the cone exactly, so
    # the cumulative mass at faces is exact; within the crossing cell the mass is taken as
    # growing with r^2 at the cell's average depth, an error of at most the cell's width
    # times the relative change of the depth across it: dr = 1e-3 and the depth falls
    # from 0.0594 to 0.0584 over that cell, so s is within 1e-3 * 0.001/0.058 < 2e-5 m
    # (measured: 7.5e-7 m).
    n = 1000
    m = radial(1.0, n)
    f = m.faces
    # the exact annulus averages: integral of (1 - r) 2 pi r dr over the annulus / volume
    h = 2 * math.pi * ((f[1:] ** 2 - f[:-1] ** 2) / 2 - (f[1:] ** 3 - f[:-1] ** 3) / 3) \
        / m.volumes
    s = mass_quantile_position(f, m.volumes, h, 0.99, radial=True)
    lo, hi = 0.5, 1.0  # bisection of 3 s^2 - 2 s^3 = 0.99 on [0.5, 1] (increasing there)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 3 * mid**2 - 2 * mid**3 < 0.99 else (lo, mid)
    assert abs(s - lo) < 2e-5
    # the root by hand: 3 (0.9411)^2 - 2 (0.9411)^3 = 2.65706 - 1.66702 = 0.99004
    assert abs(lo - 0.9411) < 1e-4


def test_densities_weight_the_layers():
    # two layers: upper (relative density 0.5) h1 = 1 on [0, 0.5), lower h2 = 1 on
    # [0.5, 1): mass 0.25 + 0.5 = 0.75, the fraction 1/3 (0.25) ends at the upper
    # layer's end, 0.5 exactly
    m = planar(1.0, 10)
    x = centres(m)
    data = np.array([np.where(x < 0.5, 1.0, 0.0), np.zeros(10),
                     np.where(x >= 0.5, 1.0, 0.0), np.zeros(10)])
    depth = weighted_depth(data, [0.5, 1.0])
    assert mass_quantile_position(m.faces, m.volumes, depth, 1 / 3) == pytest.approx(
        0.5, rel=EXACT)


def test_no_mass_and_negative_round_off():
    m = planar(1.0, 10)
    assert mass_quantile_position(m.faces, m.volumes, np.zeros(10), 0.99) is None
    h = np.full(10, -1e-18)  # round-off below zero is no material
    h[:5] = 1.0
    assert mass_quantile_position(m.faces, m.volumes, h, 0.99) == pytest.approx(
        0.495, rel=EXACT)


@pytest.mark.parametrize("bad", [0, 1, 1.5, -0.1, float("nan")])
def test_the_fraction_is_checked(bad):
    m = planar(1.0, 10)
    with pytest.raises(ValueError, match=r"fraction must lie in \(0, 1\)"):
        mass_quantile_position(m.faces, m.volumes, np.ones(10), bad)


@pytest.mark.parametrize("bad", ["0", "1", "1.2", "-0.5", "nan"])
def test_the_case_parameter_is_checked_before_any_work(bad):
    with pytest.raises(CaseError, match=r"output\.runout_mass_fraction must (lie in "
                                        r"\(0, 1\)|be a finite number)"):
        load_case("cases/paper_5_1_dam_break.toml",
                  [f"output.runout_mass_fraction={bad}"])


def test_default_fraction():
    case = load_case("cases/paper_5_1_dam_break.toml")
    assert case.runout_mass_fraction == RUNOUT_MASS_FRACTION == 0.99


def test_summaries_and_the_table_carry_it(tmp_path):
    # a coarse 5.1 (both models) and its axisymmetric collapse: the quantile front lies
    # behind the threshold front (the tail past it holds material but < 1 % of the mass),
    # within the material, and the run-out is the front minus L0 (same arithmetic: 1e-12)
    import io

    from pdeflow.simulate import run_model
    from pdeflow.summary_table import print_summary

    sets = ["grid.dx=0.1", "output.snapshot_times=[]"]
    for geometry in ("planar", "axisymmetric"):
        case = load_case("cases/paper_5_1_dam_break.toml",
                         sets + [f"grid.geometry='{geometry}'"])
        summaries = {}
        for model in case.models:
            s = run_model(case, model).summary
            summaries[model] = s
            assert case.L0 < s["front_mass_quantile"] < s["front_position"]
            assert s["runout_mass_quantile"] == pytest.approx(
                s["front_mass_quantile"] - case.L0, rel=EXACT)
            assert s["runout_mass_fraction"] == 0.99
        out = io.StringIO()
        print_summary({"case": case.name, "models": summaries}, out)
        label = "front 99% mass" if geometry == "planar" else "radius 99% mass"
        assert [line.split()[:3] for line in out.getvalue().splitlines()
                if line.startswith(label)] == [label.split()]
        assert any(line.startswith("run-out 99% mass") for line in out.getvalue().splitlines())


def test_a_smaller_fraction_gives_a_shorter_front():
    from pdeflow.simulate import run_model

    sets = ["grid.dx=0.1", "output.snapshot_times=[]", "case.models=['single_layer']"]
    fronts = [run_model(load_case("cases/paper_5_1_dam_break.toml",
                                  sets + [f"output.runout_mass_fraction={q}"]),
                        "single_layer").summary["front_mass_quantile"]
              for q in (0.5, 0.9, 0.99)]
    assert fronts[0] < fronts[1] < fronts[2]


def test_the_quantile_changes_less_with_the_grid_than_the_threshold_front():
    """The single layer of 5.1 on dx = 0.05, 0.025, 0.0125 m: between the finest two the
    run-out holding 99 % of the mass moves less than the threshold run-out (measured
    3.6 % against 5.6 %; asserted only as an ordering, which is the claim the docs make)."""
    from pdeflow.analysis.convergence import converge

    case = load_case("cases/paper_5_1_dam_break.toml", ["case.models=['single_layer']"])
    rows = converge(case, 3, "single_layer")["levels"]

    def change(key: str) -> float:
        return abs(rows[-1][key] - rows[-2][key]) / abs(rows[-1][key])

    assert change("runout_mass_quantile") < change("runout")
