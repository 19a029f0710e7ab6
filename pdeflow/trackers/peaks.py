"""The largest value of a measure of the state over a run, sampled: :class:`PeakTracker`
(a 2D summary's largest speed).

The fastest moment of a collapse lies inside the run (the final deposit is at rest),
so the summary's ``max_speed`` needs a look at the run: this tracker reads the state
every ``interval`` [s] of simulation time (and the final one) and keeps the largest
value of its ``measure`` (the caller's: e.g. :func:`pdeflow.metrics_2d.max_speed`, so
that the trackers need no metrics, as they need no models). Like every
tracker here it only reads: fv-split takes the same steps with it as without
(:mod:`pdeflow.solvers.outputs`). A peak between two samples is missed: the value is a
lower bound of the run's peak, as close as the interval is fine.

The samples are the states at the tracker's own times, whatever else watches the run:
py-pde's controller hands a tracker the state at another tracker's time when its own
lies less than 1e-8 s later (a live plot every t_end/100 meets a sample every
t_end/200 at 6 x 0.006 = 0.036000000000000004 s against 12 x 0.003 = 0.036 s), and the
state interpolated at that time differs in its last bits, so would the peak. A state
handed early is not sampled: the tracker asks for its own time again
(:class:`_OwnTimes`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pde.trackers.base import InfoDict, TrackerBase
from pde.trackers.interrupts import ConstantInterrupts

from .frames import show_final_state


class _OwnTimes(ConstantInterrupts):
    """Interrupts every ``dt`` [s] that give the same time again after a state handed
    before it (``repeat`` set by the tracker)."""

    repeat = False

    @property
    def due(self) -> float | None:
        """The next time [s] asked for (None before ``initialize``)."""
        return self._t_next

    def next(self, t: float) -> float:
        if self.repeat:
            self.repeat = False
            return float(self._t_next)  # type: ignore[arg-type]
        return super().next(t)


class PeakTracker(TrackerBase):
    """The largest ``measure(data)`` (:attr:`peak`, 0 before any) over the states'
    data seen every ``interval`` [s] and the final one."""

    def __init__(self, interval: float, measure: Callable[[np.ndarray], float]):
        super().__init__(interrupts=_OwnTimes(interval))
        self.measure = measure
        self.peak = 0.0
        self.last_time = -float("inf")
        self._final = False

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._field = field  # stepped in place by the controller: the final state
        return super().initialize(field, info)

    def handle(self, field: Any, t: float) -> None:
        due = self.interrupt.due
        if not self._final and due is not None and t < due:
            self.interrupt.repeat = True  # early, at another tracker's time: not sampled
            return
        self.peak = max(self.peak, self.measure(field.data))
        self.last_time = t

    def finalize(self, info: InfoDict | None = None) -> None:
        self._final = True  # the final state comes at the run's end, not a sample time
        show_final_state(self, info)
        super().finalize(info)
