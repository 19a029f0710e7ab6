"""Terrain inputs (issue 37, first part): what a user has -- a DEM, a release area, an
analytic bed -- turned into arrays on pdeflow's 2D grid, with one-line errors before
any work.

* :mod:`.raster`: :class:`Raster`; :mod:`.asc`: ESRI ASCII grids (.asc), read and
  written by pdeflow itself; :mod:`.rasters`: :func:`read_raster` /
  :func:`write_raster` by suffix, also GeoTIFF (:mod:`.geotiff`, through rasterio: the
  optional extra ``terrain``);
* :mod:`.resample`: the bed at the computational grid's cell centres, bilinear between
  the raster's cell centres, refused where the raster does not cover the domain;
* :mod:`.release`: release areas as polygons; :mod:`.shapefiles`: polygons from a
  shapefile (pyshp, the same extra); :mod:`.thickness`: the release thickness, given
  vertically or normal to the slope, as a vertical depth;
* :mod:`.topographies`: AvaFrame's idealised topographies z(x, y) from their equations;
  :mod:`.expression`: a bed written as an expression in x and y;
* :mod:`.corners`: the bed at a grid's cell corners (a topography evaluated, a raster
  resampled), what the flow over a bed takes (``GranularPDE(bed=...)``,
  docs/terrain.md);
* :mod:`.peaks`: a run's peak fields written as georeferenced rasters.

A case file's ``[terrain]`` table (:mod:`pdeflow.case_terrain`) reads them.
"""

from .asc import read_asc, write_asc
from .corners import analytic_bed, bed_corners, topography_parameters
from .expression import bed_expression
from .peaks import peak_rasters
from .raster import Raster
from .rasters import read_raster, write_raster
from .release import case_polygon, release_mask, same_crs
from .resample import bed_on_grid, cell_centres, cell_corners
from .shapefiles import shapefile_crs, shapefile_polygons
from .thickness import cos_slope_corners, vertical_depth, vertical_thickness

__all__ = ["Raster", "read_asc", "write_asc", "read_raster", "write_raster",
           "bed_on_grid", "cell_centres", "cell_corners", "case_polygon", "release_mask",
           "same_crs", "shapefile_crs", "shapefile_polygons", "vertical_thickness",
           "vertical_depth", "cos_slope_corners", "analytic_bed", "bed_corners",
           "topography_parameters", "peak_rasters", "bed_expression"]
