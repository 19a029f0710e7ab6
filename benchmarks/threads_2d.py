"""One thread against two on a 2D grid (issue 36: "2 threads >= 1.7x one thread on a
512 x 512 wet grid").

The set-up of :mod:`two_d_cost` (a circular dam in an L x L walled box of material on a
45 deg slope: every cell wet and moving, none skipped), hll/first-order, fv-split
(Lie) through its stepper, to ``--t-end``; both models, each with ``threads`` 1 and 2
(:mod:`pdeflow.numerics.threads`). The four runs are timed in interleaved rounds in one
process (compiled first); the table gives the median wall time of each, its CPU time
(all threads: two threads that wait for each other add to it), ns per cell update, and
the speed-up (median of one thread over median of two). It also checks
that both thread counts give the same state, bit for bit.

Run: ``python benchmarks/threads_2d.py [--cells 512] [--repeats 3] [--t-end 0.05]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from two_d_cost import SCHEME, setups_2d, stepper_run  # noqa: E402


def runs(n: int, t_end: float) -> dict[tuple[str, int], Callable[[], Any]]:
    """The timed runs on n x n cells: (model, threads) -> run."""
    _, states = setups_2d(n)
    return {(model, threads): stepper_run(eq, state, t_end, threads=threads)
            for model, (eq, state) in states.items() for threads in (1, 2)}


def interleaved(fns: list[Callable[[], Any]], repeats: int) -> list[list[tuple[float, float]]]:
    """(wall, CPU) times [s] of every ``fn`` over ``repeats`` interleaved rounds (A B C
    A B C ..., so that a change of the machine's load hits all alike); CPU: this
    process's, all its threads."""
    times: list[list[tuple[float, float]]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, out in zip(fns, times, strict=True):
            w0, c0 = time.perf_counter(), time.process_time()
            fn()
            out.append((time.perf_counter() - w0, time.process_time() - c0))
    return times


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=512, help="cells per side (n)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--t-end", type=float, default=0.05, help="end of each run [s]")
    args = ap.parse_args()
    fns = runs(args.cells, args.t_end)
    first = {k: fn() for k, fn in fns.items()}  # also the warm-up (compilation)
    load0 = os.getloadavg()[0]
    times = dict(zip(fns, interleaved(list(fns.values()), args.repeats), strict=True))
    walls = {k: [w for w, _ in v] for k, v in times.items()}
    cpus = {k: [c for _, c in v] for k, v in times.items()}
    load = os.getloadavg()[0]
    print(f"{args.cells} x {args.cells} cells, t = {args.t_end} s, {SCHEME}, median of "
          f"{args.repeats} interleaved rounds; load average {load0:.2f} before, "
          f"{load:.2f} after")
    print(f"{'run':<24}{'steps':>7}{'wall [s]':>10}{'CPU [s]':>9}{'ns/update':>11}")
    for (model, threads), w in walls.items():
        steps = first[model, threads]["steps"]
        wall = statistics.median(w)
        ns = 1e9 * wall / (steps * args.cells ** 2)
        print(f"{model + f', {threads} thread' + ('s' if threads > 1 else ''):<24}"
              f"{steps:>7}{wall:>10.3f}{statistics.median(cpus[model, threads]):>9.3f}"
              f"{ns:>11.1f}")
    for model in ("single layer", "two layers"):
        same = np.array_equal(first[model, 1]["data"], first[model, 2]["data"])
        gain = statistics.median(walls[model, 1]) / statistics.median(walls[model, 2])
        print(f"{model}: 1 thread / 2 threads = {gain:.2f} (target >= 1.7); "
              f"same bits: {same}")


if __name__ == "__main__":
    main()
