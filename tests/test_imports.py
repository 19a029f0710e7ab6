"""A run that draws, serves, studies, stores and shows nothing imports nothing for it;
one that draws its figures leaves matplotlib to the figure worker's process.

py-pde itself imports scipy and tqdm (``import pde``), so those are not checked."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "paper_5_1_dam_break.toml"
NOT_NEEDED = ("matplotlib", "panel", "bokeh", "dask", "distributed", "pandas", "h5py",
              "xarray", "optuna", "SALib", "imageio_ffmpeg", "pdeflow.plotting",
              "pdeflow.case_figures", "pdeflow.figures_2d", "pdeflow.trackers.live",
              "pdeflow.app.dam_break",
              # the other commands' modules and the stored runs' (pdeflow.cli builds
              # only the options of the command it runs)
              "pdeflow.analysis.convergence", "pdeflow.analysis.workprecision",
              "pdeflow.analysis.sweep", "pdeflow.study", "pdeflow.app.server",
              "pdeflow.storage",
              # the fv-split solver's compiled loop is pdeflow's own: py-pde's numba
              # backend (and the numba modules it pulls in) is not needed for it
              "pde.backends.numba")

SCRIPT = """
import json, sys
from pdeflow.cases import load_case
from pdeflow.simulate import run_model
case = load_case(sys.argv[1], ["output.snapshot_times=[]", "grid.dx=0.1"])
for model in case.models:
    run_model(case, model)
api = sorted(m for m in sys.argv[3:] if m in sys.modules)
from pdeflow.cli import main
main(["run", sys.argv[1], "--set", "grid.dx=0.1", "--summary", sys.argv[2], "-q"])
cli = sorted(m for m in sys.argv[3:] if m in sys.modules)
print("MODULES" + json.dumps([api, cli]))
"""


def test_a_quiet_run_imports_no_plotting_serving_or_study_machinery(tmp_path):
    proc = subprocess.run([sys.executable, "-c", SCRIPT, str(CASE),
                           str(tmp_path / "s.json"), *NOT_NEEDED],
                          capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = next(x for x in proc.stdout.splitlines() if x.startswith("MODULES"))
    api, cli = json.loads(line[len("MODULES"):])
    assert api == [], f"the Python API imported {api}"
    assert cli == [], f"pdeflow run -q --summary imported {cli}"
    assert json.loads((tmp_path / "s.json").read_text())["models"]


FIGURES = """
import json, sys
from pdeflow.cli import main
from pdeflow.numerics.compile_parallel import can_fork
forks = can_fork()
main(["run", sys.argv[1], "--set", "grid.dx=0.1", "--outdir", sys.argv[2], "-q"])
print("MODULES" + json.dumps([forks, sorted(m for m in sys.modules
                                            if m.split(".")[0] == "matplotlib")]))
"""


def test_a_run_with_figures_draws_them_in_the_figure_workers_process(tmp_path):
    proc = subprocess.run([sys.executable, "-c", FIGURES, str(CASE), str(tmp_path / "out")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = next(x for x in proc.stdout.splitlines() if x.startswith("MODULES"))
    forks, imported = json.loads(line[len("MODULES"):])
    assert sorted(p.name for p in (tmp_path / "out").glob("*.png")) == [
        "final_deposits.png", "snapshot_t0.1.png", "snapshot_t0.25.png",
        "snapshot_t0.4.png", "snapshot_t0.7.png"]
    if forks:  # else the figures are drawn in this process (macOS, Windows, one core)
        assert imported == [], f"pdeflow run --outdir imported {imported}"


def test_a_2d_run_draws_its_figure_in_the_figure_workers_process(tmp_path):
    """A 2D case's folder: its one figure (pdeflow/figures_2d.py), drawn in the worker
    as the 1D ones are."""
    import os

    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # this checkout's pdeflow, from tmp_path
    proc = subprocess.run([sys.executable, "-c", FIGURES, str(ROOT / "cases" /
                                                               "cylinder_2d.toml"),
                           str(tmp_path / "out")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=600, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = next(x for x in proc.stdout.splitlines() if x.startswith("MODULES"))
    forks, imported = json.loads(line[len("MODULES"):])
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "final_deposits.png", "summary.json"]
    if forks:
        assert imported == [], f"pdeflow run --outdir imported {imported}"
