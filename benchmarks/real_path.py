"""A real avalanche path from AvaFrame's public repository, run to rest by pdeflow's
single layer over its DEM (issue 37's documented example and its timing).

    python benchmarks/real_path.py --avaframe PATH [--path avaHit] [--out DIR]

PATH is a checkout of https://github.com/avaframe/AvaFrame (nothing of it is copied
here): the DEM ``avaframe/data/<path>/Inputs/<path>.asc`` and the release
``Inputs/REL/*.shp`` are read with pdeflow's readers (shapefiles: the ``terrain``
extra). The grid's cell corners are the DEM's cell centres (the bed there is the DEM's
value), its cells the DEM's size; no-data cells around the path's outline are filled
with the nearest value (:func:`pdeflow.terrain.resample.filled_nearest`) and the mass
that ends on them is reported. The release thickness (the shapefile's 1 m, slope-normal
as AvaFrame measures it) becomes a vertical depth; Coulomb friction ``--phi`` [deg];
open boundaries; fv-split on ``--threads`` threads until all is at rest, or until the
kinetic energy has fallen below ``--stop-energy`` times its peak (AvaFrame's com1DFA
stops so: ``stopCrit`` 0.01 of ``kinEnergy``; sampled every 1 s), or ``--t-end``. A
first run of one step compiles; the timed run is the second. Prints the
grid, the wall time, steps, the time at rest, the mass centre's travel angle, the
affected area (peak depth > 0.1 m) and the largest peaks; with ``--out`` writes the
peak rasters (.asc, the DEM's CRS) and the peak depth over the hillshade.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from pathlib import Path

import numpy as np
from pde import CartesianGrid
from pde.trackers.base import FinishedSimulation
from pde.trackers.trackers import CallbackTracker

import pdeflow
from pdeflow.metrics_2d import peak_fields
from pdeflow.terrain import (
    bed_on_grid,
    peak_rasters,
    read_raster,
    release_mask,
    shapefile_polygons,
    vertical_thickness,
)
from pdeflow.terrain.resample import filled_nearest
from pdeflow.trackers.peaks import PeakTracker

AFFECTED = 0.1
"""peak depth [m] above which a cell counts as affected"""
DENSITY = 200.0
"""flow density of the peak pressure [kg/m^3] (AvaFrame's snow default)"""


def load(root: Path, path: str) -> tuple:
    """(grid, bed corners (nx+1, ny+1), cell beds (nx, ny), filled-cell mask at the
    cells, release polygons, the DEM) of AvaFrame's ``path`` under ``root``."""
    inputs = root / "avaframe" / "data" / path / "Inputs"
    dem = read_raster(next(p for p in inputs.glob("*.asc")))
    filled, nodata = filled_nearest(dem)
    xs, ys = dem.x_centres, dem.y_centres[::-1]  # corners: the DEM's centres, y up
    cs = dem.cellsize
    grid = CartesianGrid([[xs[0], xs[-1]], [ys[0], ys[-1]]], [xs.size - 1, ys.size - 1])
    corners = bed_on_grid(filled, xs, ys)
    beds = 0.25 * (corners[:-1, :-1] + corners[1:, :-1] + corners[:-1, 1:]
                   + corners[1:, 1:])
    off = nodata[::-1].T  # (ncols, nrows), y up: no-data at the corners
    off_cells = off[:-1, :-1] | off[1:, :-1] | off[:-1, 1:] | off[1:, 1:]
    polygons = [p for f in sorted((inputs / "REL").glob("*.shp"))
                for p in shapefile_polygons(f)]
    assert abs(grid.discretization[0] - cs) < 1e-9 * cs
    return grid, corners, beds, off_cells, polygons, dem


class EnergyStop:
    """Ends a run (FinishedSimulation) once its kinetic energy sum h |u|^2 / 2 [m^4/s^2
    per cell area] has fallen below ``fraction`` of the largest seen: com1DFA's rule."""

    def __init__(self, fraction: float):
        self.fraction = fraction
        self.peak = 0.0
        self.stopped_at: float | None = None

    def __call__(self, state, t: float) -> None:
        h, m, n = state.data
        wet = h > 1e-6
        energy = 0.5 * float(((m[wet] ** 2 + n[wet] ** 2) / h[wet]).sum())
        self.peak = max(self.peak, energy)
        if self.fraction > 0 and t > 0 and energy < self.fraction * self.peak:
            self.stopped_at = t
            raise FinishedSimulation(f"kinetic energy below {self.fraction:g} of its peak")


def run(grid, corners, depth, phi: float, threads: int, t_end: float, interval: float,
        stop_energy: float):
    """(final state, peak fields, wall time [s], solver info, the energy stop) of the
    timed run."""
    pde = pdeflow.SingleLayerGranular(phi_b_deg=phi, bed=corners,
                                      bc=(("open", "open"), ("open", "open")))
    state = pde.make_state(grid, h=depth, u=0 * depth, v=0 * depth)
    pde.solve(state, 1e-3, solver="fv-split", tracker=None, threads=threads)  # compile
    peaks = PeakTracker(interval, lambda data: peak_fields(data, 1e-6, DENSITY))
    stop = EnergyStop(stop_energy)
    start = time.perf_counter()
    end, info = pde.solve(state, t_end, solver="fv-split", threads=threads, ret_info=True,
                          tracker=[peaks, CallbackTracker(stop, interrupts=1.0)])
    return end, peaks.peak, time.perf_counter() - start, info, stop


def measure_path(root: Path, path: str = "avaHit", phi: float = 20.0,
                 thickness: float = 1.0, threads: int = 2, t_end: float = 600.0,
                 interval: float = 0.5, stop_energy: float = 0.01) -> dict:
    """The run of AvaFrame's ``path`` under the checkout ``root`` (module docstring) and
    its numbers: grid, release, wall time, steps, how and when it ended, the mass
    centre's travel angle, affected area, peaks, the mass on filled no-data cells and
    the load average; ``"_arrays"`` holds what the figure and rasters need."""
    grid, corners, beds, off, polygons, dem = load(root, path)
    dx, dy = grid.discretization
    xc, yc = grid.axes_coords
    mask = release_mask(polygons, xc, yc, dem)
    depth = vertical_thickness(mask, thickness, beds, dx, dy)
    end, peak, wall, info, stop = run(grid, corners, depth, phi, threads, t_end, interval,
                                      stop_energy)
    h = end.data[0]
    x = xc[:, None] * np.ones(grid.shape)
    y = yc[None, :] * np.ones(grid.shape)
    mass0, mass = depth.sum(), h.sum()
    drop = (depth * beds).sum() / mass0 - (h * beds).sum() / mass
    travel = math.hypot((h * x).sum() / mass - (depth * x).sum() / mass0,
                        (h * y).sum() / mass - (depth * y).sum() / mass0)
    rest = bool(np.all(end.data[1:] == 0.0))
    moving = np.any(end.data[1:] != 0.0, axis=0)
    slope = np.degrees(np.arctan(np.hypot(*np.gradient(beds, dx, dy))))[moving]
    return {"moving_mass": float(h[moving].sum() / mass),
            "moving_slopes_deg": [float(np.min(slope)), float(np.median(slope)),
                                  float(np.max(slope))] if slope.size else None,
            "path": path, "cells": list(grid.shape), "dx": float(dx),
            "released_cells": int(mask.sum()), "volume_m3": float(mass0 * dx * dy),
            "phi_deg": phi, "threads": threads, "wall_s": wall,
            "steps": int(info["solver"]["steps"]),
            "t_end_s": float(info["controller"].get("t_final", float("nan"))),
            "ended": "at rest" if rest else (
                f"kinetic energy < {stop_energy:g} of its peak"
                if stop.stopped_at is not None else "t_end"),
            "travel_angle_deg": math.degrees(math.atan2(drop, travel)),
            "affected_ha": float(np.count_nonzero(peak[0] > AFFECTED) * dx * dy / 1e4),
            "peak_depth_m": float(peak[0].max()), "peak_speed_m_s": float(peak[1].max()),
            "peak_pressure_kpa": float(peak[2].max()),
            "mass_on_fill": float(h[off].sum() / mass), "load_avg": os.getloadavg(),
            "_arrays": (xc, yc, dx, dy, beds, peak, dem.crs)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--avaframe", type=Path, required=True,
                        help="a checkout of AvaFrame's repository")
    parser.add_argument("--path", default="avaHit", help="AvaFrame's path (avaHit)")
    parser.add_argument("--phi", type=float, default=20.0, help="friction angle [deg]")
    parser.add_argument("--thickness", type=float, default=1.0,
                        help="release thickness, slope-normal [m] (the shapefile's)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--t-end", type=float, default=600.0, help="longest run [s]")
    parser.add_argument("--stop-energy", type=float, default=0.01,
                        help="end when the kinetic energy is below this fraction of its "
                             "peak (0: only at rest)")
    parser.add_argument("--interval", type=float, default=0.5,
                        help="peak fields sampled every ... [s]")
    parser.add_argument("--out", type=Path, help="directory for rasters and figure")
    args = parser.parse_args()
    r = measure_path(args.avaframe, args.path, args.phi, args.thickness, args.threads,
                     args.t_end, args.interval, args.stop_energy)
    print(f"{r['path']}: {r['cells'][0]} x {r['cells'][1]} cells of {r['dx']:.3f} m, "
          f"{r['released_cells']} released ({r['volume_m3']:.0f} m^3), phi "
          f"{r['phi_deg']:g} deg, {r['threads']} threads, load {r['load_avg'][0]:.2f}")
    print(f"  wall {r['wall_s']:.2f} s, {r['steps']} steps, ended at t = {r['t_end_s']:.1f}"
          f" s ({r['ended']}), at rest: {r['ended'] == 'at rest'}")
    if r["moving_slopes_deg"]:
        lo, mid, hi = r["moving_slopes_deg"]
        print(f"  still moving: {r['moving_mass']:.2%} of the mass, on slopes of "
              f"{lo:.0f}-{hi:.0f} deg (median {mid:.0f})")
    print(f"  mass centre travel angle {r['travel_angle_deg']:.2f} deg")
    print(f"  affected area (peak depth > {AFFECTED:g} m) {r['affected_ha']:.2f} ha; peak "
          f"depth {r['peak_depth_m']:.2f} m, speed {r['peak_speed_m_s']:.1f} m/s, pressure "
          f"{r['peak_pressure_kpa']:.0f} kPa; mass on filled no-data cells "
          f"{r['mass_on_fill']:.2%}")
    if args.out:
        from pdeflow.terrain_figures import hillshade_figure

        xc, yc, dx, dy, beds, peak, crs = r["_arrays"]
        args.out.mkdir(parents=True, exist_ok=True)
        peak_rasters(peak, xc[0] - dx / 2, yc[0] - dy / 2, dx, args.out, crs)
        extent = (xc[0] - dx / 2, xc[-1] + dx / 2, yc[0] - dy / 2, yc[-1] + dy / 2)
        hillshade_figure(beds, peak[0], extent, args.out / f"{r['path']}_peak_depth.png",
                         "peak depth [m]", threshold=AFFECTED)


if __name__ == "__main__":
    main()
