"""The app's warm start: ``pdeflow app`` started to the dam-break page's first picture.

As ``docs/generate/teaching_screenshots.py`` times its second start (kernels cached):
the clock starts before the server process (``tests.browser.app_server``) and
stops when the page, loaded in headless Chromium, shows its first result
(``READY["dam-break"]``). One start first fills the numba cache this benchmark uses
(a directory of its own), then ``repeats`` warm starts; the median is reported.
Needs Debian's Chromium and Playwright, like the browser tests.
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

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # the browser driver is test support: tests/browser.py


def warm_start_to_first_picture(repeats: int = 5,
                                 trees: tuple[Path, ...] = (ROOT,)) -> dict[str, Any]:
    """Seconds from ``pdeflow app`` started to the first dam-break picture, kernels
    cached, for the checkout of each of ``trees`` (several: their starts interleaved,
    each with a numba cache of its own): ``{"walls_s": [[...] per tree], "median_s":
    [...], "load_avg_at_start": ..., "load_avg_at_end": ...}``."""
    from tests.browser import app_server, chromium, open_page

    walls: list[list[float]] = [[] for _ in trees]
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp, chromium() as browser:
        for i in range(repeats + 1):  # the first start fills the cache
            for k, tree in enumerate(trees):
                env = {"NUMBA_CACHE_DIR": str(Path(tmp) / f"numba{k}")}
                t0 = time.monotonic()
                with app_server(tree, env=env) as url:
                    page, _ = open_page(browser, url, "dam-break")
                    wall = time.monotonic() - t0
                    page.close()
                if i:
                    walls[k].append(wall)
    return {"walls_s": walls, "median_s": [statistics.median(w) for w in walls],
            "trees": [str(t) for t in trees],
            "load_avg_at_start": load, "load_avg_at_end": os.getloadavg()[0]}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs="*", type=Path, default=[ROOT],
                    help="checkouts to compare, their starts interleaved (default: this one)")
    ap.add_argument("--repeats", type=int, default=5, help="warm starts per tree")
    a = ap.parse_args(argv)
    if a.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {a.repeats}")
    out = warm_start_to_first_picture(a.repeats, tuple(a.trees))
    for tree, median, walls in zip(out["trees"], out["median_s"], out["walls_s"],
                                   strict=True):
        print(f"{tree}: warm start to the first dam-break picture {median:.1f} s median "
              f"({', '.join(f'{w:.1f}' for w in walls)}; load "
              f"{out['load_avg_at_start']:.1f} -> {out['load_avg_at_end']:.1f})")


if __name__ == "__main__":
    main()
