"""The y-axis of a case on a 2D grid (issue 36): :class:`GridAcross`, the part of
:class:`pdeflow.cases.Case` that reads ``grid.width``, ``grid.dy`` (or ``cells_y``),
``grid.y_start`` and sets up a 2D shape's initial profiles, over a ``[terrain]`` bed
(:mod:`pdeflow.case_terrain`) too. Validated by :mod:`pdeflow.case_validation_2d`."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import systems
from .case_terrain import release_depth, terrain_corners
from .initial_shapes_2d import release_centre, total_depth_2d


class GridAcross:
    """The y-axis of a :class:`~pdeflow.cases.Case` (which provides ``data``, ``_get``,
    ``dx``, ``initial`` and ``_err``)."""

    data: dict[str, dict[str, Any]]

    @property
    def is_2d(self) -> bool:
        """Whether the case is on a 2D grid: ``grid.width`` is given (x down the slope,
        y across)."""
        return "width" in self.data.get("grid", {})

    @property
    def width(self) -> float:
        """The domain across, along y [m] (0 for a 1D case)."""
        return float(self._get("grid", "width", 0.0))

    @property
    def y_start(self) -> float:
        return float(self._get("grid", "y_start", 0.0))

    @property
    def dy(self) -> float:
        """Cell size along y [m]: width / cells_y, or ``grid.dy``, by default dx
        (square cells: the CFL step is then the same along both axes)."""
        if "cells_y" in self.data.get("grid", {}):
            return self.width / int(self.data["grid"]["cells_y"])
        return float(self._get("grid", "dy", self.dx))

    @property
    def cells_y(self) -> int:
        """Cells along y (1 for a 1D case)."""
        if not self.is_2d:
            return 1
        if "cells_y" in self.data.get("grid", {}):
            return int(self.data["grid"]["cells_y"])
        return max(1, round(self.width / self.dy))

    @property
    def total_cells(self) -> int:
        """Cells of the grid: :attr:`cells` (along x) times :attr:`cells_y`."""
        return self.cells * self.cells_y

    @property
    def release_centre(self) -> tuple[float, float]:
        """The release's centre (x, y) [m] in the grid's coordinates (the shape's x0, y0
        from the domain's corner, or a polygon's area centroid, plus x_start, y_start)."""
        x0, y0 = release_centre(self.initial)
        return self.x_start + x0, self.y_start + y0

    def terrain_corners(self) -> np.ndarray | None:
        """The bed [m] at the grid's cell corners (nx + 1, ny + 1) of a case with a
        ``[terrain]`` table, the PDE's ``bed``; None without one
        (:func:`pdeflow.case_terrain.terrain_corners`)."""
        return terrain_corners(self)

    def _initial_profiles_2d(self, model: str, grid) -> dict[str, np.ndarray]:
        """:meth:`initial_profiles` on a 2D grid: the 2D shape's total depth
        (:mod:`pdeflow.initial_shapes_2d`), split by the system as a 1D heap is; over a
        ``[terrain]`` bed measured vertically (:func:`pdeflow.case_terrain.release_depth`)."""
        system = systems.get(model)
        x, y = np.meshgrid(grid.axes_coords[0] - self.x_start,
                           grid.axes_coords[1] - self.y_start, indexing="ij")
        h = total_depth_2d(self.initial, x, y)
        if not np.any(h > 0):
            raise self._err(f"initial: the {self.initial['shape']} covers no cell centre "
                            f"of the grid (dx = {self.dx:g} m, dy = {self.dy:g} m): "
                            "enlarge it or refine the grid")
        corners = self.terrain_corners()
        if corners is not None:  # the model over a bed carries the vertical depth
            h = release_depth(self, h, corners)
        params = system.parameters_class.from_dict(self.data.get(model, {}))
        depths = system.layer_depths(h, x, self.initial, params)
        out: dict[str, np.ndarray] = {}
        for layer, depth in zip(system.layers, depths, strict=True):
            out[layer.depth] = depth
            out[layer.velocity] = np.zeros_like(h)
            out[layer.velocity_y] = np.zeros_like(h)
        return out

