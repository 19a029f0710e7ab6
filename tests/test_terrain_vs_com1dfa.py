"""benchmarks/terrain_vs_com1dfa.py, pdeflow's side only (no AvaFrame): on a coarse grid
over the parabola's DEM the script's functions give a run-out on the flat beyond the
foot, travel angles the energy line bounds, and a table row (docs/terrain.md, "Side by
side with com1DFA")."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "terrain_vs_com1dfa.py"


@pytest.fixture(scope="module")
def tv():
    spec = importlib.util.spec_from_file_location("terrain_vs_com1dfa", PATH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["terrain_vs_com1dfa"] = module  # the dataclass looks its module up
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("terrain_vs_com1dfa", None)


def test_pdeflow_side_on_a_coarse_grid_runs_out_onto_the_flat(tv, tmp_path):
    """40 m cells: the run ends at rest with its run-out on the axis beyond the
    parabola's foot (1482.6 m) and inside the domain, the mass centre's travel angle
    above the friction angle (the energy line's bound) and below the path's mean slope,
    the front's from the release's top below it (the front runs farther), the
    volume released slope-normal 1 m over the rectangle (to the cells' share), and one
    table row with the run-out."""
    path = tv.PATHS["parabola"]
    dem = tmp_path / "parabola.asc"
    tv.write_dem(path, dem)
    raster = tv.read_raster(dem)
    foot = 1000.0 / math.tan(math.radians(34.0))
    run = tv.pdeflow_run(raster, path, 40.0)
    row = tv.measures(run, path)
    assert foot < row["runout"] < path.length
    assert tv.PHI_DEG < row["centre_angle"] < 34.0
    assert 20.0 < row["runout_angle"] < row["centre_angle"]  # the front runs farther
    assert row["pft"] > tv.THRESHOLD and row["area"] > 0.0 and row["t_end"] > 10.0
    _, state, geo = tv.pdeflow_setup(raster, path, 40.0)
    volume = state.data[0].sum() * 40.0 ** 2
    surface = 200.0 * 200.0 / np.mean(geo["cos"][state.data[0] > 0])
    assert volume == pytest.approx(surface, rel=0.05)
    lines = tv.table([row])
    assert len(lines) == 3 and lines[2].startswith("| pdeflow | dx = 40 m | "
                                                   f"{row['runout']:.0f} |")
    assert tv.converged_lines([row]) == ["one pdeflow resolution: no convergence "
                                         "statement"]
