"""What a dry margin costs a 2D run (issue 36): a cylinder collapse in a domain just large
enough for it and in one of ten times the area (the same flow, more dry cells).

    python benchmarks/dry_domain_2d.py                 # dx = 25 mm, 0.5 s, 3 repeats
    python benchmarks/dry_domain_2d.py --dx 0.0125 --repeats 5

The single layer (Coulomb, phi_b = 25 deg, horizontal plane, hll/muscl/mc, fv-split) from
a column of radius 1 m and depth 1 m at the domain's centre, walls on every side. The
tight domain is a square of side ``--side`` (the flow stays inside it by ``--t``); the
large one has side sqrt(10) times that, the column at its centre. Both are compiled and
run once before the clock starts; then the two are timed in turn, ``--repeats`` times,
in this process. Printed: the median (and the least) wall and CPU time of ``solve`` and
the wall time of the stepping alone (fv-split's ``info["wall_time"]``), their ratios
large / tight (on a machine shared with other work the least and the CPU time are the
steadier ones), and a check that the large run's cells under the tight domain hold the
tight run's numbers, bit for bit (the flow never reaches the tight domain's walls, so
they are the same computation).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from pde import CartesianGrid

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # this checkout's pdeflow, not an installed one

import pdeflow  # noqa: E402


def _setup(side: float, dx: float, scheme: str):
    n = int(round(side / dx))
    grid = CartesianGrid([[-n * dx / 2, n * dx / 2]] * 2, [n, n])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    eq = pdeflow.SingleLayerGranular(theta_deg=0.0, phi_b_deg=25.0, scheme=scheme,
                                     bc=("wall", "wall"))
    return eq, eq.make_state(grid, h=np.where(np.hypot(x, y) < 1.0, 1.0, 0.0)), n


def _time(eq, state, t_end: float) -> tuple[tuple[float, float, float], np.ndarray, int]:
    """((wall, CPU, stepping) times [s], final state, steps) of one ``solve``."""
    t0 = time.perf_counter()
    c0 = time.process_time()
    out, info = eq.solve(state, t_end, solver="fv-split", tracker=None, ret_info=True)
    cpu = time.process_time() - c0
    wall = time.perf_counter() - t0
    return (wall, cpu, info["solver"]["wall_time"]), out.data, info["solver"]["steps"]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dx", type=float, default=0.025, help="cell width [m]")
    parser.add_argument("--t", type=float, default=0.5, help="simulated time [s]")
    parser.add_argument("--side", type=float, default=7.0, help="the tight domain [m]")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--scheme", default="hll/muscl/mc")
    args = parser.parse_args(argv)
    tight = _setup(args.side, args.dx, args.scheme)
    n = tight[2]
    # ten times the area, the same cells under the tight domain (an even margin)
    large = _setup((n + 2 * round(n * (math.sqrt(10.0) - 1) / 2)) * args.dx, args.dx,
                   args.scheme)
    for eq, state, _ in (tight, large):  # compile (or load) the kernels
        eq.solve(state, 0.01, solver="fv-split", tracker=None)
    times: dict[str, list[tuple[float, float, float]]] = {"tight": [], "large": []}
    for _ in range(args.repeats):
        for name, (eq, state, _) in (("tight", tight), ("large", large)):
            measured, q, steps = _time(eq, state, args.t)
            times[name].append(measured)
            if name == "tight":
                q_tight, steps_tight = q, steps
            else:
                q_large, steps_large = q, steps
    m = large[2]
    k = (m - n) // 2
    same = steps_tight == steps_large and np.array_equal(q_tight, q_large[:, k:k + n, k:k + n])
    edge = max(np.abs(q_tight[0][[0, -1], :]).max(), np.abs(q_tight[0][:, [0, -1]]).max())
    print(f"pdeflow from {Path(pdeflow.__file__).parent}")
    print(f"single layer, {args.scheme}, dx = {args.dx} m, t = {args.t} s, "
          f"{steps_tight} / {steps_large} steps, median and least of {args.repeats}")
    print("| domain | cells | solve, wall [s] | solve, CPU [s] | stepping, wall [s] |")
    print("|---|---:|---:|---:|---:|")
    for stat in (statistics.median, min):
        value = {name: [stat(t[i] for t in times[name]) for i in range(3)]
                 for name in times}
        for name, cells in (("tight", n * n), ("large", m * m)):
            print(f"| {name} ({stat.__name__}) | {cells} | "
                  + " | ".join(f"{v:.3f}" for v in value[name]) + " |")
        ratios = [a / b for a, b in zip(value["large"], value["tight"], strict=True)]
        print(f"| ratio large / tight ({stat.__name__}) | {m * m / (n * n):.2f} | "
              + " | ".join(f"{r:.3f}" for r in ratios) + " |")
    print(f"large run's cells under the tight domain = tight run's, bit for bit: {same} "
          f"(deepest cell at the tight domain's walls: {edge:.3g} m)")


if __name__ == "__main__":
    main()
