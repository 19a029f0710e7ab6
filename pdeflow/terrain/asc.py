"""ESRI ASCII grids (.asc), read and written by pdeflow itself.

An ESRI ASCII grid is a header of ``key value`` lines -- ``ncols``, ``nrows``,
``xllcorner`` or ``xllcenter``, ``yllcorner`` or ``yllcenter``, ``cellsize``, optionally
``NODATA_value`` (keys in any case) -- then ``nrows`` rows of ``ncols`` values, the first
row the northernmost. Its coordinate reference system, if any, is the WKT text of a
sidecar ``.prj`` file of the same stem.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from ..io import write_text
from .raster import Raster

HEADER_KEYS = ("ncols", "nrows", "xllcorner", "xllcenter", "yllcorner", "yllcenter",
               "cellsize", "nodata_value", "dx", "dy")
"""the header keys pdeflow reads (lower case; ``dx``/``dy`` only to refuse them when
they differ)"""


def _header(lines: list[str], path: Path) -> tuple[dict[str, float], int]:
    """The header of the .asc text ``lines`` (its keys lower-cased) and its length."""
    header: dict[str, float] = {}
    for n, line in enumerate(lines):
        parts = line.split()
        if not parts or _is_number(parts[0]):  # the values begin (a row may open with nan)
            return header, n
        key = parts[0].lower()
        if key not in HEADER_KEYS or len(parts) != 2:
            raise ValueError(f"{path}: header line {n + 1} {line.strip()!r} is not one of "
                             f"'key value' with key in {list(HEADER_KEYS)}")
        try:
            header[key] = float(parts[1])
        except ValueError:
            raise ValueError(f"{path}: header {parts[0]} must be a number, got "
                             f"{parts[1]!r}") from None
    return header, len(lines)


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _geometry(header: dict[str, float], path: Path) -> tuple[int, int, float, float, float]:
    """(nrows, ncols, x_corner, y_corner, cellsize) from an .asc header; one-line errors
    naming the key."""
    for key in ("ncols", "nrows"):
        value = header.get(key)
        if value is None or value != int(value) or value < 1:
            raise ValueError(f"{path}: header {key} must be an integer >= 1, got {value}")
    if "cellsize" not in header:
        dx, dy = header.get("dx"), header.get("dy")
        if dx is None or dx != dy:
            raise ValueError(f"{path}: header cellsize is missing (dx = {dx}, dy = {dy}): "
                             "pdeflow reads uniform rasters only, one cellsize > 0 [m]")
        header["cellsize"] = dx
    cellsize = header["cellsize"]
    if not (math.isfinite(cellsize) and cellsize > 0):
        raise ValueError(f"{path}: header cellsize must lie in (0, inf) m, got {cellsize}")
    corner = []
    for axis in ("x", "y"):
        if f"{axis}llcorner" in header:
            corner.append(header[f"{axis}llcorner"])
        elif f"{axis}llcenter" in header:
            corner.append(header[f"{axis}llcenter"] - 0.5 * cellsize)
        else:
            raise ValueError(f"{path}: header {axis}llcorner or {axis}llcenter is missing")
    return int(header["nrows"]), int(header["ncols"]), corner[0], corner[1], cellsize


def read_asc(path: str | Path) -> Raster:
    """The ESRI ASCII grid at ``path`` (module docstring), with the WKT of a sidecar
    ``.prj`` as its CRS. One-line ValueError naming the header key or the count of
    values that is wrong."""
    path = Path(path)
    lines = path.read_text().splitlines()
    header, start = _header(lines, path)
    nrows, ncols, x_corner, y_corner, cellsize = _geometry(header, path)
    try:  # rows may wrap anywhere: only the count of values matters
        values = np.array(" ".join(lines[start:]).split(), dtype=float)
    except ValueError as err:
        raise ValueError(f"{path}: the values are not all numbers ({err})") from None
    if values.size != nrows * ncols:
        raise ValueError(f"{path}: {values.size} values, but the header's nrows x ncols = "
                         f"{nrows} x {ncols} = {nrows * ncols}")
    values = values.reshape(nrows, ncols)
    nodata_value = header.get("nodata_value", -9999.0)
    nodata = (values == nodata_value) if "nodata_value" in header else ~np.isfinite(values)
    prj = path.with_suffix(".prj")
    crs = prj.read_text().strip() if prj.exists() else None
    return Raster(values, x_corner, y_corner, cellsize, nodata | ~np.isfinite(values),
                  crs=crs or None, nodata_value=nodata_value)


def write_asc(raster: Raster, path: str | Path) -> Path:
    """Write ``raster`` as an ESRI ASCII grid at ``path`` (and its CRS, if any, as WKT
    in a sidecar ``.prj``), each file atomically. Values are written with 17
    significant digits, so that reading them back gives the same doubles."""
    path = Path(path)
    valid = raster.values[~raster.nodata]
    if np.any(valid == raster.nodata_value):
        raise ValueError(f"Raster.nodata_value {raster.nodata_value:g} is also the value of "
                         "a cell with data: choose a nodata_value outside the values")
    values = np.where(raster.nodata, raster.nodata_value, raster.values)
    body = io.StringIO()
    np.savetxt(body, values, fmt="%.17g")
    header = (f"ncols {raster.ncols}\nnrows {raster.nrows}\n"
              f"xllcorner {float(raster.x_corner)!r}\nyllcorner {float(raster.y_corner)!r}\n"
              f"cellsize {float(raster.cellsize)!r}\n"
              f"NODATA_value {float(raster.nodata_value)!r}\n")  # numpy scalars too
    if raster.crs is not None:
        write_text(path.with_suffix(".prj"), raster.crs + "\n")
    return write_text(path, header + body.getvalue())
