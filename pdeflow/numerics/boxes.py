"""Boxes of cells: the windows of the ``fv-split`` stepping loop on any grid.

The kernels see a grid's cells flattened (``q[field, cell]``, py-pde's C order): a cell
is ``x line + y``, ``line`` the cells of a line of the last axis. A *box* is a rectangle
of rows ``x0..x1`` and columns ``y0..y1``, named by its first and last cell,
``lo = x0 line + y0`` and ``hi = x1 line + y1``. Every empty box is ``(1, 0)``, so that
``lo > hi`` says "empty" as it does for a range. A 1D grid is one line (``line`` = its
cells): a box is then a range of cells and every function here does what the loop did
on ranges, index for index. On a 2D grid a box skips the dry margins on either side of
a flow in y as well as in x, which a range of the flattened index cannot (it holds
whole rows).

The loop keeps its windows as boxes (the live cells' bounding box, widened by a step's
reach, :mod:`pdeflow.numerics.resting`) and visits a box row by row
(:func:`rows_of`): a row of a box is a range of the flattened index, which every
kernel of a model takes.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numba import njit, prange

from . import layout as L
from .compiled import cached


@cached(inline="always")
def box_of(x0: int, x1: int, y0: int, y1: int, line: int) -> tuple[int, int]:
    """The box of rows x0..x1 and columns y0..y1 as (lo, hi); (1, 0) if empty."""
    if x0 > x1 or y0 > y1:
        return 1, 0
    return x0 * line + y0, x1 * line + y1


@cached(inline="always")
def rows_of(lo: int, hi: int, line: int) -> tuple[int, int, int, int]:
    """The rows x0..x1 and columns y0..y1 of the box (lo, hi) (x0 > x1 if empty)."""
    if lo > hi:
        return 1, 0, 1, 0
    return lo // line, hi // line, lo % line, hi % line


@cached(inline="always")
def box_grow(lo: int, hi: int, k: int, line: int, n: int) -> tuple[int, int]:
    """The box (lo, hi) widened by ``k`` cells along both axes, clipped to the grid of
    ``n`` cells (an empty box stays empty)."""
    if lo > hi:
        return 1, 0
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    return box_of(max(x0 - k, 0), min(x1 + k, n // line - 1), max(y0 - k, 0),
                  min(y1 + k, line - 1), line)


@cached(inline="always")
def box_meet(lo: int, hi: int, lo2: int, hi2: int, line: int) -> tuple[int, int]:
    """The cells both boxes hold."""
    if lo > hi or lo2 > hi2:
        return 1, 0
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    a0, a1, b0, b1 = rows_of(lo2, hi2, line)
    return box_of(max(x0, a0), min(x1, a1), max(y0, b0), min(y1, b1), line)


@cached(inline="always")
def box_join(lo: int, hi: int, lo2: int, hi2: int, line: int) -> tuple[int, int]:
    """The smallest box that holds both boxes."""
    if lo > hi:
        return lo2, hi2
    if lo2 > hi2:
        return lo, hi
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    a0, a1, b0, b1 = rows_of(lo2, hi2, line)
    return box_of(min(x0, a0), max(x1, a1), min(y0, b0), max(y1, b1), line)


@cached(inline="always")
def contiguous(lo: int, hi: int, line: int) -> bool:
    """Whether the box (lo, hi) is the range lo..hi of the flattened index (one row,
    or whole rows): then a kernel on cells lo..hi visits exactly the box."""
    return lo > hi or lo // line == hi // line or (lo % line == 0 and hi % line == line - 1)


@cached(inline="always")
def copy_box(dst: np.ndarray, src: np.ndarray, lo: int, hi: int, line: int) -> None:
    """dst[:, cells of the box] = src[:, the same cells] for 2D arrays (loops: numba
    compiles an array-to-array slice assignment with its shape-mismatch error message,
    seconds)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for k in range(dst.shape[0]):
        for x in range(x0, x1 + 1):
            for i in range(x * line + y0, x * line + y1 + 1):
                dst[k, i] = src[k, i]


@cached(inline="always")
def zero_box(a: np.ndarray, lo: int, hi: int, line: int) -> None:
    """a[:, cells of the box] = 0 for 2D arrays (its rows on threads in a parallel
    kernel)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in prange(x0, x1 + 1):
        for k in range(a.shape[0]):
            for i in range(x * line + y0, x * line + y1 + 1):
                a[k, i] = 0.0


@cached(inline="always")
def copy_box1(dst: np.ndarray, src: np.ndarray, lo: int, hi: int, line: int) -> None:
    """:func:`copy_box` for 1D arrays (one value a cell)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in range(x0, x1 + 1):
        for i in range(x * line + y0, x * line + y1 + 1):
            dst[i] = src[i]


@cached(inline="always")
def clear_outside(a: np.ndarray, lo: int, hi: int, lo2: int, hi2: int,
                  line: int) -> None:
    """a[:, i] = 0 for the cells i of the box (lo, hi) outside the box (lo2, hi2)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    a0, a1, b0, b1 = rows_of(lo2, hi2, line)  # (1, 0, 1, 0) if empty: no row inside
    for x in range(x0, x1 + 1):
        inside = a0 <= x <= a1
        for y in range(y0, y1 + 1):
            if not (inside and b0 <= y <= b1):
                a[:, x * line + y] = 0.0


@cached(inline="always")
def clear_outside1(a: np.ndarray, lo: int, hi: int, lo2: int, hi2: int,
                   line: int) -> None:
    """:func:`clear_outside` for 1D arrays (one value a cell)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    a0, a1, b0, b1 = rows_of(lo2, hi2, line)
    for x in range(x0, x1 + 1):
        inside = a0 <= x <= a1
        for y in range(y0, y1 + 1):
            if not (inside and b0 <= y <= b1):
                a[x * line + y] = 0.0


@cached(inline="always")
def gather_rows(n: int, line: int, two_d: bool) -> np.ndarray:
    """Where the rows (or lines) of a pass over a box put what they share, one row of
    ``L.N_DIAG`` floats each (the source stage's bookings,
    :func:`pdeflow.numerics.threads.box_kernels`; the largest wave speed and mass rate,
    the wet and live boxes): one array for every pass of a stepping loop's call, so that
    no pass allocates per step. ``n`` cells in lines of ``line`` (a 2D
    grid, ``two_d``: rows x columns, as many entries as the longer side; a 1D grid
    shares nothing: one entry)."""
    return np.empty((max(n // line, line) if two_d else 1, L.N_DIAG))


def _sources_in_box(sources, q, dt, t, P, diag, gather, lo, hi, line):
    """The model's source stage on the cells of the box (lo, hi): one call on a box that
    is a range of the flattened index (a 1D grid's always), else one call a row
    (``gather``, what a 2D grid's rows share, is not used).

    A stage books what it saw in ``diag`` (``splitting.SOURCES``): a model's own slots
    must come out of calls on the rows as out of one call on their cells (times of last
    motion, sums and maxima in cell order do); of the scheme's, D_CHANGED is the 'or'
    over the rows and D_STEPS counts one stage."""
    if contiguous(lo, hi, line):
        sources(q, dt, t, P, diag, lo, hi)
        return
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    steps = diag[L.D_STEPS]
    changed = 0.0
    for x in range(x0, x1 + 1):
        sources(q, dt, t, P, diag, x * line + y0, x * line + y1)
        changed = max(changed, diag[L.D_CHANGED])
    diag[L.D_CHANGED] = changed
    diag[L.D_STEPS] = steps + 1.0


def _predictor_in_box(predictor, q, dt, P, lo, hi, line):
    """MUSCL's friction predictor on the cells of the box (lo, hi), row by row (it
    books nothing)."""
    if contiguous(lo, hi, line):
        predictor(q, dt, P, lo, hi)
        return
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in range(x0, x1 + 1):
        predictor(q, dt, P, x * line + y0, x * line + y1)


def update_in_box_function(update: Any) -> Any:
    """``update_in_box(q, base, rate, dt, weight, gather, lo, hi, line) -> (mass_rate,
    ok)``: the state update ``update``
    (:func:`pdeflow.numerics.advect_step.update_function`) on the cells of the box
    (lo, hi), one call or one a row, as :func:`_sources_in_box` (``gather`` not used);
    the largest mass rate and whether every row was ok."""

    def update_in_box(q, base, rate, dt, weight, gather, lo, hi, line):
        if contiguous(lo, hi, line):
            return update(q, base, rate, dt, weight, lo, hi)
        x0, x1, y0, y1 = rows_of(lo, hi, line)
        mass_rate = 0.0
        ok = True
        for x in range(x0, x1 + 1):
            m, row_ok = update(q, base, rate, dt, weight, x * line + y0, x * line + y1)
            mass_rate = max(mass_rate, m)
            ok = ok and row_ok
        return mass_rate, ok

    return update_in_box


def _sources_of_box(sources, q, dt, t, P, diag, gather, lo, hi, line):
    """A 2D grid's source stage, which takes the box itself
    (:func:`pdeflow.numerics.threads.box_kernels`: its rows on numba's threads)."""
    sources(q, dt, t, P, diag, gather, lo, hi, line)


def _predictor_of_box(predictor, q, dt, P, lo, hi, line):
    """A 2D grid's MUSCL predictor, which takes the box itself."""
    predictor(q, dt, P, lo, hi, line)


@functools.cache
def row_calls(compiled: bool, two_d: bool = False) -> tuple[Any, Any]:
    """The source stage and the predictor on a box, :func:`_sources_in_box` and
    :func:`_predictor_in_box` (``two_d``: the 2D kernels take the box themselves):
    inlined into a compiled loop (``compiled``), else plain Python (the loop run in
    Python, see ``splitting.python_stepping``), since they take the model's kernels as
    arguments."""
    calls = (_sources_of_box, _predictor_of_box) if two_d else \
        (_sources_in_box, _predictor_in_box)
    if not compiled:
        return calls
    return njit(inline="always")(calls[0]), njit(inline="always")(calls[1])
