"""pdeflow over a bed side by side with AvaFrame's com1DFA on an idealised avalanche path
(issue 37): run-out, travel angles, peak fields, affected area and wall time, per code
and cell size, in one table.

The path is AvaFrame's parabola (PF: fall height 1000 m, mean slope 34 deg, flat beyond
its foot at x = 1483 m), hockey stick (HS: the 34 deg plane from 2200 m, bent into the
flat by a circle of radius 200 m) or bowl (BL: a spherical bowl of radius 500 m, its
centre at x = 500 m, the release on its side), from ``pdeflow.terrain.topographies``. This script
writes it as one ESRI ASCII DEM (5 m cells, x down the slope from the top, y across)
and **both codes read that file**: com1DFA as its DEM, pdeflow through ``read_raster``
and ``bed_on_grid`` at its grid's cell corners (the bed bilinear between the DEM's
centres). The release is a rectangle near the top (``RELEASE``), 1 m thick normal to the
slope (pdeflow: ``vertical_thickness``, the same volume); friction Coulomb tan 25 deg
(or ``--voellmy MU XI``, com1DFA's muvoellmy and xsivoellmy, pdeflow's voellmy_mu and
voellmy_xi).

- **pdeflow**: the single layer with fv-split (first order, one thread) to rest, on
  the grids of ``--dx``, a :class:`~pdeflow.trackers.peaks.PeakTracker` of
  :func:`~pdeflow.metrics_2d.peak_fields` sampled every 0.1 s (com1DFA's time step);
  the kernels are compiled first (a short run), the wall time is the solve's.
- **com1DFA** (optional): ``benchmarks/avaframe_paths.py`` in the interpreter
  ``--avaframe-python`` (default ``$PDEFLOW_AVAFRAME_PYTHON``, else this one if it
  imports avaframe); without it, pdeflow's side alone, said in one line. Its wall time
  is com1DFAMain's (one core, its outputs included).

Both are measured the same way: thickness **normal to the slope** (pdeflow's vertical
depth times cos(theta) of the bed's slope at the cell); the run-out is the downstream
edge of the farthest cell on the axis y = 0 whose peak thickness exceeds ``THRESHOLD``,
also as the travel angle from the release's top edge; the mass centre's travel angle
between the start and the end; the largest peak thickness, speed (pdeflow's horizontal
speed, com1DFA's along the surface) and pressure (200 kg/m^3 times speed^2, kPa); the
area (horizontal) where the peak thickness exceeds ``THRESHOLD``.

Run: ``python benchmarks/terrain_vs_com1dfa.py [--path parabola|hockey|bowl]
[--dx 20 10 5 2.5] [--avaframe-python /tmp/ava_venv/bin/python] [--stop-crit 0.01 0]
[--voellmy 0.155 4000]``.
Units: lengths [m], angles [deg], speeds [m/s], pressures [kPa], times [s].
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from pde import CartesianGrid

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from similarity_2d import avaframe_python  # noqa: E402  (the same lookup as its own)

import pdeflow  # noqa: E402
from pdeflow.metrics_2d import peak_fields  # noqa: E402
from pdeflow.numerics.geometry import corner_coordinates  # noqa: E402
from pdeflow.terrain import (  # noqa: E402
    Raster,
    bed_on_grid,
    read_raster,
    release_mask,
    vertical_thickness,
    write_raster,
)
from pdeflow.terrain.thickness import cos_slope  # noqa: E402
from pdeflow.terrain.topographies import bowl, hockey_stick, parabola  # noqa: E402
from pdeflow.trackers.peaks import PeakTracker  # noqa: E402

DEM_CELL = 5.0  #: [m]
RELEASE = (100.0, 300.0, -100.0, 100.0)  #: x0, x1, y0, y1 [m]
REL_TH = 1.0  #: release thickness normal to the slope [m]
PHI_DEG = 25.0  #: Coulomb friction angle [deg]
THRESHOLD = 0.1  #: peak thickness (slope-normal) counted as reached [m]
DENSITY = 200.0  #: [kg/m^3], com1DFA's rho
PEAK_INTERVAL = 0.1  #: [s], com1DFA's dt
DRY = 1e-6  #: [m]
T_MAX = 600.0  #: pdeflow's runs end at rest, at the latest here [s]
NO_AVAFRAME = ("AvaFrame is not available (pip install avaframe in its own environment, "
               "it pins numpy < 2; give its python with --avaframe-python): pdeflow only")


@dataclass(frozen=True)
class AvalanchePath:
    """An idealised path: its bed z(x, y) [m], the DEM's cell centres x in [0,
    ``dem_length``], |y| <= ``dem_half_width``, and pdeflow's domain x in [0,
    ``length``], |y| <= ``half_width`` + dx/2 [m]; com1DFA's ``tEnd`` [s] (beyond the
    time the mass needs to stop)."""

    name: str
    bed: Any
    dem_length: float
    dem_half_width: float
    length: float
    half_width: float
    t_end: float


def side_of_bowl(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """AvaFrame's bowl (BL, radius 500 m) with its centre at x = 500 m: the release
    (x = 100-300 m) lies on its side, 37-53 deg steep, the rim at x = 0 [m]."""
    return bowl(np.asarray(x, float) - 500.0, y)


PATHS = {"parabola": AvalanchePath("parabola", parabola, 3000.0, 500.0, 2600.0, 300.0,
                                   120.0),
         "hockey": AvalanchePath("hockey", hockey_stick, 5500.0, 500.0, 5200.0, 300.0,
                                 200.0),
         "bowl": AvalanchePath("bowl", side_of_bowl, 1000.0, 500.0, 1000.0, 400.0, 120.0)}


def write_dem(path: AvalanchePath, file: str | Path, cellsize: float = DEM_CELL) -> Raster:
    """Write the path's bed as an ESRI ASCII DEM [m], cell centres on x = 0, cellsize,
    ... and y = 0, +-cellsize, ...; returns the raster."""
    nx = round(path.dem_length / cellsize) + 1
    ny = round(path.dem_half_width / cellsize)
    xc = cellsize * np.arange(nx)
    yc = cellsize * np.arange(ny, -ny - 1, -1)  # rows north to south
    z = path.bed(*np.meshgrid(xc, yc))
    raster = Raster(z, -cellsize / 2, yc[-1] - cellsize / 2, cellsize,
                    np.zeros(z.shape, bool))
    write_raster(raster, file)
    return raster


def friction_kwargs(voellmy: tuple[float, float] | None) -> dict[str, Any]:
    """pdeflow's basal law: Coulomb tan(PHI_DEG), or Voellmy (mu [-], xi [m/s^2])."""
    if voellmy is None:
        return {"phi_b_deg": PHI_DEG}
    return {"phi_b_deg": PHI_DEG, "friction_law": "voellmy", "voellmy_mu": voellmy[0],
            "voellmy_xi": voellmy[1]}


def pdeflow_setup(raster: Raster, path: AvalanchePath, dx: float,
                  voellmy: tuple[float, float] | None = None) -> tuple[Any, Any, dict]:
    """(model, initial state, geometry) of the path on cells dx [m]: the bed from the
    DEM at the corners, the release's slope-normal thickness made vertical."""
    ny = 2 * round(path.half_width / dx) + 1  # odd: a column of cells on the axis y = 0
    grid = CartesianGrid([[0.0, path.length], [-ny * dx / 2, ny * dx / 2]],
                         [round(path.length / dx), ny])
    corners = bed_on_grid(raster, *corner_coordinates(grid))
    bed = 0.25 * (corners[:-1, :-1] + corners[1:, :-1] + corners[:-1, 1:]
                  + corners[1:, 1:])  # the cells' beds, as the model has them
    x0, x1, y0, y1 = RELEASE
    ring = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    mask = release_mask([[ring]], *grid.axes_coords)
    h = vertical_thickness(mask, REL_TH, bed, dx, dx)
    pde = pdeflow.SingleLayerGranular(bed=corners, bc=(("wall", "open"), ("open", "open")),
                                      **friction_kwargs(voellmy))
    state = pde.make_state(grid, h=h, u=0 * h, v=0 * h)
    return pde, state, {"x": grid.axes_coords[0], "y": grid.axes_coords[1], "bed": bed,
                        "cos": cos_slope(bed, dx, dx), "dx": dx}


def pdeflow_run(raster: Raster, path: AvalanchePath, dx: float,
                voellmy: tuple[float, float] | None = None) -> dict[str, Any]:
    """pdeflow on cells dx [m] to rest (or to T_MAX, said in the row's resolution): the
    peak fields, mass centres and wall time in the form of :func:`measures`."""
    pde, state, geo = pdeflow_setup(raster, path, dx, voellmy)
    peaks = PeakTracker(PEAK_INTERVAL, partial(peak_fields, dry=DRY, density=DENSITY))
    start = time.perf_counter()
    end = pde.solve(state, T_MAX, solver="fv-split", tracker=[peaks])
    wall = time.perf_counter() - start
    size = f"dx = {dx:g} m" + (f", moving at {T_MAX:g} s" if np.any(end.data[1:] != 0.0)
                               else "")  # e.g. Voellmy: a creep, not yet at rest
    depth, speed, pressure = peaks.peak
    x2d = geo["x"][:, None] * np.ones_like(geo["bed"])
    h0, h1 = state.data[0], end.data[0]
    return {"code": "pdeflow", "size": size, "dx": dx,
            "x": geo["x"], "y": geo["y"], "pft": depth * geo["cos"], "pfv": speed,
            "ppr": pressure, "x0": _mean(x2d, h0), "z0": _mean(geo["bed"], h0),
            "x1": _mean(x2d, h1), "z1": _mean(geo["bed"], h1), "wall": wall,
            "t_end": peaks.last_time, "cells": h0.size}


def _mean(values: np.ndarray, weights: np.ndarray) -> float:
    """The weighted mean of ``values``."""
    return float(np.sum(values * weights) / np.sum(weights))


def compile_kernels(raster: Raster, path: AvalanchePath, dx: float,
                    voellmy: tuple[float, float] | None = None) -> None:
    """A 1 s run on cells dx [m]: numba compiles the kernels before any timed run."""
    pde, state, _ = pdeflow_setup(raster, path, dx, voellmy)
    peaks = PeakTracker(PEAK_INTERVAL, partial(peak_fields, dry=DRY, density=DENSITY))
    pde.solve(state, 1.0, solver="fv-split", tracker=[peaks])


def com1dfa_run(exe: str, dem: Path, t_end: float, stop_crit: float = 0.01,
                voellmy: tuple[float, float] | None = None) -> dict[str, Any]:
    """com1DFA on the DEM file ``dem`` (``benchmarks/avaframe_paths.py``) with ``tEnd``
    = ``t_end`` [s] and ``stopCrit`` = ``stop_crit`` (0: run to ``t_end``): its peak
    rasters, mass centres and wall time in the form of :func:`measures`."""
    x0, x1, y0, y1 = RELEASE
    law = (["--mu", repr(voellmy[0]), "--xi", repr(voellmy[1])] if voellmy else
           ["--mu", repr(math.tan(math.radians(PHI_DEG)))])
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp, "com1dfa.npz")
        proc = subprocess.run([exe, str(ROOT / "benchmarks" / "avaframe_paths.py"),
                               str(dem), str(out), "--release", *map(repr, RELEASE),
                               "--rel-th", repr(REL_TH), "--stop-crit", repr(stop_crit),
                               "--t-end", repr(t_end),
                               *law], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"com1DFA's run failed:\n{proc.stderr[-2000:]}")
        d = {k: v for k, v in np.load(out).items()}
    cs = float(d["cellsize"])
    rows, cols = d["pft"].shape
    return {"code": "com1DFA", "size": f"{int(d['n_part'])} particles, {cs:g} m mesh, "
                                        f"stopCrit {stop_crit:g}",
            "dx": cs, "x": float(d["xllcenter"]) + cs * np.arange(cols),
            "y": float(d["yllcenter"]) + cs * np.arange(rows),
            **{k: d[k].T for k in ("pft", "pfv", "ppr")},  # (x, y) as pdeflow's
            **{k: float(d[k]) for k in ("x0", "z0", "x1", "z1", "wall", "t_end")},
            "cells": int(d["n_part"])}


def measures(run: dict[str, Any], path: AvalanchePath) -> dict[str, Any]:
    """A table row of a run (pdeflow's or com1DFA's, fields (nx, ny) on cell centres
    ``x``, ``y`` of size ``dx`` [m], thickness slope-normal): run-out on the axis [m]
    and its travel angle from the release's top [deg], the mass centre's travel angle
    [deg], the largest peak thickness [m], speed [m/s] and pressure [kPa], the area
    above THRESHOLD [m^2], the end time and wall time [s]."""
    dx, pft = run["dx"], run["pft"]
    axis = int(np.argmin(np.abs(run["y"])))
    reached = np.nonzero(pft[:, axis] > THRESHOLD)[0]
    runout = float(run["x"][reached[-1]] + dx / 2) if reached.size else math.nan
    top = RELEASE[0]
    drop = float(path.bed(np.array(top), np.array(0.0)) - path.bed(np.array(runout),
                                                                   np.array(0.0)))
    centre = math.degrees(math.atan2(run["z0"] - run["z1"], run["x1"] - run["x0"]))
    return {"code": run["code"], "size": run["size"], "runout": runout,
            "runout_angle": math.degrees(math.atan2(drop, runout - top)),
            "centre_angle": centre, "pft": float(pft.max()), "pfv": float(run["pfv"].max()),
            "ppr": float(run["ppr"].max()),
            "area": float(np.count_nonzero(pft > THRESHOLD) * dx * dx),
            "t_end": run["t_end"], "wall": run["wall"]}


def table(rows: list[dict[str, Any]]) -> list[str]:
    """The markdown table of the rows."""
    out = ["| code | resolution | run-out x [m] | run-out angle [deg] | mass centre angle "
           "[deg] | max pft [m] | max pfv [m/s] | max ppr [kPa] | area [km^2] | "
           "t end [s] | wall [s] |", "|---|---|" + "---:|" * 9]
    for r in rows:
        out.append(f"| {r['code']} | {r['size']} | {r['runout']:.0f} | "
                   f"{r['runout_angle']:.2f} | {r['centre_angle']:.2f} | {r['pft']:.2f} | "
                   f"{r['pfv']:.1f} | {r['ppr']:.0f} | {r['area'] / 1e6:.3f} | "
                   f"{r['t_end']:.1f} | {r['wall']:.1f} |")
    return out


def converged_lines(rows: list[dict[str, Any]]) -> list[str]:
    """The coarsest pdeflow resolution whose run-out is within 2 % of its finest's, and
    its wall time against com1DFA's (the issue's target: at least as fast)."""
    mine = [r for r in rows if r["code"] == "pdeflow"]
    if len(mine) < 2:
        return ["one pdeflow resolution: no convergence statement"]
    finest = mine[-1]
    ok = [r for r in mine[:-1] if abs(r["runout"] - finest["runout"])
          <= 0.02 * finest["runout"]]
    if not ok:
        return [f"no pdeflow resolution coarser than {finest['size']} has its run-out "
                f"within 2 % of {finest['runout']:.0f} m"]
    best = ok[0]
    out = [f"pdeflow {best['size']}: run-out {best['runout']:.0f} m, within 2 % of the "
           f"finest ({finest['size']}, {finest['runout']:.0f} m), in {best['wall']:.1f} s"]
    for r in (r for r in rows if r["code"] == "com1DFA"):
        verdict = "met" if best["wall"] <= r["wall"] else "missed"
        out.append(f"target (pdeflow at least as fast as com1DFA): {verdict}, "
                   f"{best['wall']:.1f} s against com1DFA's {r['wall']:.1f} s "
                   f"({r['size']})")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--path", choices=sorted(PATHS), default="parabola")
    ap.add_argument("--dx", type=float, nargs="+", default=[20.0, 10.0, 5.0, 2.5],
                    help="pdeflow's cell sizes [m]")
    ap.add_argument("--avaframe-python", default=None)
    ap.add_argument("--voellmy", type=float, nargs=2, default=None, metavar=("MU", "XI"))
    ap.add_argument("--stop-crit", type=float, nargs="+", default=[0.01, 0.0],
                    help="com1DFA's stopCrit, a run each (0: to the path's tEnd)")
    args = ap.parse_args(argv)
    path = PATHS[args.path]
    law = (f"Voellmy mu {args.voellmy[0]:g}, xi {args.voellmy[1]:g} m/s^2"
           if args.voellmy else f"Coulomb {PHI_DEG:g} deg")
    print(f"{path.name}, release x {RELEASE[0]:g}-{RELEASE[1]:g} m, y {RELEASE[2]:g}-"
          f"{RELEASE[3]:g} m, {REL_TH:g} m slope-normal, {law}; run-out: peak thickness "
          f"(slope-normal) > {THRESHOLD:g} m on y = 0")
    print(f"load before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        dem = Path(tmp, f"DEM_{path.name}.asc")
        raster = write_dem(path, dem)
        raster = read_raster(dem)  # pdeflow reads the file com1DFA reads
        exe = avaframe_python(args.avaframe_python)
        if exe is None:
            print(NO_AVAFRAME)
        else:
            rows += [measures(com1dfa_run(exe, dem, path.t_end, sc, args.voellmy), path)
                     for sc in args.stop_crit]
        dxs = sorted(args.dx, reverse=True)
        compile_kernels(raster, path, dxs[0], args.voellmy)
        rows += [measures(pdeflow_run(raster, path, dx, args.voellmy), path)
                 for dx in dxs]
    print("\n".join(table(rows)))
    print("\n".join(converged_lines(rows)))
    print(f"load after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
