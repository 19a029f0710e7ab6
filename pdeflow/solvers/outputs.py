"""States at output times that do not shorten a step (the fv-split solver's dense output).

py-pde's controller calls the stepper with the next time a tracker (snapshots, storage,
progress bar, live plot) wants the state. If the solver shortened its step to land on
that time, the step sequence, and with it every result of the run (stop times, maxima,
front positions), would depend on which observers are attached. The fv-split stepper
therefore only ever shortens a step at the end of the run: it takes the first step
that reaches the requested time and hands the trackers the state *at* that time,
interpolated linearly between the states before and after that step (a convex
combination of two states, so depths stay non-negative and mass is conserved by both
ends). The state after the step is kept here and the next call continues from it.

The interpolated state is an output only: it is never stepped from. Its error is
O(dt^2) in the smooth parts of the flow, below the scheme's own error per step.
The per-cell F_extra/rho1 that a frame records is that of the step across its time.

:func:`on_cells` hands py-pde's state to the stepper as the kernels' array of cells;
on a grid of several axes the output goes into py-pde's state while the kernels' copy
keeps the step's end, so that no third copy of the state is made at an output.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class StepAhead:
    """The state after a step that went past an output time, and the state before it.

    Attributes:
        t: time after the step [s]; ``q`` the state then (fields x cells).
        t_prev: time before the step [s]; ``prev`` the state then.
        at_rest: the step found everything at rest (the run ends at ``t``).
    """

    t: float
    q: np.ndarray
    t_prev: float
    prev: np.ndarray
    at_rest: bool = False

    def interpolate(self, out: np.ndarray, t: float) -> None:
        """Write the state at ``t`` (``t_prev <= t <= self.t``) into ``out`` (the
        state's shape, or py-pde's ``data[field, n0, n1]`` of its cells)."""
        w = self._weight(t)
        for now, before, target in self._chunks(out):
            np.multiply(now, w, out=target)
            target += (1.0 - w) * before

    def holds(self, out: np.ndarray, t: float) -> bool:
        """Whether ``out`` holds, bit for bit, what :meth:`interpolate` wrote for ``t``
        (nobody changed it since)."""
        w = self._weight(t)
        for now, before, target in self._chunks(out):
            expected = now * w
            expected += (1.0 - w) * before
            if not np.array_equal(target, expected):
                return False
        return True

    def _weight(self, t: float) -> float:
        span = self.t - self.t_prev
        return 1.0 if span <= 0 else min(max((t - self.t_prev) / span, 0.0), 1.0)

    def _chunks(self, out: np.ndarray):
        """(after, before, out) of each block of about :data:`CHUNK` values, per field:
        the temporaries of the arithmetic stay that small."""
        now = self.q.reshape(out.shape)
        before = self.prev.reshape(out.shape)
        per_row = int(np.prod(out.shape[2:], dtype=np.int64))
        rows = max(1, CHUNK // max(per_row, 1))
        for k in range(out.shape[0]):
            for a in range(0, out.shape[1], rows):
                block = slice(a, a + rows)
                yield now[k, block], before[k, block], out[k, block]


CHUNK = 1 << 16
"""values a block of :meth:`StepAhead.interpolate` holds (512 kB of float64)"""


def pending_output(q: np.ndarray, prev: np.ndarray, t: float, dt: float,
                   at_rest: bool, spare: np.ndarray | None = None,
                   copy: bool = True) -> StepAhead:
    """A :class:`StepAhead` from the state ``q`` at ``t`` [s] after a step of ``dt``
    [s] from ``prev``. ``q`` is copied if ``copy`` (the output overwrites it), into
    ``spare`` if given (the last step ahead's array, taken up: no second copy alive at
    once); ``prev`` is not: the solver writes its array again only after the step
    ahead was taken up or dropped."""
    if copy:
        if spare is None:
            spare = q.copy()
        else:
            np.copyto(spare, q)
        q = spare
    return StepAhead(t=t, q=q, t_prev=t - dt, prev=prev, at_rest=at_rest)


def on_cells(step: Any, shape: tuple[int, int]) -> Any:
    """``step(state, data, out, t_start, t_end, changed) -> (t, shown)`` as a stepper
    of py-pde's states: ``data`` is the kernels' ``q[field, cell]``, a 1D grid's
    ``state.data`` itself; on a grid of several axes a flattened copy of py-pde's
    ``data[field, n0, n1]`` (a view without the ghost cells, not contiguous), written
    back after every call unless the call wrote an output into ``out`` (py-pde's
    ``state.data``) itself: then ``shown`` is the step ahead
    (:class:`StepAhead`) whose state at ``t`` it wrote, and
    ``data`` holds the step's end. ``changed``: the state is not the one the last call
    left (the first call, or someone wrote to it in between).

    What the last call left is kept once: on a grid of several axes it is the flattened
    copy itself (no second copy of the state, and none made to flatten it)."""
    kept = np.full(shape, np.nan)  # the state the last call left
    shown: list[Any] = [None]  # (step ahead, t) whose output py-pde's state holds

    def stepper(state: Any, t_start: float, t_end: float) -> float:
        if state.data.shape == shape:
            changed = not np.array_equal(state.data, kept)
            try:
                return step(state, state.data, state.data, t_start, t_end, changed)[0]
            finally:
                np.copyto(kept, state.data)
        on_grid = kept.reshape(state.data.shape)  # a view of the flat copy
        if shown[0] is None:
            changed = not np.array_equal(state.data, on_grid)
        else:
            changed = not shown[0][0].holds(state.data, shown[0][1])
        if changed:
            on_grid[...] = state.data
        shown[0] = None
        written = None
        try:
            t, written = step(state, kept, state.data, t_start, t_end, changed)
            shown[0] = None if written is None else (written, t)
            return t
        finally:
            if written is None:
                state.data[...] = on_grid

    return stepper
