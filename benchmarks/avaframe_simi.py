"""One AvaFrame com1DFA run of the Savage-Hutter similarity set-up, for
``benchmarks/similarity_2d.py``; runs in an interpreter where ``import avaframe`` works
(AvaFrame 2.1 pins numpy < 2, pdeflow's py-pde needs numpy >= 2, so usually a separate
virtual environment: ``python -m venv V && V/bin/pip install avaframe``).

It builds AvaFrame's own analytic test through AvaFrame's public functions: an inclined
plane as an ESRI ASCII DEM (35 deg, 5 m cells, the extent of AvaFrame's
``avaSimilaritySol`` DEM), the cap's release thickness by
``ana1Tests.simiSolTest.getReleaseThickness`` (which also writes the release outline
as a shapefile), then ``com1DFA.com1DFAMain``; Coulomb friction mu = tan 25 deg, the
test's SPH settings (``sphOption`` 2, ``viscOption`` 1, ``cMax`` 0.02, the kernel radius
equal to the mesh cell), t = 5 s. The particle count follows from ``nPPK0`` and the
kernel radius (``MPPKR``). It writes an .npz with the slope-normal flow thickness FT
[m] at t = 5 s on com1DFA's horizontal raster (rows along y, columns along x, the
origin at the release's centre), the raster's ``cellsize`` and lower-left centres
[m], ``t`` [s] the time of that step (com1DFA saves the step nearest to 5 s, e.g.
5.04 s), ``n_part`` (particles at the start) and ``wall`` [s] (com1DFAMain alone).

Run: ``V/bin/python benchmarks/avaframe_simi.py OUT.npz --kernel-radius 5 --nppk0 15``.
"""

from __future__ import annotations

import argparse
import math
import pathlib
import tempfile
import time

import numpy as np

SLOPE_DEG, FRICTION_DEG, L, H, T_END = 35.0, 25.0, 80.0, 4.0, 5.0
DEM_CELL, DEM_X0, DEM_Y0, DEM_NX, DEM_NY = 5.0, -200.0, -250.0, 401, 101


def write_dem(path: pathlib.Path) -> None:
    """The plane z = 1500 m - tan(zeta) (x - x0) as ESRI ASCII [m]."""
    x = DEM_X0 + DEM_CELL * np.arange(DEM_NX)
    z = 1500.0 - math.tan(math.radians(SLOPE_DEG)) * (x - DEM_X0)
    head = (f"ncols {DEM_NX}\nnrows {DEM_NY}\nxllcenter {DEM_X0}\nyllcenter {DEM_Y0}\n"
            f"cellsize {DEM_CELL}\nnodata_value -9999\n")
    rows = "\n".join(" ".join(f"{v:.6f}" for v in z) for _ in range(DEM_NY))
    path.write_text(head + rows + "\n")


def config_text(kernel_radius: float, nppk0: float) -> str:
    """The com1DFA override file: the analytic test's settings (module docstring)."""
    mu = math.tan(math.radians(FRICTION_DEG))
    return f"""[GENERAL]
resType = FT
tSteps = {T_END}
tEnd = {T_END}
initPartDistType = random
sphKernelRadiusTimeStepping = True
cMax = 0.02
sphOption = 2
sphKernelRadius = {kernel_radius}
meshCellSize = {kernel_radius}
viscOption = 1
massPerParticleDeterminationMethod = MPPKR
sphKR0 = 5
nPPK0 = {nppk0}
aPPK = -1
thresholdMassSplit = 5
subgridMixingFactor = 10
frictModel = Coulomb
explicitFriction = 1
mucoulomb = {mu}
[SIMISOL]
L_x = {L}
L_y = {L}
relTh = {H}
bedFrictionAngle = {FRICTION_DEG}
internalFrictionAngle = {FRICTION_DEG}
planeinclinationAngle = {SLOPE_DEG}
flagEarth = False
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=pathlib.Path)
    ap.add_argument("--kernel-radius", type=float, default=5.0)
    ap.add_argument("--nppk0", type=float, default=15.0)
    args = ap.parse_args()
    import avaframe.ana1Tests.simiSolTest as simi
    import avaframe.com1DFA.com1DFA as com1DFA
    from avaframe.in2Trans import rasterUtils
    from avaframe.in3Utils import cfgUtils

    with tempfile.TemporaryDirectory() as tmp:
        ava = pathlib.Path(tmp, "avaSimilaritySol")
        (ava / "Inputs").mkdir(parents=True)
        dem = ava / "Inputs" / "DEM_IP_Topo.asc"
        write_dem(dem)
        ini = ava / "Inputs" / "simiSol_com1DFACfg.ini"
        ini.write_text(config_text(args.kernel_radius, args.nppk0))
        main_cfg = cfgUtils.getGeneralConfig()
        main_cfg["MAIN"]["avalancheDir"] = str(ava)
        cfg = cfgUtils.getModuleConfig(com1DFA, fileOverride=ini)
        simi.getReleaseThickness(ava, cfg, dem)
        start = time.perf_counter()
        _, _, _, sims = com1DFA.com1DFAMain(main_cfg, cfgInfo=cfg)
        wall = time.perf_counter() - start
        rasters = [p for p in (ava / "Outputs").rglob("*FT*")
                   if p.suffix in (".asc", ".tif")]
        # com1DFA saves the step nearest to each requested time (_t5.04): the nearest
        saved = {float(p.stem.rpartition("_t")[2]): p for p in rasters
                 if p.stem.rpartition("_t")[2].replace(".", "").isdigit()}
        if not saved:
            raise RuntimeError(f"com1DFA wrote no FT raster at a time: "
                               f"{sorted(p.name for p in rasters)}")
        t_saved = min(saved, key=lambda t: abs(t - T_END))
        raster = rasterUtils.readRaster(saved[t_saved])
        head = raster["header"]
        n_part = int(sims["nPart"].iloc[0]) if "nPart" in sims else -1
        np.savez(args.out, FT=np.asarray(raster["rasterData"], dtype=float),
                 cellsize=head["cellsize"], xllcenter=head["xllcenter"],
                 yllcenter=head["yllcenter"], n_part=n_part, wall=wall,
                 t=t_saved, source=saved[t_saved].name)


if __name__ == "__main__":
    main()
