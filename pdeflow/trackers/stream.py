"""Frames handed out while a run goes, and a run stopped from outside:
:class:`StreamTracker` (the hillside page's animation, drawn while the run computes).

Every ``interval`` [s] of simulation time (and at the final state) the tracker passes
``measure(data)`` of the state to ``emit(t, value)``, which may hand it to another
thread; then it asks ``stop()``, and if that gives a reason (a cancelled run, a wall
time limit) it raises :class:`RunStopped` with it, which py-pde's controller passes on
out of ``solve``: the run ends there, and nothing of it is summarised. Like every
tracker here it only reads: fv-split takes the same steps with it as without
(:mod:`pdeflow.solvers.outputs`), at its own times whatever else watches the run
(:mod:`pdeflow.trackers.own_times`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pde.trackers.base import InfoDict, TrackerBase

from .frames import show_final_state
from .own_times import AtOwnTimes, OwnTimes


class RunStopped(Exception):
    """A run stopped from outside before its end (the reason is the message)."""


class StreamTracker(AtOwnTimes, TrackerBase):
    """Passes ``measure(state data)`` to ``emit(t, value)`` every ``interval`` [s] and
    at the end; raises :class:`RunStopped` when ``stop()`` returns a reason."""

    def __init__(self, interval: float, measure: Callable[[np.ndarray], Any],
                 emit: Callable[[float, Any], None],
                 stop: Callable[[], str | None] = lambda: None):
        super().__init__(interrupts=OwnTimes(interval))
        self.measure = measure
        self.emit = emit
        self.stop = stop
        self.last_time = -float("inf")

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._field = field  # stepped in place by the controller: the final state
        return super().initialize(field, info)

    def handle(self, field: Any, t: float) -> None:
        if self.handed_early(t):
            return
        self.emit(float(t), self.measure(field.data))
        self.last_time = t
        reason = self.stop()
        if reason:
            raise RunStopped(reason)

    def finalize(self, info: InfoDict | None = None) -> None:
        show_final_state(self, info)
        super().finalize(info)
