"""pdeflow's helix (:func:`pdeflow.terrain.topographies.helix`) against the DEM AvaFrame
ships for it, read by pdeflow's .asc reader from the user's checkout of AvaFrame's
repository (nothing of AvaFrame's is copied here): ``avaframe/data/avaHelix/Inputs/
DEM_HX_Topo.asc`` (made by AvaFrame's generateTopo with its defaults, no channel), and
the bed under its release area ``REL/release1HX.shp`` (needs pyshp).

The DEM's cell centres run from (xllcenter, yllcenter); AvaFrame's helix equations take
x in [-xEnd/2, xEnd/2] and y in [-yEnd, 0]. Both readings of the rows are compared:
ESRI's (first row north) and the reverse, since AvaFrame's generateTopo writes its
array without flipping it (first row = its smallest y).

    python benchmarks/avaframe_topographies.py --avaframe PATH
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np


def compare(avaframe: Path) -> None:
    """Print max |z_pdeflow - z_AvaFrame| [m] for both row orders, and the bed under
    the release's centroid."""
    from pdeflow.terrain import bed_on_grid, read_raster
    from pdeflow.terrain.topographies import helix

    inputs = avaframe / "avaframe" / "data" / "avaHelix" / "Inputs"
    dem = read_raster(inputs / "DEM_HX_Topo.asc")
    x_ava = dem.x_centres - dem.x_centres[0] - 0.5 * (dem.x_centres[-1] - dem.x_centres[0])
    y_south_up = dem.y_centres[::-1] - dem.y_centres[-1]
    y_ava = y_south_up - y_south_up[-1]  # [-yEnd, 0], south to north
    for label, y in (("first row north (ESRI)", y_ava[::-1]), ("first row south", y_ava)):
        X, Y = np.meshgrid(x_ava, y)  # noqa: N806  the file's rows
        dz = np.abs(helix(X, Y) - dem.values)
        print(f"helix vs DEM_HX_Topo.asc, rows read {label}: max |dz| = {dz.max():.3g} m "
              f"over {dz.size} cells")
    release = inputs / "REL" / "release1HX.shp"
    if release.exists():
        from pdeflow.terrain import shapefile_polygons
        ring = shapefile_polygons(release)[0][0]
        cx, cy = ring[:, 0].mean(), ring[:, 1].mean()
        z = bed_on_grid(dem, np.array([cx]), np.array([cy]))[0, 0]
        print(f"bed under release1HX's vertex mean ({cx:.0f}, {cy:.0f}) m, the DEM read "
              f"ESRI's way: {z:.1f} m (the DEM spans {dem.values.min():g} to "
              f"{dem.values.max():g} m)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--avaframe", type=Path, required=True,
                        help="a checkout of github.com/avaframe/AvaFrame")
    compare(parser.parse_args().avaframe)


if __name__ == "__main__":
    main()
