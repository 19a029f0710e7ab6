r"""Erosion diagnostics of a run over an erodible bed: what the experiments measure.

Plain functions of arrays (depths in m, x in m, times in s, volumes per unit width in
m^2 on a planar grid, or m^3 with an axisymmetric grid's cell volumes). ``bed0`` is the
initial bed [m] per cell (:meth:`pdeflow.cases.Case.bed`), ``region`` the cells where
it was laid (:func:`pdeflow.initial_shapes.bed_region`), ``h_bed`` the depth of the
layer that holds the bed (the two-layer lower layer h2, see
:attr:`pdeflow.systems.EquationSystem.bed_layer`).

Which volumes, and why
----------------------
*Relative to the original bed surface* (the primary numbers): in the bed region, the
eroded volume is :math:`\int \max(e_0 - h_2, 0)\,dx` and the deposited one
:math:`\int \max(h_2 - e_0, 0)\,dx`. This is what a side view of the channel shows (the
bed's surface against where it was) and what a run of any model with an erodible layer
gives. It is *net and local*: material eroded and laid down again in the same place
does not count, and the column's own lower layer (the wedge behind the gate, not part
of the bed) is outside the region.

*Booked by the two-layer exchange* (``booked_eroded`` / ``booked_deposited``, from the
solver's diagnostics ``eroded`` / ``deposited``): every exchange across the interface
over the whole domain, cumulative (gross), counted as upper-layer depth times the cell
size. These are the closure's own bookkeeping: they include the column's wedge and
every erosion that is deposited again, so they are larger than the net numbers and are
not what an experiment can measure; they close the mass balance exactly
(:math:`V_1(t) - V_1(0) = E - D` when nothing leaves the domain; the lower layer changes
by :math:`-r (E - D)`, r = rho1/rho2).

The front is that of :func:`pdeflow.metrics.front_position` (the downstream face of the
last cell deeper than the threshold above the initial bed), so its time series is
quantised by the cell size: a front velocity from two frames ``dt`` apart is uncertain
by dx / (2 dt) (:func:`front_velocity`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .metrics import front_position, total_depth

ERODED_DEPTH = 1e-4
"""depth below the original bed surface [m] from which a cell counts as eroded for the
erosion front (:func:`erosion_front`): a fifth of a 0.5 mm grain, so that round-off and
sub-grain creep do not count, while any erosion the eye can see in a side view does"""


def _integral(values: np.ndarray, cells: float | np.ndarray) -> float:
    """sum of ``values`` times ``cells`` (dx [m], or the cells' volumes)."""
    if np.ndim(cells) == 0:
        return float(np.sum(values) * cells)
    return float(np.sum(values * cells))


def eroded_volume(h_bed: np.ndarray, bed0: np.ndarray, region: np.ndarray,
                  cells: float | np.ndarray) -> float:
    """Volume [m^2 per unit width, or m^3] missing below the original bed surface in the
    bed ``region``: the integral of max(bed0 - h_bed, 0)."""
    return _integral(np.where(region, np.maximum(bed0 - h_bed, 0.0), 0.0), cells)


def deposited_volume(h_bed: np.ndarray, bed0: np.ndarray, region: np.ndarray,
                     cells: float | np.ndarray) -> float:
    """Volume [m^2 per unit width, or m^3] of the bed layer above the original bed
    surface in the bed ``region``: the integral of max(h_bed - bed0, 0)."""
    return _integral(np.where(region, np.maximum(h_bed - bed0, 0.0), 0.0), cells)


ROUND_OFF = 1e-12
"""erosion depths [m] up to which :func:`deepest_erosion` sees none: the round-off of
the exchange's arithmetic on depths of a metre (a bed that no flow touched is 1e-18 m
'deep' in places)"""


def deepest_erosion(x: np.ndarray, h_bed: np.ndarray, bed0: np.ndarray,
                    region: np.ndarray,
                    floor: float = ROUND_OFF) -> tuple[float, float | None]:
    """(depth [m], x [m]) of the deepest erosion below the original bed surface in the
    ``region`` (the first such cell if several are as deep); (0, None) where nothing is
    eroded deeper than ``floor`` [m]."""
    depth = np.where(region, bed0 - h_bed, 0.0)
    i = int(np.argmax(depth))
    if not depth[i] > floor:
        return 0.0, None
    return float(depth[i]), float(x[i])


def erosion_front(x: np.ndarray, h_bed: np.ndarray, bed0: np.ndarray, region: np.ndarray,
                  threshold: float = ERODED_DEPTH) -> float | None:
    """x [m] of the farthest cell whose bed is eroded deeper than ``threshold`` [m]
    (None if none is): where the erosion has got to."""
    eroded = np.nonzero(region & (bed0 - h_bed > threshold))[0]
    return float(x[eroded[-1]]) if eroded.size else None


def moving_bed_volume(h_bed: np.ndarray, q_bed: np.ndarray, region: np.ndarray,
                      cells: float | np.ndarray) -> float:
    """Volume [m^2 per unit width, or m^3] of the bed layer that moves (discharge
    ``q_bed`` [m^2/s] not 0) in the bed ``region``: the bed pushed along as a whole
    (and the column's lower layer run onto it), which no erosion volume sees."""
    return _integral(np.where(region & (q_bed != 0.0), h_bed, 0.0), cells)


def final_deposit(data: np.ndarray, bed0: np.ndarray | None) -> np.ndarray:
    """The deposit [m] with the original bed surface subtracted: total depth of the state
    ``data`` minus ``bed0`` (negative where the bed was eroded and not refilled; the
    total depth where there was no bed)."""
    h = total_depth(data)
    return h if bed0 is None else h - bed0


def front_velocity(t: np.ndarray, front: np.ndarray) -> np.ndarray:
    """Front velocity [m/s] at the times ``t`` [s] from the positions ``front`` [m]
    (NaN where there is no front): centred differences inside, one-sided at the ends.
    Fronts are quantised by dx, so each value is uncertain by about dx / (2 dt)."""
    t = np.asarray(t, dtype=float)
    f = np.asarray(front, dtype=float)
    if t.size < 2:
        return np.zeros_like(f)
    return np.gradient(f, t)


def flow_duration(t: np.ndarray, front: np.ndarray) -> float | None:
    """The flow's duration [s]: the first frame time from which on the front (positions
    ``front`` [m] at the times ``t`` [s]) no longer moves, i.e. equals its last value
    in every later frame; None without a front. It is resolved to the frames' interval;
    a front still moving at the last frame gives the last time."""
    f = np.asarray(front, dtype=float)
    if f.size == 0 or not np.isfinite(f[-1]):
        return None
    moved = np.nonzero(f != f[-1])[0]
    return float(t[0] if moved.size == 0 else t[min(moved[-1] + 1, f.size - 1)])


@dataclass
class ErosionSeries:
    """Time series of one run (arrays of the frames' length; erosion entries None for a
    run without an erodible bed)."""

    t: np.ndarray
    """frame times [s] (the last one is the end of the run)"""
    front: np.ndarray
    """front position [m] above the initial bed (NaN where none)"""
    front_velocity: np.ndarray
    """its velocity [m/s] (:func:`front_velocity`)"""
    eroded: np.ndarray | None = None
    """volume below the original bed surface [m^2] (:func:`eroded_volume`)"""
    deposited: np.ndarray | None = None
    """bed layer above the original bed surface [m^2] (:func:`deposited_volume`)"""
    erosion_depth: np.ndarray | None = None
    """deepest erosion below the original bed surface [m]"""
    erosion_x: np.ndarray | None = None
    """where it is [m] (NaN where nothing is eroded)"""
    erosion_front: np.ndarray | None = None
    """x [m] of the farthest eroded cell (NaN where none)"""
    moving_bed: np.ndarray | None = None
    """bed layer moving in the bed region [m^2] (:func:`moving_bed_volume`)"""
    booked_eroded: np.ndarray | None = None
    """the two-layer exchange's cumulative erosion [m^2] (upper-layer depth x dx)"""
    booked_deposited: np.ndarray | None = None
    """its cumulative deposition [m^2]"""

    def to_dict(self) -> dict[str, Any]:
        """The series as lists (JSON-able; NaN -> None), without the absent ones."""
        out = {}
        for k, v in asdict(self).items():
            if v is not None:
                out[k] = [None if not np.isfinite(e) else float(e) for e in v]
        return out


def erosion_series(t: Sequence[float], frames: Sequence[np.ndarray], x: np.ndarray,
                   cells: float | np.ndarray, front_threshold: float, dx: float,
                   bed0: np.ndarray | None = None, region: np.ndarray | None = None,
                   bed_row: int = 2, booked: np.ndarray | None = None) -> ErosionSeries:
    """The series of the state ``frames`` (fields x cells) at the times ``t`` [s] on the
    cell centres ``x`` [m]: fronts above ``bed0`` (threshold and dx [m] as in
    :func:`pdeflow.metrics.front_position`), and with a bed (``bed0``, ``region``) its
    erosion, read from the depth row ``bed_row`` (2: the two-layer lower layer).
    ``booked``: (frames, 2) cumulative booked erosion and deposition [m^2], if any."""
    t = np.asarray(t, dtype=float)
    fronts = [front_position(x, d, front_threshold, dx, bed0) for d in frames]
    front = np.array([np.nan if f is None else f for f in fronts])
    out = ErosionSeries(t, front, front_velocity(t, front))
    if bed0 is None or region is None:
        return out
    h = [np.maximum(d[bed_row], 0.0) for d in frames]
    deep = [deepest_erosion(x, hb, bed0, region) for hb in h]
    out.eroded = np.array([eroded_volume(hb, bed0, region, cells) for hb in h])
    out.deposited = np.array([deposited_volume(hb, bed0, region, cells) for hb in h])
    out.erosion_depth = np.array([d for d, _ in deep])
    out.erosion_x = np.array([np.nan if xe is None else xe for _, xe in deep])
    fronts_e = [erosion_front(x, hb, bed0, region) for hb in h]
    out.erosion_front = np.array([np.nan if f is None else f for f in fronts_e])
    out.moving_bed = np.array([moving_bed_volume(hb, d[bed_row + 1], region, cells)
                               for hb, d in zip(h, frames, strict=True)])
    if booked is not None:
        out.booked_eroded = np.asarray(booked[:, 0], dtype=float)
        out.booked_deposited = np.asarray(booked[:, 1], dtype=float)
    return out


SERIES_KEYS = ("flow_duration", "front_velocity_max")
"""summary keys of every run with a series [s, m/s]"""
BED_KEYS = ("bed_eroded_volume", "bed_eroded_volume_max", "bed_deposited_volume",
            "bed_max_erosion_depth", "bed_max_erosion_x", "bed_max_erosion_time",
            "bed_moving_volume_max")
"""summary keys of a run with an erodible bed [m^2, m^2, m^2, m, m, s, m^2] (None for a
model that runs the case on the rigid bed)"""


def series_numbers(series: ErosionSeries, erodible: bool) -> dict[str, Any]:
    """The summary's numbers of a series: the flow's duration [s] and the largest front
    velocity [m/s]; with an erodible bed (``erodible``) the final eroded and deposited
    volumes [m^2], the largest eroded volume over the frames, and the deepest erosion
    of all frames [m] with where [m] and when [s], the largest volume of the bed layer
    moving in the bed region [m^2] (None where the run has no bed)."""
    v = series.front_velocity
    out: dict[str, Any] = {
        "flow_duration": flow_duration(series.t, series.front),
        "front_velocity_max": float(np.nanmax(v)) if np.isfinite(v).any() else None}
    out.update({k: None for k in BED_KEYS})
    if not erodible or series.eroded is None:
        return out
    depth = series.erosion_depth
    k = int(np.argmax(depth))
    out.update({"bed_eroded_volume": float(series.eroded[-1]),
                "bed_eroded_volume_max": float(np.max(series.eroded)),
                "bed_deposited_volume": float(series.deposited[-1]),
                "bed_max_erosion_depth": float(depth[k]),
                "bed_max_erosion_x": (None if not np.isfinite(series.erosion_x[k])
                                      else float(series.erosion_x[k])),
                "bed_max_erosion_time": float(series.t[k]) if depth[k] > 0 else None,
                "bed_moving_volume_max": float(np.max(series.moving_bed))})
    return out
