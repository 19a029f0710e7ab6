"""The fv-split diagnostics name the model's per-cell diagnostic as its system does."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pdeflow.cases import load_case
from pdeflow.numerics import layout as L
from pdeflow.simulate import run_model
from pdeflow.solvers.diagnostics import SplitDiagnostics

CASE_51 = Path(__file__).parents[1] / "cases" / "paper_5_1_dam_break.toml"


def test_the_per_cell_diagnostic_is_read_by_the_systems_name():
    diag = np.zeros(L.N_DIAG + 3)
    diag[L.N_DIAG:] = [1.0, 2.0, 3.0]
    view = SplitDiagnostics.from_array(diag, {}, "speed_squared")
    diag[L.N_DIAG:] = 0.0  # a later step does not change the view
    assert view.speed_squared is view.cells
    assert view.cells.tolist() == [1.0, 2.0, 3.0]
    unnamed = SplitDiagnostics.from_array(diag)
    with pytest.raises(AttributeError, match="has no 'fextra_over_rho1'"):
        unnamed.fextra_over_rho1  # noqa: B018 - no model-free name for it


def test_two_layers_name_it_fextra_over_rho1_and_one_layer_names_none():
    case = load_case(CASE_51, ["grid.dx=0.1", "case.t_end=0.3",
                               "output.snapshot_times=[]"])
    two = run_model(case, "two_layer")
    assert two.diagnostics.cell_name == "fextra_over_rho1"
    assert two.diagnostics.fextra_over_rho1 is two.diagnostics.cells
    assert np.any(two.diagnostics.cells > 0)  # F_extra acts in the collapse's first 0.3 s
    one = run_model(case, "single_layer")
    assert one.diagnostics.cell_name is None
    assert not hasattr(one.diagnostics, "fextra_over_rho1")
    assert not np.any(one.fextra_over_rho1)  # the run's zeros for one layer
