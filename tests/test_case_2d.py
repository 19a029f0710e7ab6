"""2D case files (issue 36, the first slice): a case with ``grid.width`` becomes a 2D grid
and state, ``pdeflow run`` runs it and prints the 2D summary, whose numbers are those of
:mod:`pdeflow.metrics_2d`; bad 2D input and the outputs that are 1D only are one line
before any work. Its figure: tests/test_figures_2d.py."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from pde import CartesianGrid

from pdeflow import metrics_2d
from pdeflow.cases import Case, load_case
from pdeflow.checks import RunWarning
from pdeflow.cli import main
from pdeflow.initial_shapes_2d import total_depth_2d
from pdeflow.simulate import run_model
from tests.test_two_d_cylinder import quadrant

ROOT = Path(__file__).parents[1]
CYLINDER = ROOT / "cases" / "cylinder_2d.toml"
SLOPE = ROOT / "cases" / "column_on_slope_2d.toml"


def _one_line_error(capsys, *words: str, prefix: str = "pdeflow: error:") -> str:
    err = capsys.readouterr().err
    assert err.startswith(prefix) and err.count("\n") == 1, err
    for w in words:
        assert w in err, (w, err)
    return err


def _case(**sections: dict) -> dict:
    """A small 2D case (a cylinder in a 2 m x 1 m box) with ``sections`` merged in."""
    data = {"case": {"models": ["single_layer"], "t_end": 0.5},
            "grid": {"length": 2.0, "width": 1.0, "dx": 0.05},
            "initial": {"shape": "cylinder", "x0": 0.5, "y0": 0.5, "radius": 0.2,
                        "H0": 0.2}}
    for name, table in sections.items():
        data[name] = {**data.get(name, {}), **table}
    return data


# --- the grid and the state ----------------------------------------------------------------

def test_a_2d_case_file_becomes_a_2d_grid_and_state():
    case = load_case(CYLINDER)
    grid = case.make_grid()
    assert isinstance(grid, CartesianGrid) and grid.shape == (80, 80)
    assert grid.axes_bounds == ((-2.0, 2.0), (-2.0, 2.0))
    assert case.bc == (("wall", "wall"), ("wall", "wall"))
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    column = np.where(np.hypot(x, y) < 0.5, 0.5, 0.0)
    eq, state = case.make_state("two_layer")
    assert [f.label for f in state] == ["h1", "h1u1", "h1v1", "h2", "h2u2", "h2v2"]
    np.testing.assert_allclose(state.data[0], 0.4 * column)  # upper_fraction 0.4
    np.testing.assert_allclose(state.data[3], 0.6 * column)
    assert not state.data[[1, 2, 4, 5]].any()  # at rest
    assert eq.bc == (("wall", "wall"), ("wall", "wall"))
    eq, state = case.make_state("single_layer")
    np.testing.assert_array_equal(state.data[0], column)


def test_dy_and_the_boundaries_across_are_read():
    case = Case.from_dict(_case(grid={"dy": 0.1, "y_start": -0.5},
                                boundaries={"y_high": "open"}))
    grid = case.make_grid()
    assert grid.shape == (40, 10) and grid.axes_bounds[1] == (-0.5, 0.5)
    assert case.bc == (("wall", "open"), ("wall", "open"))
    assert Case.from_dict(_case(grid={"cells_y": 5})).make_grid().shape == (40, 5)


def test_the_size_estimate_counts_the_cells_and_steps_of_both_axes():
    """A 2D case costs its nx ny cells, 1.5 times a 1D cell's memory (a third row per
    layer) and the steps of the CFL over both axes: twice the 1D steps at dy = dx."""
    from pdeflow.checks import run_cost

    two_d = Case.from_dict(_case())
    one_d = Case.from_dict({**_case(), "grid": {"length": 2.0, "dx": 0.05},
                            "initial": {"shape": "column", "L0": 0.2, "H0": 0.2}})
    c2, c1 = run_cost(two_d, "single_layer"), run_cost(one_d, "single_layer")
    assert c2.cells == 40 * 20 and c1.cells == 40
    assert c2.steps == pytest.approx(2 * c1.steps)
    assert c2.memory_bytes == pytest.approx(1.5 * 20 * c1.memory_bytes)


@pytest.mark.parametrize("shape, keys, volume", [
    ("cylinder", {"radius": 0.3}, math.pi * 0.3 ** 2 * 0.2),
    ("elliptic_column", {"semi_x": 0.4, "semi_y": 0.2}, math.pi * 0.4 * 0.2 * 0.2),
    ("cap", {"radius": 0.3}, math.pi * 0.3 ** 2 * 0.2 / 2),
    ("cap", {"semi_x": 0.4, "semi_y": 0.2}, math.pi * 0.4 * 0.2 * 0.2 / 2),
    ("box", {"semi_x": 0.3, "semi_y": 0.2}, 0.6 * 0.4 * 0.2),
])
def test_each_2d_shape_holds_its_volume(shape, keys, volume):
    """On a fine grid each shape's volume is that of its formula (cap: pi a b H0 / 2)."""
    n = 400
    x, y = np.meshgrid(*(np.arange(n) * (1.0 / n) + 0.5 / n,) * 2, indexing="ij")
    h = total_depth_2d({"shape": shape, "x0": 0.5, "y0": 0.5, "H0": 0.2, **keys}, x, y)
    assert h.max() <= 0.2 and h.min() == 0.0
    assert abs(h.sum() / n ** 2 / volume - 1) < 0.01


@pytest.mark.filterwarnings("ignore:.*reached the side")  # a small box, on purpose
def test_a_polygon_is_the_box_it_outlines_and_centred_at_its_centroid():
    box = Case.from_dict({**_case(), "initial": {"shape": "box", "x0": 0.5, "y0": 0.5,
                                                 "semi_x": 0.3, "semi_y": 0.2, "H0": 0.2}})
    polygon = {"shape": "polygon", "H0": 0.2,
               "vertices": [[0.2, 0.3], [0.8, 0.3], [0.8, 0.7], [0.2, 0.7]]}
    poly = Case.from_dict({**_case(), "initial": polygon})
    np.testing.assert_array_equal(poly.make_state("single_layer")[1].data,
                                  box.make_state("single_layer")[1].data)
    s = run_model(poly, "single_layer").summary
    assert s["mass_radius"] == run_model(box, "single_layer").summary["mass_radius"]
    assert s["runout"] == pytest.approx(s["front_position"] - 0.8)


# --- the run, the table and the metrics ----------------------------------------------------

def test_the_cli_table_is_the_2d_metrics_of_the_same_run(tmp_path, capsys):
    summary, final = tmp_path / "s.json", tmp_path / "f.npz"
    assert main(["run", str(CYLINDER), "--summary", str(summary), "--final",
                 str(final)]) == 0
    table = capsys.readouterr().out
    models = json.loads(summary.read_text())["models"]
    case = load_case(CYLINDER)
    for name, path in (("two_layer", final), ("single_layer",
                                              tmp_path / "f.single_layer.npz")):
        s = models[name]
        res = run_model(case, name)  # the same run through the API
        for key in ("front_position", "lateral_spread", "deposit_area", "mass_radius",
                    "max_depth", "max_speed", "stop_time"):
            assert res.summary[key] == s[key], key
        d, area = res.state.data, case.dx * case.dy
        x, y = res.state.grid.axes_coords
        depth = metrics_2d.total_depth(d)
        assert s["front_position"] == metrics_2d.front_x(x, depth, 1e-3, case.dx)
        assert s["runout"] == pytest.approx(s["front_position"] - 0.5)  # from x = R0
        assert s["lateral_spread"] == metrics_2d.lateral_spread(y, depth, 1e-3, case.dy)
        assert s["deposit_area"] == metrics_2d.deposit_area(depth, 1e-3, area)
        X, Y = np.meshgrid(x, y, indexing="ij")
        w = res.pde.system.densities(res.pde.parameters)
        assert s["mass_radius"] == metrics_2d.mass_radius(
            np.hypot(X, Y), metrics_2d.weighted_depth(d, w), 0.99)
        assert s["max_depth"] == depth.max() and s["at_rest"]
        assert 0 < s["max_speed"] < 5 and s["mass_relative_error"] < 1e-12
        saved = np.load(path)
        np.testing.assert_array_equal(saved[res.pde.system.layers[0].depth], d[0])
        assert saved["y"].shape == (80,)
        row = next(line for line in table.splitlines() if line.startswith("radius 99%"))
        column = list(models).index(name)
        assert row.split()[3 + 2 * column] == f"{s['mass_radius']:.4g}"
    for label in ("front (x)", "run-out (x)", "lateral spread", "deposit area",
                  "radius 99% mass", "deepest cell", "max speed", "stop time",
                  "mass error"):
        assert label in table, label


def test_the_cylinders_r99_is_the_quadrants_of_the_verification():
    """The full cylinder on 80^2 cells (dx = 0.05 m) against tests/test_two_d_cylinder.py's
    quadrant on 40^2 cells, the same dx: walls on the symmetry planes hold the symmetric
    solution, so r99 and the deepest cell agree to round-off (measured: to the last
    digit; 1.425 m single layer, 0.998 m two layers)."""
    case = load_case(CYLINDER)
    for name in case.models:
        s = run_model(case, name).summary
        r99, deepest = quadrant(name, 40)
        assert s["mass_radius"] == pytest.approx(r99, rel=1e-9)
        assert s["max_depth"] == pytest.approx(deepest, rel=1e-9)


def test_the_default_run_folder_of_a_2d_case_holds_its_summary_and_figure(
        tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(CYLINDER), "--set", "case.models=['single_layer']",
                 "--set", "grid.dx=0.1"]) == 0
    folders = list((tmp_path / "results").iterdir())
    assert len(folders) == 1
    assert sorted(p.name for p in folders[0].iterdir()) == ["final_deposits.png",
                                                            "summary.json"]


def test_material_through_open_sides_is_outflow_and_bounds_the_extents(capsys, tmp_path):
    """The cylinder in a 2 m box whose high sides are open: what leaves is the table's
    'mass outflow', not a mass error; the front and the spread are lower bounds."""
    small = [f"--set={s}" for s in ("case.models=['single_layer']", "grid.length=2",
                                    "grid.width=2", "grid.x_start=-1", "grid.y_start=-1",
                                    "initial.x0=1", "initial.y0=1", "boundaries.right=open",
                                    "boundaries.y_high=open")]
    assert main(["run", str(CYLINDER), *small, "--summary", str(tmp_path / "s.json")]) == 0
    captured = capsys.readouterr()
    rows = {line[:18].strip(): line[18:].strip() for line in captured.out.splitlines()}
    assert rows["mass error"] == "-" and rows["mass outflow"].endswith("%")
    assert rows["front (x)"].startswith(">= ") and rows["lateral spread"] == ">= 2 m"
    assert "material reached the side(s) left, right, y_low, y_high" in captured.err
    assert "the lateral spread (grid.width) are lower bounds" in captured.err


def test_the_slope_case_runs_down_x(tmp_path):
    case = load_case(SLOPE)
    for name in case.models:
        s = run_model(case, name).summary
        assert s["runout"] > 0 and s["at_rest"] and not s["warnings"]
        assert s["mass_relative_error"] < 1e-12


# --- bad input and the outputs that are 1D only: one line, before any work --------------

@pytest.mark.parametrize("sets, words", [
    (["grid.geometry='axisymmetric'"], ["grid.geometry", "1D (radial)"]),
    (["grid.width=-1"], ["grid.width", "(0, inf"]),
    (["grid.dy=0.3"], ["grid.dy", "does not divide grid.width"]),
    (["grid.cells_y=0"], ["grid.cells_y", ">= 1"]),
    (["grid.width=0.01"], ["grid.dy (by default grid.dx) must lie in (0, 0.01] m"]),
    (["boundaries.y_low='mirror'"], ["boundaries.y_low", "wall"]),
    (["initial.x0=9"], ["initial.x0", "outside the domain", "[0, 4] m"]),
    (["initial.radius=0"], ["initial.radius", "(0, inf"]),
    (["initial.L0=0.5"], ["initial.L0", "1D only for now (issue 36)"]),
    (["initial.shape='column'"], ["initial.shape 'column' is a 1D shape", "cylinder"]),
    (["initial.semi_x=0.5"], ["semi_x", "elliptic_column"]),
    (["initial.radius=0.01"], ["covers no cell centre"]),
    (["initial.shape='polygon'", "initial.vertices=[[1, 1], [2, 2], [3, 3]]"],
     ["initial.x0 is not a key of shape 'polygon'"]),

    (["output.snapshot_times=[-0.1]"], ["output.snapshot_times", "[0, inf] s"]),
    (["grid.dx=1e-4", "grid.length=1000", "grid.width=1000"],
     ["cells", "memory", "grid.dx and grid.dy >="]),
])
def test_bad_2d_input_is_one_line(sets, words, capsys, tmp_path):
    args = [a for s in sets for a in ("--set", s)]
    assert main(["run", str(CYLINDER), *args, "--summary", str(tmp_path / "s.json")]) == 2
    _one_line_error(capsys, "cylinder_2d.toml", *words)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("vertices, words", [
    ("[[1, 1], [2, 2], [3, 3]]", ["enclose no area"]),
    ("[[1, 1], [2, 2]]", ["at least 3 points"]),
    ("[[1, 1], [5, 2], [3, 3]]", ["vertex [5, 2] lies outside the domain", "[0, 4] x [0, 4]"]),
    ("[[1, 1], [2, 'a'], [3, 3]]", ["at least 3 points [x, y] of finite numbers"]),
])
def test_bad_polygons_are_one_line(vertices, words, tmp_path, capsys):
    case = tmp_path / "poly.toml"
    text = CYLINDER.read_text().split("[initial]")[0]
    case.write_text(text + f'[initial]\nshape = "polygon"\nH0 = 0.2\nvertices = {vertices}\n')
    assert main(["run", str(case)]) == 2
    _one_line_error(capsys, "poly.toml", *words)


@pytest.mark.parametrize("key", ["grid.dy=0.1", "boundaries.y_low='open'",
                                 "initial.shape='cylinder'"])
def test_2d_keys_in_a_1d_case_ask_for_the_width(key, capsys):
    assert main(["run", str(ROOT / "cases" / "ritter_dam_break.toml"), "--set", key]) == 2
    _one_line_error(capsys, "grid.width")


def test_the_app_offers_1d_cases_only():
    """The teaching app draws 1D runs: it does not list the 2D case files."""
    pytest.importorskip("panel")
    from pdeflow.app.controls import list_cases

    listed = list_cases(ROOT / "cases")
    assert "paper_5_1_dam_break.toml" in listed
    assert not {"cylinder_2d.toml", "column_on_slope_2d.toml"} & set(listed)


@pytest.mark.slow  # py-pde compiles its Runge-Kutta stepper around the 2D rate: ~50 s
def test_a_2d_case_runs_with_a_py_pde_solver():
    """numerics.solver = 'runge-kutta' on a 2D case: the method-of-lines rate on the 2D
    grid keeps the mass and the column's x <-> y mirror, and at t = 0.2 s (still
    moving) its depths lie within 5 % (L1 over the mass) of fv-split's with the same
    fluxes. They differ by the time stepping and the regularised friction of the rate
    (mol_eps), not by the space discretisation: measured 1.6 %."""
    base = ["grid.dx=0.1", "case.t_end=0.2", "numerics.reconstruction='first-order'",
            "case.models=['single_layer']"]
    split = run_model(load_case(CYLINDER, base), "single_layer")
    with pytest.warns(RunWarning, match="runge-kutta"):
        mol = run_model(load_case(CYLINDER, [*base, "numerics.solver='runge-kutta'",
                                             "numerics.dt=1e-4"]), "single_layer")
    assert mol.summary["steps"] == 2000
    assert abs(mol.summary["mass_relative_error"]) < 1e-12
    h_split, h_mol = (metrics_2d.total_depth(r.state.data) for r in (split, mol))
    np.testing.assert_allclose(h_mol, h_mol.T, rtol=0, atol=1e-12)
    assert np.abs(h_mol - h_split).sum() / h_split.sum() < 0.05
