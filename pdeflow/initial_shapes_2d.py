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
* ``box``: h = H0 where |x - x0| < ``semi_x`` and |y - y0| < ``semi_y`` (half-sides);
* ``polygon``: h = H0 inside the polygon ``vertices`` = [[x, y], ...] [m] (at least 3,
  in order, either sense; the even-odd rule, so a self-crossing outline has holes); its
  centre (x0, y0) is the area centroid, not a key.

A cell is inside where its centre is (strict inequalities, as the 1D column's
x < L0). The part of a shape beyond a side of the domain is cut off: a wall through its
centre is a symmetry plane, so a quarter of a cylinder at a corner with two walls is
the whole collapse on a quarter of the cells. The centre (a polygon: every vertex) must
lie in the domain.

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
    "polygon": ("vertices", "H0"),
}
"""the keys of [initial] each 2D shape needs"""
SHAPES_2D = tuple(REQUIRED_2D)
KEYS_2D = ("shape", "x0", "y0", "radius", "semi_x", "semi_y", "vertices", "H0",
           "upper_fraction", "measured")
"""the keys of [initial] a 2D shape may have; the others are the 1D shapes' (``measured``:
how H0 is measured over a [terrain] bed, checked by :mod:`pdeflow.case_terrain`)"""


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
    if shape == "polygon":
        _check_polygon(initial, length, width)
        return
    if "vertices" in initial:
        raise ValueError(f"initial.vertices is not a key of shape {shape!r} (only of "
                         "'polygon')")
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


def _check_polygon(initial: dict[str, Any], length: float, width: float) -> None:
    """A polygon: H0 > 0, >= 3 vertices [x, y] of finite numbers inside the domain of
    ``length`` x ``width`` [m], a non-zero area, none of the other shapes' keys."""
    for key in ("x0", "y0", "radius", "semi_x", "semi_y"):
        if key in initial:
            raise ValueError(f"initial.{key} is not a key of shape 'polygon' (its "
                             "vertices give it; its centre is their area centroid)")
    check_range("initial.H0", initial["H0"], 0, math.inf, low_open=True, unit="m")
    if "upper_fraction" in initial:
        check_range("initial.upper_fraction", initial["upper_fraction"], 0, 1)
    vertices = initial["vertices"]
    if len(vertices) < 3 or not all(
            isinstance(v, list) and len(v) == 2
            and all(isinstance(c, (int, float)) and not isinstance(c, bool)
                    and math.isfinite(c) for c in v) for v in vertices):
        raise ValueError("initial.vertices must be a list of at least 3 points [x, y] "
                         f"of finite numbers [m], got {vertices!r}")
    for x, y in vertices:
        if not (0.0 <= x <= length and 0.0 <= y <= width):
            raise ValueError(f"initial.vertices: the vertex [{x:g}, {y:g}] lies outside "
                             f"the domain: each must lie in [0, {length:g}] x "
                             f"[0, {width:g}] m (from the domain's corner)")
    if _polygon_area(np.array(vertices, dtype=float)) == 0.0:
        raise ValueError("initial.vertices enclose no area (the points lie on a line)")


def _polygon_area(p: np.ndarray) -> float:
    """The signed area [m^2] of the polygon with the vertices ``p`` (n, 2) (shoelace)."""
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def inside_polygon(vertices: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Whether the points ``x``, ``y`` [m] lie inside the polygon ``vertices`` (n, 2)
    [m], by the even-odd rule: a ray from the point towards +x crosses the outline an
    odd number of times (each edge counts where it spans the point's y half-open,
    so a ray through a vertex counts once)."""
    inside = np.zeros(np.shape(x), dtype=bool)
    for (xi, yi), (xj, yj) in zip(vertices, np.roll(vertices, -1, axis=0), strict=True):
        spans = (yi > y) != (yj > y)
        with np.errstate(divide="ignore", invalid="ignore"):  # horizontal edges: no span
            crossing = x < xi + (xj - xi) * (y - yi) / (yj - yi)
        inside ^= spans & crossing
    return inside


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
    H0 = float(initial["H0"])
    if shape == "polygon":
        return np.where(inside_polygon(np.array(initial["vertices"], dtype=float), x, y),
                        H0, 0.0)
    x0, y0 = float(initial["x0"]), float(initial["y0"])
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
    """The release's largest x [m from the domain's corner]: x0 + a (a polygon: its
    largest vertex x), from which the run-out along x is measured (as the 1D run-out
    from the column's front L0)."""
    if initial["shape"] == "polygon":
        return float(max(x for x, _ in initial["vertices"]))
    return float(initial["x0"]) + semi_axes(initial)[0]


def release_centre(initial: dict[str, Any]) -> tuple[float, float]:
    """The release's centre (x0, y0) [m from the domain's corner], about which the
    summary's mass radius is measured: the keys, or a polygon's area centroid."""
    if initial["shape"] != "polygon":
        return float(initial["x0"]), float(initial["y0"])
    p = np.array(initial["vertices"], dtype=float)
    q = np.roll(p, -1, axis=0)
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]  # twice each edge's triangle's area
    area = 0.5 * cross.sum()
    cx, cy = ((p + q) * cross[:, None]).sum(axis=0) / (6.0 * area)
    return float(cx), float(cy)
