"""docs/axisymmetric.md and its generator (docs/generate/axisymmetric.py): the generator's
core runs on a tiny grid and its cache resumes; the page is the rendering of the numbers
the generator computed from its cached runs (no hand-typed results)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.helpers import generator_modules

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def gen():
    """The generator's modules, importable while the tests run."""
    with generator_modules("axisymmetric", "axisymmetric_page", "run_cache") as modules:
        yield modules


def test_generator_core_on_a_tiny_grid(gen, tmp_path):
    """Every parameter set, a = 2 on dr = 0.02 m over 1.5 m: at rest, a run-out beyond the
    column, a final height below H0, an arrest time; the cache is written point by point
    and a second call runs nothing."""
    ax, _, _ = gen
    for name in ax.SETS:
        row = ax.measure_point(name, 0.02, 2.0, ["grid.length=1.5"])
        assert row["at_rest"] and row["r"] > 0.5, (name, row)
        assert 0 < row["H_inf_over_H0"] < 1 and row["arrest_time_scaled"] > 0
        assert row["mass_relative_error"] < 1e-12
    path = tmp_path / "sweep.csv"
    points = [("single layer", 0.05, 1.0), ("single layer", 0.05, 2.0)]
    rows = ax.fill_cache(points, path, log=None)
    again = ax.fill_cache(points, path, log=None)
    assert len(rows) == len(again) == 2 and ax.read_cache(path) == again
    assert [r["a"] for r in again] == [1.0, 2.0] and again[1]["r"] > again[0]["r"]


def test_shape_numbers_name_the_deposits(gen):
    """A cone, a truncated cone (top still at H0) and a peak on a thin skirt."""
    import numpy as np

    _, page, _ = gen
    x = np.linspace(0.0005, 1.0, 1000)
    cone = np.maximum(0.1 * (1 - x / 0.8), 0)
    assert page.shape_numbers(x, cone, 0.5)["shape"] == "cone"
    truncated = np.minimum(cone, 0.05)
    assert page.shape_numbers(x, truncated, 0.05)["shape"] == "truncated cone"
    hat = np.where(x < 0.2, 0.1 * (1 - x / 0.2), 0) + np.where(x < 0.8, 0.002, 0)
    assert page.shape_numbers(x, hat, 0.5)["shape"] == "steep centre on a thin skirt"


def test_the_page_says_what_the_runs_gave(gen):
    """numbers.json's sweep numbers are those of the cached runs (fits of the cached CSV,
    equal but for round-off: run_cache.same_numbers, relative 1e-9, since the last digits
    of a least-squares fit depend on the processor), and docs/axisymmetric.md is exactly
    the rendering of numbers.json."""
    ax, page, run_cache = gen
    numbers = json.loads((ax.OUT / "numbers.json").read_text())
    recomputed = json.loads(json.dumps(ax.page_numbers(ax.read_cache())))
    assert run_cache.same_numbers(recomputed["sets"], numbers["sets"])
    assert recomputed["points"] == numbers["points"]
    assert page.render_page(numbers) == (ROOT / "docs" / "axisymmetric.md").read_text()


def test_an_axisymmetric_sweep_reports_the_deposit():
    """`pdeflow sweep` on an axisymmetric case adds the final height and the arrest time
    to each run; a planar sweep's runs keep their keys."""
    from pdeflow.analysis.sweep import run_sweep
    from pdeflow.cases import load_case

    small = ["grid.dx=0.02", "grid.length=1.5", "sweep.aspect_ratios=[1, 2]"]
    axi = run_sweep(load_case(ROOT / "cases" / "axisymmetric_collapse_sweep.toml", small))
    for res in axi["models"].values():
        for row in res["runs"]:
            assert 0 < row["H_inf_over_L0"] <= row["a"] and row["arrest_time_scaled"] > 0
    planar = run_sweep(load_case(ROOT / "cases" / "collapse_sweep.toml",
                                 ["grid.dx=0.05", "grid.length=3", "sweep.aspect_ratios=[2]"]))
    assert set(planar["models"]["two_layer"]["runs"][0]) == {
        "a", "r", "runout", "r_mass", "runout_mass", "stop_time", "at_rest", "steps",
        "wall_time_s", "mass_relative_error"}
