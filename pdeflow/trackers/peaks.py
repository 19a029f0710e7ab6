"""The largest speed of a run, sampled: :class:`PeakSpeedTracker` (2D summaries).

The fastest moment of a collapse lies inside the run (the final deposit is at rest),
so the summary's ``max_speed`` needs a look at the run: this tracker reads the state
every ``interval`` [s] of simulation time (and the final one) and keeps the largest
speed of any layer in any wet cell (:func:`pdeflow.metrics_2d.max_speed`). Like every
tracker here it only reads: fv-split takes the same steps with it as without
(:mod:`pdeflow.solvers.outputs`). A peak between two samples is missed: the value is a
lower bound of the run's peak, as close as the interval is fine.
"""

from __future__ import annotations

from typing import Any

from pde.trackers.base import InfoDict, TrackerBase

from ..metrics_2d import max_speed
from .frames import show_final_state


class PeakSpeedTracker(TrackerBase):
    """The largest speed [m/s] (:attr:`peak`) over the states seen every ``interval``
    [s] and the final one; cells thinner than ``dry`` [m] have no speed."""

    def __init__(self, interval: float, dry: float):
        super().__init__(interrupts=interval)
        self.dry = dry
        self.peak = 0.0
        self.last_time = -float("inf")

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._field = field  # stepped in place by the controller: the final state
        return super().initialize(field, info)

    def handle(self, field: Any, t: float) -> None:
        self.peak = max(self.peak, max_speed(field.data, self.dry))
        self.last_time = t

    def finalize(self, info: InfoDict | None = None) -> None:
        show_final_state(self, info)
        super().finalize(info)
