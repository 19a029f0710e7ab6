"""Run a model of a case with py-pde's controller and summarise the result."""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pde import FieldCollection

from .analysis.metrics import front_position, mass
from .cases import Case
from .checks import RunWarning, cost_warning, domain_ends, result_warnings, solver_warning
from .numerics import layout as L
from .numerics.state import velocity_profile
from .solvers.fv_split import load_kernels
from .trackers import FextraStorageTracker


@dataclass
class RunResult:
    """Outcome of one model run: final state, snapshots, diagnostics, summary."""

    model: str
    case: Case
    state: FieldCollection
    t_final: float
    diagnostics: np.ndarray | None
    info: dict[str, Any]
    snapshots: dict[float, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    """t -> (state data, F_extra/rho1 per cell)"""
    summary: dict[str, Any] = field(default_factory=dict)

    @property
    def x(self) -> np.ndarray:
        return self.state.grid.axes_coords[0]

    @property
    def fextra_over_rho1(self) -> np.ndarray:
        """F_extra/rho1 of the last step, per cell [m^2/s^2] (zeros for one layer)."""
        if self.diagnostics is None:
            return np.zeros(self.x.size)
        return self.diagnostics[L.N_DIAG:].copy()

    def final_arrays(self) -> dict[str, np.ndarray]:
        """x, depths and velocities of the final state (keys as in the ``--final`` npz)."""
        out = {"x": self.x, "t": np.float64(self.t_final)}
        d = self.state.data
        dry = self.case.make_pde(self.model).parameters.dry_tolerance
        names = ("h1", "u1", "h2", "u2") if self.model == "two_layer" else ("h", "u")
        for k in range(0, d.shape[0], 2):
            h = d[k]
            out[names[k]] = h.copy()
            out[names[k + 1]] = velocity_profile(h, d[k + 1], dry)
        return out


def load_case_kernels(case: Case, log: Any = None) -> float:
    """Compile or load the compiled kernels that ``case`` needs, before its runs, so
    that neither its wall times nor its progress bars include it; ``log`` (a stream) is
    told when they are compiled (the first run on a machine). Returns seconds spent."""
    return load_kernels(log) if case.solver == "fv-split" else 0.0


def run_model(case: Case, model: str, *, tracker: Any = None,
              backend: str = "numba") -> RunResult:
    """Run ``model`` ('two_layer' or 'single_layer') of ``case`` to rest or t_end.

    Snapshots are stored at ``output.snapshot_times`` through a py-pde
    ``MemoryStorage`` tracker; ``tracker`` adds user trackers (e.g. a live plot).
    """
    for message in (solver_warning(case), cost_warning(case, model)):
        if message:
            warnings.warn(message, RunWarning, stacklevel=2)
    eq, state = case.make_state(model)
    dx = case.dx
    r = eq.parameters.density_ratio if model == "two_layer" else None
    mass0 = mass(state.data, dx, r)
    initial = state.data.copy()
    snaps = FextraStorageTracker(sorted(case.snapshot_times))
    trackers: list[Any] = [snaps] if case.snapshot_times else []
    if tracker is not None:
        trackers.extend(tracker if isinstance(tracker, list) else [tracker])
    solver = case.solver
    kwargs: dict[str, Any] = {}
    if solver == "fv-split":
        kwargs = {"cfl": case.cfl, "backend": backend, "splitting": case.splitting}
        if backend == "numba":
            # compiling (first run on a machine) or loading the kernels is not the run's
            # wall time, nor should it hold up its progress bar
            load_kernels()
    else:
        kwargs = {"dt": float(case.data.get("numerics", {}).get("dt", 1e-4))}
    wall0 = time.perf_counter()
    final, info = eq.solve(state, t_range=case.t_end, solver=solver, tracker=trackers,
                           ret_info=True, **kwargs)
    wall = time.perf_counter() - wall0
    if str(info.get("controller", {}).get("stop_reason", "")).startswith("User interrupted"):
        # py-pde turns Ctrl-C into a normal return; a truncated run must not be written
        # out as if it were complete
        raise KeyboardInterrupt(f"{model} run of {case.name} interrupted at "
                                f"t={info['controller'].get('t_final')}")
    sinfo = info.get("solver", {})
    diag = sinfo.get("post_step_data")
    diag = diag if isinstance(diag, np.ndarray) else None
    t_final = float(sinfo.get("rest_time", info["controller"].get("t_final", case.t_end)))
    if diag is not None and diag[L.D_T] > 0:
        t_final = float(diag[L.D_T])
    result = RunResult(model, case, final, t_final, diag, info)
    result.snapshots = snaps.snapshots
    result.summary = summarize(result, mass0, wall, initial)
    for message in result.summary["warnings"]:
        warnings.warn(message, RunWarning, stacklevel=2)
    return result


def _stop_time(last_moving: float, t_final: float, at_rest: bool) -> float | None:
    """Stop time from the last time a layer moved: None if still moving at the end."""
    if last_moving >= t_final and not at_rest:
        return None
    return float(last_moving)


_COMMON_KEYS = ("model", "solver", "t_final", "at_rest", "front_position", "runout",
                "mass_relative_error", "steps", "wall_time_s", "stop_reason", "stop_time",
                "max_fextra_over_rho1", "flux_fallback_steps", "mass_change",
                "runout_lower_bound", "domain_ends", "warnings")
SUMMARY_KEYS: dict[str, tuple[str, ...]] = {
    "two_layer": (*_COMMON_KEYS, "lower_stop_time", "upper_stop_time", "lower_slow_time",
                  "upper_slow_time", "max_fextra_x", "max_fextra_time",
                  "hyperbolicity_events", "hyperbolicity_bisections", "deposited_volume",
                  "eroded_volume", "upper_volume_final", "lower_volume_final"),
    "single_layer": (*_COMMON_KEYS, "slow_time"),
}
"""Keys of :func:`summarize` per model with the fv-split solver (other py-pde solvers
give the common keys; stop times are then None). ``domain_ends`` (a table) and
``warnings`` (a list) are not numbers: a study records them as JSON text."""


def summarize(res: RunResult, mass0: float, wall: float,
              initial: np.ndarray | None = None) -> dict[str, Any]:
    """The per-model summary written to the JSON summary file; ``initial`` (the initial
    state data) lets it tell where material reached an end of the domain."""
    case = res.case
    dx = case.dx
    d = res.state.data
    r = (res.case.make_pde("two_layer").parameters.density_ratio
         if res.model == "two_layer" else None)
    front = front_position(res.x, d, case.front_threshold, dx)
    at_rest = "rest_time" in res.info.get("solver", {})
    diag = res.diagnostics
    out: dict[str, Any] = {
        "model": res.model,
        "solver": case.solver,
        "t_final": res.t_final,
        "at_rest": at_rest,
        "front_position": front,
        "runout": (front - case.x_start - case.L0) if (front is not None and case.L0)
        else None,
        "mass_relative_error": abs(mass(d, dx, r) - mass0) / mass0 if mass0 else 0.0,
        "mass_change": (mass(d, dx, r) - mass0) / mass0 if mass0 else 0.0,
        "steps": int(res.info.get("solver", {}).get("steps", 0)),
        "wall_time_s": wall,
        "stop_reason": res.info.get("controller", {}).get("stop_reason"),
    }
    if diag is not None and case.solver == "fv-split":
        # steps that IFCP could not keep positive, redone with HLL (0 for other fluxes)
        out["flux_fallback_steps"] = int(diag[L.D_FLUX_FALLBACKS])
        tf = res.t_final
        up = _stop_time(diag[L.D_MOVE_UPPER], tf, at_rest)
        if res.model == "two_layer":
            lo = _stop_time(diag[L.D_MOVE_LOWER], tf, at_rest)
            out.update({
                "lower_stop_time": lo,
                "upper_stop_time": up,
                "stop_time": None if (lo is None or up is None) else max(lo, up),
                "lower_slow_time": _stop_time(diag[L.D_FAST_LOWER], tf, False),
                "upper_slow_time": _stop_time(diag[L.D_FAST_UPPER], tf, False),
                "max_fextra_over_rho1": float(diag[L.D_FEXTRA_MAX]),
                "max_fextra_x": float(res.x[int(diag[L.D_FEXTRA_CELL])]),
                "max_fextra_time": float(diag[L.D_FEXTRA_TIME]),
                "hyperbolicity_events": int(diag[L.D_HYP_EVENTS]),
                "hyperbolicity_bisections": int(diag[L.D_HYP_BISECTIONS]),
                "deposited_volume": float(diag[L.D_DEPOSITED] * dx),
                "eroded_volume": float(diag[L.D_ERODED] * dx),
                "upper_volume_final": float(np.sum(d[0]) * dx),
                "lower_volume_final": float(np.sum(d[2]) * dx),
            })
        else:
            out.update({
                "stop_time": up,
                "slow_time": _stop_time(diag[L.D_FAST_UPPER], tf, False),
                "max_fextra_over_rho1": 0.0,
            })
    else:
        out.update({"stop_time": None, "max_fextra_over_rho1": None})
    if initial is not None:
        out["domain_ends"] = domain_ends(case, initial, d, out["mass_change"])
        out["runout_lower_bound"] = out["domain_ends"]["runout_lower_bound"]
    out["warnings"] = result_warnings(case, res.model, out)
    return out
