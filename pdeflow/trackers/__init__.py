"""py-pde trackers for granular runs: snapshots with F_extra, stopping at rest.

Like py-pde's own trackers, they act only at their interrupts and cost nothing in
between (the compiled stepping loop runs uninterrupted from one to the next).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pde.trackers.base import FinishedSimulation, InfoDict, TrackerBase

from ..numerics import layout as L


def fextra_over_rho1(info: InfoDict | None, n: int) -> np.ndarray:
    """F_extra/rho1 per cell [m^2/s^2] of the last step, from the ``fv-split`` solver's
    post-step data in the simulation ``info``; zeros if the solver keeps none (py-pde
    solvers, one layer)."""
    diag = None if info is None else info.get("solver", {}).get("post_step_data")
    if isinstance(diag, np.ndarray) and diag.size == L.N_DIAG + n:
        return diag[L.N_DIAG:].copy()
    return np.zeros(n)


class SnapshotTracker(TrackerBase):
    """Store copies of the state and of F_extra/rho1 at the interrupt times.

    F_extra is not part of the state: it is read from the ``fv-split`` solver's
    post-step data (zeros for other solvers). ``snapshots`` maps t -> (state data,
    F_extra/rho1 per cell).
    """

    def __init__(self, interrupts: Any = 1):
        super().__init__(interrupts=interrupts)
        self.snapshots: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._info: InfoDict | None = None

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._info = info
        return super().initialize(field, info)

    def handle(self, field: Any, t: float) -> None:
        fex = fextra_over_rho1(self._info, field.grid.shape[0])
        self.snapshots[round(float(t), 9)] = (field.data.copy(), fex)


class RestTracker(TrackerBase):
    """End a run (``FinishedSimulation``) once every layer is slower than ``speed``.

    The ``fv-split`` solver detects exact rest itself; this tracker serves py-pde's
    generic solvers, whose regularised friction never gives exactly zero velocity.
    """

    def __init__(self, interrupts: Any = 0.01, speed: float = 1e-3,
                 depth: float = 1e-6):
        super().__init__(interrupts=interrupts)
        self.speed = float(speed)
        self.depth = float(depth)
        self.rest_time: float | None = None

    def handle(self, field: Any, t: float) -> None:
        d = field.data
        umax = 0.0
        for k in range(0, d.shape[0], 2):
            h = d[k]
            wet = h > self.depth
            if np.any(wet):
                umax = max(umax, float(np.max(np.abs(d[k + 1][wet] / h[wet]))))
        if t > 0 and umax < self.speed:
            self.rest_time = float(t)
            raise FinishedSimulation(f"all speeds below {self.speed} m/s at t={t:.6g} s")


__all__ = ["RestTracker", "SnapshotTracker", "fextra_over_rho1"]
