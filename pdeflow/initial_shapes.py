"""The initial shapes of case files (``initial.shape``): a total depth on the grid.

Each shape gives the total depth h(x) [m] at the cell centres, x measured from the
domain's start (on an axisymmetric grid: the radius); the model's system splits it into
its layers (:attr:`pdeflow.systems.EquationSystem.layer_depths`). ``file`` reads the
profiles of every layer from an ``.npz`` instead.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from .models.base import check_range

REQUIRED: dict[str, tuple[str, ...]] = {
    "column": ("L0", "H0"),
    "column_on_bed": ("L0", "H0", "bed_thickness"),
    "dam_break": ("x_dam", "h_left"),
    "heap": ("center", "height", "slope_deg"),
    "file": ("path",),
}
"""the keys of [initial] each shape needs"""
SHAPES = tuple(REQUIRED)
COLUMN_SHAPES = ("column", "column_on_bed")
"""shapes whose material is a column of length (radius) L0 and height H0 at x = 0"""


def is_column(initial: dict[str, Any]) -> bool:
    """Whether the [initial] table ``initial`` describes a column (L0, H0)."""
    return initial.get("shape") in COLUMN_SHAPES


def has_bed(initial: dict[str, Any]) -> bool:
    """Whether the [initial] table lays an erodible bed (``column_on_bed``)."""
    return initial.get("shape") == "column_on_bed"


def check_initial(initial: dict[str, Any], length: float, base_dir: Path) -> None:
    """ValueError (one line, naming the key and its range) unless the [initial] table
    ``initial`` has what its shape needs, in range, inside a domain of ``length`` [m]
    (``path`` relative to ``base_dir``)."""
    shape = initial["shape"]
    for key in REQUIRED[shape]:
        if key not in initial:
            raise ValueError(f"initial.{key} is required for shape {shape!r}")
    for key in ("L0", "H0", "height", "bed_length"):
        if key in initial:
            check_range(f"initial.{key}", initial[key], 0, math.inf, low_open=True,
                        unit="m")
    for key in ("h_left", "h_right"):
        if key in initial:
            check_range(f"initial.{key}", initial[key], 0, math.inf, unit="m")
    for key in ("wedge_angle_deg", "slope_deg"):
        if key in initial:
            check_range(f"initial.{key}", initial[key], 0, 90, low_open=True,
                        high_open=True, unit="deg")
    if "bed_thickness" in initial:
        check_range("initial.bed_thickness", initial["bed_thickness"], 0, math.inf,
                    unit="m")
    if "upper_fraction" in initial:
        check_range("initial.upper_fraction", initial["upper_fraction"], 0, 1)
    if is_column(initial) and initial["L0"] > length:
        raise ValueError(f"initial.L0 = {initial['L0']:g} m is longer than the domain "
                         f"(grid.length = {length:g} m): the column must lie in "
                         f"(0, {length:g}] m; lengthen the domain or shorten the column")
    if shape == "file" and not (base_dir / initial["path"]).is_file():
        raise ValueError(f"initial.path: file {initial['path']} not found next to the "
                         "case file")


def total_depth(initial: dict[str, Any], x: np.ndarray) -> np.ndarray:
    """Total depth [m] of the shape ``initial['shape']`` (not 'file') at ``x`` [m]:

    * ``column``: H0 for x < L0 (a cylinder of radius L0 on an axisymmetric grid);
    * ``column_on_bed``: the same column (its bed is :func:`bed_depth`);
    * ``dam_break``: h_left for x < x_dam, h_right (default 0) beyond;
    * ``heap``: a symmetric triangle of ``height`` with flanks at ``slope_deg`` around
      ``center`` (a cone about the axis where center = 0 on an axisymmetric grid).
    """
    shape = initial["shape"]
    if shape in COLUMN_SHAPES:
        return np.where(x < float(initial["L0"]), float(initial["H0"]), 0.0)
    if shape == "dam_break":
        return np.where(x < float(initial["x_dam"]), float(initial["h_left"]),
                        float(initial.get("h_right", 0.0)))
    if shape == "heap":
        slope = math.tan(math.radians(float(initial["slope_deg"])))
        return np.maximum(float(initial["height"])
                          - slope * np.abs(x - float(initial["center"])), 0.0)
    raise ValueError(f"initial.shape {shape!r} has no formula; allowed: {list(SHAPES)}")


def bed_depth(initial: dict[str, Any], x: np.ndarray) -> np.ndarray | None:
    """Depth [m] of the erodible bed at ``x`` [m] (None if the shape lays none): for
    ``column_on_bed`` a layer of ``bed_thickness`` at rest from the column's front
    x = L0 over ``bed_length`` [m] (default: to the domain's end). Under the column the
    bed is rigid, as behind the gate of a laboratory channel. A system with an erodible
    layer (:attr:`pdeflow.systems.EquationSystem.bed_layer`) adds it to that layer; a
    model without one runs on the rigid bed."""
    if not has_bed(initial):
        return None
    return np.where(bed_region(initial, x), float(initial["bed_thickness"]), 0.0)


def bed_region(initial: dict[str, Any], x: np.ndarray) -> np.ndarray | None:
    """Where the shape lays its bed (None if it lays none): the cells ``x`` [m] from the
    column's front over ``bed_length``, also where ``bed_thickness`` is 0, so that the
    erosion diagnostics of a bed of any thickness look at the same cells."""
    if not has_bed(initial):
        return None
    L0 = float(initial["L0"])
    end = L0 + float(initial.get("bed_length", math.inf))
    return (x >= L0) & (x < end)


def profiles_from_file(path: Path, keys: tuple[str, ...], n: int,
                       model: str) -> dict[str, np.ndarray]:
    """The arrays ``keys`` of the ``.npz`` at ``path``, each of shape (n,); ValueError
    naming the file and what is wrong."""
    try:
        with np.load(path) as data:
            found = {k: np.asarray(data[k], dtype=float) for k in keys if k in data}
    except (OSError, ValueError) as err:
        raise ValueError(f"cannot read initial profile {path}: {err}") from None
    missing = [k for k in keys if k not in found]
    if missing:
        raise ValueError(f"initial profile {path.name} lacks arrays {missing} needed by "
                         f"the {model} model")
    out = {k: found[k] for k in keys}
    for k, v in out.items():
        if v.shape != (n,):
            raise ValueError(f"initial profile {path.name}: array {k} has shape "
                             f"{v.shape}, the grid has ({n},) cells")
    return out
