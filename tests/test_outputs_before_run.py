"""Issue 28: outputs checked before the run, size refused, interrupts (one line, no
files), study files pointed to ``pdeflow study``, ``python -m pdeflow`` errors."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pdeflow.cli import main

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
RITTER = ROOT / "cases" / "ritter_dam_break.toml"
SMALL = ["--set", "grid.cells=20"]


def one_line_error(capsys, *words: str) -> str:
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: error:") and err.count("\n") == 1, err
    for w in words:
        assert w in err, (w, err)
    return err


def spy_on_runs(monkeypatch) -> list:
    """Record every model run the command starts (it must start none)."""
    import pdeflow.simulate as sim

    calls: list = []

    def refuse(self, *args, **kwargs):
        calls.append(1)
        raise AssertionError("a run started")

    monkeypatch.setattr(sim.Run, "execute", refuse)
    return calls


@pytest.mark.parametrize("make, option, words", [
    (lambda d: (d / "f").write_text("x") and d / "f", "--outdir", ["is a file"]),
    (lambda d: d, "--summary", ["is a directory"]),
    (lambda d: d, "--final", ["is a directory"]),
    (lambda d: d, "--store", ["is a directory"]),
    (lambda d: d / "p.xyz", "--plot", ["'.xyz'", ".png"]),
    (lambda d: d / "s.txt", "--summary", ["'.txt'", ".json"]),
    (lambda d: d / "f.npy", "--final", ["'.npy'", ".npz"]),
    (lambda d: d / "r.nc", "--store", ["'.nc'", ".h5"]),
    (lambda d: (d / "f").write_text("x") and d / "f", "--frames", ["is a file"]),
    (lambda d: Path("/proc/s.json"), "--summary", ["cannot write in /proc"]),
])
def test_bad_outputs_are_refused_before_any_run(make, option, words, tmp_path, capsys,
                                                 monkeypatch):
    target = make(tmp_path)
    before = sorted(tmp_path.iterdir())
    calls = spy_on_runs(monkeypatch)
    assert main(["run", str(RITTER), *SMALL, option, str(target)]) == 2
    one_line_error(capsys, option, *words)
    assert calls == [] and sorted(tmp_path.iterdir()) == before


def test_read_only_directory_is_refused(tmp_path, capsys):
    if os.geteuid() == 0:
        pytest.skip("root writes into read-only directories")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        assert main(["run", str(RITTER), *SMALL, "--summary", str(ro / "s.json")]) == 2
        one_line_error(capsys, "cannot write in")
    finally:
        ro.chmod(0o700)


def test_plot_and_export_check_their_formats(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "a.h5"), "--out", str(tmp_path / "a.xyz")]) == 2
    one_line_error(capsys, "--out", "'.xyz'")
    assert main(["export", str(tmp_path / "a.h5"), str(tmp_path / "a.xlsx")]) == 2
    one_line_error(capsys, "OUT", "'.xlsx'", ".csv")


def test_a_run_beyond_the_machine_is_refused_with_its_estimate(capsys, monkeypatch):
    calls = spy_on_runs(monkeypatch)
    assert main(["run", str(CASE_51), "--set", "grid.dx=2e-6"]) == 2
    err = one_line_error(capsys, "estimated at roughly", "days", "above the limit of",
                         "grid.dx", "--force")
    assert calls == [], err


def test_force_runs_what_the_size_check_refuses(monkeypatch, tmp_path):
    """--force skips the size check (the run itself is then the user's business)."""
    import pdeflow.sizecheck as size

    monkeypatch.setattr(size, "MAX_RUN_SECONDS", 0.0)  # every run is "too long"
    assert main(["run", str(RITTER), *SMALL, "--summary", str(tmp_path / "s.json"),
                 "-q"]) == 2
    assert main(["run", str(RITTER), *SMALL, "--summary", str(tmp_path / "s.json"),
                 "-q", "--force"]) == 0
    assert (tmp_path / "s.json").exists()


def test_converge_checks_its_finest_level_and_names_levels(capsys, monkeypatch):
    calls = spy_on_runs(monkeypatch)
    assert main(["converge", str(CASE_51), "--levels", "30"]) == 2
    one_line_error(capsys, "level 30", "--levels")
    assert calls == []


def test_a_study_file_given_to_run_points_to_study(capsys):
    assert main(["run", str(ROOT / "cases" / "study_smoke.toml")]) == 2
    one_line_error(capsys, "study file", "pdeflow study")


@pytest.mark.parametrize("argv", [[], ["missing.toml"], ["--levels", "-1", str(CASE_51)]])
def test_python_m_converge_gives_the_commands_errors(argv):
    proc = subprocess.run([sys.executable, "-m", "pdeflow", "converge", *argv],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc
    assert proc.stderr.startswith("pdeflow: error:") and proc.stderr.count("\n") == 1


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_ends_the_run_with_one_line_and_no_files(sig, tmp_path):
    """A real signal to a running ``pdeflow run`` (storage and a movie-less frame
    tracker attached): one line, exit 130, and no file at all, hidden or not."""
    out = tmp_path / "out"
    out.mkdir()
    cmd = [sys.executable, "-m", "pdeflow", "run", str(CASE_51), "--set", "grid.dx=0.0005",
           "--set", "case.t_end=30", "--store", str(out / "run.h5"), "--summary",
           str(out / "s.json"), "--no-progress"]
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        deadline = time.time() + 120
        while not list(out.iterdir()) and time.time() < deadline:  # the store is open
            time.sleep(0.2)
        assert list(out.iterdir()), "the run did not start"
        time.sleep(1.0)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert lines[-1].startswith("pdeflow: interrupted at t = "), err
    assert lines[-1].endswith("; nothing written")
    assert "Traceback" not in err
    assert list(out.iterdir()) == []
