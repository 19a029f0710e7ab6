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
        cell: index of the offending cell; ``x`` its centre [m].
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


def cell_values(pde: GranularPDE, q: np.ndarray, i: int) -> dict[str, float]:
    """Depths [m] and velocities [m/s] of the state ``q`` in cell ``i``."""
    out: dict[str, float] = {}
    for k in range(0, len(pde.field_names), 2):
        h = float(q[k, i])
        name = pde.field_names[k]
        out[name] = h
        with np.errstate(all="ignore"):
            out["u" + name[1:]] = float(q[k + 1, i] / h) if h > 0 else 0.0
    return out


def fmt_values(values: dict[str, float]) -> str:
    return ", ".join(f"{k}={v:.6g}" for k, v in values.items())


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
    names = pde.field_names
    bad_state = ~np.isfinite(q_good)
    bad_state[::2] |= q_good[::2] < 0
    if bad_state.any():
        cells = np.nonzero(bad_state.any(axis=0))[0]
        return {"cause": "the state before the step is not finite or has a negative "
                         "depth (produced by a source stage)",
                "cell": int(cells[0]), "bad_cells": cells.tolist(), "stage": 0,
                "failed": {n: float(q_good[k, cells[0]]) for k, n in enumerate(names)}}
    records: list[dict[str, Any]] = []

    def update(q: np.ndarray, base: np.ndarray, rate: np.ndarray, dt: float,
               weight: float, lo: int, hi: int) -> tuple[float, bool]:
        v = q.copy()
        cells = slice(lo, hi + 1)
        with np.errstate(all="ignore"):
            v[:, cells] = weight * base[:, cells] + (1.0 - weight) * (
                q[:, cells] + dt * rate[:, cells])
            bad = np.zeros(q.shape, dtype=bool)
            bad[:, cells] = ~np.isfinite(v[:, cells])
            bad[::2, cells] |= v[::2, cells] < -1e-12 * (1.0 + np.abs(q[::2, cells]))
            mass_rate = float(np.max(np.abs(rate[::2, cells]))) if hi >= lo else 0.0
        records.append({"dt": float(dt), "after": v.copy(), "bad": bad,
                        "first_stage": weight == 0.0})
        q[...] = v
        return mass_rate, not bool(bad.any())

    try:
        replay(q_good.copy(), t, t_end, update)
    except Exception as err:  # pragma: no cover - diagnostics must not mask the blow-up
        return {"cause": f"the failed step could not be replayed ({err!r})"}
    # an IFCP step that fails is redone with HLL: the last attempt is the one that counts
    starts = [k for k, rec in enumerate(records) if rec["first_stage"]]
    records = records[starts[-1]:] if starts else records
    failed = [(k, rec) for k, rec in enumerate(records) if rec["bad"].any()]
    if not failed:
        return {"cause": "the replayed step did not fail (non-deterministic failure?)"}
    stage, rec = failed[0]
    bad = rec["bad"]
    after = rec["after"]
    cells = np.nonzero(bad.any(axis=0))[0]
    nonfinite = np.nonzero((~np.isfinite(after)).any(axis=0))[0]
    if nonfinite.size:
        cell = int(nonfinite[0])
        cause = "non-finite values"
    else:
        with np.errstate(all="ignore"):
            rel = np.min(after[::2] / (1.0 + np.abs(q_good[::2])), axis=0)
        cell = int(cells[np.argmin(rel[cells])])
        cause = "a negative depth"
    return {"cause": cause, "cell": cell, "bad_cells": cells.tolist(), "dt": rec["dt"],
            "stage": stage + 1,
            "failed": {n: float(after[k, cell]) for k, n in enumerate(names)}}
