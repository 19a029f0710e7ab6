"""The erosion diagnostics (pdeflow.erosion): exact on constructed beds, and in
a run over an erodible bed consistent with mass conservation; stored in the summary of
bed cases only; the bed figure is written."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from pdeflow import erosion as E
from pdeflow.cases import CaseError, load_case
from pdeflow.simulate import run_model
from pdeflow.summary_table import print_summary

ROOT = Path(__file__).parents[1]
CASE = ROOT / "cases" / "erodible_bed.toml"
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
DX = 0.005
X = (np.arange(400) + 0.5) * DX  # 2 m of 5 mm cells
REGION = X >= 0.2
BED0 = np.where(REGION, 0.005, 0.0)
ERODING = ["two_layer.c=1.0", "two_layer.k=0.8", "grid.dx=0.01", "case.t_end=1.5",
           "output.snapshot_times=[]"]
"""a collisional set that erodes the bed (the law set's k and c, docs/erodible_bed.md),
cut at 1.5 s while a thin film still creeps (the series need no final deposit)"""
pytestmark = pytest.mark.filterwarnings("ignore:.*still moving at the end")


def _bed_with_hole_and_mound() -> np.ndarray:
    h2 = BED0.copy()
    h2[(X > 0.3) & (X < 0.4)] = 0.003  # a hole 2 mm deep over 0.1 m (20 cells)
    h2[(X > 0.5) & (X < 0.6)] = 0.006  # a mound 1 mm high over 0.1 m
    return h2


def test_constructed_hole_and_mound_give_exact_volumes_depth_and_place():
    h2 = _bed_with_hole_and_mound()
    assert E.eroded_volume(h2, BED0, REGION, DX) == pytest.approx(20 * DX * 0.002,
                                                                  rel=1e-12)
    assert E.deposited_volume(h2, BED0, REGION, DX) == pytest.approx(20 * DX * 0.001,
                                                                     rel=1e-12)
    depth, where = E.deepest_erosion(X, h2, BED0, REGION)
    assert depth == pytest.approx(0.002, rel=1e-12)
    assert where == pytest.approx(0.3025)  # the first cell of the hole
    assert E.erosion_front(X, h2, BED0, REGION) == pytest.approx(0.3975)
    # a bed nobody touched: nothing eroded, no place, no front
    assert E.eroded_volume(BED0, BED0, REGION, DX) == 0.0
    assert E.deepest_erosion(X, BED0 - 1e-18, BED0, REGION) == (0.0, None)
    assert E.erosion_front(X, BED0, BED0, REGION) is None


def test_region_excludes_the_column_and_axisymmetric_cells_weigh_by_volume():
    h2 = BED0.copy()
    h2[:40] = 0.1  # the column's lower layer behind the gate: no deposit on the bed
    assert E.deposited_volume(h2, BED0, REGION, DX) == 0.0
    volumes = 2 * np.pi * X * DX
    hole = _bed_with_hole_and_mound()
    expected = np.sum(np.where((X > 0.3) & (X < 0.4), 0.002, 0.0) * volumes)
    assert E.eroded_volume(hole, BED0, REGION, volumes) == pytest.approx(expected)


def test_final_deposit_subtracts_the_original_bed():
    d = np.zeros((4, X.size))
    d[2] = _bed_with_hole_and_mound()
    d[0, (X > 0.5) & (X < 0.6)] = 0.01
    dep = E.final_deposit(d, BED0)
    assert np.allclose(dep[(X > 0.3) & (X < 0.4)], -0.002)
    assert np.allclose(dep[(X > 0.5) & (X < 0.6)], 0.011)
    assert np.allclose(dep[(X > 0.7)], 0.0)
    assert np.array_equal(E.final_deposit(d, None), d[0] + d[2])


def test_front_velocity_and_duration_of_a_known_front():
    t = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
    front = np.array([0.2, 0.3, 0.45, 0.5, 0.5, 0.5])
    assert E.flow_duration(t, front) == pytest.approx(0.3)
    v = E.front_velocity(t, front)
    assert v[1] == pytest.approx(1.25) and v[-1] == 0.0
    assert E.flow_duration(t, np.full(6, 0.2)) == 0.0
    assert E.flow_duration(t, np.full(6, np.nan)) is None


@pytest.fixture(scope="module")
def eroding_run():
    case = load_case(CASE, ERODING)
    return case, run_model(case, "two_layer")


def test_run_series_conserve_mass_and_book_monotonically(eroding_run):
    case, res = eroding_run
    s = res.series
    t, frames = res.frames
    assert t[0] == 0.0 and t[-1] == pytest.approx(res.t_final)
    assert np.all(np.diff(t) > 0)
    r = res.pde.parameters.density_ratio
    v1 = np.array([f[0].sum() * case.dx for f in frames])
    v2 = np.array([f[2].sum() * case.dx for f in frames])
    # mass (per rho2) of every frame is the initial one: nothing leaves this domain
    assert np.allclose(r * v1 + v2, r * v1[0] + v2[0], rtol=0, atol=1e-12)
    # the net bed-relative change in the bed region plus the column's lower layer is
    # the lower layer's change, -r times the upper layer's
    region = case.bed_region(res.x - case.x_start)
    col = np.array([f[2][~region].sum() * case.dx for f in frames])
    assert np.allclose(s.deposited - s.eroded + col - col[0], -r * (v1 - v1[0]),
                       rtol=0, atol=1e-12)
    # booked exchange: cumulative, and at the end exactly the upper layer's change
    assert np.all(np.diff(s.booked_eroded) >= 0) and np.all(np.diff(s.booked_deposited) >= 0)
    assert s.booked_eroded[-1] - s.booked_deposited[-1] == pytest.approx(
        v1[-1] - v1[0], abs=1e-12)
    assert s.booked_eroded[-1] == pytest.approx(res.summary["eroded_volume"], rel=1e-12)
    # this set erodes: the net erosion is there and within the booked gross one
    assert 0 < np.max(s.eroded) <= s.booked_eroded[-1] + 1e-15
    assert res.summary["bed_max_erosion_depth"] == pytest.approx(np.max(s.erosion_depth))
    assert 0 < res.summary["bed_max_erosion_depth"] <= 0.005 + 1e-15


def test_series_tracker_does_not_change_the_run(eroding_run):
    case, res = eroding_run
    quiet = run_model(load_case(CASE, [*ERODING, "output.erosion_series='off'"]),
                      "two_layer")
    assert quiet.series is None and "flow_duration" not in quiet.summary
    assert np.array_equal(quiet.state.data, res.state.data)
    for key in ("t_final", "steps", "stop_time", "front_position", "eroded_volume"):
        assert quiet.summary[key] == res.summary[key], key


def test_summary_keys_for_bed_cases_only_and_the_printed_rows(eroding_run):
    case, res = eroding_run
    single = run_model(case, "single_layer")
    for key in E.SERIES_KEYS:
        assert res.summary[key] is not None and single.summary[key] is not None
    for key in E.BED_KEYS:
        assert key in res.summary and single.summary[key] is None  # the rigid bed
    assert res.summary["bed_eroded_volume_max"] > 0
    final = res.final_arrays()
    assert np.allclose(final["deposit_above_bed"],
                       final["h1"] + final["h2"] - final["bed0"], atol=0)
    assert "deposit_above_bed" not in run_model(
        load_case(CASE_51, ["grid.dx=0.1", "output.snapshot_times=[]"]),
        "two_layer").final_arrays()
    plain = run_model(load_case(CASE_51, ["grid.dx=0.1", "output.snapshot_times=[]"]),
                      "two_layer")
    assert plain.series is None
    assert not set(plain.summary) & {*E.SERIES_KEYS, *E.BED_KEYS}
    out = io.StringIO()
    print_summary({"case": "x", "models": {"two_layer": res.summary,
                                           "single_layer": single.summary}}, out)
    assert "bed eroded" in out.getvalue() and "flow duration" in out.getvalue()
    out = io.StringIO()
    print_summary({"case": "x", "models": {"two_layer": plain.summary}}, out)
    assert "bed eroded" not in out.getvalue() and "flow duration" not in out.getvalue()


def test_bed_figures_are_written(eroding_run, tmp_path):
    from pdeflow.case_figures import case_figures

    case, res = eroding_run
    paths = case_figures({"two_layer": res}, tmp_path, parallel=False)
    assert tmp_path / "bed_two_layer.png" in paths
    assert (tmp_path / "bed_two_layer.png").stat().st_size > 10_000


def test_bed_figure_labels_views_by_time_and_keeps_its_legend_off_the_profiles(eroding_run):
    """The side views' y ticks are their times, not offset depths; the legend sits above
    the panel (its bottom at or above the panel's top, in axes coordinates)."""
    from pdeflow.bed_figures import bed_figure

    case, res = eroding_run
    xs = res.x - case.x_start
    t, frames = res.frames
    fig = bed_figure(res.x, t, frames, res.model, case.bed(res.model, xs), res.series,
                     case.name, res.summary["flow_duration"], case.bed_region(xs))
    ax = fig.axes[0]
    fig.canvas.draw()
    assert all(tick.get_text().startswith("t = ") for tick in ax.get_yticklabels())
    box = ax.get_legend().get_window_extent().transformed(ax.transAxes.inverted())
    assert box.y0 >= 1.0 - 1e-9
    assert "_" not in fig._suptitle.get_text() and "two layers" in fig._suptitle.get_text()


@pytest.mark.parametrize("override, message", [
    ("output.erosion_series='maybe'", "output.erosion_series must be one of"),
    ("output.series_every=0", "output.series_every"),
    ("output.series_every=99", "output.series_every")])
def test_bad_series_options_are_one_line_errors(override, message):
    with pytest.raises(CaseError, match=message) as err:
        load_case(CASE, [override])
    assert "\n" not in str(err.value)


def test_moving_bed_volume_counts_moving_bed_cells_only():
    h2 = BED0.copy()
    q = np.zeros_like(h2)
    q[(X > 0.3) & (X < 0.4)] = 1e-3  # 20 cells of the bed pushed along
    q[:40] = 1e-3  # the column's lower layer: not the bed
    assert E.moving_bed_volume(h2, q, REGION, DX) == pytest.approx(20 * DX * 0.005)


def test_bed_stresses_follow_the_closure_and_the_bed_holds_below_phi_b():
    """The erosion criterion of bed_stresses is the sign of the kernel's closure rate,
    and a bed below its friction angle is never driven beyond its basal resistance
    without pressure gradients (phi_int < phi_B)."""
    from pdeflow.analysis.bed_stresses import bed_stresses
    from pdeflow.models import TwoLayerParameters
    from pdeflow.models.two_layer.exchange import closure_rate

    p = TwoLayerParameters(theta_deg=25.0, k=0.8, c=1.0, du_reg=0.05)
    rng = np.random.default_rng(1)
    h1, u1 = rng.uniform(0.001, 0.1, 200), rng.uniform(0, 2, 200)
    h2, u2 = np.full(200, 0.005), np.zeros(200)
    s = bed_stresses(h1, u1, h2, u2, DX, p)
    g = p.g * np.cos(np.radians(p.theta_deg))
    tan_int = np.tan(np.radians(p.phi_int_deg))
    rate = np.array([closure_rate(a, b, p.density_ratio, g, tan_int, p.k, p.c, p.du_reg)
                     for a, b in zip(h1, u1, strict=True)])
    assert np.allclose(s["M"], rate, rtol=1e-12, atol=0)
    assert np.array_equal(s["erodes"], rate > 0)
    assert np.all(s["drive_no_pressure"] < s["t_b_max"])


@pytest.mark.parametrize("geometry,volume", [("planar", "m2"), ("axisymmetric", "m3")])
def test_the_table_gives_volumes_in_the_grids_unit(geometry, volume):
    """The bed's volumes are per unit width on a planar grid (m^2) and m^3 on an
    axisymmetric one (cell volumes pi (r+^2 - r-^2)); the table printed m2 for both
    (issue 38). Its units are :func:`pdeflow.simulate.summary_unit`'s, written without
    '^'."""
    summary = {"geometry": geometry, "bed_eroded_volume": 0.25, "bed_max_erosion_x": 0.5,
               "max_fextra_over_rho1": 2.0, "steps": 7}
    out = io.StringIO()
    print_summary({"case": "x", "models": {"two_layer": summary}}, out)
    rows = {line[:18].strip(): line[18:].strip() for line in out.getvalue().splitlines()}
    assert rows["bed eroded"] == f"0.25 {volume}"
    assert rows["at x"] == "0.5 m" and rows["max F_extra/rho1"] == "2 m2/s2"
    assert rows["steps"] == "7"
