"""The initial shapes of 2D case files (``initial.shape`` on a grid with ``grid.width``,
issue 36): a total depth on the plane.

x runs down the slope (axis 0), y across (axis 1); both are measured from the domain's
corner (``grid.x_start``, ``grid.y_start``), as the 1D shapes measure x from the
domain's start (:mod:`pdeflow.initial_shapes`). Every shape is centred at (``x0``,
``y0``) [m] and has the height ``H0`` [m]; with rho^2 = ((x - x0)/a)^2 + ((y - y0)/b)^2
its normalised radius about the centre (a, b its semi-axes [m]):

* ``cylinder``: h = H0 where rho < 1, a = b = ``radius``;
* ``elliptic_column``: h = H0 where rho < 1, a = ``semi_x``, b = ``semi_y``;
* ``cap``: the paraboloid h = H0 max(1 - rho^2, 0), a = b = ``radius`` or a =
  ``semi_x``, b = ``semi_y`` (the shape of the Savage-Hutter similarity solution);
* ``box``: h = H0 where |x - x0| < ``semi_x`` and |y - y0| < ``semi_y`` (half-sides).

A cell is inside where its centre is (strict inequalities, as the 1D column's
x < L0). The part of a shape beyond a side of the domain is cut off: a wall through its
centre is a symmetry plane, so a quarter of a cylinder at a corner with two walls is
the whole collapse on a quarter of the cells. The centre must lie in the domain.

For two layers every 2D shape is split like the 1D ``dam_break`` and ``heap``: the
fraction ``upper_fraction`` (default 0.5) of the depth in the upper layer, the rest in
the lower one (:func:`pdeflow.models.two_layer.model.layer_depths`). The 1D column's
Rankine wedge (a cone under a cylinder) is not built in 2D yet.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .models.base import check_range

REQUIRED_2D: dict[str, tuple[str, ...]] = {
    "cylinder": ("x0", "y0", "radius", "H0"),
    "elliptic_column": ("x0", "y0", "semi_x", "semi_y", "H0"),
    "cap": ("x0", "y0", "H0"),  # and radius, or semi_x and semi_y
    "box": ("x0", "y0", "semi_x", "semi_y", "H0"),
}
"""the keys of [initial] each 2D shape needs"""
SHAPES_2D = tuple(REQUIRED_2D)
KEYS_2D = ("shape", "x0", "y0", "radius", "semi_x", "semi_y", "H0", "upper_fraction")
"""the keys of [initial] a 2D shape may have; the others are the 1D shapes'"""


def semi_axes(initial: dict[str, Any]) -> tuple[float, float]:
    """The semi-axes (a along x, b along y) [m] of a 2D shape: ``radius`` twice, or
    ``semi_x`` and ``semi_y`` (a box's half-sides)."""
    if "radius" in initial:
        return float(initial["radius"]), float(initial["radius"])
    return float(initial["semi_x"]), float(initial["semi_y"])


def check_initial_2d(initial: dict[str, Any], length: float, width: float) -> None:
    """ValueError (one line naming the key and its range) unless the [initial] table
    ``initial`` of a 2D shape has what it needs, in range, centred inside the domain of
    ``length`` x ``width`` [m]. The shape's name is checked before (``SHAPES_2D``)."""
    shape = initial["shape"]
    for key in initial:
        if key not in KEYS_2D:
            raise ValueError(f"initial.{key} is 1D only for now (issue 36): the 2D shape "
                             f"{shape!r} takes {[k for k in KEYS_2D if k != 'shape']}")
    for key in REQUIRED_2D[shape]:
        if key not in initial:
            raise ValueError(f"initial.{key} is required for shape {shape!r}")
    _check_axes(initial, shape)
    for key in ("radius", "semi_x", "semi_y", "H0"):
        if key in initial:
            check_range(f"initial.{key}", initial[key], 0, math.inf, low_open=True,
                        unit="m")
    if "upper_fraction" in initial:
        check_range("initial.upper_fraction", initial["upper_fraction"], 0, 1)
    for key, size, side in (("x0", length, "grid.length"), ("y0", width, "grid.width")):
        if not 0.0 <= float(initial[key]) <= size:
            raise ValueError(f"initial.{key} = {initial[key]:g} m puts the centre outside "
                             f"the domain: it must lie in [0, {size:g}] m (from the "
                             f"domain's corner; {side} = {size:g} m)")


def _check_axes(initial: dict[str, Any], shape: str) -> None:
    """The size keys of ``shape``: a cylinder has a radius only, an ellipse and a box
    their semi-axes only, a cap one or the other."""
    has_radius = "radius" in initial
    has_semi = "semi_x" in initial or "semi_y" in initial
    if shape == "cylinder" and has_semi:
        raise ValueError("initial.semi_x/semi_y are not keys of shape 'cylinder' (it "
                         "has a radius); use shape 'elliptic_column'")
    if shape in ("elliptic_column", "box") and has_radius:
        raise ValueError(f"initial.radius is not a key of shape {shape!r} (it has "
                         "semi_x and semi_y)")
    if shape == "cap" and has_radius == has_semi:
        raise ValueError("shape 'cap' needs either initial.radius or initial.semi_x "
                         "and initial.semi_y")
    if shape == "cap" and has_semi and not {"semi_x", "semi_y"} <= set(initial):
        raise ValueError("shape 'cap' with semi-axes needs both initial.semi_x and "
                         "initial.semi_y")


def total_depth_2d(initial: dict[str, Any], x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Total depth [m] of the 2D shape ``initial['shape']`` at the cell centres ``x``,
    ``y`` [m from the domain's corner; arrays of the grid's shape] (formulas in the
    module docstring)."""
    shape = initial["shape"]
    x0, y0, H0 = float(initial["x0"]), float(initial["y0"]), float(initial["H0"])
    a, b = semi_axes(initial)
    if shape == "box":
        return np.where((np.abs(x - x0) < a) & (np.abs(y - y0) < b), H0, 0.0)
    rho2 = ((x - x0) / a) ** 2 + ((y - y0) / b) ** 2
    if shape == "cap":
        return H0 * np.maximum(1.0 - rho2, 0.0)
    if shape in ("cylinder", "elliptic_column"):
        return np.where(rho2 < 1.0, H0, 0.0)
    raise ValueError(f"initial.shape {shape!r} has no 2D formula; allowed: "
                     f"{list(SHAPES_2D)}")


def release_front(initial: dict[str, Any]) -> float:
    """The release's largest x [m from the domain's corner]: x0 + a, from which the
    run-out along x is measured (as the 1D run-out from the column's front L0)."""
    return float(initial["x0"]) + semi_axes(initial)[0]
