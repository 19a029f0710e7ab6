"""Usage errors of the command line: one line naming the problem, exit code 2, no
traceback, nothing written (issue 14, part C); and its help texts."""

from __future__ import annotations

from pathlib import Path

import pytest

from pdeflow.cases import CaseError, load_case
from pdeflow.cli import build_parser, main

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
RITTER = ROOT / "cases" / "ritter_dam_break.toml"


def _one_line_error(capsys, *words: str) -> str:
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: error:") and err.count("\n") == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in err, (w, err)
    return err


@pytest.mark.parametrize("argv, words", [
    # a case without [sweep]: which section is missing and what it looks like
    (["sweep", str(CASE_51)], ["[sweep]", "aspect_ratios"]),
    (["sweep", str(CASE_51), "--set", "sweep.aspect_ratios=[2, -1]"],
     ["sweep.aspect_ratios", "> 0"]),
    (["converge", str(CASE_51), "--levels", "0"], ["--levels", ">= 2", "got 0"]),
    (["converge"], ["case file"]),
    # a column longer than the domain
    (["run", str(CASE_51), "--set", "initial.L0=5", "--set", "grid.length=1"],
     ["initial.L0 = 5 m", "grid.length = 1 m", "(0, 1] m"]),
    # a grid no machine holds: refused before any array is made
    (["run", str(CASE_51), "--set", "grid.cells=100000000000"],
     ["100,000,000,000 cells", "memory", "grid.dx >="]),
    (["run", str(RITTER), "--movie", "x.webm"], ["x.webm", ".mp4", ".avi", ".gif"]),
])
def test_usage_errors_exit_2_with_one_line(argv, words, capsys):
    assert main(argv) == 2
    _one_line_error(capsys, *words)


@pytest.mark.parametrize("option", ["--store", "--summary", "--final", "--plot", "--movie",
                                    "--outdir"])
def test_outputs_into_missing_directories_are_refused(option, tmp_path, capsys,
                                                      monkeypatch):
    monkeypatch.chdir(tmp_path)
    target = tmp_path / "missing" / "dir" / "out.h5"
    assert main(["run", str(RITTER), "--set", "grid.cells=20", option, str(target)]) == 2
    _one_line_error(capsys, option, str(target.parent), "does not exist")
    assert list(tmp_path.iterdir()) == []  # no directory was created, nothing written


def test_plot_export_sweep_converge_refuse_missing_directories(tmp_path, capsys):
    missing = tmp_path / "missing" / "x"
    for argv in (["plot", str(tmp_path / "a.h5"), "--out", f"{missing}.png"],
                 ["export", str(tmp_path / "a.h5"), f"{missing}.csv"],
                 ["sweep", str(ROOT / "cases" / "collapse_sweep.toml"), "--summary",
                  f"{missing}.json"],
                 ["converge", str(RITTER), "--summary", f"{missing}.json"]):
        assert main(argv) == 2, argv
        _one_line_error(capsys, "does not exist")
    assert list(tmp_path.iterdir()) == []


def test_column_longer_than_the_domain_is_rejected_in_python_too():
    with pytest.raises(CaseError, match="initial.L0 = 1.5 m is longer than the domain"):
        load_case(CASE_51, ["grid.length=1.0", "initial.L0=1.5"])
    load_case(CASE_51, ["grid.length=1.0", "initial.L0=1.0"])  # filling it is allowed


def test_compare_help_says_work_precision_and_its_own_name(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["compare", "--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: pdeflow compare")
    assert "python -m pdeflow.analysis.workprecision" not in out
    assert "Work-precision study" in out and "pdeflow plot" in out
    with pytest.raises(SystemExit):
        main(["--help"])
    top = capsys.readouterr().out
    line = next(t for t in top.splitlines() if t.strip().startswith("compare"))
    assert "work-precision" in line


def test_movie_help_lists_exactly_the_formats_that_are_written(capsys):
    from pdeflow.trackers.live import FFMPEG_SUFFIXES, check_movie_path

    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for suffix in (*FFMPEG_SUFFIXES, ".gif"):
        assert suffix in text, suffix
    assert ".webm" not in text
    assert check_movie_path("x.gif") == "pillow"


def test_every_cli_option_has_help():
    parser = build_parser()
    subparsers = next(a for a in parser._actions if a.choices and "run" in a.choices)
    for name in ("run", "plot", "export"):
        sub = subparsers.choices[name]
        assert sub.description, name
        for action in sub._actions:
            assert action.help and len(action.help) > 10, (name, action.dest)
