r"""The finite-volume metric of a grid: face areas and cell volumes.

A cell's average q_i changes by the fluxes through its faces weighted by their areas,

.. math:: V_i \frac{dq_i}{dt} = -(A_{i+1/2} F_{i+1/2} - A_{i-1/2} F_{i-1/2}) + \dots

On the planar slope (a 1D ``CartesianGrid``, per unit width) A = 1 and V = dx, and the
update is the one of a uniform grid. On a 2D ``CartesianGrid`` the faces of each axis
have area 1 and the cells dx dy: every face of axis a weighs 1/dx_a
(:mod:`pdeflow.numerics.advection`; a model with 2D kernels runs on it). On py-pde's
``PolarSymGrid``
(radial flow of an axisymmetric collapse on [0, R]) A_{i+1/2} = 2 pi r_{i+1/2} and
V_i = pi (r_{i+1/2}^2 - r_{i-1/2}^2); the axis r = 0 is a face of area 0.
:class:`Metric` holds these as the array the advection kernels read (rows
``layout.M_*``); the kernels are specialised to the geometry's code (``layout.GEOMETRY_*``),
so that the planar update is exactly the uniform-grid one.

The kernels see the cells of any grid flattened, ``q[field, cell]`` with py-pde's
``data[field, n0, n1]`` in C order (cell = i0 n1 + i1), and each axis as a stride in
that index, a number of cells and a cell width (row ``layout.M_AXES``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import layout as L
from .compiled import cached
from .state import velocity

COORDINATES = {"planar": "x", "axisymmetric": "r", "planar-2d": "x"}
"""the name of each geometry's coordinate [m]"""


@dataclass(frozen=True, eq=False)
class Metric:
    """Face areas and cell volumes of a 1D finite-volume grid (see the module docstring)."""

    geometry: str
    """'planar' or 'axisymmetric'"""
    coordinate: str
    """name of the grid's coordinate: 'x' [m] (planar) or 'r' [m] (axisymmetric)"""
    dx: float
    """cell width dx or dr [m]"""
    faces: np.ndarray
    """face positions [m] along the first axis, n + 1"""
    areas: np.ndarray
    """face areas: 1 (planar, per unit width) or 2 pi r [m], n + 1"""
    volumes: np.ndarray
    """cell volumes: dx [m] (planar) or pi (r+^2 - r-^2) [m^2] or dx dy [m^2] (2D),
    one per cell"""
    shape: tuple[int, ...] = ()
    """cells along each axis (default: one axis of ``volumes.size`` cells)"""
    spacing: tuple[float, ...] = ()
    """cell width along each axis [m] (default: ``(dx,)``)"""
    bed: np.ndarray | None = None
    """a 2D grid over a bed z_b(x, y): its elevation [m] at the cells' corners,
    (nx + 1, ny + 1) (:func:`bed_at_corners`); None: no bed"""

    @property
    def axes(self) -> list[tuple[int, int, float]]:
        """(stride in the flattened cell index, cells, width [m]) of each axis."""
        shape = self.shape or (self.volumes.size,)
        spacing = self.spacing or (self.dx,)
        strides = [int(np.prod(shape[a + 1:])) for a in range(len(shape))]
        return list(zip(strides, shape, spacing, strict=True))

    @property
    def code(self) -> int:
        """The geometry's code for the kernels (layout.GEOMETRY_*)."""
        if self.bed is not None:
            return L.GEOMETRY_TERRAIN_2D
        return L.GRID_GEOMETRIES[self.geometry]

    def array(self) -> np.ndarray:
        """The rows layout.M_* as one C-contiguous array of shape (N_METRIC, n + 1) (at
        least 3 per axis wide): on a 1D grid per face its weights in the cells left and
        right of it and per cell its area change; the axes (row M_AXES); over a bed
        the rows M_BED (:func:`face_beds`)."""
        n = self.volumes.size
        axes = self.axes
        rows = L.N_METRIC + (L.N_BED if self.bed is not None else 0)
        out = np.zeros((rows, max(n + 1, 3 * len(axes))))
        if self.bed is not None:
            out[L.M_BED:L.M_BED + L.N_BED, :n] = face_beds(self.bed)
        if len(axes) == 1:
            out[L.M_LEFT, 1:n + 1] = self.areas[1:] / self.volumes  # face i - 1/2 into i - 1
            out[L.M_RIGHT, :n] = self.areas[:-1] / self.volumes
            out[L.M_AREA_CHANGE, :n] = (self.areas[1:] - self.areas[:-1]) / self.volumes
        out[L.M_AXES, :3 * len(axes)] = np.ravel(axes)
        return out

    @property
    def cells(self) -> float | np.ndarray:
        """What :func:`pdeflow.metrics.mass` weights cells with: dx [m] on the planar
        grid (uniform cells, per unit width), else the cell volumes [m^3]."""
        return self.dx if self.geometry == "planar" else self.volumes

    def integral(self, values: np.ndarray) -> float:
        """sum_i V_i values_i: the volume integral of a cell field (planar: per unit width,
        sum(values) dx, computed so)."""
        if self.geometry == "planar":
            return float(np.sum(values) * self.dx)
        return float(np.sum(values * self.volumes))


def geometry_of(grid: Any, two_d: bool = False) -> str:
    """'planar' for a non-periodic 1D ``CartesianGrid``, 'axisymmetric' for a
    ``PolarSymGrid`` starting at the axis, with ``two_d`` 'planar-2d' for a non-periodic
    2D ``CartesianGrid``; ValueError for any other grid. Cheap: no arrays (the
    method-of-lines rate checks its grid on every call)."""
    from pde import CartesianGrid, PolarSymGrid

    if isinstance(grid, PolarSymGrid):
        r0, r1 = grid.axes_bounds[0]
        if r0 != 0.0:
            raise ValueError("an axisymmetric grid must start at the axis: PolarSymGrid "
                             f"on [0, R], got [{r0:g}, {r1:g}] m")
        return "axisymmetric"
    axes = (1, 2) if two_d else (1,)
    if not isinstance(grid, CartesianGrid) or grid.num_axes not in axes:
        kinds = "a 1D or 2D" if two_d else "a 1D"
        raise ValueError(f"grid must be {kinds} CartesianGrid or a PolarSymGrid, got {grid!r}")
    if any(grid.periodic):
        raise ValueError("grid must not be periodic: use wall or open boundaries")
    return "planar" if grid.num_axes == 1 else "planar-2d"


def metric_of(grid: Any, bed: np.ndarray | None = None) -> Metric:
    """The metric of a grid that :func:`geometry_of` accepts, a 2D ``CartesianGrid``
    included (a model without 2D kernels refuses it before: ``GranularPDE.geometry``);
    ``bed``: the corners' elevations of a bed under a 2D grid (:func:`bed_at_corners`)."""
    geometry = geometry_of(grid, two_d=True)
    if bed is not None and geometry != "planar-2d":
        raise ValueError(f"bed needs a 2D CartesianGrid, got a {geometry} grid")
    if geometry == "planar-2d":
        shape = tuple(int(n) for n in grid.shape)
        spacing = tuple(float(d) for d in grid.discretization)
        x0, x1 = grid.axes_bounds[0]
        return Metric(geometry, COORDINATES[geometry], spacing[0],
                      np.linspace(x0, x1, shape[0] + 1), np.ones(shape[0] + 1),
                      np.full(shape[0] * shape[1], spacing[0] * spacing[1]), shape, spacing,
                      bed)
    if geometry == "axisymmetric":
        r1 = grid.axes_bounds[0][1]
        n = grid.shape[0]
        dr = float(grid.discretization[0])
        faces = np.linspace(0.0, float(r1), n + 1)
        return Metric(geometry, COORDINATES[geometry], dr, faces, 2 * math.pi * faces,
                      math.pi * (faces[1:] ** 2 - faces[:-1] ** 2))
    n = grid.shape[0]
    dx = float(grid.discretization[0])
    x0, x1 = grid.axes_bounds[0]
    return Metric(geometry, COORDINATES[geometry], dx, np.linspace(x0, x1, n + 1),
                  np.ones(n + 1),
                  np.full(n, dx))


def corner_coordinates(grid: Any) -> tuple[np.ndarray, np.ndarray]:
    """The x (nx + 1,) and y (ny + 1,) [m] of the cell corners of a 2D grid."""
    (x0, x1), (y0, y1) = grid.axes_bounds
    nx, ny = (int(n) for n in grid.shape)
    return np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)


def bed_at_corners(grid: Any, bed: Any) -> np.ndarray | None:
    """The bed's elevations [m] at the corners of the 2D ``grid``'s cells, (nx + 1,
    ny + 1): ``bed`` is that array, or a function z_b(x, y) [m] of the corners'
    coordinates (broadcast arrays, the grid's own coordinates [m]); None for None.
    ValueError naming ``bed`` for a grid that is not 2D, a wrong shape or a value that
    is not finite."""
    if bed is None:
        return None
    if geometry_of(grid, two_d=True) != "planar-2d":
        raise ValueError(f"bed needs a 2D CartesianGrid, got a {geometry_of(grid)} grid")
    xs, ys = corner_coordinates(grid)
    if callable(bed):
        bed = bed(*np.meshgrid(xs, ys, indexing="ij"))
    z = np.array(bed, dtype=float)
    if z.shape != (xs.size, ys.size):
        raise ValueError(f"bed must give the elevation at the grid's {xs.size} x {ys.size}"
                         f" cell corners, got shape {z.shape}")
    bad = np.argwhere(~np.isfinite(z))
    if bad.size:
        i, j = bad[0]
        raise ValueError(f"bed must be finite at every corner, got {z[i, j]} at x = "
                         f"{xs[i]:g} m, y = {ys[j]:g} m and {len(bad) - 1} more")
    return np.ascontiguousarray(z)


def centre_values(corners: np.ndarray) -> np.ndarray:
    """The mean [m] of each cell's four corner values ``corners`` (nx + 1, ny + 1):
    the bed at the cell centres (nx, ny)."""
    c = np.asarray(corners, dtype=float)
    return 0.25 * (c[:-1, :-1] + c[1:, :-1] + c[:-1, 1:] + c[1:, 1:])


def face_beds(corners: np.ndarray) -> np.ndarray:
    r"""The rows layout.M_BED of a 2D grid over a bed, (4, nx ny) [m]: per cell (C
    order) the bed at the middle of its faces x-low, x-high, y-low, y-high, each the mean
    of the face's two corners. The bed is continuous and linear along every face (the
    piecewise-bilinear interpolant of the corners), so two neighbours see the same bed
    at their common face and the faces' Riemann problems have no bed step; the cell's
    bed, the mean of its four corners, is the mean of its two face values along either
    axis (Kurganov & Petrova 2007)."""
    zx = 0.5 * (corners[:, :-1] + corners[:, 1:])  # x-faces (nx + 1, ny)
    zy = 0.5 * (corners[:-1, :] + corners[1:, :])  # y-faces (nx, ny + 1)
    return np.stack([zx[:-1].ravel(), zx[1:].ravel(), zy[:, :-1].ravel(),
                     zy[:, 1:].ravel()])


@cached
def area_change(q, unused, rate, lo, hi, metric, dry, width):
    """Subtract (A_{i+1/2} - A_{i-1/2}) / V_i F^adv(q_i) in the cells lo..hi, F^adv =
    (h u, h u^2) of each layer (first order: the cell averages)."""
    for i in range(lo, hi + 1):
        c = metric[L.M_AREA_CHANGE, i]
        for k in range(0, q.shape[0], width):
            h = q[k, i]
            u = velocity(h, q[k + 1, i], dry)  # as the fluctuations: 0 in a dry layer
            rate[k, i] -= c * (u * h)
            rate[k + 1, i] -= c * (u * u * h)


@cached
def area_change_muscl(qm, qp, rate, lo, hi, metric, dry, width):
    """:func:`area_change` with F^adv averaged over the cell's face values qm, qp."""
    for i in range(lo, hi + 1):
        c = metric[L.M_AREA_CHANGE, i]
        for k in range(0, qm.shape[0], width):
            hm = qm[k, i]
            hp = qp[k, i]
            um = velocity(hm, qm[k + 1, i], dry)
            up = velocity(hp, qp[k + 1, i], dry)
            rate[k, i] -= c * 0.5 * (um * hm + up * hp)
            rate[k + 1, i] -= c * 0.5 * (um * um * hm + up * up * hp)
