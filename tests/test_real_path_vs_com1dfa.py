"""benchmarks/real_path_vs_com1dfa.py and avaframe_paths.py's ``--inputs`` layout without
AvaFrame (docs/terrain.md, "A real path: avaHit"): the measures on fields whose answer
is known, the Inputs copy without entrainment, and the script's pdeflow side on a small
DEM in AvaFrame's layout."""

from __future__ import annotations

import importlib.util
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def load(name: str):
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_measures_find_the_farthest_affected_cell_and_the_shared_area():
    """One thin and two affected cells on a 10 m grid: the area counts the affected
    ones, the run-out is the farther one's distance from the top and its angle the drop
    over it; the same run against itself is all shared."""
    rv = load("real_path_vs_com1dfa")
    x, y = 10.0 * np.arange(5), 10.0 * np.arange(4)
    pft = np.zeros((5, 4))
    pft[1, 0], pft[3, 0], pft[4, 3] = 0.5, 2.0, 0.05  # the last one below 0.1 m
    z = 100.0 - 5.0 * x[:, None] * np.ones((5, 4))
    run = {"x": x, "y": y, "dx": 10.0, "z": z, "pft": pft}
    row = rv.measures(run, (0.0, 0.0, 100.0))
    assert row["area"] == pytest.approx(2 * 100.0 / 1e4)
    assert row["runout"] == pytest.approx(30.0) and row["runout_xy"] == (30.0, 0.0)
    assert row["runout_angle"] == pytest.approx(math.degrees(math.atan2(150.0, 30.0)))
    assert rv.shared(row, row) == pytest.approx((0.02, 0.0, 0.0))


def test_the_inputs_copy_leaves_entrainment_resistance_and_secondary_release_out(
        tmp_path):
    """avaframe_paths.py --inputs copies AvaFrame's Inputs but its ENT, RES, SECREL."""
    ap = load("avaframe_paths")
    inputs = tmp_path / "Inputs"
    for part in ("REL", "ENT", "RES", "SECREL", "LINES"):
        (inputs / part).mkdir(parents=True)
        (inputs / part / "a.shp").write_text("x")
    (inputs / "dem.asc").write_text("x")
    dem = ap.copy_inputs(inputs, tmp_path / "ava")
    assert dem == tmp_path / "ava" / "Inputs" / "dem.asc"
    assert sorted(p.name for p in dem.parent.iterdir()) == ["LINES", "REL", "dem.asc"]


def test_the_script_runs_pdeflow_alone_on_a_dem_the_test_writes(tmp_path):
    """Without AvaFrame the script says so in one line and prints pdeflow's row: on a
    30 deg plane clipped to a disc (as tests/test_terrain_flow.py's real path) the
    run-out angle from the release's top is below the mass centre's."""
    shapefile = pytest.importorskip("shapefile")
    from pdeflow.terrain import Raster, write_raster

    inputs = tmp_path / "avaframe" / "data" / "avaTest" / "Inputs"
    (inputs / "REL").mkdir(parents=True)
    n, cs = 60, 5.0
    X, Y = np.meshgrid(cs * (np.arange(n) + 0.5), cs * (np.arange(n)[::-1] + 0.5))  # noqa: N806
    z = 500.0 - math.tan(math.radians(30.0)) * X
    write_raster(Raster(z, 0.0, 0.0, cs, np.hypot(X - 150, Y - 150) > 145),
                 inputs / "avaTest.asc")
    with shapefile.Writer(str(inputs / "REL" / "rel")) as w:
        w.field("thickness", "N", decimal=3)
        w.poly([[[60, 130], [60, 170], [100, 170], [100, 130], [60, 130]]])
        w.record(1.0)
    env = {**os.environ, "PDEFLOW_AVAFRAME_PYTHON": str(tmp_path / "none")}
    proc = subprocess.run([sys.executable, str(BENCH / "real_path_vs_com1dfa.py"),
                           "--avaframe", str(tmp_path), "--path", "avaTest", "--phi", "25",
                           "--threads", "1", "--avaframe-python", str(tmp_path / "none")],
                          capture_output=True, text=True, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = proc.stdout
    if "AvaFrame is not available" not in out:
        pytest.skip("this interpreter imports avaframe")
    row = next(line for line in out.splitlines() if line.startswith("| pdeflow |"))
    cells = row.split("|")
    assert "59 x 59 cells of 5.00 m" in cells[2]
    centre, runout_angle = float(cells[7]), float(cells[9])
    assert centre >= 25.0 and runout_angle < centre


def test_the_distance_along_a_polyline_is_that_of_the_nearest_point():
    """An L-shaped line (10 m east, then 10 m north): points beside each leg, before
    its start and beyond its end (on the legs prolonged)."""
    rv = load("real_path_vs_com1dfa")
    line = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    s = rv.along(line, np.array([4.0, 12.0, -3.0, 10.0]), np.array([-1.0, 6.0, 0.0, 15.0]))
    np.testing.assert_allclose(s, [4.0, 16.0, -3.0, 25.0])
