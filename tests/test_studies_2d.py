"""Sweeps, grid convergence and studies over 2D case files (issue 36): ``pdeflow sweep``
runs each aspect ratio as a 2D run and keeps the 2D summary's numbers, ``pdeflow
converge`` halves dx and dy together and reports observed orders of the 2D metrics, a
study reads the 2D summary's keys. Tiny grids (8-32 cells a side) and t_end = 0.3 s:
the point is the plumbing, not the physics."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from pdeflow.analysis.points import refined
from pdeflow.analysis.sweep_2d import release_length
from pdeflow.cases import Case, load_case
from pdeflow.cli import main
from pdeflow.simulate import run_model, summary_keys

ROOT = Path(__file__).resolve().parents[1]
CYLINDER = ROOT / "cases" / "cylinder_2d.toml"
TINY = ["--set", "grid.dx=0.25", "--set", "case.t_end=0.3"]  # 16 x 16 cells
"""a 16 x 16 version of cases/cylinder_2d.toml (R0 = 0.5 m), still moving at its end"""
METRICS = ("front_position", "runout", "lateral_spread", "deposit_area", "mass_radius",
           "max_depth", "max_speed", "stop_time", "mass_relative_error")


def test_a_2d_sweep_gives_the_numbers_of_separate_runs(tmp_path, capsys):
    """Each aspect ratio of a 2D sweep is the run `pdeflow run --set initial.H0=a R0`
    gives: the same code on the same state, so the same numbers (compared to 1e-12
    relative, round-off: nothing but the summary's arithmetic could differ)."""
    out = tmp_path / "sweep.json"
    assert main(["sweep", str(CYLINDER), *TINY, "--set", "sweep.aspect_ratios=[0.5, 1]",
                 "--summary", str(out)]) == 0
    printed = capsys.readouterr().out
    sweep = json.loads(out.read_text())
    L0 = release_length(load_case(CYLINDER))
    assert L0 == 0.5 and sweep["L0"] == L0 and sweep["dy"] == 0.25
    for a in (0.5, 1.0):
        run = tmp_path / f"run_{a}.json"
        assert main(["run", str(CYLINDER), *TINY, "--set", f"initial.H0={a * L0!r}",
                     "--summary", str(run), "-q"]) == 0
        runs = json.loads(run.read_text())["models"]
        for model, summary in runs.items():
            row = next(r for r in sweep["models"][model]["runs"] if r["a"] == a)
            assert row["steps"] == summary["steps"]
            for key in METRICS:
                if summary[key] is None:
                    assert row[key] is None, key
                else:
                    assert row[key] == pytest.approx(summary[key], rel=1e-12,
                                                     abs=1e-300), key
            assert row["r"] == pytest.approx(summary["runout"] / L0, rel=1e-12)
            assert row["r_mass"] == pytest.approx((summary["mass_radius"] - L0) / L0,
                                                  rel=1e-12)
    # the printed table: a header with units and one row per aspect ratio and model
    assert printed.count("| a | r | r_mass | front_position [m]") == 2
    assert "deposit_area [m^2]" in printed and "(paper" not in printed


def test_converge_halves_dx_and_dy_and_reports_orders_of_the_2d_metrics(tmp_path, capsys):
    out = tmp_path / "conv.json"
    assert main(["converge", str(CYLINDER), "--set", "grid.dx=0.5", "--set",
                 "case.t_end=0.3", "--levels", "3", "--model", "single_layer",
                 "--summary", str(out)]) == 0
    printed = capsys.readouterr().out
    res = json.loads(out.read_text())
    levels = res["levels"]
    assert [(r["dx"], r["cells"], r["cells_y"]) for r in levels] == [
        (0.5, 8, 8), (0.25, 16, 16), (0.125, 32, 32)]
    for key in ("mass_radius", "deposit_area", "max_depth", "runout", "lateral_spread"):
        assert all(r[key] is not None for r in levels), key
        assert math.isfinite(res["analysis"][key]["order"]), key
    # level 0 is the plain run of the case on that grid
    plain = run_model(load_case(CYLINDER, ["grid.dx=0.5", "case.t_end=0.3"]),
                      "single_layer").summary
    assert levels[0]["mass_radius"] == pytest.approx(plain["mass_radius"], rel=1e-12)
    lines = printed.splitlines()
    assert lines[0].startswith("| dx [m] | cells | cells_y |") and "mass_radius [m]" in lines[0]
    assert sum(line.startswith("| 0.") for line in lines) == 3  # one row per grid
    assert any(line.startswith("| observed order |") for line in lines)
    assert "V1(" not in printed


@pytest.mark.parametrize("grid, key, expected", [
    ({}, "dy", [0.25, 0.125, 0.0625]),                  # dy by default: dx's
    ({"dy": 0.5}, "dy", [0.5, 0.25, 0.125]),
    ({"cells_y": 8}, "cells_y", [8, 16, 32]),
])
def test_refined_2d_grids_halve_dy_with_dx(grid, key, expected):
    case = load_case(CYLINDER, ["grid.dx=0.25", *(f"grid.{k}={v}" for k, v in grid.items())])
    cases = [refined(case, level) for level in range(3)]
    assert [c.dx for c in cases] == [0.25, 0.125, 0.0625]
    assert [getattr(c, key) for c in cases] == expected
    assert cases[0].cells_y == case.cells_y


def test_summary_keys_of_a_2d_run_match_its_summary():
    case = load_case(CYLINDER, ["grid.dx=0.5", "case.t_end=0.05"])
    for model in case.models:
        assert set(run_model(case, model).summary) == set(summary_keys(model, two_d=True))


def _study_file(tmp_path: Path, quantities: str) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(f'[study]\ncase = "{CYLINDER.as_posix()}"\n'
                    'set = ["grid.dx=0.25", "case.t_end=0.3"]\ndesign = "grid"\n'
                    f'quantities = {quantities}\n[parameters]\n'
                    '"single_layer.phi_b_deg" = { values = [25, 30] }\n')
    return path


def test_a_study_point_over_a_2d_case_is_the_2d_run(tmp_path):
    """A study's evaluation of a 2D case reads the 2D summary (the same run: 1e-12)."""
    pytest.importorskip("distributed")
    from pdeflow.study import load_study
    from pdeflow.study.evaluate import DesignPoint, evaluate

    spec = load_study(_study_file(tmp_path, '["single_layer.mass_radius", '
                                            '"single_layer.deposit_area"]'))
    row = evaluate(spec, DesignPoint(0, {"single_layer.phi_b_deg": 25}))
    assert row["status"] == "ok", row["message"]
    run = run_model(load_case(CYLINDER, ["grid.dx=0.25", "case.t_end=0.3",
                                         "single_layer.phi_b_deg=25"]),
                    "single_layer").summary
    for key in ("mass_radius", "deposit_area"):
        assert row[f"single_layer.{key}"] == pytest.approx(run[key], rel=1e-12)


def test_a_study_of_a_2d_case_refuses_a_1d_quantity(tmp_path, capsys):
    pytest.importorskip("distributed")
    study = _study_file(tmp_path, '["single_layer.runout_mass_quantile"]')
    assert main(["study", str(study), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "runout_mass_quantile" in err, err
    assert "run summary (2D) has" in err and "mass_radius" in err
    assert not (tmp_path / "o").exists()


def test_a_2d_sweep_needs_its_aspect_ratios(capsys):
    assert main(["sweep", str(CYLINDER)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: error:") and err.count("\n") == 1
    assert "[sweep]" in err and "aspect_ratios" in err


def _column(two_d: bool) -> Case:
    """A single-layer column (L0 = 0.5 m, H0 = 0.5 m) on 2 m, 16 cells; ``two_d``: the
    same as a box across a 0.5 m wide channel with walls (4 cells across), uniform in y."""
    data = {"case": {"name": "col", "models": ["single_layer"], "t_end": 0.2},
            "grid": {"length": 2.0, "dx": 0.125},
            # the 2D time step bounds the sum of the Courant numbers over both axes:
            # twice the 1D number gives the 1D steps on a state uniform across
            "numerics": {"cfl": 0.4 if two_d else 0.2},
            "boundaries": {"left": "wall", "right": "open"},
            "initial": {"shape": "column", "L0": 0.5, "H0": 0.5}}
    if two_d:
        data["grid"]["width"] = 0.5
        data["initial"] = {"shape": "box", "x0": 0.0, "semi_x": 0.5, "y0": 0.25,
                           "semi_y": 0.5, "H0": 0.5}
    case = Case(data, "col.toml", ROOT)
    case.validate()
    return case


def test_compare_over_a_2d_case_uniform_across_gives_the_1d_errors_times_the_width():
    """A 2D run uniform in y is the 1D run bit for bit (docs/two_d.md), and so is its fine
    reference: its L1 errors over the area are the 1D errors per unit width times the
    width (0.5 m), to the round-off of sums over 4x more cells in another order (1e-12
    relative); the observed orders are the same."""
    from pdeflow.analysis.workprecision import compare

    kw = {"variants": ["hll/first-order", "hll/muscl/mc"], "grids": [8, 16],
          "out_dir": None, "repeats": 1}
    one, two = compare(_column(False), **kw), compare(_column(True), **kw)
    assert [r["cells_y"] for r in two.rows] == [2, 4, 2, 4]
    for r1, r2 in zip(one.rows, two.rows, strict=True):
        assert r1["status"] == r2["status"] == "ok" and r1["steps"] == r2["steps"]
        for key in ("err_h", "err_hu"):
            assert r2[key] == pytest.approx(0.5 * r1[key], rel=1e-12), key
        assert r2["rel_err_h"] == pytest.approx(r1["rel_err_h"], rel=1e-12)
        assert r2["cell_updates"] == r1["cell_updates"] * r2["cells_y"]


def test_compare_hyperbolicity_on_a_2d_case_compares_the_modes(tmp_path, capsys):
    """--hyperbolicity on a 2D case: each mode runs the two layers on the 2D grid; 'none'
    applies no F_extra, the restorations do (the collapse leaves the band at first)."""
    out = tmp_path / "o"
    assert main(["compare", str(CYLINDER), "--set", "grid.dx=0.1", "--set",
                 "case.t_end=0.5", "--hyperbolicity", "--variants", "hll/first-order",
                 "--grids", "10", "--models", "two_layer", "--repeats", "1",
                 "--out-dir", str(out)]) == 0
    rows = json.loads((out / "cylinder_2d_hyperbolicity.json").read_text())
    assert [r["mode"] for r in rows] == ["exact", "bound", "none"]
    assert all((r["cells"], r["cells_y"]) == (40, 40) for r in rows)  # the case's grid
    none = rows[2]
    assert none["hyperbolicity_events"] == 0 and none["max_fextra_over_rho1"] == 0.0
    assert all(r["hyperbolicity_events"] > 0 and r["max_fextra_over_rho1"] > 0
               for r in rows[:2])


@pytest.mark.slow  # py-pde compiles its Runge-Kutta stepper for each grid: ~1 min each
def test_compare_mol_rk_over_a_2d_case_uniform_across_gives_the_1d_errors_times_width():
    """mol-rk (py-pde's Runge-Kutta on the method-of-lines rate) on the column uniform
    across: the 2D rate of such a state is the 1D rate, so the errors over the area are
    the 1D errors per unit width times the width (1e-12 relative, as for fv-split
    above), and so are its steps."""
    from pdeflow.analysis.workprecision import compare

    kw = {"variants": ["mol-rk"], "grids": [8, 16], "out_dir": None, "repeats": 1,
          "reference": "fine:hll/first-order"}
    one, two = compare(_column(False), **kw), compare(_column(True), **kw)
    assert [r["variant"] for r in two.rows] == ["mol-rk", "mol-rk"]
    for r1, r2 in zip(one.rows, two.rows, strict=True):
        assert r1["status"] == r2["status"] == "ok" and r1["steps"] == r2["steps"]
        assert r2["err_h"] == pytest.approx(0.5 * r1["err_h"], rel=1e-12)
        assert r2["rel_err_h"] == pytest.approx(r1["rel_err_h"], rel=1e-12)


def test_a_2d_study_runs_on_dask_and_resumes(tmp_path, capsys):
    """The whole pipeline on a 2D case (one local worker): the table has the 2D
    quantities of both points; run again, it computes nothing and keeps the rows."""
    pytest.importorskip("distributed")
    import pandas as pd

    study = _study_file(tmp_path, '["single_layer.mass_radius", "single_layer.lateral_spread"]')
    out = tmp_path / "o"
    cmd = ["study", str(study), "--out", str(out), "--workers", "1"]
    assert main(cmd) == 0
    first = pd.read_csv(out / "results.csv")
    assert list(first["status"]) == ["ok", "ok"]
    assert first["single_layer.mass_radius"].notna().all()
    capsys.readouterr()
    assert main(cmd) == 0
    assert "all 2 evaluations done" in capsys.readouterr().out
    again = pd.read_csv(out / "results.csv")
    pd.testing.assert_frame_equal(first, again)
