"""The teaching app in a real browser: ``pdeflow app`` in a subprocess, each page loaded
in headless Chromium, a slider moved with the keyboard; the page must show what the
Python API gives for the same parameters, answer (not freeze), and log no error.

Needs Debian's Chromium (/usr/bin/chromium; .ci/run installs it) and Playwright (the
test extra). Without them these tests fail; on a machine without Chromium set
PDEFLOW_SKIP_BROWSER=1 to skip them. The screenshots go to a temporary directory (its
path is printed with ``-s``); ``python docs/generate/teaching_screenshots.py`` makes the
ones in docs/teaching.md.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest

from pdeflow.analysis.sweep import run_sweep
from pdeflow.app.browser import (
    CHROMIUM,
    READY,
    app_server,
    chromium,
    key_to_picture,
    open_page,
    slider_latency,
    text,
)
from pdeflow.cases import load_case
from pdeflow.simulate import run_model

pytestmark = pytest.mark.skipif(os.environ.get("PDEFLOW_SKIP_BROWSER") == "1",
                                reason="PDEFLOW_SKIP_BROWSER=1")

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"
CASE_SWEEP = ROOT / "cases" / "collapse_sweep.toml"
ANSWER_TIMEOUT_S = 30.0
"""A page that has not answered a slider within this [s] is frozen. Generous on
purpose: how fast the pages answer depends on the machine's load and is measured by
docs/generate/teaching_screenshots.py, not asserted here."""


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).is_file():
        pytest.fail(f"{CHROMIUM} is missing: apt-get install chromium (CI: .ci/run does), "
                    "or set PDEFLOW_SKIP_BROWSER=1 to skip the browser tests")
    try:
        import playwright  # noqa: F401
    except ImportError:
        pytest.fail("playwright is missing: pip install '.[test]'")
    with chromium() as b:
        yield b


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    log = tmp_path_factory.mktemp("app") / "server.log"
    with app_server(ROOT, log=log) as url:  # stopped at the end, also on failure
        yield url


@pytest.fixture(scope="module")
def shots(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("screenshots")
    print(f"\nscreenshots of the app: {folder}")
    return folder


@pytest.fixture
def opened(browser, server, shots, request):
    """open(page) -> the loaded page; at the end a screenshot, and no errors logged."""
    pages = []

    def open_(name: str):
        page, log = open_page(browser, server, name)
        pages.append((name, page, log))
        return page

    yield open_
    for name, page, log in pages:
        page.screenshot(path=shots / f"{request.node.name}_{name}.png", full_page=True)
        page.close()
        assert not log.errors, log.errors
        assert not log.foreign_requests, f"the app must work offline: {log.foreign_requests}"


def _api_rows(case_file: Path, overrides: list[str]) -> list[str]:
    """The rows of ``pdeflow run``'s table from the Python API (wall times left out)."""
    import io

    from pdeflow.simulate import print_summary

    case = load_case(case_file, overrides)
    out = io.StringIO()
    print_summary({"case": case.name,
                   "models": {m: run_model(case, m).summary for m in case.models}}, out)
    return [r.strip() for r in out.getvalue().splitlines()[2:]
            if not r.startswith("wall time")]


def _shown_rows(page) -> list[str]:
    lines = [r.strip() for r in text(page, "summary").splitlines()]
    start = next(i for i, r in enumerate(lines) if r.startswith("case ")) + 2
    end = next(i for i, r in enumerate(lines) if r.startswith("wall time"))
    return lines[start:end]


def _wait_for(predicate, timeout: float = 120.0) -> None:
    t0 = time.monotonic()
    while not predicate():
        assert time.monotonic() - t0 < timeout, "the page did not finish"
        time.sleep(0.05)


def test_dam_break_page_answers_a_slider_with_a_new_picture(opened, shots):
    """A slider move reruns the case and repaints; how fast is measured by
    docs/generate/teaching_screenshots.py (performance is not a unit test's job:
    it depends on the machine's load)."""
    page = opened("dam-break")
    assert _shown_rows(page) == _api_rows(CASE_51, [])
    picture = page.locator(".pdeflow-depths").screenshot()
    times = slider_latency(page, "phi_b_two", lambda i: f"two_layer.phi_b_deg={41 - i}",
                           moves=3, key="ArrowLeft")
    (shots / "latency.json").write_text(json.dumps({"dam_break_s": times}))
    print(f"\ndam break 5.1, slider release to new picture: "
          f"{', '.join(f'{1000 * t:.0f}' for t in times)} ms")
    assert _shown_rows(page) == _api_rows(CASE_51, ["two_layer.phi_b_deg=38"])
    assert page.locator(".pdeflow-depths").screenshot() != picture  # a new picture


def test_dam_break_animation_plays(opened):
    page = opened("dam-break")
    title = page.locator(".pdeflow-depths").screenshot()
    page.locator(".pdeflow-player button.first").click()  # to the first frame
    _wait_for(lambda: page.locator(".pdeflow-depths").screenshot() != title, 10)
    before = page.locator(".pdeflow-depths").screenshot()
    page.locator(".pdeflow-player button.play").click()
    _wait_for(lambda: page.locator(".pdeflow-depths").screenshot() != before, 10)


def test_runout_page_shows_the_sweep(opened):
    page = opened("run-out")
    _wait_for(lambda: "computing" not in text(page, "fits"))
    ratios = [float(a) for a in load_case(CASE_SWEEP).data["sweep"]["aspect_ratios"]]
    key_to_picture(page, "a", "a = 5.5", timeout=ANSWER_TIMEOUT_S)
    _wait_for(lambda: "computing" not in text(page, "fits"))
    api = run_sweep(load_case(CASE_SWEEP), sorted({*ratios, 5.0, 5.5}))
    shown = text(page, "current") + text(page, "fits")
    for model, res in api["models"].items():
        r = dict((a, r) for a, r in res["points"])[5.5]
        assert f"r = {r:.3g}" in shown, (model, shown)
        assert f"r = {res['prefactor']:.3g} a^{res['exponent']:.3f}" in shown, shown


def test_hyperbolicity_page_shows_the_eigenvalues(opened):
    from pdeflow.app.hyperbolicity import G, format_eigenvalue
    from pdeflow.numerics.hyperbolicity import eigenvalues

    page = opened("hyperbolicity")
    lam = eigenvalues(0.5, 1.0, 3.01, 0.0, G, 0.67)
    key_to_picture(page, "du", f"λ4 = {format_eigenvalue(lam[3])}", timeout=ANSWER_TIMEOUT_S)
    shown = text(page, "spectrum")
    for k, z in enumerate(lam):
        assert f"λ{k + 1} = {format_eigenvalue(z)} m/s" in shown, shown
    assert "not hyperbolic" in shown
    # the run's cell with the largest F_extra, analysed: restored to hyperbolic
    fmax = run_model(load_case(CASE_51), "two_layer").summary["max_fextra_over_rho1"]
    assert f"{fmax:.4g} m²/s²" in text(page, "cell-state")
    page.locator(".pdeflow-take button").click()
    _wait_for(lambda: "not hyperbolic" not in text(page, "spectrum"), 10)
    assert "hyperbolic" in text(page, "spectrum")


@pytest.mark.slow
def test_cold_start_says_it_compiles(browser, tmp_path):
    """A fresh machine: an empty numba cache. The page says that it compiles, with the
    elapsed time, and shows the dam break once the kernels are ready."""
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    with app_server(ROOT, env=env, log=tmp_path / "server.log") as url:
        page = browser.new_page()
        page.goto(url)
        status = page.locator(".pdeflow-kernels div").first
        status.wait_for(timeout=60_000)
        first = status.inner_text()
        assert first.startswith("compiling kernels (once per machine"), first
        time.sleep(2.5)
        assert status.inner_text() != first  # the elapsed time goes on
        page.locator(READY["dam-break"]).wait_for(timeout=900_000)
        assert _shown_rows(page) == _api_rows(CASE_51, [])
        page.close()
