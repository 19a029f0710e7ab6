"""One AvaFrame com1DFA run on a DEM written by pdeflow's side, for
``benchmarks/terrain_vs_com1dfa.py``; runs in an interpreter where ``import avaframe``
works (AvaFrame 2.1 pins numpy < 2, pdeflow's py-pde needs numpy >= 2: usually a
separate virtual environment, ``python -m venv V && V/bin/pip install avaframe``).

It lays out an avalanche directory (the given DEM as ``Inputs/``'s .asc, the release
rectangle as a polygon shapefile in ``Inputs/REL``, an override .ini) and runs
``com1DFA.com1DFAMain`` through AvaFrame's public functions. The settings are
com1DFA's defaults (fixed dt 0.1 s, SPH gradients ``sphOption`` 2 as in AvaFrame's
similarity test, artificial viscosity ``viscOption`` 1, particles from the release
thickness ``MPPDH``, the kinetic-energy stopping rule ``stopCrit``) except: the friction
law (``Coulomb`` with ``mucoulomb`` or ``Voellmy`` with ``muvoellmy``, ``xsivoellmy``),
the curvature acceleration switched off in the friction (``curvAccInFriction`` 0, as
AvaFrame's energy-line test: pdeflow's model has no curvature term), the release
thickness from the .ini (slope-normal [m]), the mesh cell equal to the DEM's, no
entrainment, resistance or secondary release, and ``tEnd``.

The .npz holds the peak rasters ``pft`` (slope-normal peak flow thickness [m]), ``pfv``
(peak flow velocity [m/s]) and ``ppr`` (peak pressure [kPa]), rows from south to north
(row i at y = ``yllcenter`` + i ``cellsize``), with ``cellsize``, ``xllcenter`` and
``yllcenter`` [m]; the particles' mass centre (``x0``, ``z0``) at the start and
(``x1``, ``z1``) at the end [m, the DEM's x]; ``n_part`` (particles at the start),
``t_end`` [s] (the last step's time: com1DFA stops when the kinetic energy falls below
``stopCrit`` times its peak, or at ``tEnd``) and ``wall`` [s] (com1DFAMain alone, one
core, its outputs included).

Run: ``V/bin/python benchmarks/avaframe_paths.py DEM.asc OUT.npz --release 100 300
-100 100 [--rel-th 1] [--mu 0.4663] [--xi XI] [--t-end 400] [--stop-crit 0.01]``.
"""

from __future__ import annotations

import argparse
import pathlib
import shutil
import tempfile
import time

import numpy as np


def friction_text(mu: float, xi: float | None) -> str:
    """The .ini lines of the friction law: Coulomb (tan phi = ``mu``) or, with ``xi``
    [m/s^2], Voellmy."""
    if xi is None:
        return f"frictModel = Coulomb\nmucoulomb = {mu!r}\n"
    return f"frictModel = Voellmy\nmuvoellmy = {mu!r}\nxsivoellmy = {xi!r}\n"


def config_text(args: argparse.Namespace, cellsize: float) -> str:
    """The com1DFA override file (module docstring)."""
    return f"""[GENERAL]
simTypeList = null
resType = pft|pfv|ppr|particles
tSteps = 0
tEnd = {args.t_end!r}
stopCrit = {args.stop_crit!r}
sphOption = 2
viscOption = 1
meshCellSize = {cellsize!r}
relThFromFile = False
relTh = {args.rel_th!r}
secRelArea = False
curvAccInFriction = 0
{friction_text(args.mu, args.xi)}"""


def write_release(path: pathlib.Path, box: list[float], rel_th: float) -> None:
    """The release rectangle ``box`` = (x0, x1, y0, y1) [m] as a polygon shapefile."""
    import shapefile  # pyshp, an AvaFrame dependency

    x0, x1, y0, y1 = box
    with shapefile.Writer(str(path), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        w.field("thickness", "N", decimal=4)
        w.poly([[(x0, y0), (x0, y1), (x1, y1), (x1, y0), (x0, y0)]])  # clockwise
        w.record("rel1", rel_th)


def mass_centre(particles: dict) -> tuple[float, float]:
    """The particles' mass-weighted x and z [m] (x in com1DFA's frame, from the DEM's
    lower-left centre)."""
    m = np.asarray(particles["m"])
    return (float(np.sum(m * particles["x"]) / m.sum()),
            float(np.sum(m * particles["z"]) / m.sum()))


def peak(ava: pathlib.Path, name: str) -> dict:
    """The raster of the peak field ``name`` (pft, pfv, ppr) com1DFA wrote."""
    from avaframe.in2Trans import rasterUtils

    found = [p for p in (ava / "Outputs" / "com1DFA" / "peakFiles").glob(f"*_{name}.*")
             if p.suffix in (".asc", ".tif")]
    if len(found) != 1:
        raise RuntimeError(f"com1DFA wrote {len(found)} {name} rasters, expected 1")
    return rasterUtils.readRaster(found[0])


def run(args: argparse.Namespace, tmp: pathlib.Path) -> dict:
    """Lay out the avalanche directory in ``tmp``, run com1DFA; the .npz's arrays."""
    import avaframe.com1DFA.com1DFA as com1DFA
    from avaframe.com1DFA import particleTools
    from avaframe.in2Trans import rasterUtils
    from avaframe.in3Utils import cfgUtils

    ava = tmp / "avaPath"
    (ava / "Inputs" / "REL").mkdir(parents=True)
    shutil.copy(args.dem, ava / "Inputs" / "DEM.asc")
    cellsize = float(rasterUtils.readRaster(args.dem)["header"]["cellsize"])
    write_release(ava / "Inputs" / "REL" / "rel1", args.release, args.rel_th)
    ini = ava / "Inputs" / "paths_com1DFACfg.ini"
    ini.write_text(config_text(args, cellsize))
    main_cfg = cfgUtils.getGeneralConfig()
    main_cfg["MAIN"]["avalancheDir"] = str(ava)
    cfg = cfgUtils.getModuleConfig(com1DFA, fileOverride=ini)
    start = time.perf_counter()
    com1DFA.com1DFAMain(main_cfg, cfgInfo=cfg)
    wall = time.perf_counter() - start
    parts, times = particleTools.readPartFromPickle(ava, flagAvaDir=True)
    order = np.argsort(times)
    first, last = parts[order[0]], parts[order[-1]]
    (x0, z0), (x1, z1) = mass_centre(first), mass_centre(last)
    out = {"wall": wall, "n_part": int(first["nPart"]), "t_end": float(last["t"]),
           "x0": x0, "z0": z0, "x1": x1, "z1": z1}
    for name in ("pft", "pfv", "ppr"):
        raster = peak(ava, name)
        out[name] = np.nan_to_num(np.asarray(raster["rasterData"], dtype=float))
        head = raster["header"]
    out.update(cellsize=float(head["cellsize"]), xllcenter=float(head["xllcenter"]),
               yllcenter=float(head["yllcenter"]))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dem", type=pathlib.Path, help="the DEM, ESRI ASCII [m]")
    ap.add_argument("out", type=pathlib.Path, help="the .npz written")
    ap.add_argument("--release", type=float, nargs=4, required=True,
                    metavar=("X0", "X1", "Y0", "Y1"), help="release rectangle [m]")
    ap.add_argument("--rel-th", type=float, default=1.0,
                    help="release thickness, slope-normal [m]")
    ap.add_argument("--mu", type=float, default=float(np.tan(np.radians(25.0))),
                    help="friction coefficient tan(phi) [-]")
    ap.add_argument("--xi", type=float, default=None,
                    help="Voellmy's turbulent coefficient [m/s^2] (default: Coulomb)")
    ap.add_argument("--t-end", type=float, default=400.0, help="tEnd [s]")
    ap.add_argument("--stop-crit", type=float, default=0.01,
                    help="stopCrit: stop when the kinetic energy < this x its peak")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        np.savez(args.out, **run(args, pathlib.Path(tmp)))


if __name__ == "__main__":
    main()
