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
(``tests/test_resting_cells.py``).

Cells are the flattened index of any grid (:mod:`pdeflow.numerics.geometry`): a cell's
neighbours are those along its line of the last axis (``line`` cells long; on a 1D grid
the whole grid) and ``line`` cells before and after it (the first axis of a 2D grid).
The prefix and suffix maxima run over the flattened index; on a 2D grid the loop scales
them as the advection stage scales the speeds of its faces.
"""

from __future__ import annotations

import math

import numpy as np

from .advection import _is_wet
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
def extend_prefix(pre: np.ndarray, q: np.ndarray, valid: int, upto: int, g: float,
                  dry: float, width: int, line: int) -> int:
    """Make ``pre[i]`` = max of :func:`rest_speed` over cells 0..i hold for i < ``upto``,
    given that it holds for i < ``valid``; returns the new count of valid entries."""
    for i in range(valid, upto):
        c = rest_speed(q, i, g, dry, width, line)
        pre[i] = c if i == 0 else max(pre[i - 1], c)
    return max(valid, upto)


@cached(inline="always")
def extend_suffix(suf: np.ndarray, q: np.ndarray, valid: int, downto: int, g: float,
                  dry: float, width: int, line: int) -> int:
    """Make ``suf[i]`` = max of :func:`rest_speed` over cells i..n-1 hold for i >=
    ``downto``, given that it holds for i >= ``valid``; returns the new first valid
    index."""
    n = q.shape[1]
    for i in range(valid - 1, downto - 1, -1):
        c = rest_speed(q, i, g, dry, width, line)
        suf[i] = c if i == n - 1 else max(suf[i + 1], c)
    return min(valid, downto)


@cached(inline="always")
def live_cells(q: np.ndarray, before: np.ndarray, lo: int, hi: int,
               width: int) -> tuple[int, int]:
    """First and last cell in ``lo..hi`` that moves (a discharge row of ``q``, any but
    0, ``width``, ..., is not zero) or changed in the last step (``q`` differs from
    ``before``); ``(1, 0)`` if none."""
    first = 1
    last = 0
    for i in range(lo, hi + 1):
        live = False
        for k in range(q.shape[0]):
            if q[k, i] != before[k, i] or (k % width != 0 and q[k, i] != 0.0):
                live = True
                break
        if live:
            if first > last:
                first = i
            last = i
    return first, last
