"""Frames for time series: the state every interval, the exchange booked up to then,
and the run's final state.

:class:`SeriesTracker` is :class:`~pdeflow.trackers.frames.FextraStorageTracker` (in a
``MemoryStorage``) that also keeps, for every frame, the cumulative erosion and
deposition the ``fv-split`` solver has booked (the model's ``eroded`` and ``deposited``
slots of its post-step data, upper-layer depth summed over cells [m]; zeros for other
solvers and for models that book none), and that stores the final state at
``finalize`` (the rest time when the run stops at rest). Like every tracker here it
only reads: the fv-split solver does not shorten a step for its interrupts
(:mod:`pdeflow.solvers.outputs`), so a run with it takes the same steps as one without.
At an interpolated frame the booked values are those after the step that went past the
frame's time (at most one step ahead).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from pde.trackers.base import InfoDict

from .frames import FextraStorageTracker, show_final_state


class SeriesTracker(FextraStorageTracker):
    """Frames every ``interval`` [s] from t = 0 and at the end, with the booked exchange
    (:attr:`booked`, shape (frames, 2): eroded, deposited [m], times dx a volume);
    ``slots``: the model's diagnostics slots (``pde.system.diagnostics``), of which
    ``eroded`` and ``deposited`` are read."""

    def __init__(self, interval: float, slots: Mapping[str, int] | None = None):
        super().__init__(interval)
        self._booked: list[tuple[float, float]] = []
        slots = slots or {}
        self._slots = ((slots["eroded"], slots["deposited"])
                       if "eroded" in slots and "deposited" in slots else None)

    def keep(self, field: Any, t: float) -> None:
        super().keep(field, t)
        diag = None if self._info is None else self._info.get("solver", {}).get(
            "post_step_data")
        if self._slots is not None and isinstance(diag, np.ndarray):
            eroded, deposited = self._slots
            self._booked.append((float(diag[eroded]), float(diag[deposited])))
        else:
            self._booked.append((0.0, 0.0))

    def finalize(self, info: InfoDict | None = None) -> None:
        show_final_state(self, info)
        super().finalize(info)

    @property
    def booked(self) -> np.ndarray:
        """(frames, 2): cumulative booked erosion and deposition [m] at each frame."""
        return np.array(self._booked, dtype=float).reshape(-1, 2)

    @property
    def frames(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """(times [s], state data per frame) of the stored frames."""
        times = np.array(self.storage.times, dtype=float)
        return times, [np.asarray(d[:-1]) for d in self.storage.data]


__all__ = ["SeriesTracker"]
