"""A run's peak fields as georeferenced rasters (issue 37's hazard outputs).

:func:`peak_rasters` writes the per-cell peaks of a 2D run
(:func:`pdeflow.metrics_2d.peak_fields`, sampled by
:class:`pdeflow.trackers.peaks.PeakTracker`) as ``peak_depth``, ``peak_speed`` and
``peak_pressure`` rasters, .asc or GeoTIFF (:func:`.rasters.write_raster`, each file
complete or absent), in the map coordinates of the grid's lower-left corner and the
DEM's CRS. Cells the flow never reached hold 0, as AvaFrame's peak files do.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..metrics_2d import PEAK_FIELDS
from .raster import Raster
from .rasters import write_raster


def peak_rasters(peaks: np.ndarray, x_corner: float, y_corner: float, cellsize: float,
                 directory: str | Path, crs: str | None = None,
                 suffix: str = ".asc") -> list[Path]:
    """Write ``peaks`` (3, nx, ny) [m, m/s, kPa] of a grid of square cells ``cellsize``
    [m] whose lower-left corner lies at (``x_corner``, ``y_corner``) [m] of the map as
    ``directory``/peak_<field><suffix>; returns the paths."""
    peaks = np.asarray(peaks, dtype=float)
    if peaks.ndim != 3 or peaks.shape[0] != len(PEAK_FIELDS):
        raise ValueError(f"peaks must have the shape ({len(PEAK_FIELDS)}, nx, ny), got "
                         f"{peaks.shape}")
    out = []
    for name, field in zip(PEAK_FIELDS, peaks, strict=True):
        values = field.T[::-1]  # (nx, ny), y up -> rows north to south
        raster = Raster(values, x_corner, y_corner, cellsize,
                        np.zeros(values.shape, bool), crs)
        out.append(write_raster(raster, Path(directory) / f"peak_{name}{suffix}"))
    return out
