"""Warnings about runs and results that would mislead (issue 14, part C): material at the
end of the domain, py-pde's method-of-lines solvers, runs that end moving, mass changes,
and grids that take long."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pdeflow.cases import load_case
from pdeflow.checks import (
    LONG_RUN_CELL_UPDATES,
    RunWarning,
    cost_warning,
    result_warnings,
    run_cost,
)
from pdeflow.cli import build_parser, main
from pdeflow.simulate import run_model

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
QUIET = ["output.snapshot_times=[]"]


def _warnings(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("pdeflow: warning:")]


def test_front_at_the_open_end_is_a_lower_bound(tmp_path, capsys):
    """The single layer of 5.1 runs out to 5.9 m: on a 4 m domain it leaves it."""
    out = tmp_path / "s.json"
    argv = ["run", str(CASE_51), "--set", "grid.length=4", "--summary", str(out)]
    assert main(argv) == 0
    cap = capsys.readouterr()
    s = json.loads(out.read_text())["models"]
    one, two = s["single_layer"], s["two_layer"]
    assert one["runout_lower_bound"] and one["domain_ends"]["sides"] == ["right"]
    assert 0 < one["domain_ends"]["outflow"] < 0.1  # the mass that left the domain
    assert not two["runout_lower_bound"] and two["domain_ends"]["sides"] == []
    (warning,) = _warnings(cap.err)
    assert "single_layer: material reached the open right end (x = 4 m)" in warning
    assert "lower bounds" in warning and "grid.length" in warning
    runout = next(line for line in cap.out.splitlines() if line.startswith("run-out"))
    assert runout.split()[-3:] == [">=", "3", "m"] and "2.5 m" in runout


def test_readme_converged_command_has_room_for_the_single_layer():
    readme = (ROOT / "README.md").read_text()
    block = readme.split("--set grid.dx=0.00625", 1)[0].rsplit("```bash", 1)[1]
    assert "--set grid.length=12" in block  # the true front is at 7.49 m


def test_reservoir_cut_by_an_open_end_is_not_a_warning(recwarn):
    """Dam breaks with a reservoir through the open end (Mangeney: mass flows in there)
    warn about nothing."""
    case = load_case(ROOT / "cases" / "mangeney_dam_break_slope.toml", QUIET)
    s = run_model(case, "single_layer").summary
    assert s["domain_ends"]["open_through_material"] == ["left"]
    assert abs(s["mass_change"]) > 1e-3 and s["warnings"] == []
    assert not [w for w in recwarn if issubclass(w.category, RunWarning)]


def test_method_of_lines_solver_is_warned_about(capsys, tmp_path):
    argv = ["run", str(CASE_51), "--set", "numerics.solver=euler", "--set",
            "case.t_end=0.05", "--set", "grid.dx=0.1", "--set", "numerics.dt=0.001",
            "--set", "output.snapshot_times=[]", "--summary", str(tmp_path / "s.json")]
    assert main(argv) == 0
    warnings = _warnings(capsys.readouterr().err)
    solver = [w for w in warnings if "method-of-lines" in w and "'euler'" in w]
    assert len(solver) == 1  # once, not once per model
    assert "set-valued Coulomb friction" in solver[0] and "never stops at rest" in solver[0]
    moving = [w for w in warnings if "still moving" in w]
    assert len(moving) == 2 and all("never stop at rest" in w for w in moving)


def test_run_ending_in_motion_is_warned_about_only_where_it_could_stop():
    with pytest.warns(RunWarning, match="two_layer: still moving at the end of the run"):
        run_model(load_case(CASE_51, [*QUIET, "case.t_end=0.1", "grid.dx=0.1"]),
                  "two_layer")
    # a frictionless dam break (an exact-solution case) runs to t_end by design
    ritter = load_case(ROOT / "cases" / "ritter_dam_break.toml", QUIET)
    assert not any("still moving" in w for w in
                   run_model(ritter, "single_layer").summary["warnings"])


def test_mass_change_is_reported():
    case = load_case(CASE_51, QUIET)
    summary = {"at_rest": True, "mass_change": 0.012, "t_final": 1.0,
               "domain_ends": {"sides": [], "outflow": 0.0}}
    (w,) = result_warnings(case, "two_layer", summary)
    assert "two_layer: the mass changed by +1.2 %" in w
    summary["mass_change"] = 1e-15  # fv-split: round-off
    assert result_warnings(case, "two_layer", summary) == []


def test_long_run_is_estimated_warned_and_shows_progress(monkeypatch):
    case = load_case(CASE_51, ["grid.dx=0.00001"])  # 700,000 cells
    cost = run_cost(case)
    assert cost.cells == 700_000 and cost.long
    assert cost.cell_updates > LONG_RUN_CELL_UPDATES
    # memory: the solver's arrays and four snapshots, about 0.3 GB
    assert 1e8 < cost.memory_bytes < 1e9
    text = cost_warning(case, "two_layer")
    assert "700,000 cells" in text and "cell updates" in text and "MB of memory" in text
    assert cost_warning(load_case(CASE_51), "two_layer") is None  # 140 cells: silent
    # the progress bar is on by default for a long run, even without a terminal
    from pdeflow.cli import _run_trackers
    from pdeflow.trackers import ProgressBar

    monkeypatch.setattr("sys.stdout.isatty", lambda: False)
    args = build_parser().parse_args(["run", str(CASE_51)])
    assert any(isinstance(t, ProgressBar) for t in _run_trackers(args, case, "two_layer",
                                                                 True))
    assert not _run_trackers(args, load_case(CASE_51), "two_layer", True)


def test_a_domain_left_by_all_the_material_is_warned_about_without_a_front():
    """35 deg, t_end = 20 s: the single layer slides out of the 7 m domain completely,
    the summary has no front (it raised a TypeError in the warning)."""
    from pdeflow.checks import result_warnings

    case = load_case(Path(__file__).parents[1] / "cases" / "paper_5_1_dam_break.toml")
    summary = {"domain_ends": {"sides": ["right"], "outflow": 1.0,
                               "runout_lower_bound": True, "open_through_material": []},
               "front_position": None, "mass_change": -1.0, "at_rest": True,
               "t_final": 20.0}
    (line,) = result_warnings(case, "single_layer", summary)
    assert "100 % of the mass left the domain" in line
    assert "the front (none left) and the run-out are lower bounds" in line
