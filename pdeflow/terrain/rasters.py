"""Rasters read and written by their file's suffix: an ESRI ASCII grid (.asc, by
pdeflow itself: :mod:`.asc`) or a GeoTIFF (.tif, .tiff, through rasterio, the extra
``terrain``: :mod:`.geotiff`, imported only for GeoTIFFs)."""

from __future__ import annotations

from pathlib import Path

from .asc import read_asc, write_asc
from .raster import Raster

GEOTIFF_SUFFIXES = (".tif", ".tiff")


def read_raster(path: str | Path) -> Raster:
    """The raster at ``path``: an ESRI ASCII grid (.asc) or a GeoTIFF (.tif, .tiff;
    needs rasterio, the extra ``terrain``)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".asc":
        return read_asc(path)
    if suffix in GEOTIFF_SUFFIXES:
        from .geotiff import read_geotiff  # rasterio only for GeoTIFFs
        return read_geotiff(path)
    raise ValueError(f"{path}: a raster must be an ESRI ASCII grid (.asc) or a GeoTIFF "
                     f"(.tif, .tiff), got {suffix or 'no suffix'!r}")


def write_raster(raster: Raster, path: str | Path) -> Path:
    """Write ``raster`` at ``path`` as .asc or GeoTIFF (.tif, .tiff), by its suffix."""
    suffix = Path(path).suffix.lower()
    if suffix == ".asc":
        return write_asc(raster, path)
    if suffix in GEOTIFF_SUFFIXES:
        from .geotiff import write_geotiff
        return write_geotiff(raster, path)
    raise ValueError(f"{path}: a raster is written as .asc or .tif/.tiff, got "
                     f"{suffix or 'no suffix'!r}")
