"""The hillside page's animation in a browser (issue 39): the time from pressing "run"
to the first frame drawn, and the frames drawn per second, while the run computes and
over the whole animation.

    python benchmarks/app_hillside.py [--repeats 3] [--json out.json]

Serves ``pdeflow app`` of this checkout (tests/browser.py: Debian's Chromium through
Playwright), opens the hillside page at 1024x768, and for each scene (the default
plane with a flat run-out and the bowl, both at the page's finest grid, 200 cells down
the path) presses run ``repeats`` times after one unmeasured run (which loads the
kernels). The page's own clock times it: every frame drawn changes the status line
to "t = ... s" (with "(computing)" while the run computes), and a listener on the
Bokeh document records when each change arrives. Medians over the repeats.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # tests.browser, and this checkout's pdeflow

from pdeflow.cases import load_case  # noqa: E402
from tests.browser import app_server, chromium, open_page, text  # noqa: E402

SCENES = (("hillside_plane.toml", 200), ("terrain_bowl.toml", 200))
"""(case file, cells down the path): 200 x 100 and 200 x 200 cells."""

PROBE = """() => {
  const probe = {click: null, frames: [], computing: []};
  window.__hillside = probe;
  for (const doc of Bokeh.documents)
    doc.on_change((event) => {
      const text = String(event.value ?? "");
      if (event.attr === "text" && text.startsWith("t = ")) {
        const now = performance.now();
        probe.frames.push(now);
        if (text.includes("(computing)")) probe.computing.push(now);
      }
    });
}"""


def _rate(times: list[float]) -> float | None:
    """Frames per second over the time stamps ``times`` [ms] (None for fewer than 3)."""
    if len(times) < 3 or times[-1] <= times[0]:
        return None
    return 1000.0 * (len(times) - 1) / (times[-1] - times[0])


def _choose(page: Any, case: str, cells: int) -> None:
    page.locator(".pdeflow-terrain select").select_option(case)
    page.locator(".pdeflow-hint").first.wait_for(timeout=60_000)
    handle = page.locator(".pdeflow-cells .noUi-handle").first
    for _ in range(40):  # the slider's steps of 10 cells, from wherever it stands
        now = int(float(handle.get_attribute("aria-valuenow")))
        if now == cells:
            break
        handle.press("ArrowRight" if now < cells else "ArrowLeft")
    page.wait_for_timeout(1500)  # the page redraws the terrain for the new grid


def _one_run(page: Any) -> dict[str, Any]:
    page.evaluate(PROBE)
    button = page.locator(".pdeflow-run button").first
    # (Panel's widgets live in shadow roots: the locator finds the button, a query
    # from the document would not)
    button.evaluate("(el) => el.addEventListener('click', () => { "
                    "window.__hillside.click = performance.now(); }, {capture: true})")
    button.click()
    # the last run's "done" stays until this run's first frame
    page.wait_for_function("() => window.__hillside.frames.length > 0", timeout=300_000)
    done = page.locator(".pdeflow-status", has_text="done in").first
    done.wait_for(timeout=300_000)
    probe = page.evaluate("() => window.__hillside")
    status = text(page, "status")
    compute = float(status.split("done in ")[1].split(" s")[0])
    return {"first_frame_s": (probe["frames"][0] - probe["click"]) / 1000.0,
            "fps_computing": _rate(probe["computing"]), "fps": _rate(probe["frames"]),
            "frames": len(probe["frames"]), "frames_computing": len(probe["computing"]),
            "compute_s": compute}


def measure(repeats: int = 3) -> list[dict[str, Any]]:
    """Per scene, the medians over ``repeats`` runs (and the runs themselves)."""
    rows = []
    with app_server(ROOT) as url, chromium() as browser:
        page, log = open_page(browser, url, "hillside", viewport=(1024, 768))
        for case, cells in SCENES:
            _choose(page, case, cells)
            _one_run(page)  # loads (or compiles) the kernels
            runs = [_one_run(page) for _ in range(repeats)]
            grid = load_case(ROOT / "cases" / case).data["grid"]
            across = max(1, round(cells * grid["width"] / grid["length"]))
            row: dict[str, Any] = {"case": case, "cells": cells, "grid": f"{cells} x {across}",
                                   "runs": runs}
            for key in ("first_frame_s", "fps_computing", "fps", "compute_s", "frames"):
                values = [r[key] for r in runs if r[key] is not None]
                row[key] = statistics.median(values) if values else None
            rows.append(row)
        if log.errors:
            raise RuntimeError(f"the page logged errors: {log.errors[:3]}")
    return rows


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3, help="runs per scene (default 3)")
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")
    t0 = time.perf_counter()
    rows = measure(args.repeats)
    print("| scene | cells | first frame [s] | frames/s while computing | frames/s "
          "overall | frames | computing [s] |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['case']} | {r['grid']} | {_fmt(r['first_frame_s'], '.2f')} "
              f"| {_fmt(r['fps_computing'], '.1f')} | {_fmt(r['fps'], '.1f')} | "
              f"{r['frames']:.0f} | {_fmt(r['compute_s'], '.2f')} |")
    print(f"(medians of {args.repeats} runs each; load average {os.getloadavg()[0]:.2f}; "
          f"{time.perf_counter() - t0:.0f} s in all)")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
