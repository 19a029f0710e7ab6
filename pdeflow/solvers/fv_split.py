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

import dataclasses
import logging
import time
from typing import Any

import numpy as np
from pde.solvers.base import SolverBase
from pde.trackers.base import FinishedSimulation

from ..models.base import GranularPDE, check_range
from ..numerics import layout as L
from ..numerics.geometry import Metric
from ..numerics.scheme import MAX_CFL_BED, SPLITTINGS, Scheme, check_choice
from ..numerics.splitting import (
    STATUS_FAIL,
    STATUS_REST,
    Stepper,
    python_stepping,
    scheme_stepper,
)
from ..numerics.threads import DEFAULT_THREADS, check_threads, on_threads
from .blowup import (
    SimulationBlowUp,
    bad_extent,
    cell_position,
    cell_values,
    diagnose_blowup,
    fmt_position,
    fmt_values,
)
from .outputs import StepAhead, on_cells, pending_output

__all__ = ["FVSplitSolver", "SimulationBlowUp", "diagnose_blowup", "split_stepper",
           "stepper_codes"]


def _kept_for_blowup(start: np.ndarray | None, data: np.ndarray, given: np.ndarray,
                     entry: np.ndarray | None) -> np.ndarray | None:
    """The state a stepper call keeps for a blow-up in a source stage: the step ahead's
    end ``start`` it went on from, if that is not the kernels' array ``data``; else a
    copy in ``entry`` where ``data`` is py-pde's state ``given`` (a 1D grid); else None:
    py-pde's state itself (several axes, where it is not the kernels' array; after an
    output inside a step it holds that output)."""
    if start is not None and start is not data:
        return start
    if data is given:
        np.copyto(entry, data)
        return entry
    return None


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


def stepper_codes(pde: GranularPDE, metric: Metric,
                  scheme: Scheme | None = None) -> tuple[Any, int, int, int, bool, int]:
    """(model kernels, flux, order, limiter, strang, geometry): ``scheme`` (default: the
    PDE's) with the model's kernels on the grid of ``metric``, as
    :func:`pdeflow.numerics.splitting.scheme_stepper` takes them."""
    scheme = pde.scheme if scheme is None else scheme
    return (pde.kernels_of(metric), *scheme.codes, scheme.strang, metric.code)


def split_stepper(pde: GranularPDE, metric: Metric,
                  scheme: Scheme | None = None) -> Stepper:
    """The compiled stepping loop of ``scheme`` (default: the PDE's) for the model of
    ``pde`` on the grid of ``metric`` (not compiled before its first call)."""
    return scheme_stepper(*stepper_codes(pde, metric, scheme))


class FVSplitSolver(SolverBase):
    """CFL-limited HLL + operator-split sources: the paper's scheme (section 4)."""

    name = "fv-split"

    def __init__(self, pde: GranularPDE, *, backend: str = "numba", cfl: float = 0.3,
                 splitting: str | None = None, stop_at_rest: bool = True,
                 max_steps: int = 100_000_000, t_end: float | None = None,
                 outputs: str = "interpolate", threads: int = DEFAULT_THREADS):
        """
        Args:
            pde: a :class:`~pdeflow.models.TwoLayerGranular` or
                :class:`~pdeflow.models.SingleLayerGranular`; its ``scheme`` (flux,
                reconstruction, limiter, splitting) is the solver's (MUSCL is advanced
                with SSP-RK2/Heun).
            backend: 'numba' (compiled loop) or 'numpy' (Python loop, for debugging).
            cfl: Courant number in (0, 1] (paper: 0.3); (0, 0.5] with MUSCL, whose
                SSP-RK2 update keeps depths non-negative only up to 1/2.
            splitting: 'lie' (advection, then sources: the paper's) or 'strang' (half a
                source step on each side of the advection step) instead of the PDE's
                scheme's; None: the scheme's.
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
            threads: numba threads of a run on a 2D grid, 1..the cores (its passes over
                the cells run row by row on them, :mod:`pdeflow.numerics.threads`; the
                same numbers for any count); default 1, so that runs in parallel
                processes (sweeps, studies) do not oversubscribe the cores. A 1D run
                checks it and runs on one.
        """
        if not isinstance(pde, GranularPDE):
            raise TypeError("fv-split solves pdeflow's granular models only")
        if backend not in ("numba", "numpy", "auto"):
            raise ValueError(f"backend must be 'numba' or 'numpy', got {backend!r}")
        super().__init__(pde, backend="numba" if backend == "auto" else backend)
        self.cfl = check_range("cfl", cfl, 0, 1, low_open=True)
        scheme = pde.scheme
        if splitting is not None:
            check_choice("splitting", splitting, SPLITTINGS)
            scheme = dataclasses.replace(scheme, splitting=splitting)
        self.scheme: Scheme = scheme
        """the scheme this solver steps with: the PDE's (its splitting as given)"""
        if scheme.max_cfl < 1:
            # SSP-RK2 with limited reconstructions keeps depths non-negative only up to 1/2
            check_range(f"cfl (with reconstruction={scheme.reconstruction!r})", cfl, 0,
                        scheme.max_cfl, low_open=True)
        self.stop_at_rest = bool(stop_at_rest)
        self.max_steps = int(max_steps)
        self.t_end = None if t_end is None else float(t_end)
        if outputs not in ("interpolate", "step"):
            raise ValueError(f"outputs must be 'interpolate' or 'step', got {outputs!r}")
        self.outputs = outputs
        self.threads = check_threads(threads)
        self.diagnostics: np.ndarray | None = None

    def make_stepper(self, state: Any, dt: float | None = None):
        """Return ``stepper(state, t_start, t_end) -> t`` advancing with CFL steps."""
        pde: GranularPDE = self.pde
        metric = pde.check_state(state)  # the grid's geometry, derived here once
        if metric.bed is not None:  # face depths up to 2 h (pdeflow.models.*.terrain)
            check_range("cfl (over a bed)", self.cfl, 0, MAX_CFL_BED, low_open=True)
        dx, M = metric.dx, metric.array()
        hook, diag = self._hook(state)
        self.info.update(dt=None, steps=0, dt_adaptive=True, stochastic=False,
                         cfl=self.cfl, post_step_data=diag,
                         variant=self.scheme.spatial, splitting=self.scheme.splitting,
                         wall_time=0.0)
        P = pde.parameter_array()
        bcl, bcr = pde.boundary_codes(len(metric.axes))
        shape = (state.data.shape[0], state.grid.num_cells)  # the kernels' q[field, cell]
        rate = np.empty(shape)
        backup = np.empty(shape)
        work = np.empty((3, *shape))
        scheme = stepper_codes(pde, metric, self.scheme)
        cfl = self.cfl
        stop = self.stop_at_rest

        def run_kernel(kernel: Any, q: np.ndarray, t0: float, t1: float, diag_: np.ndarray,
                       rate_: np.ndarray, backup_: np.ndarray, work_: np.ndarray,
                       max_steps: int, t_pause: float | None = None):
            return kernel(q, t0, t1, dx, M, bcl, bcr, P, cfl, diag_, rate_, backup_, work_,
                          max_steps, stop, t_pause)

        # the state before a call's last step: the compiled loop keeps it in backup
        before = backup if self.backend_name == "numba" else np.empty(shape)
        if self.backend_name == "numba":
            advance = self._compiled_loop(scheme_stepper(*scheme), run_kernel, diag, rate,
                                          backup, work)
            if len(metric.axes) > 1:  # only a 2D run starts numba's threads
                advance = on_threads(advance, self.threads)
        else:
            advance = self._numpy_loop(state, dx, P, hook, diag, before)

        def replay(q: np.ndarray, t0: float, t1: float, update: Any) -> None:
            # one step of the kernel's own Python code with an instrumented state update
            fresh = diag.copy()
            fresh[L.D_RESUME] = 0.0  # q is the state before the failed step
            run_kernel(python_stepping(*scheme, update), q, t0, t1, fresh,
                       np.empty_like(q), np.empty_like(q), np.empty_like(work), 1)

        ahead: list[StepAhead] = []  # the state past the last output time, if any
        entry = np.empty(shape) if len(metric.axes) == 1 else None

        def step(state: Any, data: np.ndarray, out: np.ndarray, t_start: float,
                 t_end: float, changed: bool) -> tuple[float, StepAhead | None]:
            t_pause = float(t_end)
            t_run = t_pause if self.t_end is None else max(self.t_end, t_pause)
            if changed:  # someone changed the state: go on from it, not from a step ahead
                ahead.clear()
            t_given = float(t_start)  # the time of py-pde's state
            done, t_start, start, shown = self._resume(ahead, data, out, t_given, t_pause)
            if done:
                return t_start, shown
            start = _kept_for_blowup(start, data, state.data, entry)
            t, steps, status = advance(data, float(t_start), t_pause, t_run, changed)
            self.info["steps"] += int(steps)
            # not "dt": py-pde's controller would then fire every tracker due within half
            # a step *after* the time it stopped at, early (a snapshot at 0.0957 s
            # for 0.1 s when the signal check's wall-clock interrupt came just before);
            # the steps land on the output times (interpolated), no tolerance is needed
            self.info["last_dt"] = float(diag[L.D_DT]) or None
            if status == STATUS_FAIL:
                self._blowup(state, data, start, t_given if start is None else t_start, t,
                             t_run, replay)
            if t_pause < t < t_run and self.outputs == "interpolate":
                return self._output_inside(ahead, data, out, before, diag, t, t_pause,
                                           status == STATUS_REST,
                                           None if start is entry else start)
            if status == STATUS_REST:
                self._at_rest(t)
            return float(t), None

        return self._timed(on_cells(step, shape))

    def _hook(self, state: Any) -> tuple[Any, np.ndarray]:
        """(post-step hook or None, diagnostics array) of the backend: the compiled loop
        calls the source stage itself, so it needs no hook (the state was checked, as
        the hook would)."""
        if self._backend == "numba":
            # the compiled loop is pdeflow's own kernel: py-pde's numba backend (and the
            # numba modules its import pulls in) is not needed for it
            self.info["backend"] = {"name": "numba", "implementation": "numba"}
        else:
            self._select_backend(state)
        if self.backend_name == "numba":
            hook, diag = None, self.pde.new_diagnostics(state.grid.num_cells)
        else:
            hook, diag = self.pde.make_post_step_hook(state, backend=self.backend)
        self.diagnostics = diag
        return hook, diag

    def _timed(self, step: Any) -> Any:
        """``step`` with its wall time added to ``info["wall_time"]`` [s]: the run's
        own time, without its observers (py-pde's trackers run between the calls of
        the stepper), which the summary reports as the run's wall time."""

        def stepper(state: Any, t_start: float, t_end: float) -> float:
            t0 = time.perf_counter()
            try:
                return step(state, t_start, t_end)
            finally:
                self.info["wall_time"] += time.perf_counter() - t0

        return stepper

    def _output_inside(self, ahead: list[StepAhead], data: np.ndarray, out: np.ndarray,
                       prev: np.ndarray, diag: np.ndarray, t: float, t_pause: float,
                       at_rest: bool, spare: np.ndarray | None
                       ) -> tuple[float, StepAhead | None]:
        """The step from ``prev`` to ``data`` (at ``t`` [s]; its dt in ``diag``) went
        past the output time ``t_pause`` [s]: keep its end in ``ahead`` for the next
        call to go on from (a copy, in ``spare`` if given, see :func:`pending_output`,
        where ``out`` is ``data``; else ``data`` itself), write the state at ``t_pause``
        into ``out`` and return ``t_pause`` and the step ahead if ``out`` is not
        ``data`` (:func:`on_cells`)."""
        dt = float(diag[L.D_DT]) * (2.0 if self.scheme.strang else 1.0)
        ahead.append(pending_output(data, prev, t, dt, at_rest, spare=spare,
                                    copy=out is data))
        ahead[0].interpolate(out, t_pause)
        return t_pause, None if out is data else ahead[0]

    def _resume(self, ahead: list[StepAhead], data: np.ndarray, out: np.ndarray,
                t_start: float, t_pause: float
                ) -> tuple[bool, float, np.ndarray | None, StepAhead | None]:
        """After an interpolated output (``ahead`` holds the step past it): ``(True,
        t_pause, None, shown)`` if the call to ``t_pause`` [s] is answered from it by
        another output time within the same step (written into ``out``; ``shown`` as
        :meth:`_output_inside`'s), ``(done, t, q, None)`` with the step's end ``q``
        restored as the state ``data`` (cells flattened) at ``t`` (``done``: t reaches
        ``t_pause``); ``(False, t_start, None, None)`` if nothing is ahead."""
        if not ahead:
            return False, t_start, None, None
        if t_pause < ahead[0].t:  # another output time within the same step
            ahead[0].interpolate(out, t_pause)
            return True, t_pause, None, None if out is data else ahead[0]
        step = ahead.pop()
        if step.q is not data:  # (else the kernels' copy holds it)
            data[...] = step.q
        if step.at_rest:
            self._at_rest(step.t)
        return step.t >= t_pause, step.t, step.q, None

    def _at_rest(self, t: float) -> None:
        """End the run: everything is at rest from ``t`` [s] on."""
        self.info["rest_time"] = float(t)
        _RestProfilerFilter.ended_at_rest = True
        raise FinishedSimulation(f"everything at rest at t={t:.6g} s")

    def _blowup(self, state: Any, data: np.ndarray, entry: np.ndarray | None,
                t_start: float, t: float, t_end: float, replay: Any) -> None:
        """Raise :class:`SimulationBlowUp` with the diagnostic of the failed step.

        ``data`` (the kernels' ``q[field, cell]``, see :func:`on_cells`) holds the state
        before the failed step (time ``t``); if a source stage had already spoiled it,
        the state at the start of this stepper call (``entry``, time ``t_start``; None:
        py-pde's ``state``, which :func:`on_cells` writes only after the call) is
        restored instead.
        """
        pde: GranularPDE = self.pde
        report = diagnose_blowup(pde, data, t, t_end, replay)
        t_kept = t
        if report.get("stage") == 0:
            data[...] = state.data.reshape(data.shape) if entry is None else entry
            t_kept = t_start
        step = int(self.info["steps"]) + 1
        mode = getattr(getattr(pde, "parameters", None), "hyperbolicity", None)
        variant = (f"{pde.__class__.__name__}, fv-split {self.scheme.spatial}, "
                   f"{self.scheme.splitting} "
                   f"splitting" + (f", hyperbolicity {mode!r}" if mode else "")
                   + f", cfl={self.cfl}")
        cell = report.get("cell")
        report.update(t=t, t_kept=t_kept, step=step, variant=variant)
        where = ""
        if cell is not None:
            report.update(cell_position(state.grid, cell))
            report["cell_state"] = cell_values(pde, data, cell)
            where = (f": cell {report['cell_index']} ({fmt_position(report)}) went to "
                     f"{fmt_values(report['failed'])} from "
                     f"{fmt_values(report['cell_state'])} (depths m, velocities m/s); "
                     + bad_extent(state.grid, report.get("bad_cells", [cell])))
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
        raise SimulationBlowUp(msg, report=report,
                               state=data.reshape(state.data.shape).copy())

    def _compiled_loop(self, kernel: Any, run_kernel: Any, diag: np.ndarray,
                       rate: np.ndarray, backup: np.ndarray, work: np.ndarray) -> Any:
        """``advance(q, t0, t_pause, t1, changed)`` with the compiled ``kernel`` (compiled
        or loaded at its first call): it goes on from the live cells of the state its
        last call left unless ``changed`` (someone changed that state in between, see
        :func:`on_cells`; :mod:`pdeflow.numerics.resting`)."""

        def advance(q: np.ndarray, t0: float, t_pause: float, t1: float, changed: bool):
            if changed:
                diag[L.D_RESUME] = 0.0
            return run_kernel(kernel, q, t0, t1, diag, rate, backup, work, self.max_steps,
                              t_pause)

        return advance

    def _numpy_loop(self, state: Any, dx: float, P: np.ndarray, hook: Any,
                    diag: np.ndarray, prev: np.ndarray):
        """Pure numpy/Python version of the stepping loop (same stages, slow)."""
        from ..numerics.splitting import STATUS_END

        pde: GranularPDE = self.pde
        pde._require_numpy_variant(state.grid)
        if self.scheme.strang:
            raise NotImplementedError("the numpy loop implements Lie splitting only")
        def advance(q: np.ndarray, t: float, t_pause: float, t_end: float, changed: bool):
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

