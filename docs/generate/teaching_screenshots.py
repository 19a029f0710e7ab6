"""Regenerate the screenshots of docs/teaching.md, and measure what that page quotes.

    python docs/generate/teaching_screenshots.py          # minutes: includes a cold start
    python docs/generate/teaching_screenshots.py --warm   # kernels cached: no cold start
    python docs/generate/teaching_screenshots.py --hillside   # the hillside page's only

Starts ``pdeflow app`` of this checkout with an empty numba cache (a fresh machine, as
far as the kernels go), screenshots the page while it compiles, times how long the
dam-break page takes to show its first result, then screenshots each page on a wide
screen (1920x1080) and on a projector (1024x768, presentation mode), the 35 deg
exercise with its warnings, times slider moves on the dam-break page (key press to
painted picture, measured in the browser), and times a second start with the kernels
cached. Every time is printed with the machine's load average (``os.getloadavg``): on a
shared machine the times grow with the load. Needs Debian's Chromium
(/usr/bin/chromium) and Playwright (the test extra).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # this checkout's pdeflow, as the server runs it

from tests.browser import (  # noqa: E402
    READY,
    app_server,
    chromium,
    figure_titles,
    open_page,
    press_slider,
    slider_latency,
    text,
)

FIGURES = ROOT / "docs" / "figures"
WIDE = (1920, 1080)
PROJECTOR = (1024, 768)
MOVES = 8


def _load() -> str:
    """The load average over the last minute, as the printed times quote it."""
    return f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"


def _wait(predicate, timeout: float = 120.0) -> None:
    t0 = time.monotonic()
    while not predicate():
        if time.monotonic() - t0 > timeout:
            raise TimeoutError("the page did not finish")
        time.sleep(0.05)


def _shown_time(page: Any) -> float:
    """The time [s] in the depth figure's title ('...: t = 0.40 s ...')."""
    title = figure_titles(page)["pdeflow-depths"]["text"]
    return float(title.split("t = ")[1].split(" s")[0])


def _to_time(page: Any, t: float) -> None:
    """Stop the animation (the page opens playing) and step to time ``t`` [s], a frame
    per click (the two models' frames come at slightly different times, so two frames
    may show the same rounded time)."""
    page.locator(".pdeflow-player button.pause").click()
    page.locator(".pdeflow-player button.first").click()
    _wait(lambda: _shown_time(page) == 0.0, 10)
    for _ in range(500):
        if _shown_time(page) >= t - 1e-9:
            break
        page.locator(".pdeflow-player button.next").click()
        time.sleep(0.2)  # the server draws the frame
    time.sleep(1)


def cold_start(browser: Any, url: str, t_start: float) -> None:
    """The page while the kernels compile, and the time to the first picture."""
    page = browser.new_page(viewport={"width": PROJECTOR[0], "height": PROJECTOR[1]})
    page.goto(url)
    status = page.locator(".pdeflow-kernels div").first
    status.wait_for(timeout=120_000)
    time.sleep(3)
    page.screenshot(path=FIGURES / "teaching_compiling.png")
    print(f"while compiling the page says: {status.inner_text()!r}")
    page.locator(READY["dam-break"]).wait_for(timeout=900_000)
    print(f"cold start (empty numba cache) to the first dam-break picture: "
          f"{time.monotonic() - t_start:.0f} s ({_load()})")
    page.close()


def dam_break(browser: Any, url: str) -> None:
    """Slider latency, then the page at t = 0.4 s, wide and on the projector."""
    page, _ = open_page(browser, url, "dam-break", viewport=WIDE)
    page.locator(".pdeflow-player button.pause").click()
    times = slider_latency(page, "phi_b_two", lambda i: f"two_layer.phi_b_deg={41 - i}",
                           moves=MOVES, key="ArrowLeft")
    print(f"dam break 5.1 (dx = 0.05 m), slider release to painted picture, {MOVES} "
          f"moves: {', '.join(f'{1000 * t:.0f}' for t in times)} ms; median "
          f"{1000 * statistics.median(times):.0f} ms ({_load()})")
    for _ in range(MOVES):  # back to the case's own phi_B
        press_slider(page, "phi_b_two", "ArrowRight")
    _wait(lambda: "--set" not in text(page, "summary"))
    _to_time(page, 0.4)
    page.screenshot(path=FIGURES / "teaching_dam_break.png", full_page=True)
    page.close()
    page, _ = open_page(browser, url, "dam-break", viewport=PROJECTOR, query="present=1")
    _to_time(page, 0.4)
    page.screenshot(path=FIGURES / "teaching_dam_break_projector.png")
    page.close()


def slope_35(browser: Any, url: str) -> None:
    """teaching.md's exercise: the bed tilted to 35 deg, with the warnings."""
    page, _ = open_page(browser, url, "dam-break", viewport=PROJECTOR)
    press_slider(page, "slope", "End")
    _wait(lambda: page.locator(".pdeflow-warnings").first.is_visible()
          and "97 %" in text(page, "warnings"))
    _to_time(page, 0.4)
    page.screenshot(path=FIGURES / "teaching_slope_35.png")
    print("35 deg on the 7 m domain, the page warns:\n  "
          + "\n  ".join(r for r in text(page, "warnings").splitlines() if r.strip()))
    page.close()


def other_pages(browser: Any, url: str) -> None:
    page, _ = open_page(browser, url, "run-out", viewport=WIDE)
    _wait(lambda: "computing" not in text(page, "fits"))
    time.sleep(1)
    page.screenshot(path=FIGURES / "teaching_runout.png", full_page=True)
    page.close()
    page, _ = open_page(browser, url, "hyperbolicity", viewport=WIDE)
    time.sleep(1)
    page.screenshot(path=FIGURES / "teaching_hyperbolicity.png", full_page=True)
    page.close()


def _shown_seconds(page: Any) -> float | None:
    """The hillside page's time [s] in its status line ('t = 12.5 s ...'), if shown."""
    status = text(page, "status")
    return float(status.split("t = ")[1].split(" s")[0]) if status.startswith("t = ") \
        else None


def hillside(browser: Any, url: str) -> None:
    """The hillside page: the default release on a projector in presentation mode,
    caught while it flows; and the deposit with its table on a wide screen."""
    page, log = open_page(browser, url, "hillside", viewport=PROJECTOR, query="present=1")
    page.locator(".pdeflow-run button").first.click()
    _wait(lambda: (_shown_seconds(page) or 0.0) >= 20.0)
    page.screenshot(path=FIGURES / "teaching_hillside_projector.png")
    page.close()
    page, log = open_page(browser, url, "hillside", viewport=WIDE)
    page.locator(".pdeflow-run button").first.click()
    _wait(lambda: "done in" in text(page, "status"))
    time.sleep(1)
    page.screenshot(path=FIGURES / "teaching_hillside.png", full_page=True)
    print(f"hillside page, default release: {text(page, 'status')} ({_load()})")
    if log.errors:
        raise RuntimeError(f"the hillside page logged errors: {log.errors[:3]}")
    page.close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warm", action="store_true",
                    help="use the usual numba cache (no cold start, no compiling screenshot)")
    ap.add_argument("--hillside", action="store_true",
                    help="only the hillside page's screenshots (kernels cached)")
    args = ap.parse_args(argv)
    warm = args.warm
    FIGURES.mkdir(exist_ok=True)
    if args.hillside:
        with chromium() as browser, app_server(ROOT) as url:
            hillside(browser, url)
        print("wrote docs/figures/teaching_hillside{,_projector}.png")
        return 0
    with tempfile.TemporaryDirectory() as tmp, chromium() as browser:
        env = {} if warm else {"NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        t_start = time.monotonic()
        with app_server(ROOT, env=env, log=Path(tmp) / "server.log") as url:
            if not warm:
                cold_start(browser, url, t_start)
            dam_break(browser, url)
            slope_35(browser, url)
            other_pages(browser, url)
            hillside(browser, url)
        t_start = time.monotonic()  # again, with the kernels now in the cache
        with app_server(ROOT, env=env) as url:
            page, _ = open_page(browser, url, "dam-break")
            print(f"warm start (kernels cached) to the first dam-break picture: "
                  f"{time.monotonic() - t_start:.1f} s ({_load()})")
            page.close()
    for name in ("dam_break", "dam_break_projector", "slope_35", "runout",
                 "hyperbolicity", "hillside", "hillside_projector",
                 *(() if warm else ("compiling",))):
        print(f"wrote docs/figures/teaching_{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
