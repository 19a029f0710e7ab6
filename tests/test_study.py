"""The study engine (pdeflow study): study files, Dask execution, resume, analysis."""

from __future__ import annotations

import json
import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed")

from pdeflow.cli import main  # noqa: E402
from pdeflow.study import load_study  # noqa: E402
from pdeflow.study.designs import design_points  # noqa: E402

from .helpers import ishigami_study  # noqa: E402
from .studyfunctions import ishigami, ishigami_indices  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CASE_51 = (ROOT / "cases" / "paper_5_1_dam_break.toml").as_posix()
SMOKE = ROOT / "cases" / "study_smoke.toml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _study(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _frame(directory: Path):
    """The results table without the wall times (which differ from run to run)."""
    import pandas as pd

    df = pd.read_csv(directory / "results.csv", keep_default_na=False, na_values=[""])
    return df.drop(columns="wall_s").sort_values("id").reset_index(drop=True)


# --- bad study files ------------------------------------------------------------------------
BASE = f"""
[study]
case = "{CASE_51}"
design = "lhs"
samples = 4
quantities = ["two_layer.runout"]
"""


@pytest.mark.parametrize("extra, named", [
    ('[parameters]\n"two_layer.not_a_key" = { range = [0, 1] }', "not_a_key"),
    ('[parameters]\n"grid.dxx" = { range = [0.01, 0.1] }', "grid.dxx"),
    ('[parameters]\n"two_layer.k" = { range = [0.8, 0.3] }', "two_layer.k"),
    ('[parameters]\n"two_layer.c" = { range = [0, 3], scale = "log" }', "two_layer.c"),
    ('[parameters]\n"two_layer.k" = { range = [0.3, 0.8] }\n'
     '[objectives]\nx = "two_layer.no_such_summary_key"', "no_such_summary_key"),
    ('[parameters]\n"two_layer.k" = { range = [0.3, 0.8] }\n'
     '[objectives]\nx = "__import__(1)"', "objectives.x"),
])
def test_bad_study_file_is_a_one_line_error(tmp_path, capsys, extra, named):
    path = _study(tmp_path, BASE + extra)
    assert main(["study", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_unknown_design_and_bad_workers(tmp_path, capsys):
    path = _study(tmp_path, BASE.replace('"lhs"', '"random"')
                  + '[parameters]\n"two_layer.k" = { range = [0.3, 0.8] }')
    assert main(["study", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "study.design" in capsys.readouterr().err
    assert main(["study", str(SMOKE), "--out", str(tmp_path / "o"), "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err


# --- designs ---------------------------------------------------------------------------------
def test_designs_cover_ranges_and_kinds(tmp_path):
    text = """
[study]
function = "tests.studyfunctions:ishigami"
design = "grid"
quantities = ["y"]
[parameters]
x1 = { range = [0.01, 1], scale = "log", points = 3 }
x2 = { range = [1, 4], type = "int", points = 4 }
x3 = { choices = [0.5, 1.5] }
"""
    pts = design_points(load_study(_study(tmp_path, text)))
    assert len(pts) == 3 * 4 * 2
    assert sorted({p["x1"] for p in pts}) == pytest.approx([0.01, 0.1, 1.0])
    assert sorted({p["x2"] for p in pts}) == [1, 2, 3, 4]
    lhs = load_study(_study(tmp_path, text.replace('"grid"', '"lhs"\nsamples = 400')))
    pts = design_points(lhs)
    x1 = np.array([p["x1"] for p in pts])
    # uniform in log10 x1: about a quarter of the points in each quarter-decade band
    counts = np.histogram(np.log10(x1), bins=4, range=(-2, 0))[0]
    assert counts.min() >= 95 and counts.max() <= 105
    assert {p["x2"] for p in pts} == {1, 2, 3, 4}
    assert {p["x3"] for p in pts} == {0.5, 1.5}


# --- execution -------------------------------------------------------------------------------
def test_smoke_study_same_results_with_one_and_two_workers(tmp_path, capsys):
    one, two = tmp_path / "one", tmp_path / "two"
    assert main(["study", str(SMOKE), "--out", str(one), "--workers", "1", "-q"]) == 0
    assert main(["study", str(SMOKE), "--out", str(two), "--workers", "2", "-q"]) == 0
    a, b = _frame(one), _frame(two)
    assert len(a) == 32 and list(a["id"]) == list(range(32))
    assert (a["status"] == "ok").all()
    assert a.equals(b)
    report = (two / "report.md").read_text()
    assert "## Pareto front" in report and "pdeflow run " in report
    assert (two / "pareto.png").stat().st_size > 0 and (two / "scatter.png").exists()
    # rerunning computes nothing; a changed study file is refused
    capsys.readouterr()
    assert main(["study", str(SMOKE), "--out", str(two), "--workers", "2"]) == 0
    assert "all 32 evaluations done" in capsys.readouterr().out
    assert _frame(two).equals(b)
    changed = _study(tmp_path, SMOKE.read_text().replace("seed = 1", "seed = 2").replace(
        '"paper_5_1_dam_break.toml"', f'"{CASE_51}"'), "changed.toml")
    assert main(["study", str(changed), "--out", str(two)]) == 2
    assert "another version of the study" in capsys.readouterr().err


def test_failed_evaluation_is_recorded_not_fatal(tmp_path):
    # each value is valid alone; MUSCL with CFL 0.9 is not (checked per evaluation)
    text = f"""
[study]
case = "{CASE_51}"
set = ["grid.dx=0.1"]
design = "grid"
quantities = ["single_layer.runout"]
[parameters]
"numerics.reconstruction" = {{ choices = ["first-order", "muscl"] }}
"numerics.cfl" = {{ values = [0.3, 0.9] }}
"""
    out = tmp_path / "out"
    assert main(["study", str(_study(tmp_path, text)), "--out", str(out), "--workers",
                 "1", "-q"]) == 0
    df = _frame(out)
    assert list(df["status"]) == ["ok", "ok", "ok", "failed"]
    assert "numerics.cfl" in df["message"][3]
    assert "## Failed evaluations" in (out / "report.md").read_text()


def test_sobol_indices_of_ishigami_through_the_pipeline(tmp_path):
    text = ishigami_study("sobol", 2048, 3, bound=math.pi)
    out = tmp_path / "out"
    assert main(["study", str(_study(tmp_path, text)), "--out", str(out), "--workers",
                 "1", "-q"]) == 0
    df = _frame(out)
    assert len(df) == 2048 * 5
    spec = load_study(out / "study.toml")
    from pdeflow.study.designs import sobol_indices

    s = sobol_indices(spec, df["y"].to_numpy())
    exact = ishigami_indices()
    for key in ("S1", "ST"):
        assert np.abs(s[key] - exact[key]).max() < 0.04, (key, s[key], exact[key])
    assert "## Sensitivity: Sobol indices" in (out / "report.md").read_text()
    assert (out / "sobol.png").exists()


def test_pareto_front_of_schaffer_by_nsga2(tmp_path):
    text = """
[study]
function = "tests.studyfunctions:schaffer"
design = "optimize"
samples = 96
population = 16
seed = 5
quantities = ["f1", "f2"]
[parameters]
x = { range = [-10, 10] }
[objectives]
f1 = "f1"
f2 = "f2"
"""
    out = tmp_path / "out"
    assert main(["study", str(_study(tmp_path, text)), "--out", str(out), "--workers",
                 "2", "-q"]) == 0
    df = _frame(out)
    assert len(df) == 96 and df["id"].is_unique
    from pdeflow.study.report import pareto_mask

    front = df[pareto_mask(df[["f1", "f2"]].to_numpy())]
    # the Pareto set is [0, 2]: the sampled front lies on it up to the sampling's gaps
    assert len(front) >= 8
    assert front["x"].between(-0.5, 2.5).all()
    assert front["x"].between(0, 2).mean() >= 0.8
    assert front["x"].min() < 0.3 and front["x"].max() > 1.7


def test_killed_study_resumes_without_duplicates(tmp_path):
    text = ishigami_study("lhs", 60, 7, delay=0.1)
    study, out = _study(tmp_path, text), tmp_path / "out"
    cmd = [sys.executable, "-m", "pdeflow", "study", str(study), "--out", str(out),
           "--workers", "2", "-q"]
    proc = subprocess.Popen(cmd, env=ENV, start_new_session=True)
    csv = out / "results.csv"
    try:
        t0 = time.time()
        while time.time() - t0 < 300 and proc.poll() is None:
            if csv.exists() and csv.read_text().count("\n") > 11:
                break
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the client and its worker processes
        proc.wait()
    partial = _frame(out)
    assert 1 <= len(partial) < 60, len(partial)
    assert subprocess.run(cmd, env=ENV).returncode == 0
    df = _frame(out)
    assert list(df["id"]) == list(range(60))
    pts = design_points(load_study(study))
    expect = [ishigami(p["x1"], p["x2"], p["x3"])["y"] for p in pts]
    assert df["y"].to_numpy() == pytest.approx(expect, rel=1e-12)
    # the rows written before the kill are kept as they were (with two workers their ids
    # need not be 0..n-1, so compare by id, not by position)
    kept = df.set_index("id").loc[partial["id"], "y"].to_numpy()
    assert (partial["y"].to_numpy() == kept).all()


def test_resuming_results_of_other_numerics_warns_and_keeps_them(tmp_path, capsys):
    """A study's fingerprint covers its study and case files; the code of the models and
    numerics is recorded beside it: a directory computed by other code is resumed with a
    warning (its rows are kept), as the same code resumes silently."""
    import json

    study, out = _study(tmp_path, ishigami_study("lhs", 4, 1)), tmp_path / "out"
    cmd = ["study", str(study), "--out", str(out), "--workers", "1"]
    assert main(cmd) == 0
    assert main(cmd) == 0
    assert "another version" not in capsys.readouterr().out
    meta = json.loads((out / "meta.json").read_text())
    meta["numerics"] = "0" * 16  # as if computed before a change of the numerics
    (out / "meta.json").write_text(json.dumps(meta))
    assert main(cmd) == 0
    said = capsys.readouterr().out
    assert "its 4 results were computed by another version of pdeflow's models or " \
           "numerics" in said
    assert len(_frame(out)) == 4


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_study_runs_unchanged_on_a_real_scheduler(tmp_path):
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    procs = [subprocess.Popen([*dask, "--host", "127.0.0.1", "--port", str(port),
                               "--dashboard-address", ":0"], env=ENV,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(2):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", addr, "--nthreads",
                 "1", "--nworkers", "1", "--no-dashboard"], env=ENV, cwd=tmp_path,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client

        with Client(addr, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
        remote, local = tmp_path / "remote", tmp_path / "local"
        assert main(["study", str(SMOKE), "--out", str(remote), "--scheduler", addr,
                     "-q"]) == 0
        assert main(["study", str(SMOKE), "--out", str(local), "--workers", "1",
                     "-q"]) == 0
        assert _frame(remote).equals(_frame(local))
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


@pytest.mark.parametrize("path", sorted((ROOT / "cases").glob("study_*.toml")),
                         ids=lambda p: p.stem)
def test_shipped_study_files_load(path):
    spec = load_study(path)
    assert spec.parameters and spec.quantities


def test_summary_keys_catalogue_matches_the_summaries():
    from pdeflow.cases import load_case
    from pdeflow.simulate import run_model, summary_keys

    case = load_case(CASE_51, ["output.snapshot_times=[]", "grid.dx=0.1"])
    for model in case.models:
        assert set(run_model(case, model).summary) == set(summary_keys(model))


PREPARE_STUDY_KERNELS = r"""
import json, sys
from pdeflow.solvers.fv_split import split_stepper
from pdeflow.study import load_study
from pdeflow.numerics.warmup import prepare
from pdeflow.study.evaluate import study_steppers
spec = load_study(sys.argv[1])
grid = spec.case.make_grid()
pdes = [spec.case.make_pde(m) for m in spec.models()]
kernels = [k for pde in pdes for k in split_stepper(pde, pde.metric(grid)).kernels]
before = sum(len(k.signatures) for k in kernels)
prepare(study_steppers(spec))
print("SIGNATURES" + json.dumps([before, [len(k.signatures) for k in kernels]]))
"""


def test_study_kernels_are_prepared_for_every_model_before_the_workers():
    """Before the local workers start, the study's process compiles (or loads) the
    kernels of every model its evaluations run (a fresh process: none before, one
    signature each after), so that the workers only load them."""
    proc = subprocess.run([sys.executable, "-c", PREPARE_STUDY_KERNELS, str(SMOKE)],
                          capture_output=True, text=True, timeout=900, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stderr[-3000:]
    line = [x for x in proc.stdout.splitlines() if x.startswith("SIGNATURES")][0]
    before, after = json.loads(line[len("SIGNATURES"):])
    assert before == 0
    assert set(after) == {1}


def test_the_scatter_labels_carry_units():
    """The report's scatter axes name each column's unit: model parameters from their
    dataclass's docstrings, run quantities from the summary, case keys by table."""
    from pdeflow.study.report import _label, unit_of

    assert unit_of("two_layer.phi_b_deg") == "deg"
    assert unit_of("two_layer.du_reg") == "m/s"
    assert unit_of("two_layer.c") == "-"
    assert unit_of("two_layer.runout") == "m"
    assert unit_of("two_layer.runout_mass_quantile") == "m"
    assert unit_of("two_layer.lower_stop_time") == "s"
    assert unit_of("single_layer.max_fextra_over_rho1") == "m^2/s^2"
    assert unit_of("initial.wedge_angle_deg") == "deg"
    assert unit_of("grid.dx") == "m"
    assert unit_of("sweep.two_layer.exponent") == "-"
    assert unit_of("score") is None
    assert _label("two_layer.runout") == "two_layer.runout [m]"
