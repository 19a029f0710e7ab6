"""What went wrong in a failed fv-split step: :class:`SimulationBlowUp` and the
replay of the step that finds the cell, the stage and the values (:func:`diagnose_blowup`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..models.base import GranularPDE


class SimulationBlowUp(FloatingPointError):
    """Raised when a step produced a non-finite or negative state (state kept).

    Attributes (None where unknown):
        t: time at the start of the failed step [s] = time of the kept state.
        step: number of the failed step (1 = the first step of the run).
        cell: index of the offending cell among the kernels' cells (a 2D grid's are
            flattened row by row: ``report['cell_index']`` is its (i, j)); ``x`` its
            centre [m] (and ``report['y']`` on a 2D grid).
        cell_state: the kept state in that cell, depths [m] and velocities [m/s].
        variant: model, scheme, splitting, hyperbolicity mode and CFL number.
        state: copy of the last good state data (fields x cells).
        report: everything above plus dt [s], the failed values, the stage, the range
            of bad cells (see :func:`diagnose_blowup`).
    """

    def __init__(self, message: str, *, report: dict[str, Any] | None = None,
                 state: np.ndarray | None = None):
        super().__init__(message)
        self.report: dict[str, Any] = dict(report or {})
        self.state = state
        self.t: float | None = self.report.get("t")
        self.step: int | None = self.report.get("step")
        self.cell: int | None = self.report.get("cell")
        self.x: float | None = self.report.get("x")
        self.cell_state: dict[str, float] | None = self.report.get("cell_state")
        self.variant: str | None = self.report.get("variant")


def field_names(pde: GranularPDE, q: np.ndarray) -> tuple[str, ...]:
    """The names of the rows of the kernels' state ``q`` (a 2D grid's have each
    layer's discharge along y too)."""
    return pde.system.field_names_on(q.shape[0] // len(pde.system.layers) - 1)


def cell_values(pde: GranularPDE, q: np.ndarray, i: int) -> dict[str, float]:
    """Depths [m] and velocities [m/s] of the kernels' state ``q`` in cell ``i``."""
    out: dict[str, float] = {}
    rows = q.shape[0] // len(pde.system.layers)
    for k, layer in enumerate(pde.system.layers):
        h = float(q[k * rows, i])
        out[layer.depth] = h
        for m, name in enumerate((layer.velocity, layer.velocity_y)[:rows - 1]):
            with np.errstate(all="ignore"):
                out[name] = float(q[k * rows + 1 + m, i] / h) if h > 0 else 0.0
    return out


def fmt_values(values: dict[str, float]) -> str:
    return ", ".join(f"{k}={v:.6g}" for k, v in values.items())


def cell_position(grid: Any, cell: int) -> dict[str, Any]:
    """Where the kernels' cell ``cell`` lies on ``grid``: ``cell_index`` (the index, or
    a 2D grid's (i, j) along x and y: the kernels flatten the cells row by row),
    ``x`` [m] and on a 2D grid ``y`` [m], the cell's centre."""
    index = np.unravel_index(cell, grid.shape)
    out: dict[str, Any] = {"cell_index": int(cell) if len(index) == 1 else
                           tuple(int(i) for i in index)}
    for name, coords, i in zip("xy"[:len(index)], grid.axes_coords, index, strict=True):
        out[name] = float(coords[i])
    return out


def fmt_position(report: dict[str, Any]) -> str:
    """The centre of the cell of ``report`` (:func:`cell_position`) as text."""
    return ", ".join(f"{k}={report[k]:.6g}" for k in "xy" if k in report) + " m"


def bad_extent(grid: Any, bad: list[int]) -> str:
    """How many cells ``bad`` are and the range of their centres along each axis."""
    index = np.unravel_index(np.asarray(bad, dtype=np.int64), grid.shape)
    axes = zip("xy"[:len(index)], grid.axes_coords, index, strict=True)
    ranges = ", ".join(f"{name}=[{coords[i.min()]:.6g}, {coords[i.max()]:.6g}] m"
                       for name, coords, i in axes)
    return f"{len(bad)} bad cell(s) in {ranges}"


def diagnose_blowup(pde: GranularPDE, q_good: np.ndarray, t: float, t_end: float,
                    replay: Any) -> dict[str, Any]:
    """Find where and how the failed step from the kept state ``q_good`` went wrong.

    ``replay(q, t, t_end, update)`` must take exactly one step of the solver's stepping
    kernel from ``q`` (a copy) at time ``t`` [s], with its state updates performed by
    ``update(q, base, rate, dt, weight, lo, hi)`` (the kernel's ``_update``: ``q <-
    weight base + (1 - weight) (q + dt rate)`` in cells ``lo..hi``, returning
    ``(max |mass rate|, ok)``). The recording
    update here repeats that arithmetic in numpy and keeps the update that failed, so the
    step is recomputed exactly, stages and all, in plain Python.

    Returns a dict with ``cell``, ``x`` [m], ``dt`` [s], ``stage`` (1: advection or
    predictor, 2: corrector of SSP-RK2), ``failed`` (the failed values of all fields in
    that cell), ``bad_cells`` (indices of all bad cells), ``cause`` (text); or only
    ``cause`` if the kept state itself is bad (a source stage produced it) or the step
    could not be replayed.
    """
    names = field_names(pde, q_good)
    bad_state = ~np.isfinite(q_good)
    bad_state[::2] |= q_good[::2] < 0
    if bad_state.any():
        cells = np.nonzero(bad_state.any(axis=0))[0]
        return {"cause": "the state before the step is not finite or has a negative "
                         "depth (produced by a source stage)",
                "cell": int(cells[0]), "bad_cells": cells.tolist(), "stage": 0,
                "failed": {n: float(q_good[k, cells[0]]) for k, n in enumerate(names)}}
    # one record per call of the update: a grid of several axes updates its box row by
    # row, so only a call that failed keeps its cells' values
    records: list[dict[str, Any]] = []

    def update(q: np.ndarray, base: np.ndarray, rate: np.ndarray, dt: float,
               weight: float, lo: int, hi: int) -> tuple[float, bool]:
        cells = slice(lo, hi + 1)
        with np.errstate(all="ignore"):
            v = weight * base[:, cells] + (1.0 - weight) * (q[:, cells] + dt * rate[:, cells])
            bad = ~np.isfinite(v)
            bad[::2] |= v[::2] < -1e-12 * (1.0 + np.abs(q[::2, cells]))
            mass_rate = float(np.max(np.abs(rate[::2, cells]))) if hi >= lo else 0.0
        # a new attempt of the step (a retry, IFCP's redo with HLL) starts its first
        # stage again; a box's rows come in increasing order within one stage
        last = records[-1] if records else None
        start = weight == 0.0 and (last is None or last["stage"] != 1 or lo <= last["lo"])
        record: dict[str, Any] = {"dt": float(dt), "stage": 1 if weight == 0.0 else 2,
                                  "start": start, "lo": lo, "failed": bool(bad.any())}
        if record["failed"]:
            record.update(after=v.copy(), bad=bad)
        records.append(record)
        q[:, cells] = v
        return mass_rate, not record["failed"]

    try:
        replay(q_good.copy(), t, t_end, update)
    except Exception as err:  # pragma: no cover - diagnostics must not mask the blow-up
        return {"cause": f"the failed step could not be replayed ({err!r})"}
    # an IFCP step that fails is redone with HLL: the last attempt is the one that counts
    starts = [k for k, rec in enumerate(records) if rec["start"]]
    records = records[starts[-1]:] if starts else records
    failed = [rec for rec in records if rec["failed"]]
    if not failed:
        return {"cause": "the replayed step did not fail (non-deterministic failure?)"}
    stage = failed[0]["stage"]
    return _failed_cell(q_good, names, [rec for rec in failed if rec["stage"] == stage])


def _failed_cell(q_good: np.ndarray, names: list[str],
                 recs: list[dict[str, Any]]) -> dict[str, Any]:
    """The report of the failed update calls ``recs`` of one stage: the first cell with
    non-finite values, else the one whose depth fell most below zero."""
    cells = np.concatenate([rec["lo"] + np.nonzero(rec["bad"].any(axis=0))[0]
                            for rec in recs])
    after = {int(rec["lo"]) + k: rec["after"][:, k]
             for rec in recs for k in np.nonzero(rec["bad"].any(axis=0))[0]}
    nonfinite = [i for i in sorted(after) if not np.all(np.isfinite(after[i]))]
    if nonfinite:
        cell = nonfinite[0]
        cause = "non-finite values"
    else:
        with np.errstate(all="ignore"):
            rel = {i: float(np.min(v[::2] / (1.0 + np.abs(q_good[::2, i]))))
                   for i, v in after.items()}
        cell = min(sorted(rel), key=rel.__getitem__)
        cause = "a negative depth"
    return {"cause": cause, "cell": int(cell), "bad_cells": sorted(int(i) for i in cells),
            "dt": recs[0]["dt"], "stage": recs[0]["stage"],
            "failed": {n: float(after[cell][k]) for k, n in enumerate(names)}}
