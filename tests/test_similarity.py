"""The Savage-Hutter similarity solution (pdeflow/analysis/similarity.py) and pdeflow's
2D single layer against it (pdeflow/analysis/similarity_run.py; docs/two_d.md, "The
Savage-Hutter similarity solution")."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pdeflow.analysis import similarity_run as sr
from pdeflow.analysis.similarity import CapSolution


def test_ode_gives_avaframes_numbers_at_5_s():
    """AvaFrame's set-up (L = 80 m, H = 4 m, zeta = 35 deg, delta = 25 deg, K = 1) at
    t = 5 s: g = a/L_x = 1.120, f = b/L_y = 1.040 and the centre 23.5 m down the slope,
    the values AvaFrame's ODE gives, to the digits quoted (half a unit of the last)."""
    st = sr.solution().state(5.0)
    assert abs(st["g"] - 1.120) <= 5e-4, st
    assert abs(st["f"] - 1.040) <= 5e-4, st
    assert abs(st["x_c"] - 23.5) <= 0.05, st


def test_early_spreading_follows_the_taylor_series():
    """At t = 0.02 s from rest: a - L_x = k g_z h_c t^2 / L_x and b - L_y = k g_z h_c t^2
    s / (L_y g sin zeta) (the ODE's second derivatives at t = 0, the second with the
    limit of the friction term); relative 1e-3, the next term being O(t^2) smaller."""
    cap, t = sr.solution(), 0.02
    st = cap.state(t)
    gz_h = cap.g_z * sr.H * t * t
    sin = math.sin(math.radians(sr.SLOPE_DEG))
    assert st["a"] - sr.L_X == pytest.approx(gz_h / sr.L_X, rel=1e-3)
    assert st["b"] - sr.L_Y == pytest.approx(gz_h * cap.s / (sr.L_Y * cap.g * sin),
                                             rel=1e-3)


@pytest.mark.parametrize("t", [0.0, 2.0, 5.0])
def test_the_cap_keeps_its_volume(t):
    """The thickness summed over a 0.1 m raster (midpoint rule) equals pi/2 H L_x L_y
    to 1e-6 (measured 4e-9 at 5 s: the rule's error at the cap's kinked edge)."""
    cap = sr.solution()
    axis = np.arange(-149.95, 150.0, 0.1)
    x, y = np.meshgrid(axis, axis, indexing="ij")
    assert cap.depth(x, y, t).sum() * 0.01 == pytest.approx(cap.volume, rel=1e-6)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"friction_deg": 35.0}, r"^friction_deg must lie in \(0.0, 35.0\) deg, got 35.0$"),
    ({"L_x": 0.0}, r"^L_x must lie in \(0.0, inf\] m, got 0.0$"),
])
def test_bad_parameters_are_one_line_errors(kwargs, message):
    args = {"slope_deg": 35.0, "friction_deg": 25.0, "L_x": 80.0, "L_y": 80.0, "H": 4.0,
            "t_end": 5.0} | kwargs
    with pytest.raises(ValueError, match=message):
        CapSolution(**args)


def test_errors_of_the_solution_itself_are_zero():
    """The solution on a 1 m raster at 5 s: every relative error 0, and its centroid
    within 1e-3 m of x_c (the raster samples the cap at cell centres, not symmetrically
    about x_c: the midpoint rule's error at the cap's edge)."""
    cap = sr.solution()
    x, y = np.meshgrid(np.arange(-99.5, 140), np.arange(-99.5, 100), indexing="ij")
    err = sr.errors(cap.depth(x, y, 5.0), x, y, cap, 5.0)
    assert err["L1"] == err["L2"] == err["Lmax"] == 0.0
    assert err["centre"] < 1e-3, err


def test_grid_must_hold_whole_cells():
    with pytest.raises(ValueError, match=r"^dx must divide 20 m"):
        sr.initial_state(3.0)


def test_pdeflow_first_order_error_at_coarse_grids():
    """First order at dx = 4 and 2 m (60 x 25 and 120 x 50 cells, t = 5 s): relative L1
    of h below 0.065 at 4 m (measured 0.0555; an independent first-order code gave
    0.053; the bound leaves 15 % for other fluxes' smearing, not more) and halving dx
    divides it by at least 1.6 (measured 1.91: first order, the dry edge's kink); the
    centroid within a tenth of a cell of x_c at 4 m (measured 0.23 m)."""
    cap = sr.solution()
    coarse, fine = (sr.errors(**_run(dx, "hll/first-order"), exact=cap, t=sr.T_END)
                    for dx in (4.0, 2.0))
    assert coarse["L1"] < 0.065, coarse
    assert coarse["L1"] / fine["L1"] > 1.6, (coarse, fine)
    assert coarse["centre"] < 0.4, coarse


def test_pdeflow_muscl_reaches_com1dfas_best_error_at_4_m():
    """MUSCL (hll/muscl/mc) at dx = 4 m (a run of about 0.05 s): relative L2 of h below
    0.0112, com1DFA's best on this set-up (58734 particles, docs/two_d.md; issue 36
    quotes 0.017); measured 0.0095. The solution is not exact for the PDE (module
    docstring of similarity.py), so finer grids level off near 0.006."""
    err = sr.errors(**_run(4.0, "hll/muscl/mc"), exact=sr.solution(), t=sr.T_END)
    assert err["L2"] < 0.0112, err


@pytest.mark.slow
@pytest.mark.parametrize("scheme", ["hll/first-order", "hll/muscl/mc"])
def test_pdeflow_error_falls_on_finer_grids(scheme):
    """dx = 2, 1, 0.5 m: first order, L1 falls by at least 1.6 on each halving
    (measured 1.88 and 1.67: the rate drops as the error nears the solution's own
    inexactness); MUSCL, L1 at 0.5 m below 0.0065 (measured 0.0052: it levels off where
    the solution stops being exact, near 0.5 %)."""
    cap = sr.solution()
    l1 = [sr.errors(**_run(dx, scheme), exact=cap, t=sr.T_END)["L1"]
          for dx in (2.0, 1.0, 0.5)]
    if scheme == "hll/first-order":
        assert all(a / b > 1.6 for a, b in zip(l1, l1[1:], strict=False)), l1
    else:
        assert l1[-1] < 0.0065, l1


def _run(dx: float, scheme: str) -> dict[str, np.ndarray]:
    """pdeflow's run at dx [m] with ``scheme``: the arguments h, x, y of errors()."""
    out = sr.run(dx, scheme)
    return {"h": out["h"], "x": out["x"], "y": out["y"]}
