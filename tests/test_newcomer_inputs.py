"""What a newcomer met (issue 38): bad input is one line naming the problem before any
work; set-ups that are silently inconsistent are said or refused; output that misled
says what it means."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pdeflow.cases import CaseError, load_case
from pdeflow.checks import slope_warning
from pdeflow.cli import main

ROOT = Path(__file__).parents[1]
CASES = ROOT / "cases"
RITTER = CASES / "ritter_dam_break.toml"
CASE_51 = CASES / "paper_5_1_dam_break.toml"
BED = CASES / "erodible_bed.toml"


def _one_line_error(capsys, *words: str, prefix: str = "pdeflow: error:") -> str:
    err = capsys.readouterr().err
    assert err.startswith(prefix) and err.count("\n") == 1, err
    for w in words:
        assert w in err, (w, err)
    return err


# --- one-line errors before any work -------------------------------------------------------

def test_case_and_study_files_that_are_not_utf8_are_one_line(tmp_path, capsys):
    bad = tmp_path / "latin1.toml"
    bad.write_bytes('[case]\nname = "caf\xe9"\n'.encode("latin-1"))
    assert main(["run", str(bad)]) == 2
    _one_line_error(capsys, str(bad), "not UTF-8", "0xe9", "line 2")
    assert main(["study", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "not UTF-8" in err and err.count("\n") == 1, err


def test_a_directory_is_named_as_one_not_as_missing(tmp_path, capsys):
    assert main(["run", str(CASES)]) == 2
    err = _one_line_error(capsys, str(CASES), "is a directory")
    assert "does not exist" not in err
    assert main(["plot", str(tmp_path)]) == 2
    _one_line_error(capsys, "is a directory")


@pytest.mark.parametrize("models, words", [
    ("[]", ["case.models must name at least one model", "two_layer"]),
    ("['single_layer', 'single_layer']", ["names a model twice"]),
])
def test_case_models_empty_or_repeated(models, words, capsys):
    assert main(["run", str(RITTER), "--set", f"case.models={models}"]) == 2
    _one_line_error(capsys, *words)


@pytest.mark.parametrize("grid", ["0", "-0.5", "50.0"])
def test_compare_refuses_grids_without_cells(grid, capsys, tmp_path):
    argv = ["compare", str(RITTER), f"--grids={grid}", "--out-dir", str(tmp_path / "o")]
    assert main(argv) == 2
    _one_line_error(capsys, "--grids", f"got {grid}", prefix="pdeflow compare: error:")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("solver", ["milstein", "explicit_mpi", "implicit",
                                    "crank-nicolson"])
def test_solvers_that_cannot_run_a_case_are_refused_with_the_reason(solver, capsys):
    assert main(["run", str(RITTER), "--set", f"numerics.solver={solver}"]) == 2
    err = _one_line_error(capsys, "numerics.solver must be one of", "'runge-kutta'",
                          f"got {solver!r}", "cannot run a case")
    allowed = err.split("must be one of", 1)[1].split("]", 1)[0]
    assert solver not in allowed


def test_variant_names_refuse_the_same_solvers():
    from pdeflow.variant import Variant, VariantError

    with pytest.raises(VariantError, match="cannot run a case") as err:
        Variant.parse("mol-implicit")
    assert str(err.value).count("'mol-euler'") == 1  # each name once


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
def test_a_kernel_file_system_is_named_as_such(capsys):
    assert main(["run", str(RITTER), "--summary", "/proc/x.json"]) == 2
    err = _one_line_error(capsys, "--summary /proc/x.json", "takes no new files")
    assert "No such file" not in err


@pytest.mark.parametrize("t", ["nan", "inf"])
def test_plot_time_must_be_finite(t, tmp_path, capsys):
    # checked before the stored run is opened: the file need not exist
    assert main(["plot", str(tmp_path / "run.h5"), "--time", t]) == 2
    _one_line_error(capsys, "--time must be a finite time", t)


# --- set-ups that were silently inconsistent ----------------------------------------------

SMALL_COLLAPSE = ["--set", "grid.dx=0.02", "--set", "grid.length=2", "--set",
                  "case.t_end=0.5"]


def test_run_of_a_sweep_file_says_it_runs_one_column(tmp_path, capsys):
    sweep = CASES / "collapse_sweep.toml"
    out = tmp_path / "s.json"
    assert main(["run", str(sweep), *SMALL_COLLAPSE, "--summary", str(out)]) == 0
    err = capsys.readouterr().err
    assert "is a sweep file" in err and f"pdeflow sweep {sweep}" in err, err
    assert out.is_file()
    assert main(["run", str(sweep), *SMALL_COLLAPSE, "-q", "--summary", str(out)]) == 0
    assert "note" not in capsys.readouterr().err  # -q prints nothing


def test_models_on_different_slopes_are_warned_about(tmp_path, capsys):
    argv = ["run", str(BED), "--set", "two_layer.theta_deg=22", "--set",
            "case.t_end=0.05", "--summary", str(tmp_path / "s.json")]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "different slopes" in err and "two_layer.theta_deg = 22" in err, err
    assert "single_layer.theta_deg = 20" in err and "--set single_layer.theta_deg=22" in err
    assert err.count("different slopes") == 1  # once, not once per model
    # the command of docs/erodible_bed.md sets both
    page = (ROOT / "docs" / "erodible_bed.md").read_text()
    command = next(line for line in page.splitlines() if "theta_deg=22" in line)
    sets = re.findall(r"--set (\S+)", command)
    assert slope_warning(load_case(BED, sets)) is None
    assert slope_warning(load_case(BED)) is None


def test_a_slope_on_an_axisymmetric_grid_is_refused():
    with pytest.raises(CaseError, match=r"two_layer.theta_deg must be 0 on an "
                                        r"axisymmetric grid.*got 10") as err:
        load_case(CASES / "axisymmetric_collapse.toml", ["two_layer.theta_deg=10"])
    assert "\n" not in str(err.value)


def test_a_short_check_drops_the_later_snapshots_with_a_note(tmp_path, capsys):
    case = load_case(CASE_51, ["case.t_end=0.1"])
    assert case.snapshot_times == [0.1] and case.dropped_snapshot_times == [0.25, 0.4, 0.7]
    out = tmp_path / "s.json"
    assert main(["run", str(CASE_51), "--set", "case.t_end=0.1", "--summary",
                 str(out)]) == 0
    err = capsys.readouterr().err
    assert "output.snapshot_times 0.25, 0.4, 0.7 s lie past case.t_end = 0.1 s" in err
    assert json.loads(out.read_text())["models"]["two_layer"]["t_final"] == \
        pytest.approx(0.1, rel=1e-12)  # the run ends at t_end (a step is cut to it)


# --- output that misled --------------------------------------------------------------------

def _row(table: str, label: str) -> list[str]:
    line = next(ln for ln in table.splitlines() if ln.startswith(label + " "))
    return re.split(r"\s{2,}", line[18:].strip())


def test_outflow_is_its_own_row_not_a_mass_error(tmp_path, capsys):
    out = tmp_path / "s.json"
    assert main(["run", str(CASE_51), "--set", "two_layer.theta_deg=35", "--set",
                 "single_layer.theta_deg=35", "--set", "grid.dx=0.1", "--summary",
                 str(out)]) == 0
    table = capsys.readouterr().out
    models = json.loads(out.read_text())["models"]
    assert _row(table, "mass error") == ["-", "-"]
    shown = [float(c.rstrip(" %")) for c in _row(table, "mass outflow")]
    for value, m in zip(shown, ("two_layer", "single_layer"), strict=True):
        lost = -100 * models[m]["mass_change"]
        assert lost > 1  # material left through the open end
        # printed to 4 significant digits
        assert value == pytest.approx(lost, rel=1e-3)
    # a run that keeps its mass has the mass error and no outflow row
    assert main(["run", str(CASE_51), "--set", "grid.dx=0.1", "--set", "case.t_end=0.1",
                 "--summary", str(out)]) == 0
    table = capsys.readouterr().out
    assert "mass outflow" not in table and _row(table, "mass error") != ["-", "-"]


def test_compare_says_a_cfl_cap_once_per_variant(tmp_path, capsys):
    argv = ["compare", str(RITTER), "--grids", "10", "20", "40", "--variants",
            "hll/muscl/mc", "--repeats", "1", "--out-dir", str(tmp_path)]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.count("hll/muscl/mc at CFL 0.5: the case's 0.9 is above") == 1, err


class _FakeClock:
    """``time`` for pdeflow.solvers.fv_split (and pdeflow.simulate): a clock that only
    an observer advances."""

    now = 0.0

    @classmethod
    def perf_counter(cls) -> float:
        return cls.now


def test_wall_time_is_the_run_alone_without_its_observers(monkeypatch):
    """A tracker that takes 100 s per frame (a movie, a live plot) adds nothing to the
    run's wall time: on a clock that only the tracker advances, the run took 0 s (the
    solver times its own stepping, between the trackers' calls)."""
    from pde.trackers.base import TrackerBase

    from pdeflow import simulate
    from pdeflow.solvers import fv_split

    class SlowFrames(TrackerBase):
        def handle(self, field, t):
            _FakeClock.now += 100.0

        def finalize(self, info=None):
            super().finalize(info)  # py-pde's finalize: counted once with it
            _FakeClock.now += 100.0

    monkeypatch.setattr(simulate, "time", _FakeClock)
    monkeypatch.setattr(fv_split, "time", _FakeClock)
    case = load_case(RITTER, ["grid.cells=20", "case.t_end=0.1"])
    slow = SlowFrames(interrupts=0.01)
    res = simulate.run_model(case, "single_layer", tracker=[slow])
    assert _FakeClock.now >= 1000.0  # the tracker drew its frames
    assert res.summary["wall_time_s"] == 0.0  # exact: the fake clock never moved else
    assert res.info["solver"]["wall_time"] == 0.0


def test_progress_bar_rate_is_simulated_time_per_wall_second(capsys):
    from pdeflow.simulate import run_model

    case = load_case(RITTER, ["grid.cells=20", "case.t_end=0.1"])
    from pdeflow.trackers import ProgressBar

    run_model(case, "single_layer", tracker=[ProgressBar(0.01, label="ritter")])
    lines = capsys.readouterr().err.replace("\r", "\n").strip().splitlines()
    assert lines and all("it/s" not in ln and "s/it" not in ln for ln in lines), lines
    assert "/0.1 s [" in lines[-1] and " s simulated/s" in lines[-1], lines[-1]


def test_sweep_says_where_it_wrote(tmp_path, capsys):
    out, fig = tmp_path / "s.json", tmp_path / "r.png"
    assert main(["sweep", str(CASES / "collapse_sweep.toml"), *SMALL_COLLAPSE, "--set",
                 "sweep.aspect_ratios=[2, 3]", "--summary", str(out), "--plot",
                 str(fig)]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[-2:] == [f"wrote {out}", f"wrote {fig}"]
    assert out.is_file() and fig.is_file()


def test_a_whole_output_block_fails_on_a_printed_line_it_leaves_out():
    """``<!-- test: whole -->``: the user guide's Euler warnings are all the command
    prints (an excerpt had shown 3 of its 5 warnings)."""
    from tests.doc_commands import blocks, compare_output

    printed = "warning: a 1 m\nwarning: b 2 m\nwarning: c 3 m\n"
    excerpt = "warning: a 1 m\nwarning: c 3 m\n"
    assert compare_output(excerpt, printed, []) == []
    assert compare_output(excerpt, printed, [], whole=True) == [
        "printed but not documented: warning: b 2 m"]
    assert compare_output(printed, printed, [], whole=True) == []
    euler = [b for b in blocks(ROOT / "docs" / "user_guide.md")
             if any("numerics.solver=euler" in c for c in b.get("output"))]
    assert len(euler) == 1 and euler[0].has("whole")
    assert euler[0].text.count("pdeflow: warning:") == 5
