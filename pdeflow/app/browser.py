"""The app in a real browser: ``pdeflow app`` in a subprocess, driven through Playwright
in Debian's Chromium. Used by the browser tests and by
``docs/generate/teaching_screenshots.py``; needs ``playwright`` (the ``test`` extra) and
``/usr/bin/chromium`` (``apt-get install chromium``; Playwright's own browser download is
not used).
"""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]
"""Headless, no sandbox (CI runs as root), and no traffic of Chromium's own."""
READY = {"dam-break": ".pdeflow-summary pre", "run-out": ".pdeflow-fits ul",
         "hyperbolicity": ".pdeflow-spectrum ul"}
"""Per page, an element that exists once the page has shown its first result."""


@contextmanager
def app_server(root: Path, *, timeout: float = 60.0, env: dict[str, str] | None = None,
               log: Path | None = None) -> Iterator[str]:
    """Run ``pdeflow app --no-browser`` of the checkout ``root`` on a free port of
    127.0.0.1; yield the page's URL; stop the server when the block ends, also on an
    error (Ctrl-C, then kill after 10 s).

    ``root/pdeflow`` is put first on PYTHONPATH, so the server runs the same code as the
    caller; ``env`` adds variables (e.g. NUMBA_CACHE_DIR); the server's stderr goes to
    ``log`` (default: discarded).
    """
    full_env = dict(os.environ, **(env or {}))
    full_env["PYTHONPATH"] = os.pathsep.join(
        p for p in (str(root), full_env.get("PYTHONPATH", "")) if p)
    err = open(log, "w") if log else subprocess.DEVNULL  # closed in the finally below
    proc = subprocess.Popen(
        [sys.executable, "-m", "pdeflow.cli", "app", "--no-browser", "--host",
         "127.0.0.1", "--port", "0"], cwd=root, env=full_env, stdout=subprocess.PIPE,
        stderr=err, text=True)
    try:
        yield _read_url(proc, timeout)
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


@dataclass
class PageLog:
    """What a page reported: console errors, uncaught exceptions, foreign requests."""

    host: str
    errors: list[str] = field(default_factory=list)
    foreign_requests: list[str] = field(default_factory=list)
    """requests to any host but the app's (the app must work offline)"""

    def attach(self, page: Any) -> None:
        page.on("console", lambda m: self.errors.append(f"console: {m.text}")
                if m.type == "error" else None)
        page.on("pageerror", lambda e: self.errors.append(f"page error: {e}"))
        page.on("request", lambda r: self.foreign_requests.append(r.url)
                if urlparse(r.url).hostname not in (self.host, None) else None)


def open_page(browser: Any, url: str, page: str, *, timeout: float = 300.0,
              viewport: tuple[int, int] = (1500, 1000)) -> tuple[Any, PageLog]:
    """Load ``page`` ('dam-break', 'run-out', 'hyperbolicity') and wait for its first
    result (``timeout`` [s] covers compiling the kernels on a fresh machine)."""
    p = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
    log = PageLog(urlparse(url).hostname or "")
    log.attach(p)
    p.goto(f"{url}?page={page}")
    p.locator(READY[page]).first.wait_for(timeout=timeout * 1000)
    return p, log


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
