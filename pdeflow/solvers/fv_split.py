"""The paper's finite-volume splitting scheme as a py-pde solver (``solver="fv-split"``).

Each step: time step from the CFL number and the largest wave speed of the current
state (recomputed every step), HLL advection (29), then the model's post-step hook
(source stages (31)-(34)) with that time step. py-pde's controller, trackers and
storage work unchanged; the solver ends the run itself (``FinishedSimulation``) once
everything is at rest and unchanged, and refuses to write a state that is not finite
or has negative depths: the run stops at once with :class:`SimulationBlowUp`, whose
message names the time, the step, the cell and the state there, and the variant, and
the last good state is kept (see :func:`diagnose_blowup`).

With the numba backend the whole stepping loop between two tracker interrupts runs in
one compiled, disk-cached kernel (:func:`pdeflow.numerics.splitting.scheme_stepper`: the loop
and the kernels of the model's scheme only), which calls the same source-stage kernel
that the hook wraps.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np
from pde.solvers.base import SolverBase
from pde.trackers.base import FinishedSimulation

from ..models.base import MAX_CFL, GranularPDE, check_range
from ..numerics import layout as L
from ..numerics.splitting import STATUS_FAIL, STATUS_REST, python_stepping, scheme_stepper
from .outputs import StepAhead, pending_output


class _RestProfilerFilter(logging.Filter):
    """Drop py-pde's "more time on trackers than on the simulation" warning after a run
    that fv-split ended at rest: the controller does not book the time of a stepper
    call that ends the run (FinishedSimulation) as solver time, so the warning would be
    wrong."""

    ended_at_rest = False

    def filter(self, record: logging.LogRecord) -> bool:
        if self.ended_at_rest and record.getMessage().startswith("Spent more time"):
            _RestProfilerFilter.ended_at_rest = False
            return False
        return True


logging.getLogger("pde.solvers.controller").addFilter(_RestProfilerFilter())


def scheme_codes(pde: GranularPDE, splitting: str = "lie",
                 geometry: int = L.GEOMETRY_PLANAR) -> tuple[Any, int, int, int, bool, int]:
    """(model kernels, flux, order, limiter, strang, geometry): the scheme of ``pde`` with
    ``splitting`` on a grid of ``geometry`` (layout.GEOMETRY_*), as
    :func:`pdeflow.numerics.splitting.scheme_stepper` takes it."""
    return (pde.kernels, *pde.scheme_codes, splitting == "strang", geometry)


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


def _cell_values(pde: GranularPDE, q: np.ndarray, i: int) -> dict[str, float]:
    """Depths [m] and velocities [m/s] of the state ``q`` in cell ``i``."""
    out: dict[str, float] = {}
    for k in range(0, len(pde.field_names), 2):
        h = float(q[k, i])
        name = pde.field_names[k]
        out[name] = h
        with np.errstate(all="ignore"):
            out["u" + name[1:]] = float(q[k + 1, i] / h) if h > 0 else 0.0
    return out


def _fmt_values(values: dict[str, float]) -> str:
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


class FVSplitSolver(SolverBase):
    """CFL-limited HLL + operator-split sources: the paper's scheme (section 4)."""

    name = "fv-split"

    def __init__(self, pde: GranularPDE, *, backend: str = "numba", cfl: float = 0.3,
                 splitting: str = "lie", stop_at_rest: bool = True,
                 max_steps: int = 100_000_000, t_end: float | None = None,
                 outputs: str = "interpolate"):
        """
        Args:
            pde: a :class:`~pdeflow.models.TwoLayerGranular` or
                :class:`~pdeflow.models.SingleLayerGranular` (its flux and reconstruction
                choose the advection stage; MUSCL is advanced with SSP-RK2/Heun).
            backend: 'numba' (compiled loop) or 'numpy' (Python loop, for debugging).
            cfl: Courant number in (0, 1] (paper: 0.3); (0, 0.5] with MUSCL, whose
                SSP-RK2 update keeps depths non-negative only up to 1/2.
            splitting: 'lie' (advection, then sources: the paper's) or 'strang' (half a
                source step on each side of the advection step).
            stop_at_rest: end the run once nothing moves or changes any more.
            max_steps: safety limit on the number of steps per call.
            t_end: end of the run [s] (``GranularPDE.solve`` passes its ``t_range``):
                the only time that shortens a step. A call of the stepper with an
                earlier end (a tracker's interrupt) takes the first step that reaches
                it and returns the state interpolated at that time (see
                :mod:`pdeflow.solvers.outputs`), so that observers do not change the
                steps. None: every call's end shortens the step (py-pde's behaviour).
            outputs: what such a call returns: 'interpolate' (the state at the
                requested time, interpolated between the steps around it) or 'step'
                (the state after the first step that reaches it, at its true time: a
                state of the scheme, with every property the scheme gives its states,
                e.g. hyperbolicity after the restoration). Neither changes the steps.
        """
        if not isinstance(pde, GranularPDE):
            raise TypeError("fv-split solves pdeflow's granular models only")
        if backend not in ("numba", "numpy", "auto"):
            raise ValueError(f"backend must be 'numba' or 'numpy', got {backend!r}")
        super().__init__(pde, backend="numba" if backend == "auto" else backend)
        self.cfl = check_range("cfl", cfl, 0, 1, low_open=True)
        if pde.reconstruction == "muscl":
            # SSP-RK2 with limited reconstructions keeps depths non-negative only up to 1/2
            check_range("cfl (with reconstruction='muscl')", cfl, 0, MAX_CFL["muscl"],
                        low_open=True)
        if splitting not in ("lie", "strang"):
            raise ValueError(f"splitting must be 'lie' or 'strang', got {splitting!r}")
        self.splitting = splitting
        self.stop_at_rest = bool(stop_at_rest)
        self.max_steps = int(max_steps)
        self.t_end = None if t_end is None else float(t_end)
        if outputs not in ("interpolate", "step"):
            raise ValueError(f"outputs must be 'interpolate' or 'step', got {outputs!r}")
        self.outputs = outputs
        self.diagnostics: np.ndarray | None = None

    def make_stepper(self, state: Any, dt: float | None = None):
        """Return ``stepper(state, t_start, t_end) -> t`` advancing with CFL steps."""
        pde: GranularPDE = self.pde
        dx = pde.check_state(state)
        metric = pde.metric(state.grid)
        M = metric.array()
        if self._backend == "numba":
            # the compiled loop is pdeflow's own kernel: py-pde's numba backend (and the
            # numba modules its import pulls in) is not needed for it
            self.info["backend"] = {"name": "numba", "implementation": "numba"}
        else:
            self._select_backend(state)
        if self.backend_name == "numba":
            # the compiled loop calls the source stage itself: no hook to compile (the
            # state was checked above, as the hook would)
            hook, diag = None, pde.new_diagnostics(state.grid.shape[0])
        else:
            hook, diag = pde.make_post_step_hook(state, backend=self.backend)
        self.diagnostics = diag
        self.info.update(dt=None, steps=0, dt_adaptive=True, stochastic=False,
                         cfl=self.cfl, post_step_data=diag, variant=pde.variant,
                         splitting=self.splitting)
        P = pde.parameter_array()
        bcl, bcr = pde.bc_codes
        rate = np.empty_like(state.data)
        backup = np.empty_like(state.data)
        work = np.empty((3, *state.data.shape))
        prev = np.empty_like(state.data)
        scheme = scheme_codes(pde, self.splitting, metric.code)
        cfl = self.cfl
        stop = self.stop_at_rest

        def run_kernel(kernel: Any, q: np.ndarray, t0: float, t1: float, diag_: np.ndarray,
                       rate_: np.ndarray, backup_: np.ndarray, work_: np.ndarray,
                       max_steps: int, t_pause: float | None = None):
            return kernel(q, t0, t1, dx, M, bcl, bcr, P, cfl, diag_, rate_, backup_, work_,
                          max_steps, stop, t_pause, prev)

        if self.backend_name == "numba":
            advance = self._compiled_loop(scheme_stepper(*scheme), run_kernel, diag, rate,
                                          backup, work)
        else:
            advance = self._numpy_loop(state, dx, P, hook, diag, prev)

        def replay(q: np.ndarray, t0: float, t1: float, update: Any) -> None:
            # one step of the kernel's own Python code with an instrumented state update
            fresh = diag.copy()
            fresh[L.D_RESUME] = 0.0  # q is the state before the failed step
            run_kernel(python_stepping(*scheme, update), q, t0, t1, fresh,
                       np.empty_like(q), np.empty_like(q), np.empty_like(work), 1)

        ahead: list[StepAhead] = []  # the state past the last output time, if any

        def stepper(state: Any, t_start: float, t_end: float) -> float:
            t_pause = float(t_end)
            t_run = t_pause if self.t_end is None else max(self.t_end, t_pause)
            done, t_start = self._resume(ahead, state, float(t_start), t_pause)
            if done:
                return t_start
            entry = state.data.copy()
            t, steps, status = advance(state.data, float(t_start), t_pause, t_run)
            self.info["steps"] += int(steps)
            # not "dt": py-pde's controller would then fire every tracker due within half
            # a step *after* the time it stopped at, early (a snapshot at 0.0957 s
            # for 0.1 s when the signal check's wall-clock interrupt came just before);
            # the steps land on the output times (interpolated), no tolerance is needed
            self.info["last_dt"] = float(diag[L.D_DT]) or None
            if status == STATUS_FAIL:
                self._blowup(state, entry, t_start, t, t_run, replay)
            if t_pause < t < t_run and self.outputs == "interpolate":
                # the step went past the output time: output the state at that time,
                # continue from the step's end at the next call
                dt = float(diag[L.D_DT]) * (2.0 if self.splitting == "strang" else 1.0)
                ahead.append(pending_output(state.data, prev, t, dt,
                                            status == STATUS_REST))
                ahead[0].interpolate(state.data, t_pause)
                return t_pause
            if status == STATUS_REST:
                self._at_rest(t)
            return float(t)

        return stepper

    def _resume(self, ahead: list[StepAhead], state: Any, t_start: float,
                t_pause: float) -> tuple[bool, float]:
        """After an interpolated output (``ahead`` holds the step past it): ``(True,
        t)`` if the call to ``t_pause`` [s] is answered from it (another output time
        within the same step, or its end), else ``(False, t)`` with the step's end
        restored as the state at ``t``; ``(False, t_start)`` if nothing is ahead."""
        if not ahead:
            return False, t_start
        if t_pause < ahead[0].t:  # another output time within the same step
            ahead[0].interpolate(state.data, t_pause)
            return True, t_pause
        step = ahead.pop()
        state.data[...] = step.q
        if step.at_rest:
            self._at_rest(step.t)
        return step.t >= t_pause, step.t

    def _at_rest(self, t: float) -> None:
        """End the run: everything is at rest from ``t`` [s] on."""
        self.info["rest_time"] = float(t)
        _RestProfilerFilter.ended_at_rest = True
        raise FinishedSimulation(f"everything at rest at t={t:.6g} s")

    def _blowup(self, state: Any, entry: np.ndarray, t_start: float, t: float,
                t_end: float, replay: Any) -> None:
        """Raise :class:`SimulationBlowUp` with the diagnostic of the failed step.

        ``state.data`` holds the state before the failed step (time ``t``); if a source
        stage had already spoiled it, the state at the start of this stepper call
        (``entry``, time ``t_start``) is restored instead.
        """
        pde: GranularPDE = self.pde
        report = diagnose_blowup(pde, state.data, t, t_end, replay)
        t_kept = t
        if report.get("stage") == 0:
            state.data[...] = entry
            t_kept = t_start
        step = int(self.info["steps"]) + 1
        mode = getattr(getattr(pde, "parameters", None), "hyperbolicity", None)
        variant = (f"{pde.__class__.__name__}, fv-split {pde.variant}, {self.splitting} "
                   f"splitting" + (f", hyperbolicity {mode!r}" if mode else "")
                   + f", cfl={self.cfl}")
        x_c = state.grid.axes_coords[0]
        cell = report.get("cell")
        report.update(t=t, t_kept=t_kept, step=step, variant=variant)
        where = ""
        if cell is not None:
            report["x"] = float(x_c[cell])
            report["cell_state"] = _cell_values(pde, state.data if t_kept == t else
                                                entry, cell)
            bad = report.get("bad_cells", [cell])
            where = (f": cell {cell} (x={x_c[cell]:.6g} m) went to "
                     f"{_fmt_values(report['failed'])} from "
                     f"{_fmt_values(report['cell_state'])} (depths m, velocities m/s); "
                     f"{len(bad)} bad cell(s) in x=[{x_c[min(bad)]:.6g}, "
                     f"{x_c[max(bad)]:.6g}] m")
        dt = report.get("dt")
        stage = {1: "update", 2: "corrector (SSP-RK2 stage 2)"}.get(report.get("stage"),
                                                                    "source stage")
        msg = (f"fv-split blew up in step {step} at t={t:.6g} s"
               + (f" (dt={dt:.3g} s, {stage})" if dt else "")
               + f" with {report.get('cause', 'a non-finite or negative state')}{where}. "
               f"[{variant}] Nothing of this step was kept: the last good state "
               f"(t={t_kept:.6g} s) is the solver's state, SimulationBlowUp.state and "
               "pde.diagnostics['last_state'].")
        self.info["blowup"] = report
        raise SimulationBlowUp(msg, report=report, state=state.data.copy())

    def _compiled_loop(self, kernel: Any, run_kernel: Any, diag: np.ndarray,
                       rate: np.ndarray, backup: np.ndarray, work: np.ndarray) -> Any:
        """``advance(q, t0, t_pause, t1)`` with the compiled ``kernel`` (compiled or
        loaded at its first call): it goes on from the live cells of the state its last
        call left only if nobody changed that state in between
        (:mod:`pdeflow.numerics.resting`)."""
        left = np.full_like(rate, np.nan)  # the state the last call left

        def advance(q: np.ndarray, t0: float, t_pause: float, t1: float):
            if not np.array_equal(q, left):
                diag[L.D_RESUME] = 0.0
            out = run_kernel(kernel, q, t0, t1, diag, rate, backup, work, self.max_steps,
                             t_pause)
            np.copyto(left, q)
            return out

        return advance

    def _numpy_loop(self, state: Any, dx: float, P: np.ndarray, hook: Any,
                    diag: np.ndarray, prev: np.ndarray):
        """Pure numpy/Python version of the stepping loop (same stages, slow)."""
        from ..numerics.splitting import STATUS_END

        pde: GranularPDE = self.pde
        pde._require_numpy_variant(state.grid)
        if self.splitting != "lie":
            raise NotImplementedError("the numpy loop implements Lie splitting only")
        def advance(q: np.ndarray, t: float, t_pause: float, t_end: float):
            steps = 0
            while t < t_pause and steps < self.max_steps:
                prev[...] = q  # the state before the step, as the compiled loop keeps
                rate, smax = pde.kernels.numpy_advection(q, dx, pde.bc_codes, P)
                dt = t_end - t if smax <= 0 else min(t_end - t, self.cfl * dx / smax)
                new = q + dt * rate
                if not np.all(np.isfinite(new)) or np.any(new[::2] < -1e-12):
                    return t, steps, STATUS_FAIL
                q[...] = new
                diag[L.D_DT] = dt
                hook(q, t, diag)
                t = t + dt
                steps += 1
                if (self.stop_at_rest and not np.any(rate[::2])
                        and diag[L.D_CHANGED] == 0):
                    return t, steps, STATUS_REST
            return t, steps, STATUS_END

        return advance

