"""The largest value of a measure of the state over a run, sampled: :class:`PeakTracker`
(a 2D summary's largest speed; per cell, the peak fields of a run over a bed).

The fastest moment of a collapse lies inside the run (the final deposit is at rest),
so the summary's ``max_speed`` needs a look at the run: this tracker reads the state
every ``interval`` [s] of simulation time (and the final one) and keeps the largest
value of its ``measure`` (the caller's: e.g. :func:`pdeflow.metrics_2d.max_speed`, so
that the trackers need no metrics, as they need no models). Like every
tracker here it only reads: fv-split takes the same steps with it as without
(:mod:`pdeflow.solvers.outputs`). A peak between two samples is missed: the value is a
lower bound of the run's peak, as close as the interval is fine.

The samples are the states at the tracker's own times, whatever else watches the run
(:mod:`pdeflow.trackers.own_times`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pde.trackers.base import InfoDict, TrackerBase

from .frames import show_final_state
from .own_times import AtOwnTimes, OwnTimes


class PeakTracker(AtOwnTimes, TrackerBase):
    """The largest ``measure(data)`` (:attr:`peak`, 0 before any) over the states'
    data seen every ``interval`` [s] and the final one; a measure that gives an array
    is maximised element by element (peak fields: :func:`pdeflow.metrics_2d.peak_fields`)."""

    def __init__(self, interval: float, measure: Callable[[np.ndarray], float]):
        super().__init__(interrupts=OwnTimes(interval))
        self.measure = measure
        self.peak = 0.0
        self.last_time = -float("inf")

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._field = field  # stepped in place by the controller: the final state
        return super().initialize(field, info)

    def handle(self, field: Any, t: float) -> None:
        if self.handed_early(t):  # at another tracker's time: not sampled
            return
        value = self.measure(field.data)
        self.peak = np.maximum(self.peak, value) if np.ndim(value) else \
            max(self.peak, value)
        self.last_time = t

    def finalize(self, info: InfoDict | None = None) -> None:
        show_final_state(self, info)
        super().finalize(info)
