"""Stopping a run of a generic py-pde solver once it is practically at rest."""

from __future__ import annotations

from typing import Any

import numpy as np
from pde.trackers.base import FinishedSimulation, TrackerBase

from ..numerics.state import DRY_TOLERANCE, velocity_profile


class RestTracker(TrackerBase):
    """End a run (``FinishedSimulation``) once every layer is slower than ``speed``.

    The ``fv-split`` solver detects exact rest itself; this tracker serves py-pde's
    generic solvers, whose regularised friction never gives exactly zero velocity.

    Args:
        interrupts: when to look, in simulation time [s] (anything py-pde accepts).
        speed: the speed below which every layer counts as at rest [m/s].
        depth: the model's dry tolerance [m]: thinner layers have no velocity.
    """

    def __init__(self, interrupts: Any = 0.01, speed: float = 1e-3,
                 depth: float = DRY_TOLERANCE):
        super().__init__(interrupts=interrupts)
        self.speed = float(speed)
        self.depth = float(depth)
        self.rest_time: float | None = None

    def handle(self, field: Any, t: float) -> None:
        d = field.data
        umax = 0.0
        for k in range(0, d.shape[0], 2):
            umax = max(umax, float(np.max(np.abs(velocity_profile(d[k], d[k + 1],
                                                                  self.depth)))))
        if t > 0 and umax < self.speed:
            self.rest_time = float(t)
            raise FinishedSimulation(f"all speeds below {self.speed} m/s at t={t:.6g} s")
