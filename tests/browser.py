"""The app in a real browser: ``pdeflow app`` in a subprocess, driven through Playwright
in Debian's Chromium. Used by the browser tests and by
``docs/generate/teaching_screenshots.py``; needs ``playwright`` (the ``test`` extra) and
Chromium at ``$PDEFLOW_CHROMIUM``, by default ``/usr/bin/chromium`` (``apt-get install
chromium``; Playwright's own browser download is not used). Test support, outside the
package (scripts import it as ``tests.browser`` with the checkout on ``sys.path``).
"""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

CHROMIUM = os.environ.get("PDEFLOW_CHROMIUM", "/usr/bin/chromium")
"""the Chromium executable: ``$PDEFLOW_CHROMIUM``, by default Debian's"""
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]
"""Headless, no sandbox (CI runs as root), and no traffic of Chromium's own."""
READY = {"dam-break": ".pdeflow-summary pre", "run-out": ".pdeflow-fits ul",
         "hyperbolicity": ".pdeflow-spectrum ul", "hillside": ".pdeflow-hint"}
"""Per page, an element that exists once the page has shown its first result."""


class ServerURL(str):
    """The page's URL, as :func:`app_server` yields it; ``pid`` is the server's process
    id (its memory in ``/proc/<pid>/status``)."""

    pid: int


@contextmanager
def app_server(root: Path, *, timeout: float = 60.0, env: dict[str, str] | None = None,
               log: Path | None = None, args: Sequence[str] = ()) -> Iterator[ServerURL]:
    """Run ``pdeflow app --no-browser`` of the checkout ``root`` on a free port of
    127.0.0.1; yield the page's URL (a :class:`ServerURL`: a string with the server's
    ``pid``); stop the server when the block ends, also on an error (Ctrl-C, then kill
    after 10 s).

    ``root/pdeflow`` is put first on PYTHONPATH, so the server runs the same code as the
    caller; ``env`` adds variables (e.g. NUMBA_CACHE_DIR); the server's stderr goes to
    ``log`` (default: discarded); ``args`` are more options of ``pdeflow app`` (e.g.
    ``--present``).
    """
    full_env = dict(os.environ, **(env or {}))
    full_env["PYTHONPATH"] = os.pathsep.join(
        p for p in (str(root), full_env.get("PYTHONPATH", "")) if p)
    err = open(log, "w") if log else subprocess.DEVNULL  # closed in the finally below
    proc = subprocess.Popen(
        [sys.executable, "-m", "pdeflow.cli", "app", "--no-browser", "--host",
         "127.0.0.1", "--port", "0", *args], cwd=root, env=full_env, stdout=subprocess.PIPE,
        stderr=err, text=True)
    try:
        url = ServerURL(_read_url(proc, timeout))
        url.pid = proc.pid
        yield url
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        if log:
            err.close()


def _read_url(proc: subprocess.Popen, timeout: float) -> str:
    """The URL from the server's first line of output (RuntimeError if none comes)."""
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.put(line)

    threading.Thread(target=read, daemon=True).start()
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            line = lines.get(timeout=0.2)
        except queue.Empty:
            if proc.poll() is not None:
                break
            continue
        for word in line.split():
            if word.startswith("http://"):
                return word
    raise RuntimeError(f"pdeflow app did not print its address within {timeout:g} s "
                       f"(exit code {proc.poll()})")


@contextmanager
def chromium(executable: str = CHROMIUM) -> Iterator[Any]:
    """A headless Chromium (Playwright ``Browser``), closed when the block ends."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        try:
            yield browser
        finally:
            browser.close()


@contextmanager
def browser_for_tests() -> Iterator[Any]:
    """:func:`chromium` for a test module's fixture: the test fails (not skips) with a
    one-line reason when Chromium or Playwright is missing."""
    import pytest

    if not Path(CHROMIUM).is_file():
        pytest.fail(f"{CHROMIUM} is missing: apt-get install chromium (CI: .ci/run does), "
                    "set PDEFLOW_CHROMIUM to another Chromium, or set "
                    "PDEFLOW_SKIP_BROWSER=1 to skip the browser tests")
    try:
        import playwright  # noqa: F401
    except ImportError:
        pytest.fail("playwright is missing: pip install '.[test]'")
    with chromium() as b:
        yield b


@dataclass
class PageLog:
    """What a page reported: console errors and warnings, uncaught exceptions, foreign
    requests."""

    host: str
    errors: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    """console warnings (Bokeh's "could not set initial ranges", ...)"""
    foreign_requests: list[str] = field(default_factory=list)
    """requests to any host but the app's (the app must work offline)"""

    def attach(self, page: Any) -> None:
        page.on("console", lambda m: self.errors.append(f"console: {m.text}")
                if m.type == "error" else None)
        page.on("console", lambda m: self.warnings.append(m.text)
                if m.type == "warning" else None)
        page.on("pageerror", lambda e: self.errors.append(f"page error: {e}"))
        page.on("request", lambda r: self.foreign_requests.append(r.url)
                if urlparse(r.url).hostname not in (self.host, None) else None)


def open_page(browser: Any, url: str, page: str, *, timeout: float = 300.0,
              viewport: tuple[int, int] = (1500, 1000), query: str = ""
              ) -> tuple[Any, PageLog]:
    """Load ``page`` ('dam-break', 'run-out', 'hyperbolicity') and wait for its first
    result (``timeout`` [s] covers compiling the kernels on a fresh machine); ``query``
    adds URL arguments (``present=1``)."""
    p = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
    log = PageLog(urlparse(url).hostname or "")
    log.attach(p)
    p.goto(f"{url}?page={page}" + (f"&{query}" if query else ""))
    p.locator(READY[page]).first.wait_for(timeout=timeout * 1000)
    return p, log


FOREIGN_URLS = """(host) => {
  const out = [];
  for (const doc of Bokeh.documents)
    for (const m of doc.all_models)
      if (typeof m.url === "string" && /^[a-z]+:\\/\\//.test(m.url)
          && new URL(m.url).hostname !== host)
        out.push(`${m.type}: ${m.url}`);
  return out;
}"""
"""The models of the page (stylesheets, ...) that name a URL on another host than
``host``: a browser offline could not load them."""


def foreign_urls(page: Any, host: str) -> list[str]:
    """:data:`FOREIGN_URLS` of the page."""
    return page.evaluate(FOREIGN_URLS, host)


def text(page: Any, css_class: str) -> str:
    """The text of the element with the CSS class ``pdeflow-<css_class>``."""
    return page.locator(f".pdeflow-{css_class} div, .pdeflow-{css_class} pre").first \
        .inner_text()


def press_slider(page: Any, name: str, key: str = "ArrowRight") -> None:
    """Press ``key`` on the handle of the slider ``pdeflow-<name>`` (one step)."""
    page.locator(f".pdeflow-{name} .noUi-handle").first.press(key)


PROBE = """(marker) => {
  const probe = {key: null, shown: null};
  window.__pdeflow_probe = probe;
  window.addEventListener("keydown", () => { probe.key = performance.now(); },
                          {capture: true, once: true});
  for (const doc of Bokeh.documents) {
    doc.on_change((event) => {
      if (probe.key !== null && probe.shown === null && event.attr === "text"
          && String(event.value).includes(marker)) {
        probe.shown = -1;  // painted two animation frames after the change arrived
        requestAnimationFrame(() => requestAnimationFrame(() => {
          probe.shown = performance.now(); }));
      }
    });
  }
}"""
"""Times, in the page, a key press until the text ``marker`` has arrived from the server
and the browser has painted the frame after it."""


def key_to_picture(page: Any, slider: str, marker: str, key: str = "ArrowRight",
                   timeout: float = 30.0) -> float:
    """Seconds from pressing ``key`` on ``slider`` until a text containing ``marker``
    came from the server (with the new figures: one message) and was painted; timed
    by the browser's clock, so the test's polling does not count."""
    page.evaluate(PROBE, marker)
    press_slider(page, slider, key)
    page.wait_for_function("() => window.__pdeflow_probe.shown > 0", polling="raf",
                           timeout=timeout * 1000)
    probe = page.evaluate("() => window.__pdeflow_probe")
    return (probe["shown"] - probe["key"]) / 1000.0


def slider_latency(page: Any, slider: str, marker: Callable[[int], str], moves: int = 3,
                   key: str = "ArrowRight") -> list[float]:
    """:func:`key_to_picture` for ``moves`` presses on ``slider``; ``marker(i)`` is the
    text the i-th press shows (i = 1, 2, ...), e.g. the override in the summary."""
    return [key_to_picture(page, slider, marker(i), key) for i in range(1, moves + 1)]


FIGURE_TITLES = """() => {
  const ctx = document.createElement("canvas").getContext("2d");
  const out = {};
  // the plot areas as laid out: [top, bottom] in the figure's canvas, per model id
  const frames = {};
  const walk = (v) => {
    if (v.frame && v.model) frames[v.model.id] = [v.frame.bbox.y0, v.frame.bbox.y1];
    for (const c of v.child_views || []) walk(c);
  };
  for (const v of Bokeh.index.roots || []) walk(v);
  for (const doc of Bokeh.documents) {
    for (const m of doc.all_models) {
      if (!m.css_classes || !m.title || m.title.text === undefined) continue;
      const t = m.title;
      ctx.font = `${t.text_font_style} ${t.text_font_size} ${t.text_font}`;
      const width = ctx.measureText(t.text).width;
      // the y axis' label, drawn upright along the figure's height
      let ylabel = 0;
      for (const axis of m.left || []) {
        if (!axis.axis_label) continue;
        ctx.font = `${axis.axis_label_text_font_style} ${axis.axis_label_text_font_size} ` +
                   `${axis.axis_label_text_font}`;
        ylabel = Math.max(ylabel, ctx.measureText(String(axis.axis_label)).width);
      }
      for (const c of m.css_classes)
        out[c] = {text: t.text, font_px: parseFloat(t.text_font_size) *
                  (String(t.text_font_size).endsWith("pt") ? 4 / 3 : 1),
                  width, ylabel, plot_width: m.inner_width,
                  frame: frames[m.id] || null};
    }
  }
  return out;
}"""
"""Per CSS class of a Bokeh figure: its title, the title's font size [px], the width
the browser needs to draw it [px] (a canvas title that does not fit is cut off), and
the length of its y axis' label [px] (upright, centred on the plot area: it must not
reach beyond the figure's top or bottom), the width of its plot area [px] (the figure
less its axes, toolbar and a legend beside it) and the plot area's top and bottom [px]
from the figure's top."""


TITLE_INDENT_PX = 90
"""Room left of a figure's title: the y axis with its label and tick labels [px]."""


PLOT_MIN_PX = 300
"""The narrowest plot area a figure may have [px]. It replaces "the figure at least half
the viewport", which did not see a legend beside the plot: under it the dam-break
plots were 345 px of 644 at 1024x768 with the side bar folded; with their legends above
they are 315 px beside the results with the side bar shown, 555 px with it folded."""


def figure_titles(page: Any) -> dict[str, dict[str, Any]]:
    """:data:`FIGURE_TITLES` of the page (keys ``pdeflow-<name>``)."""
    return page.evaluate(FIGURE_TITLES)


def layout_problems(page: Any, figures: Sequence[str], others: Sequence[str] = ()
                    ) -> list[str]:
    """What does not fit the page's viewport, one sentence each ([] if all fits).

    Every figure ``pdeflow-<name>`` of ``figures`` must be visible, with a plot area
    at least :data:`PLOT_MIN_PX` wide, inside the viewport left and right, and wide
    enough for its title;
    every element of ``others`` inside the viewport left and right; and the page must
    not scroll sideways (what sticks out on the right would be cut off on a projector).
    """
    width = page.viewport_size["width"]
    problems = []
    scroll = page.evaluate("() => document.documentElement.scrollWidth")
    if scroll > width:
        problems.append(f"the page is {scroll} px wide in a {width} px viewport")
    titles = figure_titles(page)
    for name in (*figures, *others):
        loc = page.locator(f".pdeflow-{name}").first
        box = loc.bounding_box() if loc.is_visible() else None
        if box is None:
            problems.append(f"{name}: not shown")
            continue
        left, right = box["x"], box["x"] + box["width"]
        if left < 0 or right > width + 0.5:
            problems.append(f"{name}: from {left:.0f} to {right:.0f} px, outside the "
                            f"{width} px viewport")
        if name not in figures:
            continue
        title = titles.get(f"pdeflow-{name}")
        if title and title["plot_width"] < PLOT_MIN_PX:
            problems.append(f"{name}: a plot area {title['plot_width']:.0f} px wide, "
                            f"less than {PLOT_MIN_PX} px")
        # the title starts above the plot area, right of the y axis (its labels take
        # up to TITLE_INDENT_PX)
        if title and title["width"] + TITLE_INDENT_PX > box["width"]:
            problems.append(f"{name}: its title needs {title['width']:.0f} px, the "
                            f"figure is {box['width']:.0f} px wide")
        # the y label is centred on the plot area; beyond the figure's canvas it is cut
        # (above or below the plot area, beside the title or a legend, it is drawn)
        if title and not title["frame"]:
            problems.append(f"{name}: its plot area is not among Bokeh's views")
        elif title:
            middle = (title["frame"][0] + title["frame"][1]) / 2
            if title["ylabel"] / 2 > min(middle, box["height"] - middle):
                problems.append(f"{name}: its y axis' label needs {title['ylabel']:.0f} "
                                f"px, centred {middle:.0f} px below the top of a "
                                f"figure {box['height']:.0f} px high")
    return problems
