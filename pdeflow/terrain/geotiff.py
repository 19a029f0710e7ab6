"""GeoTIFF rasters through rasterio (the optional extra ``terrain``:
``pip install "pdeflow[terrain]"``): band 1 read as a :class:`~.rasters.Raster`, and a
raster written with its CRS.

Only north-up rasters of square cells are read: a transform with rotation or shear
terms, cells that are not square, or rows that run south to north are refused with one
line naming the transform.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..io import atomic_path
from .raster import Raster


def _rasterio() -> Any:
    """rasterio, or a one-line ImportError naming the extra that installs it."""
    try:
        import rasterio
    except ImportError:
        raise ImportError("reading or writing a GeoTIFF needs rasterio: pip install "
                          "'pdeflow[terrain]' (or read an ESRI ASCII grid, .asc, which "
                          "needs nothing)") from None
    return rasterio


def check_transform(transform: Any, path: str | Path) -> float:
    """The cell size [m] of the affine ``transform`` (a, b, c, d, e, f) of a north-up
    raster of square cells (b = d = 0, a = -e > 0); one-line ValueError otherwise."""
    a, b, _, d, e, _ = (transform.a, transform.b, transform.c, transform.d, transform.e,
                        transform.f)
    if b != 0.0 or d != 0.0:
        raise ValueError(f"{path}: the GeoTIFF's transform is rotated or sheared (b = {b:g},"
                         f" d = {d:g}): pdeflow reads north-up rasters only (b = d = 0)")
    if not (a > 0 and e < 0):
        raise ValueError(f"{path}: the GeoTIFF's transform has a = {a:g}, e = {e:g}: "
                         "pdeflow reads rasters whose columns run east (a > 0) and rows "
                         "south (e < 0)")
    if a != -e:
        raise ValueError(f"{path}: the GeoTIFF is not uniform: its cells are {a:g} m x "
                         f"{-e:g} m; pdeflow reads square cells only (one cellsize)")
    return float(a)


def read_geotiff(path: str | Path) -> Raster:
    """Band 1 of the GeoTIFF at ``path`` as a :class:`Raster` (its nodata value and
    mask, its CRS as WKT or None)."""
    rasterio = _rasterio()
    with rasterio.open(path) as src:
        cellsize = check_transform(src.transform, path)
        values = src.read(1).astype(float)
        nodata = src.read_masks(1) == 0
        crs = src.crs.to_wkt() if src.crs is not None else None
        nodata_value = float(src.nodata) if src.nodata is not None else -9999.0
        left, bottom = float(src.bounds.left), float(src.bounds.bottom)
    return Raster(values, left, bottom, cellsize, nodata | ~np.isfinite(values), crs=crs,
                  nodata_value=nodata_value)


def write_geotiff(raster: Raster, path: str | Path) -> Path:
    """Write ``raster`` as a single-band float64 GeoTIFF at ``path``, atomically, with
    its CRS (if any) and its nodata value in the no-data cells."""
    rasterio = _rasterio()
    if np.any(raster.values[~raster.nodata] == raster.nodata_value):
        raise ValueError(f"Raster.nodata_value {raster.nodata_value:g} is also the value of "
                         "a cell with data: choose a nodata_value outside the values")
    x_min, _, _, y_max = raster.bounds
    transform = rasterio.transform.Affine(raster.cellsize, 0.0, x_min, 0.0, -raster.cellsize,
                                          y_max)
    values = np.where(raster.nodata, raster.nodata_value, raster.values)
    with atomic_path(path) as tmp, rasterio.open(
            tmp, "w", driver="GTiff", height=raster.nrows, width=raster.ncols, count=1,
            dtype="float64", crs=raster.crs, transform=transform,
            nodata=raster.nodata_value) as dst:
        dst.write(values, 1)
    return Path(path)
