"""A raster: a north-up grid of square cells with values [m], its georeference, its
no-data cells and its coordinate reference system (a DEM, later the peak fields of a
run). Read and written by :mod:`.asc` (ESRI ASCII grids) and :mod:`.geotiff`;
:mod:`.rasters` picks one by the file's suffix."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(eq=False)
class Raster:
    """A north-up raster of square cells.

    ``values`` [m] (nrows, ncols): row 0 is the northernmost, column 0 the westernmost
    (the file's order); ``x_corner``, ``y_corner`` [m]: the lower-left corner of the
    lower-left cell in the raster's map coordinates; ``cellsize`` [m]; ``nodata``: a
    boolean mask of the cells without data (their ``values`` are not used);
    ``crs``: the coordinate reference system as WKT text, or None when unknown;
    ``nodata_value``: what a writer puts in no-data cells.
    """

    values: np.ndarray
    x_corner: float
    y_corner: float
    cellsize: float
    nodata: np.ndarray
    crs: str | None = None
    nodata_value: float = -9999.0

    def __post_init__(self) -> None:
        self.values = np.asarray(self.values, dtype=float)
        # plain floats: a writer prints them (repr of a numpy scalar is not a number)
        self.x_corner, self.y_corner = float(self.x_corner), float(self.y_corner)
        self.cellsize = float(self.cellsize)
        self.nodata = np.asarray(self.nodata, dtype=bool)
        if self.values.ndim != 2 or min(self.values.shape) < 1:
            raise ValueError(f"Raster.values must be a 2D array (nrows, ncols) of at least "
                             f"one cell, got shape {self.values.shape}")
        if self.nodata.shape != self.values.shape:
            raise ValueError(f"Raster.nodata must have the shape of values "
                             f"{self.values.shape}, got {self.nodata.shape}")
        if not (math.isfinite(self.cellsize) and self.cellsize > 0):
            raise ValueError(f"Raster.cellsize must lie in (0, inf) m, got {self.cellsize!r}")
        if not np.all(np.isfinite(self.values[~self.nodata])):
            raise ValueError("Raster.values must be finite outside the no-data cells")

    @property
    def nrows(self) -> int:
        return int(self.values.shape[0])

    @property
    def ncols(self) -> int:
        return int(self.values.shape[1])

    @property
    def x_centres(self) -> np.ndarray:
        """The columns' centres [m], west to east."""
        return self.x_corner + self.cellsize * (np.arange(self.ncols) + 0.5)

    @property
    def y_centres(self) -> np.ndarray:
        """The rows' centres [m], north to south (the rows' order)."""
        return self.y_corner + self.cellsize * (self.nrows - 0.5 - np.arange(self.nrows))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The outer edges (x_min, x_max, y_min, y_max) [m] of the raster's cells."""
        return (self.x_corner, self.x_corner + self.ncols * self.cellsize,
                self.y_corner, self.y_corner + self.nrows * self.cellsize)

    def __eq__(self, other: object) -> bool:
        """Equal geometry, CRS, no-data mask and values (exactly, on the cells with
        data: a written and re-read raster is the same raster)."""
        if not isinstance(other, Raster):
            return NotImplemented
        return (self.values.shape == other.values.shape
                and (self.x_corner, self.y_corner, self.cellsize, self.crs)
                == (other.x_corner, other.y_corner, other.cellsize, other.crs)
                and np.array_equal(self.nodata, other.nodata)
                and np.array_equal(self.values[~self.nodata], other.values[~other.nodata]))

    __hash__ = None  # type: ignore[assignment]  # mutable arrays
