"""Regenerate docs/rheology.md: every basal friction law on the planar and axisymmetric
collapses, both models, on refined grids, against the experiments and Lagree et al. (2011).

    python docs/generate/rheology.py            # runs what the cache lacks, then the page
    python docs/generate/rheology.py --rerun    # runs every point again, then the page
    python docs/generate/rheology.py --no-runs  # the page from the cache as it is
    python docs/generate/rheology.py --runs-only  # fill the cache only (resumable)

The points (geometry, model, law set, grid, aspect ratio) are those of
docs/generate/rheology_runs.py; each is one run to rest whose row goes to
docs/rheology/sweep.csv as soon as it ends, so an interrupted call resumes. The page's
numbers (rheology_numbers.page_numbers, only complete grids count) are stored in
docs/rheology/numbers.json and rendered by rheology_page.render_page. The options below
the first four shrink the sweep (the tests run it on coarse grids into a temporary
directory).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import rheology_runs as runs
import run_cache
from rheology_figures import figures
from rheology_numbers import page_numbers
from rheology_page import render_page

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "benchmarks" / "measurements" / "bench.json"


def arguments(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rerun", action="store_true", help="run every point again")
    ap.add_argument("--no-runs", action="store_true", help="the page from the cache")
    ap.add_argument("--runs-only", action="store_true", help="fill the cache, no page")
    ap.add_argument("--out", default=str(ROOT / "docs"),
                    help="output directory (rheology.md, figures/, rheology/)")
    ap.add_argument("--planar-grids", type=float, nargs="+",
                    default=list(runs.GRIDS["planar"]), help="planar dx [m], coarse first")
    ap.add_argument("--axisymmetric-grids", type=float, nargs="+",
                    default=list(runs.GRIDS["axisymmetric"]), help="radial dr [m]")
    ap.add_argument("--planar-ratios", type=float, nargs="+",
                    default=list(runs.RATIOS["planar"]))
    ap.add_argument("--axisymmetric-ratios", type=float, nargs="+",
                    default=list(runs.RATIOS["axisymmetric"]))
    ap.add_argument("--planar-length", type=float, default=runs.LENGTH["planar"],
                    help="planar domain [m]")
    ap.add_argument("--axisymmetric-length", type=float,
                    default=runs.LENGTH["axisymmetric"], help="radial domain [m]")
    return ap.parse_args(argv)


def stored_cost(path: Path = BENCH) -> dict | None:
    """The friction-law rows of the stored benchmark results (docs/performance.md's
    section, ``python benchmarks/run_benchmarks.py --only laws``), if measured."""
    if not path.is_file():
        return None
    b = json.loads(path.read_text())
    if not b.get("friction_laws"):
        return None
    return {"rows": b["friction_laws"], "conditions": b.get("friction_laws_conditions")}


def main(argv: list[str] | None = None) -> int:
    """Fill the cache (unless --no-runs), then (unless --runs-only) write the page, its
    figures and numbers."""
    args = arguments(argv)
    out = Path(args.out)
    cache = out / "rheology" / "sweep.csv"
    grids = {"planar": tuple(args.planar_grids),
             "axisymmetric": tuple(args.axisymmetric_grids)}
    ratios = {"planar": tuple(args.planar_ratios),
              "axisymmetric": tuple(args.axisymmetric_ratios)}
    length = {"planar": args.planar_length, "axisymmetric": args.axisymmetric_length}
    points = runs.all_points(grids, ratios)
    t0 = time.perf_counter()
    if args.no_runs:
        rows = runs.read_cache(cache)
    else:
        rows = runs.fill_cache(points, cache, rerun=args.rerun, length=length)
    if args.runs_only:
        return 0
    wanted = set(points)
    rows = [r for r in rows if runs.key(r) in wanted]
    numbers = page_numbers(rows)
    numbers["static_angles"] = {g: runs.static_angles(g) for g in ("planar", "axisymmetric")}
    numbers["static_depth"] = runs.STATIC_DEPTH
    numbers["cost"] = stored_cost()
    before = run_cache.snapshot((out / "figures").glob("rheology_*.png"))
    numbers["figures"] = figures(numbers, out)
    run_cache.publish(numbers, t0, out / "rheology" / "numbers.json", out / "rheology.md",
                      lambda n: render_page(n, n["figures"]), before)
    print(f"written: {out / 'rheology.md'} ({len(rows)} runs)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
