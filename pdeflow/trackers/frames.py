"""Frames of a granular run: the state with F_extra/rho1, stored through py-pde storages.

F_extra is not part of the state: :func:`fextra_over_rho1` reads it from the ``fv-split``
solver's post-step data in the simulation ``info`` (zeros for other solvers and for one
layer). :class:`FextraStorageTracker` is py-pde's ``StorageTracker`` whose frames are the
state followed by that field, in any py-pde storage (a ``MemoryStorage`` by default; the
HDF5 files of :mod:`pdeflow.storage` use a ``FileStorage``).

Example::

    from pdeflow.trackers import FextraStorageTracker
    frames = FextraStorageTracker([0.5, 1.0])            # or an interval [s]
    eq.solve(state, t_range=2, solver="fv-split", tracker=frames)
    frames.storage                      # py-pde MemoryStorage: times, fields h1 ... F_extra
    frames.snapshots[0.5]               # (state data, F_extra/rho1 per cell)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pde import FieldCollection, MemoryStorage, ScalarField
from pde.storage.base import StorageBase, StorageTracker
from pde.trackers.base import InfoDict

from ..numerics import layout as L
from .own_times import AtOwnTimes, OwnTimes

FEXTRA_LABEL = "fextra_over_rho1"
"""Label of the F_extra/rho1 field [m^2/s^2] that follows the state in every frame."""


def fextra_over_rho1(info: InfoDict | None, n: int | tuple[int, ...]) -> np.ndarray:
    """F_extra/rho1 per cell [m^2/s^2] of the last step, from the ``fv-split`` solver's
    post-step data in the simulation ``info``; zeros if the solver keeps none (py-pde
    solvers, one layer). ``n``: the cells (1D) or the grid's shape, e.g. (nx, ny): the
    solver keeps a 2D grid's cells flat, in the state's (C) order."""
    shape = (n,) if isinstance(n, (int, np.integer)) else tuple(n)
    diag = None if info is None else info.get("solver", {}).get("post_step_data")
    if isinstance(diag, np.ndarray) and diag.size == L.N_DIAG + int(np.prod(shape)):
        return diag[L.N_DIAG:].reshape(shape).copy()
    return np.zeros(shape)


def state_labels(field: FieldCollection) -> tuple[str, ...]:
    """Labels of the fields of a granular state (depths in m, discharges in m^2/s; the
    model's :attr:`~pdeflow.systems.EquationSystem.field_names`)."""
    return tuple(f.label for f in field)


def final_time(info: InfoDict | None) -> float | None:
    """End time [s] of a run from the controller's diagnostics: the rest time if the
    ``fv-split`` solver stopped at rest, else the controller's final time."""
    if not info:
        return None
    rest = info.get("solver", {}).get("rest_time")
    if rest is not None:
        return float(rest)
    t = info.get("controller", {}).get("t_final")
    return None if t is None else float(t)


def show_final_state(tracker: Any, info: InfoDict | None) -> float | None:
    """At ``finalize``: hand the run's last state to ``tracker.handle`` unless the
    tracker already saw it (its ``last_time``); returns the end time [s] of the run.

    py-pde calls a tracker only at its interrupts, so a run that stops at rest or at
    t_end between two interrupts would otherwise miss its final state. ``tracker``
    keeps the state it was initialised with in ``_field``: py-pde's controller steps
    that object in place, so at ``finalize`` it holds the final state."""
    t_end = final_time(info)
    state = (info or {}).get("last_state", tracker._field)
    if state is not None and t_end is not None and t_end > tracker.last_time + 1e-12:
        if isinstance(tracker, AtOwnTimes):
            tracker.final_state_next()
        tracker.handle(state, t_end)
    return t_end


class FextraStorageTracker(AtOwnTimes, StorageTracker):
    """py-pde's ``StorageTracker`` storing, at its interrupts, the state followed by
    F_extra/rho1 per cell (field ``fextra_over_rho1`` [m^2/s^2], see
    :func:`fextra_over_rho1`).

    Args:
        interrupts: when to store, in simulation time: an interval [s] (from t = 0), a
            list of times, or anything py-pde accepts.
        storage: the py-pde storage written to (default: a new ``MemoryStorage``).
    """

    def __init__(self, interrupts: Any = 1, *, storage: StorageBase | None = None):
        super().__init__(MemoryStorage() if storage is None else storage,
                         OwnTimes(interrupts))
        self._info: InfoDict | None = None
        self._field: Any = None
        self._frame: FieldCollection | None = None
        self.last_time = -np.inf

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._info = info
        self._field = field
        grid = field.grid
        labels = (*state_labels(field), FEXTRA_LABEL)
        self._frame = FieldCollection([ScalarField(grid, label=name) for name in labels])
        return super().initialize(field, info)

    def _transform(self, field: Any, t: float) -> FieldCollection:
        """The frame: the state's fields (labelled as :func:`state_labels`), then
        F_extra/rho1 of the last step. One collection is refilled for every frame (the
        storage copies its data when appending): building one per frame would cost
        more than the run between two frames of the app's animation."""
        assert self._frame is not None, "initialize() first"
        data = self._frame.data
        data[:-1] = field.data
        data[-1] = fextra_over_rho1(self._info, data.shape[1:])  # 1D: (n,), 2D: (nx, ny)
        return self._frame

    def handle(self, field: Any, t: float) -> None:
        if not self.handed_early(t):  # else at another tracker's time: not kept
            self.keep(field, t)

    def keep(self, field: Any, t: float) -> None:
        """Store the frame of the state ``field`` at ``t`` [s] (subclasses add what
        they keep with it)."""
        super().handle(field, t)
        self.last_time = float(t)

    @property
    def snapshots(self) -> dict[float, tuple[np.ndarray, np.ndarray]]:
        """Stored frames as t [s] (rounded to 1e-9 s) -> (state data, F_extra/rho1 per
        cell), views of the storage's arrays."""
        return {round(float(t), 9): (d[:-1], d[-1])
                for t, d in zip(self.storage.times, self.storage.data, strict=True)}


__all__ = ["FEXTRA_LABEL", "FextraStorageTracker", "fextra_over_rho1", "final_time",
           "show_final_state", "state_labels"]
