"""Timed runs of one variant on one grid: the measure of the work-precision study.

The wall time of a run is the median over ``repeats`` runs of the compiled stepper (more,
up to :data:`MAX_REPEATS`, while the timed runs add up to less than :data:`MIN_TIMING_S`:
short runs are noisy), after one warm-up run that compiles (numba) and is not counted.
fv-split runs its CFL stepper to ``t``; the method of lines (``mol-rk``) py-pde's solver
with the fixed step :func:`mol_time_step`, in chunks, stopped at a wall-time cap.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pde.trackers.base import FinishedSimulation

from ..cases import Case
from ..simulate import Run
from ..solvers import SimulationBlowUp
from ..variant import Variant
from .points import Point

MIN_TIMING_S = 0.25
"""Short runs are repeated until their timed runs add up to this [s] (noise)."""
MAX_REPEATS = 25


@dataclass
class RunTiming:
    """Outcome of timing one compiled run."""

    data: np.ndarray
    """state at time ``t`` (rows h, hu or h1, h1u1, h2, h2u2)"""
    t: float
    wall_s: list[float]
    compile_s: float
    steps: int
    status: str = "ok"
    note: str = ""
    info: dict[str, Any] = field(default_factory=dict)


def _repeat(run: Any, repeats: int) -> list[float]:
    """Wall times [s] of ``repeats`` calls of ``run()`` (more while they are short)."""
    walls: list[float] = []
    while len(walls) < repeats or (sum(walls) < MIN_TIMING_S and len(walls) < MAX_REPEATS):
        walls.append(run())
    return walls


def _fv_split_run(run: Run, t: float, repeats: int) -> RunTiming:
    def once() -> tuple[float, np.ndarray, int, dict]:
        solver = run.make_solver()
        s = run.state.copy()
        stepper = solver.make_stepper(s)
        w0 = time.perf_counter()
        try:
            stepper(s, 0.0, float(t))
        except FinishedSimulation:
            pass  # at rest before t: the state is stationary
        wall = time.perf_counter() - w0
        return wall, s.data.copy(), int(solver.info["steps"]), dict(solver.info)

    try:
        warm, data, steps, info = once()
        walls = [warm] if repeats <= 0 else _repeat(lambda: once()[0], repeats)
    except SimulationBlowUp as err:
        return RunTiming(run.state.data.copy(), t, [math.nan], math.nan, 0, "failed",
                         str(err))
    med = statistics.median(walls)
    return RunTiming(data, t, walls, max(warm - med, 0.0), steps, info=info)


def _layers(run: Run, d: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each layer's depth [m] and speed |u| [m/s] (0 where thinner than 1e-6 m) in
    the state data ``d`` of ``run`` (a 2D grid's layers have hv too)."""
    rows = d.shape[0] // len(run.pde.system.layers)
    out = []
    for k in range(0, d.shape[0], rows):
        h = d[k]
        wet = np.where(h > 1e-6, h, 1.0)
        momentum = np.sqrt(sum(d[k + m] ** 2 for m in range(1, rows)))
        out.append((h, np.where(h > 1e-6, momentum / wet, 0.0)))
    return out


def _courant_length(case: Any) -> float:
    """dx [m]; on a 2D grid 1 / (1/dx + 1/dy): the Courant numbers of both axes summed,
    as fv-split bounds them."""
    return 1.0 / (1.0 / case.dx + 1.0 / case.dy) if case.is_2d else case.dx


def mol_time_step(run: Run, t: float) -> float:
    """Fixed RK4 step [s]: CFL L / s_est (L: :func:`_courant_length`), s_est = 2 max(|u|
    + sqrt(g_z H)) + g_x t over the initial state, shortened so that a whole number of
    steps reaches ``t``."""
    P = run.pde.parameter_array()
    gz, gx = float(P[0]), float(P[1])  # G_Z, G_X come first in both layouts
    layers = _layers(run, run.state.data)
    H = sum(np.maximum(h, 0.0) for h, _ in layers)
    speed = max(float(np.max(u + np.sqrt(gz * H))) for _, u in layers)
    s_est = 2.0 * speed + abs(gx) * t
    dt = run.case.cfl * _courant_length(run.case) / s_est
    return t / math.ceil(t / dt)


def _mol_run(run: Run, t: float, repeats: int, cap: float) -> RunTiming:
    state = run.state
    h_max0 = float(np.max(sum(np.maximum(h, 0.0) for h, _ in _layers(run, state.data))))
    dt = mol_time_step(run, t)
    s_est = run.case.cfl * _courant_length(run.case) / dt

    def broken(d: np.ndarray) -> bool:
        """Blow-up: non-finite, a depth above 1.5 x the initial one, or a velocity
        above 5 x the speed bound (the hook clips negative depths silently)."""
        if not np.all(np.isfinite(d)):
            return True
        rows = d.shape[0] // len(run.pde.system.layers)
        if np.max(d[::rows]) > 1.5 * h_max0:
            return True
        for k in range(0, d.shape[0], rows):
            momentum = np.sqrt(sum(d[k + m] ** 2 for m in range(1, rows)))
            if np.max(momentum / np.maximum(d[k], 1e-3)) > 5.0 * s_est:
                return True
        return False

    n_steps = round(t / dt)
    chunk = max(1, math.ceil(n_steps / 50))
    c0 = time.perf_counter()
    solver = run.make_solver()
    stepper = solver.make_stepper(state, dt)
    compile_s = time.perf_counter() - c0

    def once() -> tuple[float, np.ndarray, str, str, float]:
        s = state.copy()
        done = 0
        w0 = time.perf_counter()
        status, note = "ok", ""
        with np.errstate(all="ignore"):
            while done < n_steps:
                k = min(chunk, n_steps - done)
                stepper(s, done * dt, (done + k) * dt)
                done += k
                elapsed = time.perf_counter() - w0
                d = s.data
                if broken(d):
                    status = "failed"
                    note = f"blow-up at t = {done * dt:.4g} s (dt = {dt:.3g} s)"
                    break
                if elapsed > cap and done < n_steps:
                    status = "capped"
                    note = (f"wall-time cap {cap:g} s reached at t = {done * dt:.4g} s of "
                            f"{t:g} s; projected {elapsed * n_steps / done:.3g} s")
                    break
        wall = time.perf_counter() - w0
        return wall, s.data.copy(), status, note, done * dt

    warm, data, status, note, t_reached = once()
    walls = [warm]
    if status == "ok":
        walls = []
        budget = cap
        for _ in range(max(1, repeats)):
            w = once()[0]
            walls.append(w)
            budget -= w
            if budget <= 0:
                break
        compile_s += max(warm - statistics.median(walls), 0.0)
    return RunTiming(data, t_reached, walls, compile_s, n_steps if status == "ok" else
                     round(t_reached / dt), status, note, {"dt": dt})


def run_variant(case: Case, model: str, variant: Variant, t: float, repeats: int = 3,
                mol_cap: float = 20.0) -> RunTiming:
    """Time ``variant`` of ``model`` on ``case`` (already on its grid) up to ``t`` [s]."""
    run = Run(case, model, variant)
    if variant.is_mol:
        return _mol_run(run, t, repeats, mol_cap)
    return _fv_split_run(run, t, repeats)


def timed(point: Point, t: float, repeats: int, mol_cap: float) -> dict[str, Any]:
    """Measure of :func:`compare`: the timing of one point (see :class:`RunTiming`)."""
    return {"run": run_variant(point.case, point.model, point.variant or Variant(), t,
                               repeats, mol_cap)}
