"""Validation of a case (:meth:`pdeflow.cases.Case.validate`): sections, keys, types,
ranges and choices, each error one line naming the key and the file, before any work."""

from __future__ import annotations

import math
from typing import Any

from . import systems
from .case_schema import FRAMES, SCHEMA, SERIES, CaseError
from .case_terrain import check_bed, check_terrain
from .case_validation_2d import check_dimension, check_shape_2d
from .initial_shapes import SHAPES, check_initial
from .initial_shapes_2d import SHAPES_2D
from .models.base import check_range
from .numerics.layout import BOUNDARIES, GEOMETRIES
from .variant import MAX_CFL, VariantError


def _err(case: Any, msg: str) -> CaseError:
    return CaseError(f"{case.source}: {msg}")


def validate(case: Any) -> None:
    """Check sections, keys, types and ranges; raise CaseError naming the key."""
    from .checks import check_memory

    _check_sections(case)
    try:
        check_range("case.t_end", case.t_end, 0, math.inf, low_open=True, unit="s")
        check_range("grid.length", case.length, 0, math.inf, low_open=True,
                    unit="m")
        _check_cells(case)
        check_range("grid.dx", case.dx, 0, case.length, low_open=True, unit="m")
        check_range("numerics.cfl", case.cfl, 0, 1, low_open=True)
        reconstruction = case.data.get("numerics", {}).get("reconstruction")
        if reconstruction == "muscl":
            check_range("numerics.cfl (with reconstruction = 'muscl')", case.cfl, 0,
                        MAX_CFL[reconstruction], low_open=True)
        if "dt" in case.data.get("numerics", {}):
            check_range("numerics.dt", case.data["numerics"]["dt"], 0, math.inf,
                        low_open=True, unit="s")
        for t in case._all_snapshot_times():  # those past t_end are dropped
            check_range("output.snapshot_times", t, 0, math.inf, unit="s")
        check_range("output.front_threshold", case.front_threshold, 0, math.inf,
                    low_open=True, unit="m")
        check_range("output.runout_mass_fraction", case.runout_mass_fraction, 0, 1,
                    low_open=True, high_open=True)
        check_range("output.series_every", case.series_every, 0, case.t_end,
                    low_open=True, unit="s")
    except ValueError as err:
        raise _err(case, str(err)) from None
    check_dimension(case)  # a 2D grid's keys, or none of them (before the geometry's)
    check_terrain(case)  # a [terrain] table's keys (2D, single layer), before any work
    _check_geometry(case)
    if case._get("output", "erosion_series", "auto") not in SERIES:
        raise _err(case, f"output.erosion_series must be one of {list(SERIES)}, got "
                        f"{case._get('output', 'erosion_series', 'auto')!r}")
    if case.frames not in FRAMES:
        raise _err(case, f"output.frames must be one of {list(FRAMES)}, got "
                        f"{case.frames!r}")
    for side in ("left", "right"):
        bc = case.data.get("boundaries", {}).get(side, "wall" if side == "left"
                                                  else "open")
        if bc not in BOUNDARIES:
            raise _err(case, f"boundaries.{side} must be one of {list(BOUNDARIES)}, got "
                             f"{bc!r}")
    if "initial" not in case.data or "shape" not in case.data["initial"]:
        raise _err(case, "[initial] with a 'shape' is required")
    try:
        case.variant  # noqa: B018 - checks solver, flux, reconstruction, limiter, ...
    except VariantError as err:
        raise _err(case, str(err)) from None
    shapes = SHAPES_2D if case.is_2d else SHAPES
    if case.initial["shape"] not in shapes:
        raise _err(case, f"initial.shape must be one of {list(shapes)}, got "
                        f"{case.initial['shape']!r}")
    if case.is_2d:
        check_shape_2d(case)
    else:
        _check_initial(case)
    try:
        check_memory(case)
    except ValueError as err:
        raise _err(case, str(err)) from None
    check_bed(case)  # the bed itself, last: reads a DEM, checks its coverage

def _check_sections(case: Any) -> None:
    """Known sections and keys of the right types; the models' parameters; known
    models."""
    for section, content in case.data.items():
        if section not in SCHEMA and section not in systems.names():
            raise _err(case, f"unknown section [{section}]; allowed: "
                            f"{[*SCHEMA, *systems.names()]}")
        if not isinstance(content, dict):
            raise _err(case, f"[{section}] must be a table")
        allowed = SCHEMA.get(section)
        if not allowed:
            continue  # a model's section: checked by its parameter class
        for key, value in content.items():
            if key not in allowed:
                raise _err(case, f"unknown key {section}.{key}; allowed: "
                                f"{sorted(allowed)}")
            if isinstance(value, bool) or not isinstance(value, allowed[key]):
                names = " or ".join(t.__name__ for t in allowed[key])
                raise _err(case, f"{section}.{key} must be {names}, got {value!r}")
            _check_finite(case, f"{section}.{key}", value)
    for name in systems.names():
        try:
            systems.get(name).parameters_class.from_dict(case.data.get(name, {}))
        except (ValueError, TypeError) as err:
            raise _err(case, f"[{name}] {err}") from None
    if not case.models:
        raise _err(case, f"case.models must name at least one model of "
                        f"{list(systems.names())}, got []")
    for model in case.models:
        if model not in systems.names():
            raise _err(case, f"case.models: unknown model {model!r}; allowed: "
                            f"{list(systems.names())}")
    if len(set(case.models)) < len(case.models):
        raise _err(case, f"case.models names a model twice: {case.models}")


def _check_geometry(case: Any) -> None:
    """grid.geometry is 'planar' or 'axisymmetric'; an axisymmetric grid starts at the
    axis (x_start = 0), whose boundary is a wall (mirror symmetry: no flux)."""
    if case.geometry not in GEOMETRIES:
        raise _err(case, f"grid.geometry must be one of {list(GEOMETRIES)}, got "
                        f"{case.geometry!r}")
    if case.geometry != "axisymmetric":
        return
    if case.x_start != 0.0:
        raise _err(case, f"grid.x_start must be 0 on an axisymmetric grid (the axis), "
                        f"got {case.x_start:g}")
    if case.bc[0] != "wall":
        raise _err(case, "boundaries.left is the axis on an axisymmetric grid and must "
                        f"be 'wall' (symmetry: no flux), got {case.bc[0]!r}")
    for model in case.models:
        theta = systems.get(model).parameters_class.from_dict(
            case.data.get(model, {})).theta_deg
        if theta != 0.0:
            raise _err(case, f"{model}.theta_deg must be 0 on an axisymmetric grid "
                            f"(radial flow on a horizontal plane), got {theta:g}")

def _check_finite(case: Any, key: str, value: Any) -> None:
    """Numbers (also inside lists) must be finite: TOML allows nan and inf."""
    items = value if isinstance(value, list) else [value]
    for v in items:
        if isinstance(value, list) and key == "output.snapshot_times" and (
                isinstance(v, bool) or not isinstance(v, (int, float))):
            raise _err(case, f"{key} must be a list of numbers [s], got {v!r}")
        if isinstance(v, float) and not math.isfinite(v):
            raise _err(case, f"{key} must be a finite number, got {v!r}")

def _check_cells(case: Any) -> None:
    """grid.cells >= 1 (it wins over grid.dx); grid.dx must divide grid.length."""
    grid = case.data.get("grid", {})
    if "cells" in grid:
        if grid["cells"] < 1:
            raise ValueError(f"grid.cells must be an integer >= 1, got "
                             f"{grid['cells']!r}")
    elif "dx" in grid and case.dx > 0:
        n = case.length / case.dx
        if abs(n - round(n)) > 1e-9 * n:
            raise ValueError(
                f"grid.dx = {case.dx:g} m does not divide grid.length = "
                f"{case.length:g} m into whole cells ({n:.6g}); use a dx in "
                f"(0, {case.length:g}] m with length/dx an integer, or grid.cells")

def _check_initial(case: Any) -> None:
    try:
        check_initial(case.initial, case.length, case.base_dir)
    except ValueError as err:
        raise _err(case, str(err)) from None
