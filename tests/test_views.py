"""What the user reads: the converge table and the figures of ``pdeflow plot`` and
``pdeflow sweep`` (issue 14, part C)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from pdeflow.analysis.convergence import header, richardson, table  # noqa: E402
from pdeflow.cli import main  # noqa: E402

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"


# --- converge -----------------------------------------------------------------------------
def test_no_relative_change_of_a_zero():
    assert richardson([0.5, 0.01, 0.0])["relative_change"] is None  # was 1e10
    assert richardson([0.0, 0.0, 0.0])["relative_change"] == 0.0
    assert richardson([1.0, 1.1, 1.2])["relative_change"] == pytest.approx(0.1 / 1.2)


def test_richardson_only_for_monotone_sequences_that_keep_their_sign():
    mono = richardson([1.0, 0.5, 0.25])  # first order towards 0 ... extrapolates to 0
    assert mono["order"] == pytest.approx(1.0) and mono["extrapolated"] == pytest.approx(0.0)
    assert richardson([1.0, 1.5, 1.75])["extrapolated"] == pytest.approx(2.0)
    zigzag = richardson([1.0, 1.5, 1.3])  # converging (p > 0) but not monotone
    assert zigzag["order"] > 0 and zigzag["extrapolated"] is None
    # the paper closure's upper stop time: monotone, p = 0.49, estimate -0.15 s
    stop = richardson([0.9539, 0.6346, 0.4074])
    assert stop["order"] > 0 and stop["extrapolated"] is None
    volume = richardson([0.008553, 0.001717, 0.0])  # V1(0.5): would be -0.000576 m^2
    assert volume["extrapolated"] is None
    assert richardson([-1.0, -0.5, -0.25])["extrapolated"] == pytest.approx(0.0)
    assert richardson([1.0, 1.25, 1.75])["extrapolated"] is None  # diverging, p < 0


def test_headers_carry_units():
    assert header("runout") == "runout [m]"
    assert header("upper_stop_time") == "upper_stop_time [s]"
    assert header("stop_time") == "stop_time [s]"
    assert header("V1(0.25)") == "V1(0.25) [m^2]"
    assert header("wall_time_s") == "wall_time [s]"
    assert header("max_fextra_over_rho1") == "max_fextra_over_rho1 [m^2/s^2]"
    assert header("cells") == "cells"
    res = {"levels": [{"dx": 0.1, "runout": 1.0}, {"dx": 0.05, "runout": 1.1}],
           "analysis": {"runout": richardson([1.0, 1.1])}}
    assert table(res).splitlines()[0] == "| dx [m] | runout [m] |"


def test_converge_prints_a_short_table_by_default(capsys):
    argv = ["converge", str(CASE_51), "--levels", "2", "--set", "grid.dx=0.1"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    head = out.splitlines()[0]
    assert head.startswith("| dx [m] | cells | stop_time [s] |") and "V1(" not in head
    assert head.count("|") - 1 <= 8 and "--all" in out
    assert main([*argv, "--all"]) == 0
    assert "V1(0.1) [m^2]" in capsys.readouterr().out.splitlines()[0]
