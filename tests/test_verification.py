"""Accuracy against exact solutions (fast forms)."""

import numpy as np
import pytest

import pdeflow
from pdeflow.analysis import ritter

from .helpers import grid


def ritter_errors(n: int) -> tuple[float, float]:
    g = grid(n, -1.0, 1.0)
    x = g.axes_coords[0]
    eq = pdeflow.SingleLayerGranular(phi_b_deg=1e-9, bc=("open", "open"))
    st = eq.make_state(g, h=np.where(x < 0, 0.1, 0.0))
    res = eq.solve(st, t_range=0.5, solver="fv-split", cfl=0.9, tracker=None)
    h, u = ritter(x, 0.5, 0.1)
    dx = 2.0 / n
    return (float(np.abs(res.data[0] - h).sum() * dx),
            float(np.abs(res.data[1] - h * u).sum() * dx))


def test_ritter_first_order_convergence():
    """Frictionless dam break on a dry bed: L1 errors fall at the rate a first-order
    scheme reaches on a problem with a dry front and a kink (measured ~0.6-0.75)."""
    levels = [100, 200, 400, 800]
    errs = np.array([ritter_errors(n) for n in levels])
    orders = np.log2(errs[:-1] / errs[1:])
    assert np.all(orders > 0.55), orders
    assert np.all(orders[-1] > 0.65), orders
    # and the error itself is small: relative L1 depth error below 1 % at 800 cells
    assert errs[-1, 0] / (0.1 * 1.0) < 0.01


def test_ritter_two_layer_with_empty_upper_layer_matches_single_layer():
    """With no upper layer the two-layer model is the single-layer model."""
    n = 200
    g = grid(n, -1.0, 1.0)
    x = g.axes_coords[0]
    h = np.where(x < 0, 0.1, 0.0)
    one = pdeflow.SingleLayerGranular(phi_b_deg=20, bc=("open", "open"))
    two = pdeflow.TwoLayerGranular(phi_b_deg=20, bc=("open", "open"))
    a = one.solve(one.make_state(g, h=h), t_range=0.3, solver="fv-split", tracker=None)
    b = two.solve(two.make_state(g, h1=0 * h, h2=h), t_range=0.3, solver="fv-split",
                  tracker=None)
    assert np.all(b.data[0] == 0)
    np.testing.assert_allclose(b.data[2], a.data[0], atol=1e-13)
    np.testing.assert_allclose(b.data[3], a.data[1], atol=1e-13)


@pytest.mark.parametrize("theta, delta", [(30.0, 20.0)])
def test_mangeney_slope_with_friction(theta, delta):
    from pdeflow.analysis import mangeney

    n = 400
    g = grid(n, -1.0, 3.0)
    x = g.axes_coords[0]
    eq = pdeflow.SingleLayerGranular(theta_deg=theta, phi_b_deg=delta,
                                     bc=("open", "open"))
    st = eq.make_state(g, h=np.where(x < 0, 0.1, 0.0))
    res = eq.solve(st, t_range=0.3, solver="fv-split", cfl=0.9, tracker=None)
    h, _ = mangeney(x, 0.3, 0.1, theta_deg=theta, delta_deg=delta)
    err = np.abs(res.data[0] - h).sum() * 0.01
    assert err / 0.1 < 0.01
