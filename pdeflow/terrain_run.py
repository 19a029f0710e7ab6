"""What a 2D run over a ``[terrain]`` bed adds to its results (issue 37's hazard
outputs; docs/terrain.md, "A run over a bed: its outputs").

* :func:`peak_fields_tracker`: the per-cell peaks of depth, speed and pressure
  (:func:`pdeflow.metrics_2d.peak_fields`), sampled as the 2D run's largest speed is
  (every t_end / ``PEAK_SAMPLES`` and the final state): lower bounds of the run's
  peaks, as close as the sampling is fine; only a run over a bed keeps them.
* :func:`terrain_summary`: the mass centre's travel angle (its drop over its
  horizontal travel, the energy line's angle), the affected area (peak depth above
  ``output.front_threshold``) and the largest peak pressure.
* :func:`write_peak_outputs`: the peak fields as rasters in the map's coordinates and
  the DEM's CRS, and the peak depth over the bed's hillshade.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from .case_terrain import flow_density, map_corner
from .metrics_2d import peak_fields, total_depth
from .numerics.geometry import centre_values
from .trackers.peaks import PeakTracker

TERRAIN_KEYS = ("travel_angle", "affected_area", "max_pressure")
"""the summary keys of a run over a bed (units: deg, m^2, kPa)"""


def peak_fields_tracker(case: Any, pde: Any, samples: int) -> PeakTracker | None:
    """The tracker of a run's peak fields over a bed, ``samples`` states over t_end;
    None without a ``[terrain]`` bed (nothing is kept)."""
    if "terrain" not in case.data:
        return None
    dry = pde.parameters.dry_tolerance
    density = flow_density(case)
    return PeakTracker(case.t_end / samples, lambda data: peak_fields(data, dry, density))


def terrain_summary(res: Any, peaks: np.ndarray, initial: np.ndarray) -> dict[str, Any]:
    """:data:`TERRAIN_KEYS` of the run ``res`` (a RunResult over a bed) from its peak
    fields ``peaks`` (3, nx, ny) and its initial state data."""
    bed = centre_values(res.metric.bed)
    x, y = res.state.grid.axes_coords
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806
    centres = []
    for data in (initial, res.state.data):
        h = total_depth(data)
        m = h.sum()
        centres.append(((h * X).sum() / m, (h * Y).sum() / m, (h * bed).sum() / m))
    (x0, y0, z0), (x1, y1, z1) = centres
    travel = math.hypot(x1 - x0, y1 - y0)
    case = res.case
    return {"travel_angle": math.degrees(math.atan2(z0 - z1, travel)) if travel else None,
            "affected_area": float(np.count_nonzero(peaks[0] > case.front_threshold)
                                   * case.dx * case.dy),
            "max_pressure": float(peaks[2].max())}


def write_peak_outputs(case: Any, model: str, peaks: np.ndarray, bed: np.ndarray,
                       directory: Path, suffix: str = "") -> list[Path]:
    """Write ``peaks`` (3, nx, ny) of ``model``'s run as ``peak_<field><suffix>.asc``
    georeferenced (:func:`pdeflow.case_terrain.map_corner`) and
    ``peak_depth<suffix>.png`` over the hillshade of the cell beds ``bed`` (nx, ny)
    [m] in ``directory`` (the rasters only for square cells); returns the paths."""
    from .terrain import peak_rasters
    from .terrain_figures import hillshade_figure

    x0, y0, crs = map_corner(case)
    paths = []
    if case.dx == case.dy:  # a raster's cells are square
        paths = peak_rasters(peaks, x0, y0, case.dx, directory, crs)
        if suffix:
            paths = [p.rename(p.with_name(p.stem + suffix + p.suffix)) for p in paths]
    extent = (x0, x0 + case.length, y0, y0 + case.width)
    paths.append(hillshade_figure(bed, peaks[0], extent,
                                  directory / f"peak_depth{suffix}.png", "peak depth [m]",
                                  threshold=case.front_threshold,
                                  title=f"{case.name}: {model}, peak depth"))
    return paths
