"""The checks of a case that are about its dimension (issue 36), each error one line
naming the key, before any work: a 2D case (``grid.width`` given) has a valid y-axis
and boundaries across, a 2D shape, and none of the keys that are 1D only for now; a
1D case has none of the 2D keys. Called by :func:`pdeflow.case_validation.validate`."""

from __future__ import annotations

import math
from typing import Any

from . import systems
from .case_schema import CaseError
from .initial_shapes import SHAPES
from .initial_shapes_2d import SHAPES_2D, check_initial_2d
from .models.base import check_range
from .numerics.layout import BOUNDARIES

GRID_KEYS_2D = ("width", "dy", "cells_y", "y_start")
"""the [grid] keys of the y-axis"""
BOUNDARY_KEYS_2D = ("y_low", "y_high")
"""the [boundaries] keys of the sides across (y = y_start and y = y_start + width)"""
ISSUE = "is 1D only for now (issue 36)"
"""what the one-line errors about 1D-only keys and options say"""


def _err(case: Any, msg: str) -> CaseError:
    return CaseError(f"{case.source}: {msg}")


def check_dimension(case: Any) -> None:
    """A 1D case has no 2D key, shape or slope azimuth; a 2D case is checked by
    :func:`_check_2d`."""
    grid = case.data.get("grid", {})
    bounds = case.data.get("boundaries", {})
    if case.is_2d:
        _check_2d(case)
        return
    for section, keys in (("grid", GRID_KEYS_2D), ("boundaries", BOUNDARY_KEYS_2D)):
        for key in keys:
            if key in (grid if section == "grid" else bounds):
                raise _err(case, f"{section}.{key} belongs to a 2D grid: give "
                                 "grid.width [m] (the domain across) too")
    if case.initial.get("shape") in SHAPES_2D:
        raise _err(case, f"initial.shape {case.initial['shape']!r} is a 2D shape: give "
                         "grid.width [m] (the domain across) too")
    for model in systems.names():
        azimuth = case.data.get(model, {}).get("slope_azimuth_deg", 0.0)
        if azimuth != 0.0:
            raise _err(case, f"{model}.slope_azimuth_deg = {azimuth:g} belongs to a 2D "
                             "grid (a 1D slope is along x): give grid.width [m] too, or 0")


def _check_2d(case: Any) -> None:
    """The y-axis, the boundaries across, the keys that stay 1D, the shape."""
    if case.geometry != "planar":
        raise _err(case, f"grid.geometry = {case.geometry!r} is a 1D (radial) grid: "
                         "remove grid.width, or use geometry 'planar' for a 2D grid")
    try:
        check_range("grid.width", case.width, 0, math.inf, low_open=True, unit="m")
        grid = case.data["grid"]
        if "cells_y" in grid and grid["cells_y"] < 1:
            raise ValueError(f"grid.cells_y must be an integer >= 1, got "
                             f"{grid['cells_y']!r}")
        given = "dy" in grid or "cells_y" in grid
        check_range("grid.dy" if given else "grid.dy (by default grid.dx)", case.dy, 0,
                    case.width, low_open=True, unit="m")
        if "cells_y" not in grid:
            n = case.width / case.dy
            if abs(n - round(n)) > 1e-9 * n:
                raise ValueError(
                    f"grid.dy = {case.dy:g} m does not divide grid.width = "
                    f"{case.width:g} m into whole cells ({n:.6g}); use a dy in "
                    f"(0, {case.width:g}] m with width/dy an integer (dy defaults to "
                    "dx), or grid.cells_y")
    except ValueError as err:
        raise _err(case, str(err)) from None
    for side in BOUNDARY_KEYS_2D:
        bc = case.data.get("boundaries", {}).get(side, "wall")
        if bc not in BOUNDARIES:
            raise _err(case, f"boundaries.{side} must be one of {list(BOUNDARIES)}, got "
                             f"{bc!r}")
    _check_1d_only(case)
    shape = case.initial.get("shape")
    if shape is not None and shape not in SHAPES_2D:
        one_d = " is a 1D shape" if shape in SHAPES else " is no shape"
        raise _err(case, f"initial.shape {shape!r}{one_d}; on a 2D grid use one of "
                         f"{list(SHAPES_2D)}")


def _check_1d_only(case: Any) -> None:
    """What a 2D case may not ask for yet: the erosion series (its figures and
    trackers are 1D), py-pde's solvers (not tested in 2D)."""
    if case.data.get("output", {}).get("erosion_series") == "on":
        raise _err(case, f"output.erosion_series = 'on' {ISSUE}")


def check_shape_2d(case: Any) -> None:
    """The 2D shape's keys, ranges and centre (:func:`check_initial_2d`)."""
    try:
        check_initial_2d(case.initial, case.length, case.width)
    except ValueError as err:
        raise _err(case, str(err)) from None
