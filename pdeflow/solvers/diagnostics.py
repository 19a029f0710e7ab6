"""A typed view of the ``fv-split`` solver's diagnostics (its post-step data).

The kernels keep their counters in one flat float64 array: the scheme's slots are named
in :mod:`pdeflow.numerics.layout`, the model's own in its layout and, by name, in its
system's :attr:`~pdeflow.systems.EquationSystem.diagnostics`. This is the one place
above the kernels that reads the array, so that results, trackers and reports use names
with units instead of index slicing.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..numerics import layout as L


@dataclass(frozen=True)
class SplitDiagnostics:
    """What the splitting hook recorded over a run: the scheme's counters, and the
    model's own numbers by the names its system gives them (``diag.fextra_max``, ...:
    attributes, floats; see e.g. :data:`pdeflow.models.two_layer.layout.DIAGNOSTICS`),
    its per-cell diagnostic too (``diag.fextra_over_rho1`` of two layers: its system's
    :attr:`~pdeflow.systems.EquationSystem.cell_diagnostic`).
    """

    t: float
    """simulation time at the end of the last step [s]"""
    dt: float
    """the last time step [s]"""
    flux_fallbacks: int
    """steps redone with HLL because the IFCP step was not positive"""
    source_stages: int
    """number of source stages applied"""
    positivity_retries: int
    """steps rejected because a depth would have turned negative, retried with dt/2"""
    cells: np.ndarray
    """the model's per-cell diagnostic of the last step (e.g. F_extra/rho1 [m^2/s^2] of
    two layers; zeros for a model that writes none)"""
    model: Mapping[str, float] = field(default_factory=dict)
    """the model's numbers, name -> value (as recorded: times [s], counts, volumes)"""
    cell_name: str | None = None
    """the name of :attr:`cells` that the model's system gives it (None: none)"""

    def __getattr__(self, name: str) -> Any:
        # the model's numbers read as attributes (diag.last_move_upper), its per-cell
        # diagnostic by its name (diag.fextra_over_rho1)
        model = self.__dict__.get("model", {})
        if name in model:
            return model[name]
        if name == self.__dict__.get("cell_name"):
            return self.__dict__["cells"]
        raise AttributeError(f"{type(self).__name__} has no {name!r} (the model records "
                             f"{sorted(model)})")

    @classmethod
    def from_array(cls, diag: np.ndarray, slots: Mapping[str, int] | None = None,
                   cell_name: str | None = None) -> SplitDiagnostics:
        """The view of a post-step data array (copied: later steps do not change it);
        ``slots``: the model's names of its slots (its system's ``diagnostics``);
        ``cell_name``: the name of its per-cell diagnostic (its system's
        ``cell_diagnostic``)."""
        return cls(
            t=float(diag[L.D_T]), dt=float(diag[L.D_DT]),
            flux_fallbacks=int(diag[L.D_FLUX_FALLBACKS]),
            source_stages=int(diag[L.D_STEPS]),
            positivity_retries=int(diag[L.D_RETRIES]),
            cells=np.array(diag[L.N_DIAG:], dtype=float),
            model={name: float(diag[i]) for name, i in (slots or {}).items()},
            cell_name=cell_name)
