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

With ``--inputs`` the first argument is instead an AvaFrame ``Inputs`` directory of a
real path (e.g. ``avaframe/data/avaHit/Inputs`` of AvaFrame's checkout): it is copied
into the temporary avalanche directory (its DEM, ``REL`` release shapefiles, ``LINES``,
``POINTS``; its ``ENT``, ``RES`` and ``SECREL`` are left out: no entrainment, resistance
or secondary release), the release thickness is ``--rel-th`` (the shapefile's 1 m for
avaHit) and the mesh cell the DEM's.

The .npz holds the peak rasters ``pft`` (slope-normal peak flow thickness [m]), ``pfv``
(peak flow velocity [m/s]) and ``ppr`` (peak pressure [kPa]), rows from south to north
(row i at y = ``yllcenter`` + i ``cellsize``), with ``cellsize``, ``xllcenter`` and
``yllcenter`` [m]; the particles' mass centre (``x0``, ``y0``, ``z0``) at the start
and (``x1``, ``y1``, ``z1``) at the end [m; x and y from the DEM's lower-left cell
centre]; ``n_part`` (particles at the start), ``mass0`` and ``mass1`` [kg] (their mass at the
start and the end),
``t_end`` [s] (the last step's time: com1DFA stops when the kinetic energy falls below
``stopCrit`` times its peak, or at ``tEnd``) and ``wall`` [s] (com1DFAMain alone, one
core, its outputs included).

Run: ``V/bin/python benchmarks/avaframe_paths.py DEM.asc OUT.npz --release 100 300
-100 100 [--rel-th 1] [--mu 0.4663] [--xi XI] [--t-end 400] [--stop-crit 0.01]``, or
``V/bin/python benchmarks/avaframe_paths.py AVAFRAME/avaframe/data/avaHit/Inputs OUT.npz
--inputs --mu 0.36397 [...]``.
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


def mass_centre(particles: dict) -> tuple[float, float, float]:
    """The particles' mass-weighted x, y and z [m] (x and y in com1DFA's frame, from the
    DEM's lower-left centre)."""
    m = np.asarray(particles["m"])
    return tuple(float(np.sum(m * particles[k]) / m.sum()) for k in ("x", "y", "z"))


LEFT_OUT = ("ENT", "RES", "SECREL")
"""an Inputs directory's parts not copied: entrainment, resistance, secondary release"""


def copy_inputs(inputs: pathlib.Path, ava: pathlib.Path) -> pathlib.Path:
    """Copy AvaFrame's ``inputs`` directory without LEFT_OUT into ``ava``/Inputs; its
    DEM (the one .asc or .tif at its top)."""
    shutil.copytree(inputs, ava / "Inputs",
                    ignore=lambda d, names: [n for n in names if n in LEFT_OUT
                                             and pathlib.Path(d) == inputs])
    dems = [p for p in (ava / "Inputs").iterdir() if p.suffix in (".asc", ".tif")]
    if len(dems) != 1:
        raise RuntimeError(f"{inputs} has {len(dems)} DEMs at its top, expected 1")
    return dems[0]


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
    if args.inputs:
        dem = copy_inputs(args.dem, ava)
    else:
        (ava / "Inputs" / "REL").mkdir(parents=True)
        dem = ava / "Inputs" / "DEM.asc"
        shutil.copy(args.dem, dem)
        write_release(ava / "Inputs" / "REL" / "rel1", args.release, args.rel_th)
    cellsize = float(rasterUtils.readRaster(dem)["header"]["cellsize"])
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
    (x0, y0, z0), (x1, y1, z1) = mass_centre(first), mass_centre(last)
    out = {"wall": wall, "n_part": int(first["nPart"]), "t_end": float(last["t"]),
           "x0": x0, "y0": y0, "z0": z0, "x1": x1, "y1": y1, "z1": z1,
           "mass0": float(np.sum(first["m"])), "mass1": float(np.sum(last["m"]))}
    for name in ("pft", "pfv", "ppr"):
        raster = peak(ava, name)
        out[name] = np.nan_to_num(np.asarray(raster["rasterData"], dtype=float))
        head = raster["header"]
    out.update(cellsize=float(head["cellsize"]), xllcenter=float(head["xllcenter"]),
               yllcenter=float(head["yllcenter"]))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dem", type=pathlib.Path,
                    help="the DEM, ESRI ASCII [m] (with --inputs: an Inputs directory)")
    ap.add_argument("out", type=pathlib.Path, help="the .npz written")
    ap.add_argument("--release", type=float, nargs=4, default=None,
                    metavar=("X0", "X1", "Y0", "Y1"), help="release rectangle [m]")
    ap.add_argument("--inputs", action="store_true",
                    help="DEM is AvaFrame's Inputs directory of a path, its release "
                         "its REL shapefiles")
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
    if (args.release is None) != args.inputs:
        ap.error("give either --release X0 X1 Y0 Y1 or --inputs")
    with tempfile.TemporaryDirectory() as tmp:
        np.savez(args.out, **run(args, pathlib.Path(tmp)))


if __name__ == "__main__":
    main()
