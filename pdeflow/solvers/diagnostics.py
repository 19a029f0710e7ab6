"""A typed view of the ``fv-split`` solver's diagnostics (its post-step data).

The kernels keep their counters in one flat float64 array whose indices are named in
:mod:`pdeflow.numerics.layout`; this is the one place above the kernels that reads it,
so that results, trackers and reports use names with units instead of index slicing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..numerics import layout as L


@dataclass(frozen=True)
class SplitDiagnostics:
    """What the splitting hook recorded over a run (times in s, volumes per unit width).

    Times of the last motion are the run's end if a layer still moved then.
    """

    t: float
    """simulation time at the end of the last step [s]"""
    dt: float
    """the last time step [s]"""
    last_move_upper: float
    """last time any upper-layer cell (or the single layer) moved [s]"""
    last_move_lower: float
    """last time any lower-layer cell moved [s]"""
    last_fast_upper: float
    """last time |u1| >= slow_speed where h1 > slow_depth [s]"""
    last_fast_lower: float
    """same for the lower layer [s]"""
    fextra_max: float
    """largest F_extra/rho1 applied [m^2/s^2]"""
    fextra_cell: int
    """cell index of ``fextra_max``"""
    fextra_time: float
    """time of ``fextra_max`` [s]"""
    deposited: float
    """cumulative upper -> lower exchange, sum over cells of depth [m] (x dx: volume)"""
    eroded: float
    """cumulative lower -> upper exchange, sum over cells of depth [m]"""
    hyperbolicity_events: int
    """cell-steps in which hyperbolicity was restored"""
    hyperbolicity_bisections: int
    """restorations that needed the bisection fallback"""
    flux_fallbacks: int
    """steps redone with HLL because the IFCP step was not positive"""
    source_stages: int
    """number of source stages applied"""
    positivity_retries: int
    """steps rejected because a depth would have turned negative, retried with dt/2"""
    fextra_over_rho1: np.ndarray
    """F_extra/rho1 per cell of the last step [m^2/s^2]"""

    @classmethod
    def from_array(cls, diag: np.ndarray) -> SplitDiagnostics:
        """The view of a post-step data array (copied: later steps do not change it)."""
        return cls(
            t=float(diag[L.D_T]), dt=float(diag[L.D_DT]),
            last_move_upper=float(diag[L.D_MOVE_UPPER]),
            last_move_lower=float(diag[L.D_MOVE_LOWER]),
            last_fast_upper=float(diag[L.D_FAST_UPPER]),
            last_fast_lower=float(diag[L.D_FAST_LOWER]),
            fextra_max=float(diag[L.D_FEXTRA_MAX]),
            fextra_cell=int(diag[L.D_FEXTRA_CELL]),
            fextra_time=float(diag[L.D_FEXTRA_TIME]),
            deposited=float(diag[L.D_DEPOSITED]), eroded=float(diag[L.D_ERODED]),
            hyperbolicity_events=int(diag[L.D_HYP_EVENTS]),
            hyperbolicity_bisections=int(diag[L.D_HYP_BISECTIONS]),
            flux_fallbacks=int(diag[L.D_FLUX_FALLBACKS]),
            source_stages=int(diag[L.D_STEPS]),
            positivity_retries=int(diag[L.D_RETRIES]),
            fextra_over_rho1=np.array(diag[L.N_DIAG:], dtype=float))
