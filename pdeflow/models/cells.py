"""A grid's cells as the models' py-pde shell hands them to the kernels.

The kernels see the cells of any grid flattened, ``q[field, cell]`` (py-pde's
``data[field, n0, n1]`` in C order, :mod:`pdeflow.numerics.geometry`): the
method-of-lines rate and the post-step hook on a grid of several axes
(:func:`flat_rate`, :func:`flat_hook`), the boundaries per axis (:func:`boundaries`)
and a flattened cell's name in messages (:func:`cell_name`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from pde import FieldCollection, ScalarField

from ..numerics import layout as L

BC_NAMES = L.BOUNDARIES


def flat_rate(advect: Any, sources: Any, shape: tuple[int, ...], dx: float,
              M: np.ndarray, bcl: int, bcr: int, g: float, r: float, dry: float,
              P: np.ndarray) -> Callable:
    """The compiled method-of-lines rate on a grid of several axes: the kernels see
    py-pde's ``data[field, n0, n1]`` with its cells flattened (C order)."""
    from numba import njit

    flat = (shape[0], int(np.prod(shape[1:])))
    work_shape = (2, *flat)  # closure arrays are read-only in numba

    @njit
    def rate(state_data, t):  # pragma: no cover - compiled
        # py-pde's data is a view without the ghost cells: flattening it copies
        q = np.ascontiguousarray(state_data).reshape(flat)
        out = np.empty(flat)
        advect(q, out, np.empty(work_shape), dx, M, bcl, bcr, g, r, dry)
        sources(q, out, P)
        return out.reshape(shape)

    return rate


def flat_hook(kernel: Any, shape: tuple[int, ...], P: np.ndarray) -> Callable:
    """The post-step hook on a grid of several axes (as
    :meth:`pdeflow.models.base.GranularPDE.make_post_step_hook`'s): the source stage on
    the flattened cells; depths in rows 0, 3, ... (depth, discharges along x and y)."""
    flat = (shape[0], int(np.prod(shape[1:])))

    def post_step_hook(state_data, t, post_step_data):
        dt = post_step_data[0]
        # a copy if state_data is py-pde's view without the ghost cells; py-pde's
        # compiled steppers keep their own reference: the result goes back in place
        q = np.ascontiguousarray(state_data).reshape(flat)
        if not (np.all(np.isfinite(q)) and np.all(q[::3] >= -1e-12)):
            post_step_data[L.D_BAD_STEPS] += 1.0  # the kernel clips what it counts
        kernel(q, dt, t + dt, P, post_step_data)
        state_data[:] = q.reshape(state_data.shape)
        return state_data, post_step_data

    return post_step_hook


def boundaries(bc: Any) -> tuple[tuple[str, str], ...]:
    """``bc`` of :class:`~pdeflow.models.base.GranularPDE` as (low, high) names per
    axis (one pair: every axis), or ValueError naming the allowed forms."""

    def pair(b: Any) -> bool:
        return (not isinstance(b, str) and isinstance(b, Sequence) and len(b) == 2
                and all(isinstance(n, str) and n in BC_NAMES for n in b))

    if pair(bc):
        return ((bc[0], bc[1]),)
    if not isinstance(bc, str) and isinstance(bc, Sequence) and len(bc) == 2 \
            and all(pair(b) for b in bc):
        return tuple((b[0], b[1]) for b in bc)
    raise ValueError(f"bc must be a pair of 'wall' or 'open' (left, right), or on a 2D "
                     f"grid one such pair per axis, got {bc!r}")


def cell_name(grid: Any, k: int) -> str:
    """Cell ``k`` of the flattened cells of ``grid`` and its position, for messages."""
    if grid.num_axes == 1:
        return f"cell {k} (x={grid.axes_coords[0][k]:g} m)"
    i, j = (int(n) for n in np.unravel_index(k, grid.shape))
    return (f"cell ({i}, {j}) (x={grid.axes_coords[0][i]:g} m, "
            f"y={grid.axes_coords[1][j]:g} m)")


def layer_fields(system: Any, grid: Any, axes: int, owner: str,
                 profiles: dict[str, np.ndarray]) -> FieldCollection:
    """The state of ``system`` on ``grid`` (``axes`` axes) from its depth and velocity
    profiles (:meth:`pdeflow.models.base.GranularPDE.make_state`; ``owner``: the PDE
    class's name for messages): ValueError naming a profile of the wrong name, shape or
    value."""
    shape = tuple(int(n) for n in grid.shape)
    known = list(system.profile_names_on(axes))
    unknown = sorted(set(profiles) - set(known))
    if unknown:
        raise ValueError(f"unknown profile(s) {unknown} for {owner}; allowed: {known}")
    hint = " (a 2D grid takes arrays of its shape: cells along x, y)" if axes == 2 else ""
    fields = []
    for layer in system.layers:
        names = (layer.depth, layer.velocity, layer.velocity_y)[:1 + axes]
        arrays = [np.asarray(profiles.get(name, np.zeros(shape)), dtype=float)
                  for name in names]
        for name, arr in zip(names, arrays, strict=True):
            if arr.shape != shape:
                raise ValueError(f"{name} must have shape {shape}, got {arr.shape}{hint}")
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{name} must be finite (no NaN or inf)")
        h = arrays[0]
        if np.any(h < 0):
            raise ValueError(f"{layer.depth} must be >= 0 m, got min {h.min():g}")
        discharges = (layer.discharge, layer.discharge_y)
        fields.append(ScalarField(grid, h, label=layer.depth))
        for label, u in zip(discharges, arrays[1:], strict=False):
            fields.append(ScalarField(grid, h * u, label=label))
    return FieldCollection(fields)
