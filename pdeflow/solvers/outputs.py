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
"""

from __future__ import annotations

from dataclasses import dataclass

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
        """Write the state at ``t`` (``t_prev <= t <= self.t``) into ``out``."""
        span = self.t - self.t_prev
        w = 1.0 if span <= 0 else min(max((t - self.t_prev) / span, 0.0), 1.0)
        np.multiply(self.q, w, out=out)
        for row, before in zip(out, self.prev, strict=True):  # a temporary of one row
            row += (1.0 - w) * before


def pending_output(q: np.ndarray, prev: np.ndarray, t: float, dt: float,
                   at_rest: bool, spare: np.ndarray | None = None) -> StepAhead:
    """A :class:`StepAhead` from the state ``q`` at ``t`` [s] after a step of ``dt``
    [s] from ``prev``. ``q`` is copied (the output overwrites it), into ``spare`` if
    given (the last step ahead's array, taken up: no second copy alive at once);
    ``prev`` is not: the solver writes its array again only after the step ahead was
    taken up or dropped."""
    if spare is None:
        spare = q.copy()
    else:
        np.copyto(spare, q)
    return StepAhead(t=t, q=spare, t_prev=t - dt, prev=prev, at_rest=at_rest)
