"""The hillside page (issue 39) in a real browser: ``pdeflow app`` in a subprocess, the
page in headless Chromium. A release drawn with the mouse runs, its frames are drawn
while it computes, and the table is what the command line gives for the downloaded
case file; nothing loads from elsewhere; the page fits a projector and a wide screen;
a new run replaces the old; and (``-m slow``) a class of 30 pressing run at once.

Needs Debian's Chromium and Playwright, as tests/test_app_browser.py (same skip rule:
PDEFLOW_SKIP_BROWSER=1). The runs' numbers are compared with the Python API's to the
table's precision (the page runs on one numba thread, the command line on its default).
"""

from __future__ import annotations

import os
import re
import time
from itertools import pairwise
from pathlib import Path
from urllib.parse import urlparse

import pytest

from pdeflow.app.dam_break import LABELS
from pdeflow.app.hillside import SUMMARY_ROWS
from pdeflow.cases import load_case
from pdeflow.simulate import run_model

from .browser import (
    READY,
    PageLog,
    app_server,
    browser_for_tests,
    figure_titles,
    foreign_urls,
    layout_problems,
    open_page,
    press_slider,
    text,
)

pytestmark = [pytest.mark.skipif(os.environ.get("PDEFLOW_SKIP_BROWSER") == "1",
                                 reason="PDEFLOW_SKIP_BROWSER=1"),
              pytest.mark.filterwarnings("ignore::pdeflow.checks.RunWarning")]

ROOT = Path(__file__).parents[1]
DRAWN = ((150.0, 380.0), (380.0, 420.0), (400.0, 600.0), (160.0, 640.0))
"""The release the tests draw [m from the grid's corner]: high on the 34 deg plane of
cases/hillside_plane.toml (it flattens at x = 1262 m), across the path's axis."""
CELL_M = 2000.0 / 120
"""The default grid's cell size down the path [m] (120 cells over 2000 m)."""
FIGURES = ("plan-single_layer", "plan-two_layer", "section")
PROJECTOR, WIDE = (1024, 768), (1920, 1080)
WAIT_S = 180.0
"""A run and its animation (about 90 frames at 15 per second) end within this [s]:
a guard against a hung page, not a measurement."""
HOLD_S, GAP_S = 0.8, 0.4
"""Bokeh 3's PolyDrawTool starts and ends a polygon with a *press* (the button held
300 ms, UIGestures.press_threshold); a click adds a vertex while drawing; two clicks
within 300 ms (doubletap_threshold) are a double tap, which the tool ignores."""

FRAME = """(cls) => {
  // the plot area of the figure with CSS class cls: its box [px] in the figure's
  // canvas (Bokeh's frame bbox: x0, y0 at the top left) and its x and y ranges [m]
  let out = null;
  const walk = (v) => {
    if (v.frame && v.model && (v.model.css_classes || []).includes(cls)) {
      const f = v.frame;
      out = {box: [f.bbox.x0, f.bbox.y0, f.bbox.x1, f.bbox.y1],
             x: [f.x_range.start, f.x_range.end], y: [f.y_range.start, f.y_range.end],
             drag: String(v.model.toolbar.active_drag?.type)};
    }
    for (const c of v.child_views || []) walk(c);
  };
  for (const v of Bokeh.index.roots || []) walk(v);
  return out;
}"""
RELEASE = """() => {
  // the release polygon as the browser holds it (the PolyDrawTool's source)
  for (const m of Bokeh.documents[0].all_models)
    if (m.type === "PolyDrawTool") {
      const d = m.renderers[0].data_source.data;  // a Map, or an object
      const get = (key) => d instanceof Map ? d.get(key) : d[key];
      return Array.from(get("xs"), (xs, i) => Array.from(xs, (x, k) =>
        [x, get("ys")[i][k]]));
    }
}"""
LISTEN = """() => {
  // every text the server sends the status line, in order (as the benchmark's probe)
  window.__statuses = [];
  for (const doc of Bokeh.documents)
    doc.on_change((e) => {
      if (e.attr === "text" && (e.model.css_classes || []).includes("pdeflow-status"))
        window.__statuses.push(String(e.value));
    });
}"""
FRONTS = re.compile(r"(single layer|two layers) (\d+) m")


@pytest.fixture(scope="module")
def browser():
    with browser_for_tests() as b:
        yield b


@pytest.fixture(scope="module")
def server_log(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("app") / "server.log"


@pytest.fixture(scope="module")
def server(server_log):
    with app_server(ROOT, log=server_log) as url:  # stopped at the end, also on failure
        yield url


def _to_screen(page, frame: dict, x: float, y: float) -> tuple[float, float]:
    """Page pixels of the point (x, y) [m] of the single-layer plan view: Bokeh's frame
    box is in the figure's canvas, whose top left is the figure element's (y upward)."""
    fig = page.locator(".pdeflow-plan-single_layer").first.bounding_box()
    (x0, y0, x1, y1), (xs, xe), (ys, ye) = frame["box"], frame["x"], frame["y"]
    return (fig["x"] + x0 + (x - xs) / (xe - xs) * (x1 - x0),
            fig["y"] + y1 - (y - ys) / (ye - ys) * (y1 - y0))


def _draw(page, vertices) -> dict:
    """Draw ``vertices`` [m] with the mouse: press and hold at the first, click the
    next ones, press and hold at the last. Returns the plot area (:data:`FRAME`)."""
    frame = page.evaluate(FRAME, "pdeflow-plan-single_layer")
    for k, (x, y) in enumerate(vertices):
        page.mouse.move(*_to_screen(page, frame, x, y))
        page.mouse.down()
        time.sleep(HOLD_S if k in (0, len(vertices) - 1) else 0.05)
        page.mouse.up()
        time.sleep(GAP_S)
    return frame


def _wait_done(page, timeout: float = WAIT_S, samples: list | None = None) -> None:
    """Wait until the status says "done"; ``samples`` gets (status, shown fronts)
    every 0.1 s."""
    t0 = time.monotonic()
    while not (status := text(page, "status")).startswith("done"):
        assert time.monotonic() - t0 < timeout, f"no end within {timeout:g} s: {status}"
        assert "cannot run" not in status and "the run " not in status, status
        if samples is not None and status.startswith("t = "):
            # read at once, without waiting: the run may end (and the span go) between
            # the status read above and this one
            fronts = page.locator("span.pdeflow-fronts").all_inner_texts()
            samples.append((status, fronts[0] if fronts else ""))
        time.sleep(0.1)


def _statuses(page) -> list[str]:
    return page.evaluate("() => window.__statuses")


def _fronts(status: str) -> dict[str, int]:
    return {label: int(x) for label, x in FRONTS.findall(status)}


def _table(page) -> dict[str, dict[str, str]]:
    """The results table: per model label, row label -> cell text."""
    rows = page.locator(".pdeflow-summary table.pdeflow-table").first.evaluate(
        "t => Array.from(t.rows, r => Array.from(r.cells, c => c.innerText.trim()))")
    return {label: {r[0]: r[i] for r in rows[1:]} for i, label in enumerate(rows[0]) if i}


def _download(page, folder: Path) -> Path:
    """The case file of the download button, saved in ``folder`` under its name."""
    with page.expect_download(timeout=60_000) as d:
        page.locator(".pdeflow-download").first.click()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / d.value.suggested_filename
    d.value.save_as(path)
    return path


def _api_table(path: Path, overrides: list[str] = ()) -> dict[str, dict[str, str]]:
    """The page's table as the Python API (``pdeflow run``) gives it for ``path``."""
    case = load_case(path, list(overrides))
    out = {}
    for m in case.models:
        s = run_model(case, m).summary
        out[LABELS[m]] = {label: "-" if s.get(key) is None else fmt.format(s[key])
                          for key, label, fmt in SUMMARY_ROWS}
    return out


def _no_traceback(log: Path) -> None:
    shown = log.read_text(errors="replace")
    assert "Traceback" not in shown, shown[-3000:]


# --- 1, 2: a drawn release, its run, its case file ----------------------------------------
@pytest.fixture(scope="module")
def drawn(browser, server, tmp_path_factory):
    """The page at 1024x768 with DRAWN drawn and run to the end, and its download."""
    page, log = open_page(browser, server, "hillside", viewport=PROJECTOR)
    hint = page.locator(READY["hillside"]).first.inner_text()
    frame = _draw(page, DRAWN)
    shown = page.evaluate(RELEASE)
    page.evaluate(LISTEN)
    page.locator(".pdeflow-run button").click()
    samples: list[tuple[str, str]] = []
    _wait_done(page, samples=samples)
    path = _download(page, tmp_path_factory.mktemp("drawn"))
    yield {"page": page, "log": log, "hint": hint, "frame": frame, "shown": shown,
           "samples": samples, "statuses": _statuses(page), "table": _table(page),
           "path": path}
    page.close()


def test_a_drawn_release_runs_as_the_command_line_runs_it(drawn):
    """Drawn with the mouse, the release replaces the case's box; the page draws
    frames while it computes, the fronts go down the slope past the release, and the
    table is what ``pdeflow run`` prints for the downloaded file."""
    assert drawn["frame"]["drag"] == "PolyDrawTool"  # drawing is the default drag
    assert "press and hold" in drawn["hint"], drawn["hint"]  # the gesture that works
    px_m = (drawn["frame"]["x"][1] - drawn["frame"]["x"][0]) / (
        drawn["frame"]["box"][2] - drawn["frame"]["box"][0])
    assert len(drawn["shown"]) == 1 and len(drawn["shown"][0]) == len(DRAWN), drawn["shown"]
    for (x, y), (sx, sy) in zip(drawn["shown"][0], DRAWN, strict=True):
        assert abs(x - sx) <= px_m and abs(y - sy) <= px_m, (drawn["shown"], DRAWN)
    # frames while it computes, the fronts read at several moments going down
    frames = [s for s, _ in drawn["samples"]]
    assert any("(computing)" in s for s in frames), frames[:3]
    fronts = [_fronts(f) for _, f in drawn["samples"] if f]
    assert len(fronts) >= 5, drawn["samples"]
    for label in ("single layer", "two layers"):
        xs = [f[label] for f in fronts]
        assert xs[-1] > xs[0] + 10 * CELL_M, (label, xs)
        assert all(b >= a - CELL_M for a, b in pairwise(xs)), (label, xs)
    # the case file holds the drawn polygon, and the command line's numbers
    case = load_case(drawn["path"])
    vertices = case.initial["vertices"]
    assert case.initial["shape"] == "polygon" and len(vertices) == len(DRAWN), vertices
    for (x, y), (sx, sy) in zip(vertices, DRAWN, strict=True):
        assert abs(x - sx) <= CELL_M and abs(y - sy) <= CELL_M, (vertices, DRAWN)
    assert drawn["table"] == _api_table(drawn["path"])
    # the last frame's fronts: past the polygon's lowest point by the run-out shown
    last = _fronts([s for s in drawn["statuses"] if s.startswith("t = ")][-1])
    lowest = max(x for x, _ in vertices)
    for label, front in last.items():
        assert front > lowest + 10 * CELL_M, (label, front, lowest)
        runout = float(drawn["table"][label]["run-out [m]"])
        assert abs(front - (lowest + runout)) <= 1.0, (label, front, lowest, runout)
    print(f"\ndrawn release to x = {lowest:.0f} m; last fronts {last}; "
          f"table {drawn['table']}")


def test_the_session_logs_no_error_and_loads_nothing_from_elsewhere(drawn, server,
                                                                    server_log):
    """Over the drawing, the run, the download and presentation mode on and off: no
    console error or warning, no request to another host, no model naming a URL on one, and no
    traceback in the server's log."""
    page, log = drawn["page"], drawn["log"]
    for _ in range(2):
        page.locator(".pdeflow-present button").click()
        time.sleep(1.0)  # every figure laid out again
    assert foreign_urls(page, urlparse(server).hostname) == []
    assert log.errors == [] and log.warnings == [], (log.errors, log.warnings)
    assert log.foreign_requests == [], f"the app must work offline: {log.foreign_requests}"
    _no_traceback(server_log)


# --- 3: the lecture hall ------------------------------------------------------------------
def _width(page, name: str) -> float:
    return page.locator(f".pdeflow-{name}").first.bounding_box()["width"]


@pytest.mark.parametrize("size", [PROJECTOR, WIDE], ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_page_fits_the_screen_after_a_run(browser, server, size):
    """After a run, with the side bar shown and folded and in presentation mode:
    every figure and the status, the run button, the table and the player inside the
    viewport left and right, no plot area under PLOT_MIN_PX; at 1024x768 with the
    controls folded away the plan views take at least 60 % of the width (issue 39)."""
    page, log = open_page(browser, server, "hillside", viewport=size)
    try:
        page.locator(".pdeflow-run button").click()
        _wait_done(page)
        others = ("sidebar", "status", "run", "download", "command", "summary", "player")
        assert layout_problems(page, FIGURES, others) == [], "side bar shown"
        below = page.locator(".pdeflow-summary").first.bounding_box()
        if size == PROJECTOR:  # the table above the fold (issue 39)
            assert below["y"] + below["height"] <= size[1], below
        plans = sum(_width(page, n) for n in FIGURES[:2])
        page.locator(".pdeflow-sidebar-toggle button").click()
        t0 = time.monotonic()
        while sum(_width(page, n) for n in FIGURES[:2]) < plans + 100:
            assert time.monotonic() - t0 < 10, "the side bar stays"
            time.sleep(0.1)
        folded = layout_problems(page, FIGURES, ("status", "run", "summary", "player"))
        assert folded == [], "side bar folded"
        share = {"folded": sum(_width(page, n) for n in FIGURES[:2]) / size[0]}
        page.locator(".pdeflow-present button").click()
        time.sleep(1.5)  # larger fonts, taller figures: laid out again
        present = layout_problems(page, FIGURES, ("status", "run", "summary", "player"))
        assert present == [], "presentation mode"
        share["present"] = sum(_width(page, n) for n in FIGURES[:2]) / size[0]
        areas = [round(figure_titles(page)[f"pdeflow-{n}"]["plot_width"]) for n in FIGURES]
        table = page.locator(".pdeflow-summary").first.bounding_box()
        print(f"\n{size[0]}x{size[1]}: plan views {plans:.0f} px with the side bar, "
              f"{', '.join(f'{k} {100 * v:.0f} %' for k, v in share.items())} of the "
              f"width; plot areas in presentation mode {areas} px; the table from "
              f"{below['y']:.0f} to {below['y'] + below['height']:.0f} px with the side "
              f"bar, {table['y']:.0f} to {table['y'] + table['height']:.0f} px in "
              f"presentation mode")
        if size == PROJECTOR:
            assert min(share.values()) >= 0.6, share
        assert log.errors == [], log.errors
    finally:
        page.close()


# --- 4: a new run replaces the old ---------------------------------------------------------
def test_a_new_run_cancels_the_old(browser, server, tmp_path):
    """Run, then at once a thicker release (the slider's end, 5 m) and run again: one
    run ends, and its table is the second's (not the first's, 2 m)."""
    page, log = open_page(browser, server, "hillside", viewport=PROJECTOR)
    try:
        page.evaluate(LISTEN)
        page.locator(".pdeflow-run button").click()
        press_slider(page, "thickness", "End")
        page.locator(".pdeflow-run button").click()
        _wait_done(page)
        table = _table(page)
        path = _download(page, tmp_path)
        assert load_case(path).initial["H0"] == pytest.approx(5.0)
        assert table == _api_table(path)
        assert table != _api_table(path, ["initial.H0=2.0"])  # the first run's
        ends = [s for s in _statuses(page) if s.startswith("done")]
        assert len(ends) == 1, ends
        assert log.errors == [], log.errors
    finally:
        page.close()


# --- 5: a class of 30 pressing run at once --------------------------------------------------
CLASS = 30
"""Pages opened on one server, one browser context each (browser.new_page)."""
CLASS_WAIT_S = 1800.0
"""Every run of the class and its animation end within this [s] (2 cores: the runs
queue; the pages draw their frames in one busy server and one busy browser)."""
LECTURE_S = 10.0
"""How long the lecturer's animation is watched while the class's runs compute [s]."""
PEAK_GB = 4.0
"""The server's peak resident memory (VmHWM) must stay below this [GB]: the lecturer's
laptop serves the class and runs its browser; 4 GB is half of a common 8 GB laptop.
Each session holds its pages' figures and at most one run's frames (120 x 60 cells x
~100 frames x 2 models x 4 bytes, about 6 MB)."""


def _peak_memory_gb(pid: int) -> float:
    """The process' peak resident memory [GB] (VmHWM, in kB in /proc/<pid>/status)."""
    status = Path(f"/proc/{pid}/status").read_text()
    return int(re.search(r"VmHWM:\s*(\d+) kB", status).group(1)) / 1024**2


@pytest.mark.slow
def test_a_class_of_30_runs_at_once(browser, tmp_path):
    """30 pages press run at once, each with its own thickness (1.0 + 0.1 k m, set
    with the slider's keys): the runs queue (some pages say "in the queue"), a page
    closed while its run waits leaves the others to finish, every other page ends
    "done" with the table of ITS downloaded case file, the server logs no traceback
    and its peak memory stays below PEAK_GB. The lecturer's page, whose run ended
    before, plays its animation while the class's runs compute (the frames it draws
    are printed) and again once they are done (it must then move)."""
    log_path = tmp_path / "server.log"
    with app_server(ROOT, log=log_path) as url:
        lecturer, lecturer_log = open_page(browser, url, "hillside", viewport=PROJECTOR)
        lecturer.locator(".pdeflow-run button").click()
        _wait_done(lecturer)
        pages = []
        for _ in range(CLASS):  # the class opens the page at once: loaded in parallel
            page = browser.new_page(viewport={"width": PROJECTOR[0], "height": PROJECTOR[1]})
            log = PageLog(urlparse(url).hostname or "")
            log.attach(page)
            page.goto(f"{url}?page=hillside", wait_until="commit")
            pages.append((page, log))
        for page, _ in pages:
            page.locator(READY["hillside"]).first.wait_for(timeout=CLASS_WAIT_S * 1000)
        for k, (page, _) in enumerate(pages):  # 2.0 m by default, 0.1 m a step
            for _ in range(abs(k - 10)):
                press_slider(page, "thickness", "ArrowRight" if k > 10 else "ArrowLeft")
            page.evaluate(LISTEN)
        lecturer.evaluate(LISTEN)
        lecturer.locator(".pdeflow-player button.first").click()
        t0 = time.monotonic()
        for page, _ in pages:
            page.locator(".pdeflow-run button").click()
        lecturer.locator(".pdeflow-player button.play").click()
        time.sleep(LECTURE_S)  # the class's runs compute meanwhile
        drawn = [s for s in _statuses(lecturer) if s.startswith("t = ")]
        # measured, not asserted: on a machine where the server and all 31 pages share
        # two cores the lecturer's browser is starved too (docs/teaching.md's numbers)
        print(f"\nthe lecturer's page drew {len(drawn)} frames in the {LECTURE_S:g} s "
              f"after the class pressed run ({len(drawn) / LECTURE_S:.1f} per second)")
        # a tab closed while its run waits: the last one whose status says so
        closed = next(k for k in reversed(range(CLASS))
                      if any("in the queue" in s for s in _statuses(pages[k][0])))
        pages[closed][0].close()
        left = [(k, p, log) for k, (p, log) in enumerate(pages) if k != closed]
        for _, page, _ in left:
            _wait_done(page, timeout=max(CLASS_WAIT_S - (time.monotonic() - t0), 1.0))
        wall = time.monotonic() - t0
        peak = _peak_memory_gb(url.pid)
        queued = [k for k, page, _ in left
                  if any("in the queue" in s for s in _statuses(page))]
        print(f"\n{CLASS} pages pressed run at once: all done {wall:.0f} s after the "
              f"first press; {len(queued) + 1} saw the queue (page {closed} closed "
              f"while waiting); server peak memory (VmHWM) {peak:.2f} GB")
        for k, page, log in left:
            path = _download(page, tmp_path / f"page{k}")
            assert load_case(path).initial["H0"] == pytest.approx(1.0 + 0.1 * k), k
            assert _table(page) == _api_table(path), k
            assert log.errors == [] and log.foreign_requests == [], (k, log)
            page.close()
        lecturer.evaluate(LISTEN)  # the class is done: the lecturer's page still plays
        lecturer.locator(".pdeflow-player button.first").click()
        lecturer.locator(".pdeflow-player button.play").click()
        time.sleep(LECTURE_S)
        drawn = {s for s in _statuses(lecturer) if s.startswith("t = ")}
        print(f"then {len(drawn)} frames in {LECTURE_S:g} s")
        assert len(drawn) >= 2, "the lecturer's animation stood still after the class"
        assert lecturer_log.errors == [], lecturer_log.errors
        assert queued, "no page showed the queue"
        assert peak < PEAK_GB, f"server peak memory {peak:.2f} GB"
    _no_traceback(log_path)
