"""What the user reads: the converge table and the figures of ``pdeflow plot`` and
``pdeflow sweep`` (issue 14, part C)."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest

from pdeflow.analysis.convergence import header, richardson, table
from pdeflow.cli import main

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"

h5py = pytest.importorskip("h5py")


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
    # 9 columns: the two run-outs (threshold and 99 % of the mass) side by side
    assert head.count("|") - 1 <= 9 and "--all" in out
    assert main([*argv, "--all"]) == 0
    assert "V1(0.1) [m^2]" in capsys.readouterr().out.splitlines()[0]


# --- pdeflow plot -------------------------------------------------------------------------
@pytest.fixture(scope="module")
def stored_51(tmp_path_factory):
    folder = tmp_path_factory.mktemp("runs")
    assert main(["run", str(CASE_51), "--store",
                 str(folder / "5_1.h5"), "--store-every", "0.1", "-q"]) == 0
    return folder / "5_1.h5", folder / "5_1.single_layer.h5"


def _figure(monkeypatch, argv):
    """Run ``pdeflow plot`` and return the RunFigure it drew."""
    import pdeflow.plotting as plotting

    made = []
    original = plotting.RunFigure.__init__

    def spy(self, *args, **kwargs):
        original(self, *args, **kwargs)
        made.append(self)

    monkeypatch.setattr(plotting.RunFigure, "__init__", spy)
    monkeypatch.setattr(plotting.RunFigure, "close", lambda self: None)
    assert main(argv) == 0
    return made[0]


def test_plot_of_final_deposits_looks_like_the_runs_figure(stored_51, tmp_path,
                                                           monkeypatch, capsys):
    a, b = stored_51
    fig = _figure(monkeypatch, ["plot", str(a), str(b), "--out", str(tmp_path / "f.png")])
    # both runs at rest: one panel of depths (no flat velocity and F_extra panels)
    assert len(fig.fig.axes) == 1 and fig.ax_u is None
    assert "final deposits" in fig.fig._suptitle.get_text()
    assert fig.fig._suptitle.get_text().startswith("paper 5.1 dam break")  # not a file name
    texts = [t.get_text() for t in fig.ax_h.get_legend().get_texts()]
    assert texts == ["lower layer $h_2$", "upper layer $h_1$", "single layer"]
    single = fig._lines[1]["surface"]
    assert matplotlib.colors.to_hex(single.get_color()) == "#000000"  # black, as in run's
    assert (tmp_path / "f.png").stat().st_size > 5000


def test_plot_in_motion_has_three_panels_and_names_files_only_when_needed(
        stored_51, tmp_path, monkeypatch):
    a, b = stored_51
    fig = _figure(monkeypatch, ["plot", str(a), str(b), "--time", "0.3", "--out",
                                str(tmp_path / "f.png"), "-q"])
    assert len(fig.fig.axes) == 3
    for ax in (fig.ax_h, fig.ax_u):
        for text in ax.get_legend().get_texts():
            assert ".h5" not in text.get_text()
    # two runs of the same model: their file names tell them apart
    fig = _figure(monkeypatch, ["plot", str(a), str(a), "--time", "0.3", "--out",
                                str(tmp_path / "g.png"), "-q"])
    texts = [t.get_text() for t in fig.ax_h.get_legend().get_texts()]
    assert all(t.startswith(str(a)) for t in texts)


def test_plot_says_which_frame_it_shows(stored_51, tmp_path, capsys):
    a, _ = stored_51
    assert main(["plot", str(a), "--time", "99", "--out", str(tmp_path / "f.png")]) == 0
    err = capsys.readouterr().err
    assert "no frame at t = 99 s" in err and "its last frame" in err
    assert main(["plot", str(a), "--time", "0.3", "--out", str(tmp_path / "f.png")]) == 0
    assert "no frame" not in capsys.readouterr().err


# --- pdeflow sweep ------------------------------------------------------------------------
def test_sweep_axis_is_labelled_at_2_4_8_16_30(tmp_path):
    from pdeflow.analysis.sweep import sweep_figure

    pts = [[a, 1.2 * a] for a in (2, 3, 4, 6, 8, 10, 14, 18, 24, 30)]
    summary = {"models": {"two_layer": {"points": pts, "prefactor": 1.2, "exponent": 1.0,
                                        "paper_prefactor": 1.61, "paper_exponent": 0.84}}}
    import matplotlib.pyplot as plt

    closed = []
    original = plt.close
    plt.close = lambda fig=None: closed.append(fig)
    try:
        sweep_figure(summary, tmp_path / "r.png")
    finally:
        plt.close = original
    ax = closed[0].axes[0]
    ticks = [t for t in ax.get_xticks() if 2 <= t <= 30]
    np.testing.assert_allclose(ticks, [2, 4, 8, 16, 30])
    assert all(t.get_text() == "" for t in ax.xaxis.get_minorticklabels())
    original(closed[0])


def test_richardson_only_in_the_asymptotic_range_and_says_why_not():
    """Issue 28: measured stop times 1.37, 1.10, 0.84 s (p = 0.05) gave an estimate
    far outside them; now only orders within ORDER_RANGE, consistent over the last two
    triples, are extrapolated, and the table says why not."""
    slow = richardson([1.369, 1.10, 0.84])
    assert slow["extrapolated"] is None and "outside" in slow["reason"]
    first = [1.0 + 0.5 * h for h in (0.8, 0.4, 0.2, 0.1)]
    assert richardson(first)["extrapolated"] == pytest.approx(1.0)
    assert richardson(first)["reason"] is None
    kinked = richardson([1.0, 1.9, 1.95, 1.975])  # orders 4.2 then 1
    assert kinked["extrapolated"] is None and "disagree" in kinked["reason"]
    assert richardson([1.0, 1.5, 1.3])["reason"] == "not monotone"
    assert richardson([1.0, 1.5])["reason"] == "fewer than 3 values"
    res = {"levels": [{"dx": 0.1, "stop_time": 1.369}, {"dx": 0.05, "stop_time": 1.10},
                      {"dx": 0.025, "stop_time": 0.84}],
           "analysis": {"stop_time": slow}}
    last = table(res).splitlines()[-1]
    assert last.startswith("| no Richardson because |") and "outside" in last
