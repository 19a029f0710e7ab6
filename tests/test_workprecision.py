"""The work-precision harness (fast form: tiny grids, no mol-rk compilation)."""

import json
from pathlib import Path

import numpy as np
import pytest

from pdeflow.analysis import workprecision as wp
from pdeflow.analysis.points import case_on_grid, resolve_case
from pdeflow.analysis.timing import mol_time_step
from pdeflow.cases import load_case
from pdeflow.simulate import Run
from pdeflow.variant import Variant

CASES = Path(__file__).parents[1] / "cases"
CASE_5_1 = CASES / "paper_5_1_dam_break.toml"
# the work-precision benchmark's Ritter problem (benchmarks/run_benchmarks.py)
RITTER = load_case(CASES / "ritter_dam_break.toml",
                   ["grid.length=2.5", "numerics.cfl=0.45", "output.snapshot_times=[]"])


def test_restriction_is_exact_cell_averaging():
    fine = np.linspace(0.0, 1.0, 13)
    coarse = np.linspace(0.0, 1.0, 5)
    rng = np.random.default_rng(1)
    v = rng.random((2, 12))
    out = wp.restrict(v, fine, coarse)
    np.testing.assert_allclose(out, v.reshape(2, 4, 3).mean(axis=2))
    # non-nested grids keep the integral
    coarse = np.linspace(0.0, 1.0, 6)
    out = wp.restrict(v, fine, coarse)
    np.testing.assert_allclose((out * 0.2).sum(axis=1), (v / 12).sum(axis=1))


def test_ritter_errors_fall_and_outputs_are_written(tmp_path):
    res = wp.compare(RITTER, ["hll/first-order", "hll/muscl/minmod"], [50, 100, 200],
                     out_dir=tmp_path, repeats=1, label="ritter")
    assert len(res.rows) == 6
    for r in res.rows:
        assert r["status"] == "ok" and r["reference"] == "exact Ritter"
        assert r["wall_s"] > 0 and r["steps"] > 0 and r["cell_updates"] > 0
        assert r["t"] == 0.5
    for v in ("hll/first-order", "hll/muscl/minmod"):
        errs = [r["err_h"] for r in res.rows if r["variant"] == v]
        moms = [r["err_hu"] for r in res.rows if r["variant"] == v]
        assert errs[0] > errs[1] > errs[2] > 0, errs
        assert moms[0] > moms[-1] > 0
    muscl = [r for r in res.rows if r["variant"] == "hll/muscl/minmod"]
    assert muscl[-1]["order_h"] > 0.8
    first = [r for r in res.rows if r["variant"] == "hll/first-order"]
    assert muscl[-1]["err_h"] < first[-1]["err_h"]
    for key in ("png", "md", "json"):
        assert Path(res.files[key]).stat().st_size > 0
    data = json.loads(Path(res.files["json"]).read_text())
    assert len(data["rows"]) == 6
    assert "| single_layer | hll/muscl/minmod | 200 |" in Path(res.files["md"]).read_text()


def test_fine_reference_on_the_two_layer_case(tmp_path):
    res = wp.compare(CASE_5_1, ["hll/first-order"], [0.25, 0.125], out_dir=None,
                     t=0.2, repeats=1, models=["two_layer"], reference_dx=0.03125)
    assert [r["cells"] for r in res.rows] == [28, 56]
    assert all(r["reference"].startswith("fine hll/first-order") for r in res.rows)
    assert res.rows[1]["err_h"] < res.rows[0]["err_h"]


def test_exact_reference_is_found_for_dam_breaks_only():
    from pdeflow.analysis.exact import exact_solution_for

    assert exact_solution_for(RITTER, "single_layer").name == "ritter"
    assert exact_solution_for(RITTER, "two_layer") is None
    assert exact_solution_for(resolve_case(CASE_5_1), "single_layer") is None
    with pytest.raises(ValueError, match="no exact solution"):
        wp.compare(CASE_5_1, ["hll/first-order"], [0.5], reference="exact", out_dir=None,
                   models=["single_layer"])


def test_mol_time_step_is_cfl_bound_and_divides_t():
    case = case_on_grid(RITTER, 100, Variant.parse("mol-rk"))
    dt = mol_time_step(Run(case, "single_layer"), 0.5)
    c0 = np.sqrt(9.81 * 0.1)
    assert dt <= 0.45 * case.dx / (2 * c0) + 1e-15
    assert abs(0.5 / dt - round(0.5 / dt)) < 1e-9


def test_command_line(tmp_path, capsys):
    from pdeflow.cli import main

    ritter = str(CASES / "ritter_dam_break.toml")
    assert main(["compare", ritter, "--set", "numerics.cfl=0.45", "--variants",
                 "rusanov/first-order", "--grids", "50", "100", "--repeats", "1",
                 "--out-dir", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "rusanov/first-order" in out
    assert (tmp_path / "ritter_dam_break_workprecision.png").exists()
    assert main(["compare", ritter, "--variants", "roe/first-order", "--quiet"]) == 2
    assert "flux must be one of" in capsys.readouterr().err


def test_a_variant_runs_at_its_own_cfl_limit_below_the_cases(capsys):
    """Ritter's case runs at CFL 0.9, above MUSCL's limit 0.5: compare runs MUSCL at 0.5
    and the first-order variant at the case's 0.9 (the README's command), and says so."""
    import sys

    case = load_case(CASES / "ritter_dam_break.toml", ["output.snapshot_times=[]"])
    res = wp.compare(case, ["hll/first-order", "hll/muscl/minmod"], [50], out_dir=None,
                     repeats=1, log=sys.stderr)
    steps = {r["variant"]: r["steps"] for r in res.rows}
    assert "hll/muscl/minmod at CFL 0.5" in capsys.readouterr().err
    # about 0.9/0.5 as many steps at the larger Courant number (dt ~ cfl dx / smax)
    assert 1.4 < steps["hll/muscl/minmod"] / steps["hll/first-order"] < 2.2
