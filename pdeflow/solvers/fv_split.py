"""The paper's finite-volume splitting scheme as a py-pde solver (``solver="fv-split"``).

Each step: time step from the CFL number and the largest wave speed of the current
state (recomputed every step), HLL advection (29), then the model's post-step hook
(source stages (31)-(34)) with that time step. py-pde's controller, trackers and
storage work unchanged; the solver ends the run itself (``FinishedSimulation``) once
everything is at rest and unchanged, and refuses to write a state that is not finite
or has negative depths (the last good state is kept and an error names time and step).

With the numba backend the whole stepping loop between two tracker interrupts runs in
one compiled, disk-cached kernel (:func:`pdeflow.numerics.splitting.advance_split`),
which calls the same source-stage kernel that the hook wraps.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pde.solvers.base import SolverBase
from pde.trackers.base import FinishedSimulation

from ..models.base import GranularPDE, check_range
from ..numerics import layout as L
from ..numerics.splitting import STATUS_FAIL, STATUS_REST, advance_split


class SimulationBlowUp(FloatingPointError):
    """Raised when a step produced a non-finite or negative state (state kept)."""


class FVSplitSolver(SolverBase):
    """CFL-limited HLL + operator-split sources: the paper's scheme (section 4)."""

    name = "fv-split"

    def __init__(self, pde: GranularPDE, *, backend: str = "numba", cfl: float = 0.3,
                 splitting: str = "lie", stop_at_rest: bool = True,
                 max_steps: int = 100_000_000):
        """
        Args:
            pde: a :class:`~pdeflow.models.TwoLayerGranular` or
                :class:`~pdeflow.models.SingleLayerGranular` (its flux and reconstruction
                choose the advection stage; MUSCL is advanced with SSP-RK2/Heun).
            backend: 'numba' (compiled loop) or 'numpy' (Python loop, for debugging).
            cfl: Courant number in (0, 1] (paper: 0.3).
            splitting: 'lie' (advection, then sources: the paper's) or 'strang' (half a
                source step on each side of the advection step).
            stop_at_rest: end the run once nothing moves or changes any more.
            max_steps: safety limit on the number of steps per call.
        """
        if not isinstance(pde, GranularPDE):
            raise TypeError("fv-split solves pdeflow's granular models only")
        if backend not in ("numba", "numpy", "auto"):
            raise ValueError(f"backend must be 'numba' or 'numpy', got {backend!r}")
        super().__init__(pde, backend="numba" if backend == "auto" else backend)
        self.cfl = check_range("cfl", cfl, 0, 1, low_open=True)
        if splitting not in ("lie", "strang"):
            raise ValueError(f"splitting must be 'lie' or 'strang', got {splitting!r}")
        self.splitting = splitting
        self.stop_at_rest = bool(stop_at_rest)
        self.max_steps = int(max_steps)
        self.diagnostics: np.ndarray | None = None

    def make_stepper(self, state: Any, dt: float | None = None):
        """Return ``stepper(state, t_start, t_end) -> t`` advancing with CFL steps."""
        pde: GranularPDE = self.pde
        dx = pde.check_state(state)
        self._select_backend(state)
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
        flux, order, limiter = pde.scheme_codes
        strang = self.splitting == "strang"
        two = pde.two_layer
        cfl = self.cfl
        stop = self.stop_at_rest

        if self.backend_name == "numba":

            def advance(q: np.ndarray, t0: float, t1: float):
                return advance_split(q, t0, t1, dx, bcl, bcr, P, cfl, diag, rate,
                                     backup, work, self.max_steps, two, stop, flux,
                                     order, limiter, strang)
        else:
            advance = self._numpy_loop(state, dx, P, hook, diag)

        def stepper(state: Any, t_start: float, t_end: float) -> float:
            t, steps, status = advance(state.data, t_start, t_end)
            self.info["steps"] += int(steps)
            self.info["dt"] = float(diag[L.D_DT]) or None
            if status == STATUS_FAIL:
                raise SimulationBlowUp(
                    f"step {self.info['steps'] + 1} from t={t:.6g} s produced a "
                    f"non-finite or negative state ({pde.__class__.__name__}, fv-split, "
                    f"{pde.variant}, {self.splitting}, cfl={cfl}); the last good state at "
                    f"t={t:.6g} s is kept")
            if status == STATUS_REST:
                self.info["rest_time"] = float(t)
                raise FinishedSimulation(f"everything at rest at t={t:.6g} s")
            return float(t)

        return stepper

    def _numpy_loop(self, state: Any, dx: float, P: np.ndarray, hook: Any,
                    diag: np.ndarray):
        """Pure numpy/Python version of the stepping loop (same stages, slow)."""
        from ..numerics.splitting import STATUS_END
        from ..numerics.vectorized import advection_rate

        pde: GranularPDE = self.pde
        pde._require_numpy_variant()
        if self.splitting != "lie":
            raise NotImplementedError("the numpy loop implements Lie splitting only")
        g = P[L.G_Z]
        dry = pde._dry(P)
        r = P[L.R] if pde.two_layer else None

        def advance(q: np.ndarray, t: float, t_end: float):
            steps = 0
            while t < t_end and steps < self.max_steps:
                rate, smax = advection_rate(q, dx, pde.bc_codes, g, dry, r)
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

