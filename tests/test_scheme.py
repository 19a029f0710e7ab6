"""One scheme object: the PDE assembles a model and a Scheme, fv-split reads it there,
a Variant is built around it, and the geometry comes from the grid."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

import pdeflow
from pdeflow.cases import load_case
from pdeflow.numerics import layout as L
from pdeflow.numerics.scheme import MAX_CFL, Scheme, SchemeError
from pdeflow.numerics.splitting import scheme_stepper
from pdeflow.simulate import Run, case_steppers
from pdeflow.solvers import FVSplitSolver
from pdeflow.variant import Variant, VariantError, variant_of

CASES = Path(__file__).parents[1] / "cases"


def test_scheme_names_codes_and_errors():
    s = Scheme.parse("ifcp/muscl/mc+strang")
    assert s == Scheme("ifcp", "muscl", "mc", "strang")
    assert s.name == "ifcp/muscl/mc+strang" and s.spatial == "ifcp/muscl/mc"
    assert s.codes == (L.FLUX_IFCP, 2, L.LIMITER_MC) and s.strang
    assert s.max_cfl == MAX_CFL["muscl"] == 0.5
    assert Scheme.parse(Scheme().name) == Scheme()
    assert Scheme().name == "hll/first-order" and not Scheme().strang
    with pytest.raises(SchemeError, match=r"^flux must be one of \['hll', 'rusanov', "
                                          r"'ifcp'\], got 'roe'$"):
        Scheme(flux="roe")
    with pytest.raises(SchemeError, match="^splitting must be one of"):
        Scheme(splitting="marchuk")
    with pytest.raises(SchemeError, match="a limiter with muscl only"):
        Scheme.parse("hll/first-order/mc")


def test_the_pde_assembles_a_model_and_a_scheme():
    by_name = pdeflow.TwoLayerGranular(scheme="rusanov/muscl/mc+strang")
    by_fields = pdeflow.TwoLayerGranular(flux="rusanov", reconstruction="muscl",
                                         limiter="mc", splitting="strang")
    assert by_name.scheme == by_fields.scheme == Scheme("rusanov", "muscl", "mc",
                                                        "strang")
    assert pdeflow.SingleLayerGranular().scheme == Scheme()
    given = pdeflow.Scheme(flux="ifcp")  # the package's name for it
    assert pdeflow.SingleLayerGranular(scheme=given).scheme is given
    assert not hasattr(by_name, "scheme_codes") and not hasattr(by_name, "variant")
    with pytest.raises(ValueError, match="the scheme or its fields, not both"):
        pdeflow.SingleLayerGranular(scheme=Scheme(), flux="hll")


def test_fv_split_reads_the_pdes_scheme():
    eq = pdeflow.SingleLayerGranular(scheme="hll/muscl/mc+strang")
    assert FVSplitSolver(eq, cfl=0.4).scheme is eq.scheme
    lie = FVSplitSolver(eq, cfl=0.4, splitting="lie").scheme
    assert lie == dataclasses.replace(eq.scheme, splitting="lie")
    assert eq.scheme.splitting == "strang"  # the PDE's scheme is not changed
    with pytest.raises(ValueError, match=r"cfl \(with reconstruction='muscl'\) must lie "
                                         r"in \(0, 0.5\]"):
        FVSplitSolver(eq, cfl=0.6)


def test_a_variant_is_a_scheme_with_a_hyperbolicity_treatment_and_an_integrator():
    v = Variant.parse("ifcp/muscl/mc+strang@bound")
    assert v.scheme == Scheme("ifcp", "muscl", "mc", "strang")
    assert (v.flux, v.reconstruction, v.limiter, v.splitting) == ("ifcp", "muscl", "mc",
                                                                  "strang")
    assert Variant(scheme=v.scheme, hyperbolicity="bound") == v
    with pytest.raises(VariantError, match=r"^variant 'roe/first-order': flux must be"):
        Variant.parse("roe/first-order")
    with pytest.raises(VariantError, match=r"^numerics.flux must be one of"):
        variant_of({"flux": "roe"})


def test_a_case_builds_its_pde_with_its_variants_scheme():
    case = load_case(CASES / "ritter_dam_break.toml",
                     ["numerics.reconstruction='muscl'", "numerics.splitting='strang'",
                      "numerics.cfl=0.4"])
    run = Run(case, "single_layer")
    assert run.pde.scheme == run.variant.scheme == Scheme("hll", "muscl", "minmod",
                                                          "strang")
    assert "splitting" not in run.solver_arguments()  # the solver reads the PDE's
    assert run.make_solver().scheme is run.pde.scheme


def test_the_geometry_of_the_steppers_comes_from_the_grid():
    """``case_steppers`` builds each stepper for the grid the case makes (a
    PolarSymGrid: the axisymmetric metric), as the run's solver will."""
    case = load_case(CASES / "paper_5_1_dam_break.toml",
                     ["grid.geometry='axisymmetric'", "grid.x_start=0.0"])
    for model, stepper in zip(case.models, case_steppers(case), strict=True):
        eq = case.make_pde(model)
        assert stepper is scheme_stepper(eq.kernels, *eq.scheme.codes, False,
                                         L.GEOMETRY_AXISYMMETRIC)
        assert Run(case, model).metric.geometry == "axisymmetric"


def test_a_run_derives_its_grids_metric_once(monkeypatch):
    """The run, its solver and its summary share one metric of the grid."""
    from pdeflow.models import base

    calls = []
    real = base.metric_of
    monkeypatch.setattr(base, "metric_of",
                        lambda grid, bed=None: calls.append(grid) or real(grid, bed))
    case = load_case(CASES / "ritter_dam_break.toml", ["grid.cells=20",
                                                      "case.t_end=0.05"])
    run = Run(case, "single_layer")
    result = run.execute()
    assert len(calls) == 1 and result.metric is run.metric
    assert run.pde.metric(case.make_grid()) is not run.metric  # another grid: its own
