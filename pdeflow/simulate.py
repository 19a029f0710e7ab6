"""Runs: a case, a model and a numerical variant, set up once and run with py-pde.

A :class:`Run` turns a :class:`~pdeflow.cases.Case` (+ a
:class:`~pdeflow.variant.Variant`) into the PDE, the initial state, the solver and its
arguments exactly once; :meth:`Run.execute` integrates it with py-pde's controller and
returns a :class:`RunResult` that carries the PDE, the final state, the snapshots, a
typed view of the solver's diagnostics and the summary.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pde import FieldCollection

from . import metrics_2d, systems
from .cases import Case
from .checks import (
    RunWarning,
    cost_warning,
    domain_ends,
    result_warnings,
    slope_warning,
    solver_warning,
)
from .erosion import (
    BED_KEYS,
    SERIES_KEYS,
    ErosionSeries,
    erosion_series,
    final_deposit,
    series_numbers,
)
from .metrics import (
    front_position,
    mass,
    mass_quantile_position,
    total_depth,
    weighted_depth,
)
from .models.base import GranularPDE
from .numerics import layout as L
from .numerics.geometry import Metric
from .numerics.splitting import Stepper
from .numerics.state import velocity_profile
from .numerics.threads import DEFAULT_THREADS, check_threads
from .numerics.warmup import prepare
from .solvers.diagnostics import SplitDiagnostics
from .solvers.fv_split import SimulationBlowUp, split_stepper
from .summary_2d import COMMON_KEYS_2D, summarize_2d
from .terrain_run import peak_fields_tracker, terrain_summary
from .trackers import FextraStorageTracker
from .trackers.peaks import PeakTracker
from .trackers.series import SeriesTracker
from .variant import Variant


@dataclass
class RunResult:
    """Outcome of one model run: PDE, final state, snapshots, diagnostics, summary."""

    model: str
    case: Case
    pde: GranularPDE
    state: FieldCollection
    t_final: float
    diagnostics: SplitDiagnostics | None
    """the fv-split solver's record (None for py-pde's solvers)"""
    info: dict[str, Any]
    metric: Metric
    """the grid's finite-volume metric (its geometry, face areas, cell volumes)"""
    snapshots: dict[float, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    """t -> (state data, F_extra/rho1 per cell)"""
    summary: dict[str, Any] = field(default_factory=dict)
    frames: tuple[np.ndarray, list[np.ndarray]] | None = None
    """(times [s], state data) of the series' frames, if it records them"""
    series: ErosionSeries | None = None
    """the erosion time series (:mod:`pdeflow.erosion`) of a case that records
    it (:attr:`pdeflow.cases.Case.erosion_series`), else None"""
    peak_fields: np.ndarray | None = None
    """over a ``[terrain]`` bed, the sampled peaks of depth [m], speed [m/s] and pressure
    [kPa] per cell (3, nx, ny) (:mod:`pdeflow.terrain_run`), else None"""

    @property
    def x(self) -> np.ndarray:
        return self.state.grid.axes_coords[0]

    @property
    def fextra_over_rho1(self) -> np.ndarray:
        """F_extra/rho1 of the last step, per cell [m^2/s^2] (zeros for one layer)."""
        if self.diagnostics is None:
            return np.zeros(self.x.size)
        return self.diagnostics.cells.copy()

    def _final_arrays_2d(self) -> dict[str, np.ndarray]:
        """The final state of a 2D run: x [m] (nx), y [m] (ny), t [s], and each layer's
        depth [m] and velocities along x and y [m/s] of shape (nx, ny)."""
        x, y = self.state.grid.axes_coords
        out = {"x": x, "y": y, "t": np.float64(self.t_final)}
        d = self.state.data
        dry = self.pde.parameters.dry_tolerance
        for k, layer in enumerate(self.pde.system.layers):
            h = d[3 * k]  # depth, discharge along x, discharge along y
            out[layer.depth] = h.copy()
            out[layer.velocity] = velocity_profile(h, d[3 * k + 1], dry)
            out[layer.velocity_y] = velocity_profile(h, d[3 * k + 2], dry)
        return out

    def final_arrays(self) -> dict[str, np.ndarray]:
        """x, depths and velocities of the final state (keys as in the ``--final`` npz;
        a 2D run's: :meth:`_final_arrays_2d`)."""
        if self.case.is_2d:
            return self._final_arrays_2d()
        out = {"x": self.x, "t": np.float64(self.t_final)}
        d = self.state.data
        dry = self.pde.parameters.dry_tolerance
        for k, layer in enumerate(self.pde.system.layers):
            h = d[2 * k]
            out[layer.depth] = h.copy()
            out[layer.velocity] = velocity_profile(h, d[2 * k + 1], dry)
        if self.case.bed_kind(self.model) is not None:
            bed0 = self.case.bed(self.model, self.x - self.case.x_start)
            # the initial bed and the deposit with it subtracted (0: the rigid bed)
            out["bed0"] = np.zeros_like(self.x) if bed0 is None else bed0
            out["deposit_above_bed"] = final_deposit(d, bed0)
        return out


def case_steppers(case: Case) -> list[Stepper]:
    """The compiled steppers that the ``fv-split`` runs of ``case`` call, one per model
    (none for another solver): what :func:`pdeflow.numerics.warmup.prepare` compiles
    before the runs, all at once."""
    if case.solver != "fv-split":
        return []
    grid = case.make_grid()  # the geometry comes from the grid
    return [split_stepper(pde, pde.metric(grid)) for pde in map(case.make_pde, case.models)]


class Run:
    """One model of one case with one numerical variant, set up once.

    Args:
        case: the case (not modified; with ``variant`` a copy solved that way).
        model: the registered name of the model (:func:`pdeflow.systems.names`).
        variant: how to solve it; default: what the case file selects.
        backend: ``"numba"`` (compiled stepping loop) or ``"numpy"`` (fv-split only).
        threads: numba threads of a 2D fv-split run (the ``fv-split`` solver's
            ``threads``: 1..the cores, default 1; a 1D run runs on one).

    Attributes ``case``, ``variant``, ``pde`` (with the variant's scheme), ``state``
    (the initial state) and ``metric`` (of its grid: the geometry, derived from the grid
    once) are built here, once; :meth:`execute` may be called more than once (it never
    changes them).
    """

    def __init__(self, case: Case, model: str, variant: Variant | str | None = None, *,
                 backend: str = "numba", threads: int = DEFAULT_THREADS):
        self.threads = check_threads(threads)
        if isinstance(variant, str):
            variant = Variant.parse(variant)
        self.case = case if variant is None else case.with_variant(variant)
        self.variant = variant or case.variant
        self.model = model
        self.backend = backend
        self.pde, self.state = self.case.make_state(model)
        self.metric = self.pde.metric(self.state.grid)

    def solver_arguments(self) -> dict[str, Any]:
        """Keyword arguments of py-pde's ``solve`` that select the integrator."""
        if self.variant.is_mol:
            return {"solver": self.variant.solver,
                    "dt": float(self.case.data.get("numerics", {}).get("dt", 1e-4))}
        return {"solver": "fv-split", "cfl": self.case.cfl, "backend": self.backend,
                "outputs": self.case.frames,  # the scheme is the PDE's
                "threads": self.threads}

    def make_solver(self) -> Any:
        """The py-pde solver of this run (for timing the bare stepper, as the
        work-precision study does: ``solver.make_stepper(state[, dt])``)."""
        from pde.solvers.base import SolverBase

        kwargs = self.solver_arguments()
        name = kwargs.pop("solver")
        kwargs.pop("dt", None)  # a fixed step is the stepper's argument
        if self.variant.is_mol:
            kwargs["backend"] = self.backend
        return SolverBase.from_name(name, self.pde, **kwargs)

    def execute(self, tracker: Any = None) -> RunResult:
        """Integrate to rest or ``case.t_end`` and summarise.

        Snapshots are stored at ``output.snapshot_times``; ``tracker`` adds user
        trackers (one or a list, e.g. a live plot). Run warnings (cost, domain ends,
        mass) are issued as :class:`~pdeflow.checks.RunWarning`.
        """
        case, model = self.case, self.model
        for message in (solver_warning(case), slope_warning(case),
                        cost_warning(case, model)):
            if message:
                warnings.warn(message, RunWarning, stacklevel=2)
        mass0 = initial_mass(self.case, self.pde, self.state.data, self.metric)
        snaps = FextraStorageTracker(sorted(case.snapshot_times))
        trackers: list[Any] = [snaps] if case.snapshot_times else []
        peaks = peak_tracker(case, self.pde)
        fields = peak_fields_tracker(case, self.pde, PEAK_SAMPLES)
        trackers.extend(t for t in (peaks, fields) if t is not None)
        series = (SeriesTracker(case.series_every, self.pde.system.diagnostics)
                  if case.erosion_series else None)
        if series is not None:
            trackers.append(series)
        observers = [] if tracker is None else (
            tracker if isinstance(tracker, list) else [tracker])
        trackers.extend(observers)
        if not self.variant.is_mol and self.backend == "numba":
            # compiling (first run on a machine) or loading the kernels is not the run's
            # wall time, nor should it hold up its progress bar
            prepare(split_stepper(self.pde, self.metric))
        wall0 = time.perf_counter()
        final, info = self.pde.solve(self.state, t_range=case.t_end, tracker=trackers,
                                     ret_info=True, **self.solver_arguments())
        # fv-split's wall time is its stepping alone (a movie or a live plot takes
        # longer than the run itself); py-pde's solvers have no clock of their own:
        # the whole solve, observers included
        wall = info.get("solver", {}).get("wall_time", time.perf_counter() - wall0)
        stop = str(info.get("controller", {}).get("stop_reason", ""))
        from .interrupts import RunInterrupted, received

        if stop.startswith("User interrupted") or received():
            # py-pde turns Ctrl-C into a normal return; a truncated run must not be
            # written out as if it were complete (nor one whose Ctrl-C was swallowed)

            t_stop = info["controller"].get("t_final")
            raise RunInterrupted(f"{model} run of {case.name} interrupted at t={t_stop}",
                                 t=t_stop)
        sinfo = info.get("solver", {})
        data = sinfo.get("post_step_data")
        if self.variant.is_mol and not np.all(np.isfinite(final.data)):
            # py-pde's solvers have no step control: a blow-up runs on to t_end as NaN
            bad = int(data[L.D_BAD_STEPS]) if isinstance(data, np.ndarray) else 0
            raise SimulationBlowUp(
                f"{model} run of {case.name} with {self.variant.name} "
                f"(dt={self.solver_arguments()['dt']:g} s) blew up: the state is not "
                f"finite at t={case.t_end:g} s ({bad} step(s) left a non-finite value or "
                f"a negative depth); nothing is kept. Use a smaller numerics.dt, or the "
                f"fv-split solver (CFL-limited).",
                report={"variant": self.variant.name}, state=final.data.copy())
        system = self.pde.system
        diag = (SplitDiagnostics.from_array(data, system.diagnostics,
                                            system.cell_diagnostic)
                if isinstance(data, np.ndarray) and not self.variant.is_mol else None)
        t_final = float(sinfo.get("rest_time", info["controller"].get("t_final",
                                                                      case.t_end)))
        if diag is not None and diag.t > 0:
            t_final = diag.t
        result = RunResult(model, case, self.pde, final, t_final, diag, info, self.metric)
        result.snapshots = snaps.snapshots
        if series is not None:
            result.frames = series.frames
            result.series = run_series(result, series)
        result.summary = (summarize(result, mass0, wall, self.state.data) if peaks is None
                          else summarize_2d(result, mass0, wall, peaks.peak,
                                            self.state.data))
        if fields is not None:
            result.peak_fields = fields.peak
            result.summary.update(terrain_summary(result, fields.peak, self.state.data))
        for message in result.summary["warnings"]:
            warnings.warn(message, RunWarning, stacklevel=2)
        return result


PEAK_SAMPLES = 200
"""states a 2D run's largest speed is sampled from (every t_end / this, as the erosion
series' frames: the peak of a collapse lasts longer than t_end / 200)"""


def peak_tracker(case: Case, pde: GranularPDE) -> Any:
    """The tracker of a 2D run's largest speed (its summary's ``max_speed``, sampled
    every t_end / :data:`PEAK_SAMPLES`), None for a 1D run (no such number)."""
    if not case.is_2d:
        return None
    dry = pde.parameters.dry_tolerance
    return PeakTracker(case.t_end / PEAK_SAMPLES, lambda data: metrics_2d.max_speed(data, dry))


def initial_mass(case: Case, pde: GranularPDE, data: np.ndarray, metric: Metric) -> float:
    """The mass of the state ``data`` over the densest layer's density: per unit width
    [m^2] on a planar grid, [m^3] on an axisymmetric or 2D one."""
    densities = pde.system.densities(pde.parameters)
    if case.is_2d:
        return metrics_2d.mass(data, densities, case.dx * case.dy)
    return mass(data, metric.cells, densities)


def run_series(res: RunResult, tracker: SeriesTracker) -> ErosionSeries:
    """The erosion series of the run ``res`` from the frames of ``tracker``: fronts above
    the initial bed and, for a model with an erodible layer, the bed's erosion (booked
    exchange volumes on a planar grid only, as in the summary)."""
    case = res.case
    times, frames = tracker.frames
    metric = res.metric
    xs = res.x - case.x_start
    bed0 = case.bed(res.model, xs)
    layer = res.pde.system.bed_layer
    booked = tracker.booked * metric.dx if (metric.geometry == "planar"
                                           and res.pde.system.has_fextra) else None
    return erosion_series(times, frames, res.x, metric.cells, case.front_threshold,
                          case.dx, bed0, case.bed_region(xs) if bed0 is not None else None,
                          bed_row=2 * (layer or 0), booked=booked)


def run_model(case: Case, model: str, *, tracker: Any = None, backend: str = "numba",
              threads: int = DEFAULT_THREADS) -> RunResult:
    """Run ``model`` (a registered name) of ``case`` to rest or t_end:
    ``Run(case, model, backend=backend, threads=threads).execute(tracker)``."""
    return Run(case, model, backend=backend, threads=threads).execute(tracker)


_COMMON_KEYS = ("model", "solver", "geometry", "bed", "t_final", "at_rest", "front_position",
                "runout", "front_mass_quantile", "runout_mass_quantile",
                "runout_mass_fraction", "mass_relative_error", "steps", "wall_time_s",
                "stop_reason", "stop_time",
                "max_fextra_over_rho1", "flux_fallback_steps", "positivity_retries",
                "mass_change", "runout_lower_bound", "domain_ends", "warnings")


def summary_keys(model: str, series: bool = False,
                 two_d: bool = False) -> tuple[str, ...]:
    """Keys of :func:`summarize` for ``model`` with the fv-split solver: the common ones
    and the system's own (other py-pde solvers give the common keys; stop times are
    then None); with ``series`` also those of a run that records the erosion series
    (cases with a bed, :data:`SERIES_KEYS` and :data:`BED_KEYS`); with ``two_d`` those
    of a run on a 2D grid instead (:func:`pdeflow.summary_2d.summarize_2d`: no series,
    no mass-quantile front). ``domain_ends`` (a table) and ``warnings`` (a list) are
    not numbers: a study records them as JSON text."""
    own = systems.get(model).summary_keys
    if two_d:
        return (*COMMON_KEYS_2D, "stop_time", "max_fextra_over_rho1", *own)
    extra = (*SERIES_KEYS, *BED_KEYS) if series else ()
    return (*_COMMON_KEYS, *own, *extra)


_LENGTH_KEYS = ("front_position", "runout", "front_mass_quantile", "runout_mass_quantile",
                "max_fextra_x", "bed_max_erosion_x", "bed_max_erosion_depth",
                "lateral_spread", "mass_radius", "max_depth")


def summary_unit(key: str, geometry: str | None = None) -> str | None:
    """The unit of the summary number ``key`` ('-' for counts and ratios; None for a key
    that is no number, e.g. 'model' or 'warnings'); volumes are per unit width on a
    planar grid (m^2) and m^3 on an axisymmetric one ('m^2 or m^3' if ``geometry``, the
    case's grid.geometry, is not given). The one table of the units of summary keys:
    the printed table, ``pdeflow converge`` and study reports read it."""
    if key in ("t_final", "wall_time_s", "flow_duration") or key.endswith("_time"):
        return "s"
    if key in _LENGTH_KEYS:
        return "m"
    if "_volume" in key:
        return {"planar": "m^2", "axisymmetric": "m^3", "planar-2d": "m^3"}.get(
            geometry or "", "m^2 or m^3")
    units = {"max_fextra_over_rho1": "m^2/s^2", "front_velocity_max": "m/s",
             "max_speed": "m/s", "deposit_area": "m^2", "affected_area": "m^2",
             "travel_angle": "deg", "max_pressure": "kPa"}
    if key in units:
        return units[key]
    if key in ("steps", "mass_relative_error", "mass_change", "runout_mass_fraction",
               "flux_fallback_steps", "positivity_retries", "hyperbolicity_events",
               "hyperbolicity_bisections"):
        return "-"
    return None


def mass_front(res: RunResult, bed: np.ndarray | None = None) -> float | None:
    """The mass-quantile front [m] of a run's final state: the position (a radius on an
    axisymmetric grid) from the domain's start within which ``case.runout_mass_fraction``
    of the mass lies (:func:`pdeflow.metrics.mass_quantile_position`); with an initial
    ``bed`` [m], of the material above it (the deposit on the bed, clipped at 0, as
    :func:`pdeflow.metrics.front_position` measures above the bed), else of the
    layers' mass (relative densities)."""
    d = res.state.data
    metric = res.metric
    depth = (weighted_depth(d, res.pde.system.densities(res.pde.parameters)) if bed is None
             else total_depth(d) - bed)
    return mass_quantile_position(metric.faces, metric.volumes, depth,
                                  res.case.runout_mass_fraction,
                                  radial=metric.geometry == "axisymmetric")


def summarize(res: RunResult, mass0: float, wall: float,
              initial: np.ndarray | None = None) -> dict[str, Any]:
    """The per-model summary written to the JSON summary file; ``initial`` (the initial
    state data) lets it tell where material reached an end of the domain."""
    case = res.case
    dx = case.dx
    d = res.state.data
    weights = res.pde.system.densities(res.pde.parameters)
    metric = res.metric
    cells = metric.cells
    bed = case.bed(res.model, res.x - case.x_start)
    front = front_position(res.x, d, case.front_threshold, dx, bed)
    front_q = mass_front(res, bed)
    at_rest = "rest_time" in res.info.get("solver", {})
    diag = res.diagnostics
    out: dict[str, Any] = {
        "model": res.model,
        "solver": case.solver,
        "geometry": metric.geometry,  # from the grid
        "bed": case.bed_kind(res.model),
        "t_final": res.t_final,
        "at_rest": at_rest,
        "front_position": front,
        "runout": (front - case.x_start - case.L0) if (front is not None and case.L0)
        else None,
        # the front that holds runout_mass_fraction of the mass: it converges with the
        # grid, where the threshold front follows the last per mille of a thin tail
        "front_mass_quantile": front_q,
        "runout_mass_quantile": (front_q - case.x_start - case.L0)
        if (front_q is not None and case.L0) else None,
        "runout_mass_fraction": case.runout_mass_fraction,
        "mass_relative_error": abs(mass(d, cells, weights) - mass0) / mass0 if mass0 else 0.0,
        "mass_change": (mass(d, cells, weights) - mass0) / mass0 if mass0 else 0.0,
        "steps": int(res.info.get("solver", {}).get("steps", 0)),
        "wall_time_s": wall,
        "stop_reason": res.info.get("controller", {}).get("stop_reason"),
    }
    if diag is not None:
        # steps that IFCP could not keep positive, redone with HLL (0 for other fluxes)
        out["flux_fallback_steps"] = diag.flux_fallbacks
        # steps rejected by the positivity safety net and redone with dt/2 (see
        # docs/stability.md): 0 where the scheme kept depths non-negative by itself
        out["positivity_retries"] = diag.positivity_retries
        out.update(res.pde.system.summarize(diag, res.t_final, at_rest, res.x, d,
                                            metric))
    else:
        out.update({"stop_time": None, "max_fextra_over_rho1": None})
    if res.series is not None:
        out.update(series_numbers(res.series, case.bed_kind(res.model) == "erodible"))
    if initial is not None:
        out["domain_ends"] = domain_ends(case, initial, d, out["mass_change"], bed)
        out["runout_lower_bound"] = out["domain_ends"]["runout_lower_bound"]
    out["warnings"] = result_warnings(case, res.model, out)
    return out
