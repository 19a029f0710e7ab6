"""Regenerate the screenshots of docs/teaching.md, and measure what that page quotes.

    python docs/generate/teaching_screenshots.py          # ~2 min: includes a cold start

Starts ``pdeflow app`` of this checkout with an empty numba cache (a fresh machine, as
far as the kernels go), screenshots the page while it compiles, times how long the
dam-break page takes to show its first result, then screenshots each page, times
slider moves on the dam-break page (key press to painted picture, measured in the
browser), and times a second start with the kernels cached. Needs Debian's Chromium
(/usr/bin/chromium) and Playwright (the test extra).
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # this checkout's pdeflow, as the server runs it

from pdeflow.app.browser import (  # noqa: E402
    READY,
    app_server,
    chromium,
    open_page,
    press_slider,
    slider_latency,
    text,
)

FIGURES = ROOT / "docs" / "figures"
VIEWPORT = {"width": 1400, "height": 900}
MOVES = 8


def _wait(predicate, timeout: float = 120.0) -> None:
    t0 = time.monotonic()
    while not predicate():
        if time.monotonic() - t0 > timeout:
            raise TimeoutError("the page did not finish")
        time.sleep(0.05)


def main() -> int:
    FIGURES.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp, chromium() as browser:
        env = {"NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        t_start = time.monotonic()
        with app_server(ROOT, env=env, log=Path(tmp) / "server.log") as url:
            page = browser.new_page(viewport=VIEWPORT)
            page.goto(url)
            status = page.locator(".pdeflow-kernels div").first
            status.wait_for(timeout=120_000)
            time.sleep(3)
            page.screenshot(path=FIGURES / "teaching_compiling.png")
            print(f"while compiling the page says: {status.inner_text()!r}")
            page.locator(READY["dam-break"]).wait_for(timeout=900_000)
            cold = time.monotonic() - t_start
            print(f"cold start (empty numba cache) to the first dam-break picture: "
                  f"{cold:.0f} s")
            page.close()

            page, _ = open_page(browser, url, "dam-break",
                                viewport=(VIEWPORT["width"], VIEWPORT["height"]))
            times = slider_latency(page, "phi_b_two",
                                   lambda i: f"two_layer.phi_b_deg={41 - i}",
                                   moves=MOVES, key="ArrowLeft")
            print(f"dam break 5.1 (dx = 0.05 m), slider release to painted picture, "
                  f"{MOVES} moves: {', '.join(f'{1000 * t:.0f}' for t in times)} ms; "
                  f"median {1000 * statistics.median(times):.0f} ms")
            for _ in range(MOVES):  # back to the case's own phi_B
                press_slider(page, "phi_b_two", "ArrowRight")
            _wait(lambda: "--set" not in text(page, "summary"))
            page.locator(".pdeflow-player button.first").click()
            for _ in range(20):  # frame 20: t = 0.4 s
                page.locator(".pdeflow-player button.next").click()
            time.sleep(1)
            page.screenshot(path=FIGURES / "teaching_dam_break.png")
            page.close()

            page, _ = open_page(browser, url, "run-out",
                                viewport=(VIEWPORT["width"], VIEWPORT["height"]))
            _wait(lambda: "computing" not in text(page, "fits"))
            time.sleep(1)
            page.screenshot(path=FIGURES / "teaching_runout.png")
            page.close()

            page, _ = open_page(browser, url, "hyperbolicity",
                                viewport=(VIEWPORT["width"], 1150))
            time.sleep(1)
            page.screenshot(path=FIGURES / "teaching_hyperbolicity.png")
            page.close()
        t_start = time.monotonic()  # again, with the kernels now in the cache
        with app_server(ROOT, env=env) as url:
            page, _ = open_page(browser, url, "dam-break")
            print(f"warm start (kernels cached) to the first dam-break picture: "
                  f"{time.monotonic() - t_start:.1f} s")
            page.close()
    for name in ("compiling", "dam_break", "runout", "hyperbolicity"):
        print(f"wrote docs/figures/teaching_{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
