r"""Cells at rest that a step of the ``fv-split`` loop does not visit.

A step changes a cell only through its stencil. A cell whose stencil holds no *live*
cell -- one that moved (some layer's discharge is not zero) or changed in the last
step -- is left exactly as it is by the next step: its faces are faces of layers at
rest (no mass crosses them, :mod:`pdeflow.numerics.hll`), the hydrostatic force and
gravity it feels are those friction held in the last step, and the set-valued implicit
friction holds them again whatever dt is. So the loop visits the live cells widened by
the reach of one step (:func:`reach`) and skips the rest: a long erodible bed at rest
ahead of the flow, or the part of a deposit that has stopped, costs nothing per step.

The time step must not notice: dt = CFL dx / max|S| is taken over *every* face a full
sweep would visit, and the skipped ones are faces at rest, whose wave-speed bound is
:math:`\max(c_L, c_R)`, :math:`c = \sqrt{g_z H}` with H the cell's total depth (the
Davis bound of every flux with zero velocities, single or two layers). The loop keeps
the running maxima of c from either end of the grid (:func:`extend_prefix`,
:func:`extend_suffix`) and updates them only where cells froze, so that a run gives the
same numbers, bit for bit, as one that visits every wet cell
(``tests/test_resting_cells.py``; 2D: ``tests/test_two_d_dry_margin.py``). Over a bed
(layout.GEOMETRY_TERRAIN_2D) the reconstruction's face depths reach h + |d|, so the
advection stage gives a face between two resting cells this same bound instead of its
states' speeds (:func:`pdeflow.numerics.advection._faces_function`), and the identity
holds there too.

Cells are the flattened index of any grid (:mod:`pdeflow.numerics.geometry`): a cell's
neighbours are those along its line of the last axis (``line`` cells long; on a 1D grid
the whole grid) and ``line`` cells before and after it (the first axis of a 2D grid).
The loop's windows are boxes of rows x columns (:mod:`pdeflow.numerics.boxes`; on a 1D
grid ranges), so on a 2D grid a flow's dry (or resting) margins in y are skipped as well
as those in x. The running maxima of the rest speeds outside a box
(:func:`rest_outside`) are kept along the flattened index for the rows before and
after the box, and along each of the box's rows for its cells before and after the
box's columns; on a 2D grid the loop scales them as the advection stage scales the
speeds of its faces.
"""

from __future__ import annotations

import math

import numpy as np

from .advection import _is_wet
from .boxes import box_of, rows_of
from .compiled import cached


def reach(order: int) -> int:
    """How many cells away from a live cell one step can change a cell at rest: a
    first-order stage reads the two faces of a cell (one cell; 2 is kept, as the wet
    region's margin always was), a MUSCL stage also the neighbours' reconstructions
    (two cells), twice per step (SSP-RK2)."""
    return 4 if order == 2 else 2


@cached(inline="always")
def rest_speed(q: np.ndarray, i: int, g: float, dry: float, width: int,
               line: int) -> float:
    """c_i = sqrt(g_z H_i) [m/s] of cell ``i`` at rest if a face next to it is visited by
    a full sweep (the cell or a neighbour is wet), else 0; depths in rows 0, ``width``,
    ... of ``q``."""
    n = q.shape[1]
    j = i % line
    if not (_is_wet(q, i, dry, width) or (j > 0 and _is_wet(q, i - 1, dry, width))
            or (j < line - 1 and _is_wet(q, i + 1, dry, width))
            or (i >= line and _is_wet(q, i - line, dry, width))
            or (i + line < n and _is_wet(q, i + line, dry, width))):
        return 0.0
    depth = 0.0
    for k in range(0, q.shape[0], width):
        depth += max(q[k, i], 0.0)
    return math.sqrt(g * depth)


@cached(inline="always")
def extend_prefix(pre: np.ndarray, q: np.ndarray, start: int, valid: int, upto: int,
                  g: float, dry: float, width: int, line: int) -> int:
    """Make ``pre[i]`` = max of :func:`rest_speed` over cells start..i hold for i <
    ``upto``, given that it holds for i < ``valid``; returns the new bound of the valid
    entries."""
    for i in range(valid, upto):
        c = rest_speed(q, i, g, dry, width, line)
        pre[i] = c if i == start else max(pre[i - 1], c)
    return max(valid, upto)


@cached(inline="always")
def extend_suffix(suf: np.ndarray, q: np.ndarray, end: int, valid: int, downto: int,
                  g: float, dry: float, width: int, line: int) -> int:
    """Make ``suf[i]`` = max of :func:`rest_speed` over cells i..end hold for i >=
    ``downto``, given that it holds for i >= ``valid``; returns the new first valid
    index."""
    for i in range(valid - 1, downto - 1, -1):
        c = rest_speed(q, i, g, dry, width, line)
        suf[i] = c if i == end else max(suf[i + 1], c)
    return min(valid, downto)


@cached(inline="always")
def rest_maxima(n: int, line: int) -> tuple[np.ndarray, np.ndarray]:
    """Empty running maxima of :func:`rest_speed` for a grid of ``n`` cells in lines of
    ``line``, for :func:`rest_outside`: ``speeds`` (4, n), from the first cell on and
    from the last one back over the flattened index, and along each row from its
    first and its last cell; ``valid`` the bounds of the valid entries of each: 0, n,
    then each row's first cell, then the cell after each row's last."""
    rows = n // line
    valid = np.empty(2 + 2 * rows, np.int64)
    valid[0] = 0
    valid[1] = n
    for x in range(rows):
        valid[2 + x] = x * line
        valid[2 + rows + x] = (x + 1) * line
    # every entry is written before it is read (valid says which): no memory is
    # touched for the rows a run never looks outside of
    return np.empty((4, n)), valid


@cached(inline="always")
def rest_outside(speeds: np.ndarray, valid: np.ndarray, q: np.ndarray, lo: int, hi: int,
                 g: float, dry: float, width: int, line: int) -> float:
    """The largest :func:`rest_speed` [m/s] over the cells outside the box (lo, hi)
    (:mod:`pdeflow.numerics.boxes`; empty: over every cell), from the running maxima of
    :func:`rest_maxima`, extended as far as this needs: the rows before the box's and
    after them along the flattened index, and each row of the box before its first and
    after its last column. A step costs the box's rows, and the cells the maxima newly
    cover (each once while the box only grows)."""
    n = q.shape[1]
    rows = n // line
    if lo > hi:
        valid[0] = extend_prefix(speeds[0], q, 0, valid[0], n, g, dry, width, line)
        return speeds[0, n - 1]
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    s = 0.0
    if x0 > 0:
        valid[0] = extend_prefix(speeds[0], q, 0, valid[0], x0 * line, g, dry, width, line)
        s = speeds[0, x0 * line - 1]
    if x1 < rows - 1:
        valid[1] = extend_suffix(speeds[1], q, n - 1, valid[1], (x1 + 1) * line, g, dry,
                                 width, line)
        s = max(s, speeds[1, (x1 + 1) * line])
    if y0 > 0 or y1 < line - 1:
        for x in range(x0, x1 + 1):
            base = x * line
            if y0 > 0:
                valid[2 + x] = extend_prefix(speeds[2], q, base, valid[2 + x], base + y0,
                                             g, dry, width, line)
                s = max(s, speeds[2, base + y0 - 1])
            if y1 < line - 1:
                valid[2 + rows + x] = extend_suffix(speeds[3], q, base + line - 1,
                                                    valid[2 + rows + x], base + y1 + 1, g,
                                                    dry, width, line)
                s = max(s, speeds[3, base + y1 + 1])
    return s


@cached(inline="always")
def rest_changed(valid: np.ndarray, lo: int, hi: int, line: int) -> None:
    """A step changed cells of the box (lo, hi) only: the running maxima of
    :func:`rest_outside` stay valid up to its cells."""
    rows = valid.shape[0] // 2 - 1
    valid[0] = min(valid[0], lo)
    valid[1] = max(valid[1], hi + 1)
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in range(x0, x1 + 1):
        valid[2 + x] = min(valid[2 + x], x * line + y0)
        valid[2 + rows + x] = max(valid[2 + rows + x], x * line + y1 + 1)


@cached(inline="always")
def live_box(q: np.ndarray, before: np.ndarray, lo: int, hi: int, width: int,
             line: int, sync: bool = True) -> tuple[int, int]:
    """The bounding box of the cells of the box (lo, hi) that move (a discharge row of
    ``q``, any but 0, ``width``, ..., is not zero) or changed in the last step (``q``
    differs from ``before``); ``(1, 0)`` if none. On a 1D grid: the first and the last
    such cell. With ``sync``, ``before`` is then set to ``q`` in the box: the state the
    next step starts from, which it keeps to undo itself (one pass over the box for
    both)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    a0 = x1 + 1
    a1 = x0 - 1
    b0 = y1 + 1
    b1 = y0 - 1
    for x in range(x0, x1 + 1):
        for i in range(x * line + y0, x * line + y1 + 1):
            live = False
            for k in range(q.shape[0]):
                v = q[k, i]
                if v != before[k, i] or (k % width != 0 and v != 0.0):
                    live = True
                if sync:
                    before[k, i] = v
            if live:
                a0 = min(a0, x)
                a1 = max(a1, x)
                b0 = min(b0, i - x * line)
                b1 = max(b1, i - x * line)
    return box_of(a0, a1, b0, b1, line)
