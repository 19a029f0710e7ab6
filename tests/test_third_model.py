"""A model is cheap to add: frictionless shallow water, a package of its own and one
registration line.

The package :mod:`tests.shallow_water` is the recipe of docs/architecture.md ("Adding a
model") carried out outside pdeflow: its parameter vector and diagnostics slots, its
kernels (the source stage is its own; the Saint-Venant fluctuations of the single layer
are reused, which is what a one-layer model's flux is), its PDE class and its
:class:`~pdeflow.systems.EquationSystem`. Nothing in pdeflow is edited: registering it
(the fixture below) is the one line, and the model runs through a case,
:class:`~pdeflow.simulate.Run`, a sweep, storage and the figures, and matches Ritter's
dam break as closely as the single layer does.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pdeflow import systems
from pdeflow.analysis.exact import ritter
from pdeflow.cases import load_case
from tests.shallow_water import NAME, SYSTEM

ROOT = Path(__file__).resolve().parents[1]


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
    from pdeflow.storage import RunStorageTracker, run_metadata
    from pdeflow.stored_runs import open_run

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
