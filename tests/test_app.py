"""The teaching app without a browser: its options, and that every page shows what the
Python API gives for the same case and overrides (the browser tests,
tests/test_app_browser.py, check the same through Chromium)."""

from __future__ import annotations

import io
import socket
import threading
from html import escape
from pathlib import Path

import numpy as np
import pytest

pn = pytest.importorskip("panel")  # the app extra (part of the test extra)

from pdeflow.analysis.sweep import PUBLISHED_LAWS, published_law, run_sweep  # noqa: E402
from pdeflow.app.controls import KNOBS, command_line, find_case_dir  # noqa: E402
from pdeflow.app.dam_break import (  # noqa: E402
    FRAMES_PER_T_END,
    DamBreakPage,
    SharedRun,
    simulate,
)
from pdeflow.app.hyperbolicity import (  # noqa: E402
    G,
    HyperbolicityPage,
    band_edges,
    cell_state,
    format_eigenvalue,
)
from pdeflow.app.kernels import WARMUP, KernelWarmup  # noqa: E402
from pdeflow.app.runout import RunoutPage, format_r  # noqa: E402
from pdeflow.cases import load_case  # noqa: E402
from pdeflow.cli import main  # noqa: E402
from pdeflow.models.two_layer.hyperbolicity import (  # noqa: E402
    discriminant,
    eigenvalues,
    lower_bound_fl,
    upper_bound_fr,
)
from pdeflow.simulate import run_model  # noqa: E402
from pdeflow.summary_table import print_summary  # noqa: E402

from .helpers import cli_warnings, skip_or_fail_in_ci  # noqa: E402

ROOT = Path(__file__).parents[1]
CASES = ROOT / "cases"
CASE_51 = CASES / "paper_5_1_dam_break.toml"


@pytest.fixture(scope="module", autouse=True)
def kernels() -> None:
    assert WARMUP.wait(600), "the kernels did not load"
    assert WARMUP.error is None, WARMUP.error


# --- the command ------------------------------------------------------------------------
@pytest.mark.parametrize("argv, says", [
    (["--port", "70000"], "--port must lie in [0, 65535]"),
    (["--cases", "/nonexistent/cases"], "--cases /nonexistent/cases"),
])
def test_app_bad_options_are_one_line_errors(argv, says, capsys):
    assert main(["app", "--no-browser", *argv]) == 2
    err = capsys.readouterr().err
    assert says in err and err.count("\n") == 1, err


def test_app_refuses_a_port_in_use(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert main(["app", "--no-browser", "--port", str(port)]) == 2
    err = capsys.readouterr().err
    assert f"cannot serve on --host 127.0.0.1 --port {port}" in err
    assert err.count("\n") == 1


def test_case_dir_is_found_from_elsewhere(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no cases/ here: the repository's
    assert find_case_dir() == CASES


# --- page 1: dam break ------------------------------------------------------------------
def _api_table(case_file: Path, overrides: list[str]) -> list[str]:
    """``pdeflow run``'s table of the same case from the Python API, but the wall times."""
    case = load_case(case_file, overrides)
    out = io.StringIO()
    print_summary({"case": case.name,
                   "models": {m: run_model(case, m).summary for m in case.models}}, out)
    return [r for r in out.getvalue().splitlines() if not r.startswith("wall time")]


def test_dam_break_page_shows_the_api_numbers_for_its_sliders():
    page = DamBreakPage(CASES)
    shown = [r for r in page.run.table().splitlines() if not r.startswith("wall time")]
    assert shown == _api_table(CASE_51, [])
    sliders = page.controls.sliders
    sliders["phi_b_two"].value = 35.0
    sliders["H0"].value = 1.5
    page.controls.closure.value = "relaxed"  # watched: reruns
    overrides = page.controls.overrides()
    assert overrides == ["initial.H0=1.5", "two_layer.phi_b_deg=35",
                         "two_layer.exchange_closure='relaxed'"]
    table = [r for r in page.run.table().splitlines() if not r.startswith("wall time")]
    assert table == _api_table(CASE_51, overrides) != shown
    assert "--set initial.H0=1.5" in page.summary.text
    assert command_line(CASE_51, overrides).startswith("pdeflow run ")


def test_the_axisymmetric_geometry_is_a_choice_with_a_plan_view():
    """Picking 'axisymmetric' is the override grid.geometry='axisymmetric' (the table is
    the command line's), the profile's axis reads r, and a plan view shows the revolved
    deposit: the depth at distance d from the centre is the profile's at r = d."""
    from pdeflow.app.plan_view import plan_view

    page = DamBreakPage(CASES)
    assert page.controls.geometry.value == "planar" and not page.plan.visible
    page.controls.geometry.value = "axisymmetric"  # watched: reruns
    overrides = page.controls.overrides()
    assert overrides == ["grid.geometry='axisymmetric'"]
    table = [r for r in page.run.table().splitlines() if not r.startswith("wall time")]
    assert table == _api_table(CASE_51, overrides)
    assert "front radius" in page.run.table()
    assert page.fig_f.xaxis.axis_label == "r [m]" and page.plan.visible
    image = page.plan.source.data["image"][0]
    assert np.isfinite(image).any()
    r = np.linspace(0.05, 6.95, 70)
    depth = np.maximum(1.0 - 0.2 * r, 0.0)
    view = plan_view(r, depth, 7.0, pixels=141)  # pixels 0.1 m apart, (70, 70) the centre
    np.testing.assert_allclose(view[70, 70 + 10], np.interp(1.0, r, depth))
    np.testing.assert_allclose(view[70 + 30, 70 + 40], np.interp(5.0, r, depth) or np.nan)
    assert np.isnan(view[0, 0])  # beyond the domain (and dry beyond r = 5 m)
    page.controls.geometry.value = "planar"  # hidden again, kept for the next time
    assert not page.plan.visible
    page.controls.case_select.value = "ritter_dam_break.toml"  # open at x = -1 m
    assert page.controls.geometry.disabled


def test_dam_break_animation_ends_on_the_summarised_state():
    case = load_case(CASE_51)
    run = simulate(case, CASE_51, [])
    assert len(run.times) > 50 and np.all(np.diff(run.times) > 0)
    for m, res in run.results.items():
        assert np.array_equal(run.states[m][-1], res.state.data)  # the last frame
        np.testing.assert_allclose(run.states[m][0], case.make_state(m)[1].data)
    assert run.fextra.shape == (len(run.times), run.x.size)
    assert run.fextra.max() > 0
    # one frame per frame time for both models, not one per model's step time
    interval = case.t_end / FRAMES_PER_T_END
    ends = {res.t_final for res in run.results.values()}
    inner = [t for t in run.times if not np.isclose(list(ends), t, rtol=0, atol=1e-8).any()]
    np.testing.assert_allclose(np.diff(inner), interval, rtol=1e-6)
    assert len(inner) == int(max(ends) / interval + 1e-9) + 1


def test_scheme_and_case_choices_become_overrides():
    page = DamBreakPage(CASES)
    page.controls.scheme.value = "ifcp/muscl/mc+strang"
    assert page.controls.overrides() == [
        "numerics.flux='ifcp'", "numerics.reconstruction='muscl'",
        "numerics.limiter='mc'", "numerics.splitting='strang'"]
    assert page.run.case.make_pde("two_layer").scheme.name == "ifcp/muscl/mc+strang"
    page.controls.case_select.value = "ritter_dam_break.toml"  # one model, no column
    assert page.run.case.models == ["single_layer"]
    for name in ("H0", "L0", "phi_b_two", "k", "c", "density_ratio"):
        assert page.controls.sliders[name].disabled, name
    assert not page.controls.sliders["phi_b_single"].disabled
    assert page.controls.closure.disabled
    assert page.controls.overrides() == []
    assert page.status.object == ""
    page.controls.case_select.value = "mangeney_dam_break_slope.toml"  # 30 deg, one layer
    assert page.controls.sliders["slope"].value == 30.0
    assert page.controls.overrides() == []
    page.controls.sliders["slope"].value = 25.0
    assert page.controls.overrides() == ["single_layer.theta_deg=25"]


def test_every_knob_names_case_keys():
    case = load_case(CASE_51)
    for k in KNOBS:
        for key in k.keys:
            load_case(CASE_51, [f"{key}={k.start}"])  # a valid override
        assert k.start < k.end and k.step > 0
    assert case.initial["H0"] == 2.0


def _readout(value: float, fmt: str) -> str:
    """What a slider's read-out shows for ``value`` with the numeral.js format ``fmt``
    ('0' or '0.' and zeros: fixed decimals, as Python's f-format)."""
    return f"{value:.{max(fmt.count('0') - 1, 0)}f}"


def test_slider_readouts_show_every_position():
    """Every slider of every page, on every case: the read-out of its start, first
    steps, case value and end is that number (to a thousandth of a step: the
    positions differ by a step), and never 0 for a non-zero value (Bokeh's default
    format, two decimals, showed the Pouliquen L of 0.001 m as 0). The read-out is
    numeral.js's in the browser; _readout is its Python twin for these formats."""
    from pdeflow.app.controls import ParameterControls, list_cases
    from pdeflow.app.slider import MAX_DECIMALS, readout_format

    assert [readout_format(0.0, s) for s in (1.0, 0.25, 5e-5, 100.0)] == \
        ["0", "0.00", "0.00000", "0"]
    cases = list_cases(CASES)
    controls = ParameterControls(cases, "paper_5_1_dam_break.toml", lambda: None)
    sliders = [*HyperbolicityPage(SharedRun()).sliders.values(),
               RunoutPage(CASES, start=False).a]
    checked = 0
    for name in cases:
        controls.set_case(load_case(cases[name]))
        for s in [*controls.sliders.values(), *sliders]:
            for v in (s.start, s.start + s.step, s.start + 2 * s.step, s.value, s.end):
                shown = _readout(v, s.format)
                assert abs(float(shown) - v) < s.step / 1000, (s.name, v, shown)
                # below half the 6th decimal is 0 to a slider (the frictionless
                # cases' phi_B of 1e-9 deg)
                assert abs(v) < 0.5 * 10**-MAX_DECIMALS or float(shown) != 0, \
                    (s.name, v, shown)
                checked += 1
    assert checked > 1000
    assert controls.sliders["pouliquen_L"].format == "0.00000"


# --- page 2: run-out law ----------------------------------------------------------------
def test_runout_page_points_and_fit_are_the_sweeps():
    page = RunoutPage(CASES)  # not served: the whole set at once
    sweep_case = CASES / "collapse_sweep.toml"
    ratios = sorted(set(load_case(sweep_case).data["sweep"]["aspect_ratios"]) | {5.0})
    api = run_sweep(load_case(sweep_case), [float(a) for a in ratios])
    for model, res in api["models"].items():
        assert [[a, row["r"]] for a, row in sorted(page.points[model].items())] == \
            res["points"]
        p, e = page.fit(model)
        assert (p, e) == pytest.approx((res["prefactor"], res["exponent"]), rel=1e-12)
        assert f"r = {format_r(res['points'][ratios.index(5.0)][1])}" in \
            page.current.object
    page.add_point(7.5)
    assert 7.5 in page.points["two_layer"]
    page.clear.clicks += 1  # clear the set
    assert page.fit("two_layer") is None and "needs two points" in page.fits.object


def test_the_runout_axes_are_labelled_in_every_decade():
    """Bokeh's log ticker labelled the a axis (1 to 35) at 5, 10, 15, ... only: now
    1, 2, 3, 5 times each power of ten, as plain numbers."""
    from bokeh.models import NumeralTickFormatter

    from pdeflow.app.look import log_ticks
    from pdeflow.app.runout import A_RANGE, R_RANGE

    assert log_ticks(1.0, 35.0) == [1, 2, 3, 5, 10, 20, 30]
    assert log_ticks(0.5, 150.0) == [0.5, 1, 2, 3, 5, 10, 20, 30, 50, 100]
    assert log_ticks(0.02, 0.2, range(1, 10)) == pytest.approx(
        [0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.1, 0.2], rel=1e-12)
    fig = RunoutPage(CASES, start=False).fig
    for axis, (low, high) in ((fig.xaxis[0], A_RANGE), (fig.yaxis[0], R_RANGE)):
        shown = [t for t in axis.ticker.ticks if low <= t <= high]
        assert shown == log_ticks(low, high), shown
        assert isinstance(axis.formatter, NumeralTickFormatter)
    assert [t for t in fig.xaxis[0].ticker.ticks if t < 5] == [0.1, 0.2, 0.3, 0.5, 1, 2, 3]


def test_published_laws_leave_their_transition_open():
    a = np.array([1.0, 2.0, 2.5, 3.0])
    lube = published_law("Lube et al. 2005", a)
    assert lube[0] == pytest.approx(1.2) and np.isnan(lube[1:3]).all()
    assert lube[3] == pytest.approx(1.9 * 3 ** (2 / 3))
    assert not np.isnan(published_law("Lube et al. 2005", a, bridge=True)).any()
    assert not np.isnan(published_law("Lajeunesse et al. 2005", a)).any()
    assert set(PUBLISHED_LAWS) == {"Lube et al. 2005", "Lajeunesse et al. 2005"}


# --- page 3: hyperbolicity --------------------------------------------------------------
@pytest.mark.parametrize("h1, h2, r", [(0.5, 1.0, 0.67), (1.0, 0.2, 0.3), (0.05, 1.5, 0.9)])
def test_band_edges_bracket_the_complex_eigenvalues(h1, h2, r):
    f_c1, f_c2 = band_edges(h1, h2, r)
    assert lower_bound_fl(h1, h2, G, r) <= f_c1 + 1e-9 < f_c2 <= upper_bound_fr(h1, h2, G, r)
    for du, complex_pair in ((0.99 * f_c1, False), (0.5 * (f_c1 + f_c2), True),
                             (1.01 * f_c2, False)):
        lam = eigenvalues(h1, h2, du, 0.0, G, r)
        assert (np.abs(lam.imag).max() > 1e-9) == complex_pair, du
        assert (discriminant(h1, h2, du, 0.0, G, r) < 0) == complex_pair


def test_hyperbolicity_page_shows_the_eigenvalues_and_the_run():
    shared = SharedRun()
    dam = DamBreakPage(CASES, shared)
    page = HyperbolicityPage(shared)
    for z in eigenvalues(0.5, 1.0, 3.0, 0.0, G, 0.67):
        assert format_eigenvalue(z) in page.text.object
    assert "not hyperbolic" in page.text.object  # du = 3 m/s lies in the band
    # the cell where the run needed the largest F_extra: after the restoration its
    # state lies at the band's lower edge, hyperbolic
    run = dam.run
    k, c = page.frame.value, page.cell.value
    assert run.fextra[k, c] == run.fextra.max() > 0
    page.take.clicks += 1
    s = cell_state(run, k, c)
    assert page.sliders["h1"].value == s["h1"] and page.sliders["du"].value == abs(s["du"])
    assert "<b style='color:green'>hyperbolic</b>" in page.text.object
    assert f"{run.results['two_layer'].summary['max_fextra_over_rho1']:.4g}" in \
        page.cell_text.object
    # and so in every cell and frame where F_extra acted: |du| at F_c1, from below
    ratios = []
    for k, c in zip(*np.nonzero(run.fextra > 0), strict=True):
        s = cell_state(run, k, c)
        if min(s["h1"], s["h2"]) > 1e-3:
            ratios.append(abs(s["du"]) / band_edges(s["h1"], s["h2"], s["r"], s["g"])[0])
    assert len(ratios) > 100
    assert 1 - 1e-6 < min(ratios) and max(ratios) <= 1 + 1e-12


# --- kernels and Jupyter ----------------------------------------------------------------
def test_warmup_says_what_it_waits_for_and_why_it_failed():
    gate = threading.Event()
    w = KernelWarmup(gate.wait)
    w.start()
    assert not w.done and w.message().startswith("compiling kernels (once per machine")
    assert "elapsed" in w.message()
    gate.set()
    assert w.wait(10) and w.error is None and "ready" in w.message()

    def broken() -> None:
        raise RuntimeError("no compiler")

    w = KernelWarmup(broken)
    assert w.wait(10)
    assert w.message() == "loading the kernels failed: RuntimeError: no compiler"


def test_create_app_displays_in_jupyter():
    """One call shows the app in a notebook (the kernel renders Panel's bundle)."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell("from pdeflow.app import create_app\n"
                                          "create_app()")]
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(ROOT)}})
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError:
        raise
    except Exception as err:  # noqa: BLE001 - no kernel here (see tests/test_notebooks.py)
        skip_or_fail_in_ci(f"no Jupyter kernel can start here: {err!r}")
    data = [o.get("data", {}) for o in nb.cells[0].outputs]
    assert any("application/vnd.holoviews_exec.v0+json" in d for d in data), data


def test_command_lines_are_readable_and_mean_the_overrides():
    """A TOML string value is shown in double quotes (not shlex's '"'"' chains), and
    every command line splits back into exactly the overrides (a POSIX shell's view)."""
    import shlex

    overrides = ["two_layer.exchange_closure='relaxed'", "grid.dx=0.05",
                 "case.name=\"a b\"", "case.models=['single_layer']",
                 "case.description='it''s $HOME'"]
    line = command_line(CASE_51, overrides)
    assert "--set \"two_layer.exchange_closure='relaxed'\"" in line
    assert "'\"'\"'" not in line.split("case.description")[0]
    assert shlex.split(line)[4::2] == overrides


def test_friction_law_choice_sets_every_model_and_enables_its_sliders():
    """The law choice becomes ``<model>.friction_law`` of each model of the case, and
    only the chosen law's parameter sliders are enabled (issue 23); the laws offered are
    the registered ones (no list of its own in the app)."""
    from pdeflow.app.controls import ParameterControls
    from pdeflow.models.friction_laws import LAWS

    calls = []
    controls = ParameterControls({"5.1": CASE_51}, "5.1", lambda: calls.append(1))
    assert list(controls.law.options) == list(LAWS)
    assert controls.law.value == "coulomb" and controls.sliders["voellmy_xi"].disabled
    controls.law.value = "voellmy"
    assert calls and not controls.sliders["voellmy_xi"].disabled
    assert controls.sliders["pouliquen_L"].disabled
    over = controls.overrides()
    assert "two_layer.friction_law='voellmy'" in over
    assert "single_layer.friction_law='voellmy'" in over
    case = controls.load()
    assert case.make_pde("single_layer").parameters.friction_law == "voellmy"


# --- the lecture hall: warnings, domain length, opening frame, presentation mode ---------
def _cli_warnings(overrides: list[str], tmp_path: Path, capsys) -> list[str]:
    """The warning lines of ``pdeflow run`` for test 5.1 with ``overrides``."""
    return cli_warnings(CASE_51, overrides, tmp_path, capsys)


def test_the_page_warns_as_the_command_line_does(tmp_path, capsys):
    """At 35 deg the 7 m domain loses 25 % (two layers) and 97 % (one layer) of the
    mass: the page shows the command line's warnings, and a longer domain keeps the
    two layers' mass (then the page warns that they still move at t_end)."""
    page = DamBreakPage(CASES)
    assert page.run.warnings == [] and not page.warnings.visible
    page.controls.sliders["slope"].value = 35.0
    page.controls.sliders["slope"].param.trigger("value_throttled")
    over = page.controls.overrides()
    assert over == ["two_layer.theta_deg=35", "single_layer.theta_deg=35"]
    expected = _cli_warnings(over, tmp_path, capsys)
    assert page.run.warnings == expected and len(expected) == 2
    assert "25 % of the mass left the domain" in expected[0]
    assert "97 % of the mass left the domain" in expected[1]
    assert page.warnings.visible and all(w in page.warnings.object for w in expected)
    length = page.controls.sliders["length"]
    assert length.start == 7.0 and length.step == 2.0  # whole cells of dx = 0.05 m
    length.value = 41.0
    length.param.trigger("value_throttled")
    over = page.controls.overrides()
    assert over[-1] == "grid.length=41"
    assert page.run.warnings == _cli_warnings(over, tmp_path, capsys)
    assert not any("two_layer: material reached" in w for w in page.run.warnings)
    assert page.run.results["two_layer"].summary["mass_change"] == pytest.approx(0,
                                                                                 abs=1e-9)


def test_run_warnings_are_one_line_each_once():
    import warnings

    from pdeflow.checks import RunWarning, run_warnings

    lines: list[str] = []
    with run_warnings(lines.append):
        for _ in range(2):
            warnings.warn("the same", RunWarning, stacklevel=1)
        warnings.warn("another", RunWarning, stacklevel=1)
    assert lines == ["pdeflow: warning: the same", "pdeflow: warning: another"]


def test_around_case_sliders_keep_the_cases_value_and_whole_cells():
    from pdeflow.app.controls import nice_step

    assert [nice_step(v) for v in (1.75, 0.5, 0.3, 7.0, 0.012)] == [2, 0.5, 0.2, 5, 0.01]
    page = DamBreakPage(CASES)
    for name, own in (("length", 7.0), ("t_end", 5.0)):
        s = page.controls.sliders[name]
        positions = np.arange(s.start, s.end + s.step / 2, s.step)
        assert np.isclose(positions, own).any() and s.value == own, name
    dx = page.run.case.dx
    cells = page.controls.sliders["length"].step / dx
    assert cells == pytest.approx(round(cells))


def test_the_page_opens_on_the_collapse_in_motion():
    from pdeflow.app.dam_break import opening_frame

    page = DamBreakPage(CASES)
    last = len(page.run.times) - 1
    assert page.player.value == opening_frame(page.run) < last
    assert np.nanmax(np.abs(page.src_two.data["u1"])) > 1.0  # m/s: moving
    assert np.nanmax(page.src_two.data["f"]) > 0 or np.nanmax(page.run.fextra) > 0
    assert "final state" not in page.fig_h.title.text
    page.controls.sliders["phi_b_two"].value = 38.0
    page.controls.sliders["phi_b_two"].param.trigger("value_throttled")
    assert page.player.value == len(page.run.times) - 1  # a change: the deposit


def _all_figures(dam, runout, hyper):
    return [dam.fig_h, dam.fig_u, dam.fig_f, runout.fig, hyper.fig_spec]


def test_presentation_mode_enlarges_and_hides_and_switches_back():
    from bokeh.models import GlyphRenderer

    shared = SharedRun()
    pages = (DamBreakPage(CASES, shared), RunoutPage(CASES, start=False),
             HyperbolicityPage(shared))
    figs = _all_figures(*pages)

    def looks():
        return [(f.title.text_font_size, f.xaxis[0].axis_label_text_font_size,
                 [r.glyph.line_width for r in f.renderers
                  if isinstance(r, GlyphRenderer) and hasattr(r.glyph, "line_width")])
                for f in figs]

    normal = looks()
    for p in pages:
        p.set_present(True)
    big = looks()
    for (t0, a0, w0), (t1, a1, w1) in zip(normal, big, strict=True):
        assert float(t1[:-2]) > 1.3 * float(t0[:-2]) and float(a1[:-2]) > float(a0[:-2])
        assert w1 == pytest.approx([2 * w for w in w0])
    controls = pages[0].controls
    controls.panel()
    assert not controls.scheme.visible and not controls.sliders["k"].visible
    assert controls.sliders["slope"].visible and controls.sliders["length"].visible
    for p in pages:
        p.set_present(False)
    assert looks() == normal and controls.scheme.visible


def test_legends_are_beside_the_data_and_every_line_is_named():
    """Every legend outside the plot area; every line named by a legend, or, alone in
    its figure (F_extra), by the y axis. The dam break's legends stand above the plots,
    which keep the figure's width (issue 38: at 1024 px they crowded the plots)."""
    from bokeh.models import GlyphRenderer, Legend

    shared = SharedRun()
    dam, runout = DamBreakPage(CASES, shared), RunoutPage(CASES, start=False)
    for f in _all_figures(dam, runout, HyperbolicityPage(shared)):
        lines = [r for r in f.renderers if isinstance(r, GlyphRenderer)]
        assert f.legend or len(lines) == 1 and f.yaxis[0].axis_label, f.css_classes
        assert not [m for m in f.center if isinstance(m, Legend)], f.css_classes
    labels = [i.label.value for i in runout.fig.legend[0].items]
    assert "a of the slider (the current point)" in labels
    for f in (dam.fig_h, dam.fig_u):
        assert f.legend[0] in f.above, f.css_classes
    fronts = next(i for i in dam.fig_h.legend[0].items if "fronts" in i.label.value)
    colours = {r.glyph.line_color for r in fronts.renderers}
    assert colours == {s.line_color for s in dam.fronts.values()}  # both models


def test_app_present_option():
    from pdeflow.cli import build_parser

    assert build_parser().parse_args(["app", "--present"]).present
    assert not build_parser().parse_args(["app"]).present


def test_pages_not_shown_are_built_when_their_tab_opens():
    """Only the dam-break page is built at start; the run-out, hyperbolicity and
    hillside pages when their tab is first opened (then in the mode of that moment)."""
    from pdeflow.app.layout import SessionPages, build_pages

    toggle = pn.widgets.Toggle(value=False)
    pages = SessionPages(CASES)
    tabs = build_pages(CASES, toggle=toggle, pages=pages)
    assert list(pages.pages) == ["dam-break"]
    assert [len(t.objects) for t in tabs.objects] == [1, 0, 0, 0]
    toggle.value = True  # presentation mode before the others exist
    tabs.active = 2
    assert [len(t.objects) for t in tabs.objects] == [1, 0, 1, 0]
    tabs.active = 1
    assert [len(t.objects) for t in tabs.objects] == [1, 1, 1, 0]
    tabs.active = 3
    assert [len(t.objects) for t in tabs.objects] == [1, 1, 1, 1]
    runout = pages.pages["run-out"]
    assert runout.started and runout.present and pages.pages["hyperbolicity"].present
    assert pages.pages["hillside"].present
    shown = tabs.objects[1].objects[0]
    tabs.active = 0
    tabs.active = 1  # built once
    assert tabs.objects[1].objects[0] is shown and pages.pages["run-out"] is runout
    toggle.value = False
    assert not any(p.present for p in pages.pages.values())


def test_the_page_asked_for_is_built_at_start():
    from pdeflow.app.layout import build_pages

    tabs = build_pages(CASES, page="hyperbolicity")
    assert tabs.active == 2
    assert [len(t.objects) for t in tabs.objects] == [1, 0, 1, 0]
    tabs = build_pages(CASES, page="hillside")
    assert tabs.active == 3
    assert [len(t.objects) for t in tabs.objects] == [1, 0, 0, 1]


def _short_sweep(tmp_path: Path, t_end: float, length: float) -> Path:
    """cases/collapse_sweep.toml with its a values 2 and 3, ``t_end`` and ``length``."""
    text = (CASES / "collapse_sweep.toml").read_text()
    text = text.replace("t_end = 30.0", f"t_end = {t_end}")
    text = text.replace("length = 12.0", f"length = {length}")
    text = text.replace("aspect_ratios = [2, 3, 4, 6, 8, 10, 14, 18, 24, 30]",
                        "aspect_ratios = [2, 3]")
    (tmp_path / "collapse_sweep.toml").write_text(text)
    return tmp_path / "collapse_sweep.toml"


@pytest.mark.parametrize("t_end, length, says", [
    (0.3, 12.0, "still moving at the end of the run"),
    (30.0, 0.4, "material reached"),
])
def test_the_runout_page_warns_as_the_command_line_does(tmp_path, capsys, t_end, length,
                                                        says):
    """Runs still moving at t_end, material at the domain's end: the run-out page shows
    the lines ``pdeflow sweep`` prints for the same points, in a box, each with its a."""
    case = _short_sweep(tmp_path, t_end, length)
    page = RunoutPage(tmp_path)  # a = 2, 3 and the slider's 5
    capsys.readouterr()
    assert main(["sweep", str(case), "--quiet", "--set",
                 "sweep.aspect_ratios=[2, 3, 5]"]) == 0
    cli = [r for r in capsys.readouterr().err.splitlines()
           if r.startswith("pdeflow: warning:")]
    shown = page.warning_lines()
    assert cli and any(says in line for line in cli)
    assert {line.split(": ", 1)[1] for line in shown} == set(cli)
    assert {line.split(":")[0] for line in shown} == {"a = 2", "a = 3", "a = 5"}
    assert page.warnings.visible and all(escape(w) in page.warnings.object
                                         for w in shown)
    page.recompute([])  # an empty set: no warnings
    assert page.warning_lines() == [] and not page.warnings.visible


def test_the_runout_page_shows_no_warnings_box_for_runs_at_rest(tmp_path):
    _short_sweep(tmp_path, 30.0, 12.0)
    page = RunoutPage(tmp_path)
    assert len(page.points["two_layer"]) == 3 and page.warning_lines() == []
    assert not page.warnings.visible


def test_runout_page_shows_the_mass_quantile_run_out_and_its_fit():
    page = RunoutPage(CASES)
    sweep_case = CASES / "collapse_sweep.toml"
    ratios = sorted(set(load_case(sweep_case).data["sweep"]["aspect_ratios"]) | {5.0})
    api = run_sweep(load_case(sweep_case), [float(a) for a in ratios])
    for model, res in api["models"].items():
        p, e = page.fit(model, "r_mass")
        # the same runs, the same fit: only the summation order of the fit differs
        assert (p, e) == pytest.approx((res["prefactor_mass"], res["exponent_mass"]),
                                       rel=1e-12)
        assert f"r_mass = {p:.3g} a^{e:.3f}" in page.fits.object
        assert f"r_mass = {format_r(res['points_mass'][ratios.index(5.0)][1])}" in \
            page.current.object
    assert "99% of the mass" in page.fits.object


def test_every_time_on_the_page_says_what_it_is():
    """Issue 38 saw four end times on one page (1.347 s, 'at rest at 1.35 s', 't = 1.36
    s', 't = 1.38 s (final state)'). The stop time reads as the table prints it, and
    the end of each model's run is the time of one of its frames, said as such."""
    page = DamBreakPage(CASES)
    for m, res in page.run.results.items():
        stop = res.summary["stop_time"]
        assert f"{stop:.4g} s" in page.run.table()  # the table's stop time ...
        said = f"at rest at {stop:.4g} s (the stop time); the run ended at t = " \
               f"{res.t_final:.2f} s"
        assert said in page.summary.text, (m, page.summary.text)  # ... is the page's
        # the run's end is a frame's time (the last, final state, is the later model's;
        # the frames' times are rounded to 1e-9 s)
        assert np.isclose(page.run.times, res.t_final, rtol=0, atol=1e-9).any(), m
    page.player.value = len(page.run.times) - 1
    t_end = max(r.t_final for r in page.run.results.values())
    assert f"t = {t_end:.2f} s (final state)" in page.fig_h.title.text
