"""The numbers docs/terrain.md quotes for the flow over a bed (issue 37).

    python benchmarks/terrain_checks.py            # about 10 s after compiling

Prints (1) the largest method-of-lines rate of a lake at rest on a random bed, fully
wet and with a shore in a bowl; (2) the energy-line check on AvaFrame's parabolic path
(fall height 1000 m, mean slope 34 deg): a release of 1 m over 200 m near the top,
friction 25 deg, on a strip 4 cells across, run to rest with fv-split; the mass
centre's travel angle against the friction angle, per cell size, with the wall time.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from pde import CartesianGrid

import pdeflow
from pdeflow.numerics.geometry import bed_at_corners
from pdeflow.terrain.topographies import parabola

WALLS = (("wall", "wall"), ("wall", "wall"))


def cell_beds(corners: np.ndarray) -> np.ndarray:
    """The cells' beds [m], each the mean of its four corners."""
    c = corners
    return 0.25 * (c[:-1, :-1] + c[1:, :-1] + c[:-1, 1:] + c[1:, 1:])


def lake_rate(grid: CartesianGrid, bed, level: float) -> tuple[float, float]:
    """(largest |rate| of the lake at rest at ``level`` [m] over ``bed``, wet fraction)."""
    corners = bed_at_corners(grid, bed)
    h = np.maximum(level - cell_beds(corners), 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=1e-6, bc=WALLS, bed=corners)
    state = pde.make_state(grid, h=h, u=0 * h, v=0 * h)
    rate = pde.make_evolution_rate(state, "numba")(state.data, 0.0)
    return float(np.abs(rate).max()), float(np.mean(h > 0))


def energy_line(dx: float, phi_deg: float = 25.0, depth: float = 1.0) -> tuple[float, float]:
    """(travel angle of the mass centre [deg], wall time [s]) on the parabola."""
    grid = CartesianGrid([[0, 2600], [-2 * dx, 2 * dx]], [round(2600 / dx), 4])
    corners = bed_at_corners(grid, parabola)
    x = grid.axes_coords[0][:, None] * np.ones(grid.shape)
    h = np.where((x > 100) & (x < 300), depth, 0.0)
    pde = pdeflow.SingleLayerGranular(phi_b_deg=phi_deg, bed=corners,
                                      bc=(("wall", "open"), ("wall", "wall")))
    state = pde.make_state(grid, h=h, u=0 * h, v=0 * h)
    start = time.perf_counter()
    end = pde.solve(state, 600.0, solver="fv-split", tracker=None)
    wall = time.perf_counter() - start
    if np.any(end.data[1:] != 0.0):
        raise RuntimeError(f"dx = {dx:g} m: not at rest after 600 s")
    z = cell_beds(corners)
    h1 = end.data[0]
    drop = (h * z).sum() / h.sum() - (h1 * z).sum() / h1.sum()
    travel = (h1 * x).sum() / h1.sum() - (h * x).sum() / h.sum()
    return math.degrees(math.atan(drop / travel)), wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dx", type=float, nargs="+", default=[20.0, 10.0, 5.0, 2.5],
                        help="cell sizes of the energy-line check [m]")
    args = parser.parse_args()
    rough = np.random.default_rng(1).uniform(0.0, 1.0, (51, 41))
    rate, wet = lake_rate(CartesianGrid([[0, 100], [0, 80]], [50, 40]), rough, 2.0)
    print(f"lake at rest on a random bed (0-1 m, level 2 m, 50 x 40 cells, {wet:.0%} wet): "
          f"max |rate| = {rate:.1e}")
    def bowl(x, y):
        return 0.002 * (x ** 2 + y ** 2) + 0.3 * np.sin(x / 7) * np.cos(y / 5)

    rate, wet = lake_rate(CartesianGrid([[-50, 50], [-50, 50]], [40, 40]), bowl, 2.0)
    print(f"lake at rest in a bowl with a shore (40 x 40 cells, {wet:.0%} wet): "
          f"max |rate| = {rate:.3f}")
    print("energy line on the parabola, friction 25 deg, 1 m released over x = 100-300 m")
    print("  dx [m]   travel angle [deg]   excess [deg]   wall [s]")
    for dx in args.dx:
        angle, wall = energy_line(dx)
        print(f"  {dx:6g}   {angle:18.2f}   {angle - 25.0:12.2f}   {wall:8.2f}")


if __name__ == "__main__":
    main()
