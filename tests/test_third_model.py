"""A model is cheap to add: frictionless shallow water, registered in this file alone.

This file is the recipe of docs/architecture.md ("Adding a model") carried out: its
parameter class, its kernels (the source stage is its own; the Saint-Venant fluctuations
of the single layer are reused, which is what a one-layer model's flux is), its PDE
class and its :class:`~pdeflow.systems.EquationSystem`, registered under
``shallow_water``. Nothing else in pdeflow is edited, and the model runs through a case,
:class:`~pdeflow.simulate.Run`, a sweep, storage and the figures, and matches Ritter's
dam break as closely as the single layer does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from pdeflow import systems
from pdeflow.analysis.exact import ritter
from pdeflow.cases import load_case
from pdeflow.models.base import GranularPDE, SharedParameters, stop_time
from pdeflow.models.single_layer import flux as saint_venant
from pdeflow.numerics import layout as L
from pdeflow.numerics.compiled import FIELDS, PARAMS, STATE, VECTOR, f8, i8, kernel
from pdeflow.numerics.model_kernels import ModelKernels
from pdeflow.numerics.state import velocity
from pdeflow.numerics.vectorized import advection_rate

ROOT = Path(__file__).resolve().parents[1]
NAME = "shallow_water"

# --- parameters: the header (g_z, g_x) and the dry tolerance -----------------------------
DRY = L.N_HEADER
SIZE = L.N_HEADER + 1


@dataclass
class ShallowWaterParameters(SharedParameters):
    """Frictionless shallow water: gravity, slope and the shared tolerances only."""

    kind = "shallow-water"

    def to_array(self) -> np.ndarray:
        th = math.radians(self.theta_deg)
        P = np.zeros(SIZE)
        P[L.G_Z] = self.g * math.cos(th)
        P[L.G_X] = self.g * math.sin(th)
        P[DRY] = self.dry_tolerance
        return P


# --- kernels: gravity along the bed, nothing else ---------------------------------------
@kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)
def sw_sources(q, dt, t, P, diag, lo, hi):  # pragma: no cover - compiled
    """h u <- h (u + dt g_x) in the wet cells lo..hi; dry cells lose their momentum."""
    moving = False
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        u = velocity(h, q[1, i], P[DRY])
        if h > P[DRY]:
            u += dt * P[L.G_X]
        m = h * u if h > P[DRY] else 0.0
        moving = moving or m != 0.0
        q[0, i] = h
        q[1, i] = m
    if moving:
        diag[L.D_MOVE_UPPER] = t
    diag[L.D_T] = t
    diag[L.D_CHANGED] = 1.0 if moving else 0.0
    diag[L.D_STEPS] += 1.0


@kernel(STATE, f8, f8, PARAMS, VECTOR)
def sw_source_stage(q, dt, t, P, diag):  # pragma: no cover - compiled
    sw_sources(q, dt, t, P, diag, 0, q.shape[1] - 1)


@kernel(STATE, f8, PARAMS, i8, i8)
def sw_predictor(q, dt, P, lo, hi):  # pragma: no cover - compiled
    for i in range(lo, hi + 1):
        if q[0, i] > P[DRY]:
            q[1, i] += dt * P[L.G_X] * q[0, i]


@kernel(STATE, FIELDS, PARAMS)
def sw_mol_sources(q, rate, P):  # pragma: no cover - compiled
    for i in range(q.shape[1]):
        if q[0, i] > P[DRY]:
            rate[1, i] += P[L.G_X] * q[0, i]


def sw_numpy_sources(q: np.ndarray, P: np.ndarray) -> np.ndarray:
    rate = np.zeros_like(q)
    rate[1] = np.where(q[0] > P[DRY], P[L.G_X] * q[0], 0.0)
    return rate


KERNELS = ModelKernels(
    fields=2, face=saint_venant.face, fluctuations=saint_venant.fluctuations,
    cell_jump=saint_venant.cell_jump, sources=sw_sources, source_stage=sw_source_stage,
    predictor=sw_predictor, mol_sources=sw_mol_sources,
    numpy_advection=lambda q, dx, bc, P: advection_rate(q, dx, bc, P[L.G_Z], P[DRY], None),
    numpy_sources=sw_numpy_sources,
    constants=lambda P: (float(P[L.G_Z]), 0.0, float(P[DRY])))


class ShallowWater(GranularPDE):
    """Frictionless shallow water: d_t h + d_x(hu) = 0, d_t(hu) + d_x(hu^2 + g h^2/2) =
    g_x h."""

    parameters_class = ShallowWaterParameters


SYSTEM = systems.EquationSystem(
    name=NAME, label="shallow water", adjective="shallow-water",
    layers=(systems.Layer("h", "hu", "u", "water", "single"),),
    parameters_class=ShallowWaterParameters, pde_class=ShallowWater, kernels=KERNELS,
    densities=lambda p: (1.0,), layer_depths=lambda h, x, ini, p: (h,),
    summarize=lambda diag, tf, at_rest, x, d, metric: {
        "stop_time": stop_time(diag.last_move_upper, tf, at_rest),
        "max_fextra_over_rho1": 0.0},
    bytes_per_cell=180)
ShallowWater.system = SYSTEM


@pytest.fixture(scope="module", autouse=True)
def registered():
    systems.register(SYSTEM)  # the one registration line
    yield
    systems.unregister(NAME)


def _l1_error(case, model: str) -> float:
    from pdeflow.simulate import Run

    res = Run(case, model).execute()
    x = res.x
    h_exact, _ = ritter(x, case.t_end, 0.1)
    return float(np.sum(np.abs(res.state.data[0] - h_exact)) * case.dx)


def test_shallow_water_matches_ritter_as_the_single_layer_does():
    """Ritter's dam break at t = 0.5 s on 400 cells: the new model's L1 depth error is
    the single layer's (phi_B = 1e-9 deg, i.e. the same equations) to 1 %, and of the
    first-order size (below 2 % of the reservoir's volume)."""
    case = load_case(ROOT / "cases" / "ritter_dam_break.toml",
                     ["output.snapshot_times=[]"])
    err_new = _l1_error(case, NAME)
    err_single = _l1_error(case, "single_layer")
    assert err_new == pytest.approx(err_single, rel=0.01)
    assert err_new < 0.02 * 0.1 * 1.0


def test_shallow_water_through_cli_storage_sweep_and_figures(tmp_path):
    """A case naming the model runs with its summary, its stored run reads back with the
    model's fields, a sweep gives a run-out per aspect ratio, and the figures draw."""
    from pdeflow.case_figures import case_figures
    from pdeflow.simulate import run_model
    from pdeflow.storage import RunStorageTracker, open_run, run_metadata

    sets = [f"case.models=['{NAME}']", "output.snapshot_times=[0.1]", "case.t_end=0.2"]
    case = load_case(ROOT / "cases" / "ritter_dam_break.toml", sets)
    store = RunStorageTracker(tmp_path / "run.h5", 0.1, metadata=run_metadata(case, NAME))
    res = run_model(case, NAME, tracker=store)
    assert res.summary["model"] == NAME
    assert res.summary["mass_relative_error"] < 1e-12
    assert set(res.final_arrays()) == {"x", "t", "h", "u"}
    run = open_run(tmp_path / "run.h5")
    assert run.model == NAME and run.columns() == ["h", "u"]
    np.testing.assert_array_equal(run.data[-1], res.state.data)
    paths = case_figures({NAME: res}, tmp_path / "figures", parallel=False)
    assert [p.name for p in paths] == ["snapshot_t0.1.png", "final_deposits.png"]
    assert all(p.stat().st_size > 1000 for p in paths)

    from pdeflow.analysis.sweep import run_sweep

    collapse = load_case(ROOT / "cases" / "collapse_sweep.toml",
                         [f"case.models=['{NAME}']", "grid.dx=0.05", "case.t_end=0.3"])
    summary = run_sweep(collapse, [1.0, 2.0])
    points = summary["models"][NAME]["points"]
    assert [p[0] for p in points] == [1.0, 2.0]
    assert all(p[1] is not None and p[1] > 0 for p in points)


def test_an_unknown_model_is_a_one_line_error():
    from pdeflow.cases import CaseError

    with pytest.raises(CaseError, match="unknown model 'no_such_model'; allowed: "):
        load_case(ROOT / "cases" / "ritter_dam_break.toml",
                  ["case.models=['no_such_model']"])
