"""docs/erodible_bed.md and its generator (docs/generate/erodible_bed.py): the generator's
core runs a point and its cache resumes; the page is the rendering of the numbers the
generator computed from its cached runs (no hand-typed results)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.helpers import generator_modules

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def gen():
    """The generator's modules, importable while the tests run."""
    with generator_modules("erodible_bed", "erodible_bed_page") as modules:
        yield modules


def test_generator_point_and_resumable_cache(gen, tmp_path):
    """A two-layer point erodes (law set) and comes to rest; the cache is written point by
    point and a second call runs nothing."""
    eb, _ = gen
    row = eb.measure_point("two layers, planar law set", "du_reg", 22.0, 0.005, 0.01)
    assert row["at_rest"] and row["runout"] > 0.2 and row["mass_relative_error"] < 1e-12
    assert 0 < row["bed_max_erosion_depth"] <= 0.005 + 1e-15
    path = tmp_path / "sweep.csv"
    points = [("single layer", "-", 10.0, 0.0, 0.02), ("single layer", "-", 20.0, 0.0, 0.02)]
    rows = eb.fill_cache(points, path, log=None)
    again = eb.fill_cache(points, path, log=None)
    assert len(rows) == len(again) == 2 and eb.read_cache(path) == again
    assert again[1]["runout"] > again[0]["runout"]


def test_sweep_points_cover_the_issue(gen):
    """theta 0-25 deg, e_i 0 to H0/10, the three closures, both two-layer sets, and the
    key points refined three times."""
    eb, _ = gen
    pts = eb.sweep_points()
    assert {p[1] for p in pts} == {"paper", "du_reg", "relaxed", "-"}
    assert min(p[2] for p in pts) == 0 and 25 in {p[2] for p in pts}
    assert max(p[3] for p in pts) == pytest.approx(eb.H0 / 10)
    fine = [p for p in pts if p[4] == min(eb.REFINE)]
    assert {p[2] for p in fine} == set(eb.KEY_THETAS) and len(fine) >= 36


def test_page_is_the_rendering_of_its_numbers(gen):
    """docs/erodible_bed.md says what numbers.json holds, and every figure it shows
    exists; the answer's verdict follows the sign of the computed trend."""
    _, page = gen
    numbers = json.loads((ROOT / "docs" / "erodible_bed" / "numbers.json").read_text())
    text = (ROOT / "docs" / "erodible_bed.md").read_text()
    assert text == page.render_page(numbers)
    steep = [v for t in numbers["trend"].values() for v in t["dr_steep"]]
    assert ("**No.**" in text) == (max(steep) <= 0)
    for name in ("runout", "duration", "near_phi_b", "side_views", "stresses"):
        assert (ROOT / "docs" / "erodible_bed" / f"{name}.png").is_file()
